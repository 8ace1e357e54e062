// The Lie groups with ceres::Jet scalars: every member compiles with Jets (explicit instantiation
// below), and the derivatives that Jets carry through Exp, Log, Inverse, Compose, Act, Plus, Minus
// and Between (and the left Jacobian) equal the analytic Jacobians, at identity, tiny angles,
// within 1e-6 of π, exactly π and on seeded random elements. Unlike finite differences this is
// exact up to rounding, so it also checks the small-angle series branches (their derivatives) and
// Log right at the cut.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include <ceres/jet.h>
#include <gtest/gtest.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cheval/lie/detail.h"
#include "cheval/lie/se23.h"
#include "cheval/lie/se3.h"
#include "cheval/lie/sim3.h"
#include "cheval/lie/so3.h"

#include "lie_test_util.h"

// Every member function of every group, those inherited from LieGroupBase and the Jacobian
// outputs included, compiles with Jets.
template class cheval::lie::SO3<ceres::Jet<double, 3>>;
template class cheval::lie::SE3<ceres::Jet<double, 6>>;
template class cheval::lie::Sim3<ceres::Jet<double, 7>>;
template class cheval::lie::SE23<ceres::Jet<double, 9>>;
template class cheval::lie::LieGroupBase<cheval::lie::SO3<ceres::Jet<double, 3>>,
                                         ceres::Jet<double, 3>, 3, 3>;
template class cheval::lie::LieGroupBase<cheval::lie::SE3<ceres::Jet<double, 6>>,
                                         ceres::Jet<double, 6>, 6, 4>;
template class cheval::lie::LieGroupBase<cheval::lie::Sim3<ceres::Jet<double, 7>>,
                                         ceres::Jet<double, 7>, 7, 4>;
template class cheval::lie::LieGroupBase<cheval::lie::SE23<ceres::Jet<double, 9>>,
                                         ceres::Jet<double, 9>, 9, 5>;

namespace cheval::lie {
namespace {

using namespace ::cheval::lie::testing;

constexpr unsigned kSeed = 20240613;  // fixed, and every sample list restarts from it

// Jets and the closed forms compute the same derivative along different roundings: chain rules
// through sin/cos/atan2/sqrt versus Jacobian formulas. Entries are ≤ ~30 and each side is a few
// hundred flops, so agreement is ~1e-14 relative; 1e-12 (relative to max(1, largest entry))
// leaves a margin of 100 and is 1e5 tighter than the finite-difference check.
constexpr double kTol = 1e-12;

// G<double> → G<S>.
template <typename G, typename S>
struct Rebind;
template <template <typename> class G, typename S>
struct Rebind<G<double>, S> {
  using type = G<S>;
};

template <typename T>
using ScalarOf = typename std::decay_t<T>::Scalar;

template <typename J, typename T>
auto ToJet(const T& x) {
  if constexpr (Group<T>) {
    return x.template Cast<J>();
  } else {
    return x.template cast<J>().eval();
  }
}

// ∂(f(x ⊕ δ) ⊖ f(x))/∂δ at δ = 0 by forward-mode autodiff: δ is a vector of Jets with unit
// derivatives, evaluated at zero. f must be generic in the scalar.
template <typename In, typename F>
auto AutoDiffJacobian(const F& f, const In& x) {
  constexpr int kIn = Dim<In>();
  using Jet = ceres::Jet<double, kIn>;
  using Out = std::decay_t<decltype(f(x))>;
  Eigen::Matrix<Jet, kIn, 1> delta;
  for (int i = 0; i < kIn; ++i) delta[i] = Jet(0.0, i);
  const auto x_jet = ToJet<Jet>(x);
  const auto y0 = f(x_jet);  // x_jet has zero derivatives: y0 is a constant
  const auto diff = Difference(f(Perturb(x_jet, delta)), y0);
  Eigen::Matrix<double, Dim<Out>(), kIn> j;
  for (int r = 0; r < Dim<Out>(); ++r) {
    for (int c = 0; c < kIn; ++c) j(r, c) = diff[r].v[c];
  }
  return j;
}

template <typename A, typename B>
::testing::AssertionResult JacobianNear(const A& analytic, const B& autodiff) {
  return MaxEntryNear(analytic, autodiff, kTol, "autodiff");
}

template <typename G>
std::vector<Sample<typename G::Tangent>> TangentSamples() {
  const auto draw = [](double angle, double extent, std::mt19937& rng) {
    typename G::Tangent tau = TangentWithAngle<G>(angle, extent, rng);
    if constexpr (G::kDoF == 7) tau[6] /= std::max(extent, 1.0);  // log-scale within ±1
    return tau;
  };
  return MakeTangentSamples<G>(kSeed, draw);
}

// Exp of the tangent samples, plus an element whose quaternion is (0, u): θ = π exactly, where Log
// sits on its cut and both Jets and J_r⁻¹ give the derivative of the branch with w ≥ 0.
template <typename G>
std::vector<Sample<G>> ElementSamples() {
  std::vector<Sample<G>> s;
  for (const auto& [name, tau] : TangentSamples<G>()) s.push_back({name, G::Exp(tau)});
  std::mt19937 rng(kSeed + 1);
  const Eigen::Vector3d u = RandomUnitVector(rng);
  // Other parts random in ±2 (log-scale ±1).
  s.push_back(
      {"pi", WithRotation<G>(SO3d(Eigen::Quaterniond(0.0, u.x(), u.y(), u.z())), 2.0, rng)});
  return s;
}

template <typename G>
class LieJetTest : public ::testing::Test {};

TYPED_TEST_SUITE(LieJetTest, Groups, GroupName);

TYPED_TEST(LieJetTest, Exp) {
  using G = TypeParam;
  for (const auto& [name, tau] : TangentSamples<G>()) {
    SCOPED_TRACE(name);
    typename G::Jacobian j;
    G::Exp(tau, &j);
    const auto f = [](const auto& t) { return Rebind<G, ScalarOf<decltype(t)>>::type::Exp(t); };
    EXPECT_TRUE(JacobianNear(j, AutoDiffJacobian(f, tau)));
  }
}

TYPED_TEST(LieJetTest, LeftJacobian) {
  using G = TypeParam;
  for (const auto& [name, tau] : TangentSamples<G>()) {
    SCOPED_TRACE(name);
    // Exp(τ + δ) = Exp(J_l(τ) δ) Exp(τ): J_l(τ) = ∂ Log(Exp(τ + δ) Exp(τ)⁻¹)/∂δ at δ = 0.
    const auto f = [&tau](const auto& t) {
      using GS = typename Rebind<G, ScalarOf<decltype(t)>>::type;
      return (GS::Exp(t) * GS::Exp(tau.template cast<ScalarOf<decltype(t)>>().eval()).Inverse())
          .Log();
    };
    EXPECT_TRUE(JacobianNear(G::LeftJacobian(tau), AutoDiffJacobian(f, tau)));
  }
}

TYPED_TEST(LieJetTest, Log) {
  using G = TypeParam;
  for (const auto& [name, g] : ElementSamples<G>()) {
    SCOPED_TRACE(name);
    typename G::Jacobian j;
    g.Log(&j);
    EXPECT_TRUE(JacobianNear(j, AutoDiffJacobian([](const auto& x) { return x.Log(); }, g)));
  }
}

TYPED_TEST(LieJetTest, Inverse) {
  using G = TypeParam;
  for (const auto& [name, g] : ElementSamples<G>()) {
    SCOPED_TRACE(name);
    typename G::Jacobian j;
    g.Inverse(&j);
    EXPECT_TRUE(JacobianNear(j, AutoDiffJacobian([](const auto& x) { return x.Inverse(); }, g)));
  }
}

// The Jacobians of op(a, b, J_a*, J_b*) (Compose, Between; op generic in the scalar) at (g, h)
// against autodiff in each argument.
template <typename G, typename Op>
void ExpectBothSidesNear(const G& g, const G& h, const Op& op) {
  typename G::Jacobian j_self, j_other;
  op(g, h, &j_self, &j_other);
  const auto on_self = [&](const auto& x) {
    return op(x, h.template Cast<ScalarOf<decltype(x)>>(), nullptr, nullptr);
  };
  const auto on_other = [&](const auto& x) {
    return op(g.template Cast<ScalarOf<decltype(x)>>(), x, nullptr, nullptr);
  };
  EXPECT_TRUE(JacobianNear(j_self, AutoDiffJacobian(on_self, g)));
  EXPECT_TRUE(JacobianNear(j_other, AutoDiffJacobian(on_other, h)));
}

TYPED_TEST(LieJetTest, ComposeBothSides) {
  const auto check = [](const auto& g, const auto& h) { ExpectBothSidesNear(g, h, kCompose); };
  ForEachPair(ElementSamples<TypeParam>(), 1, check);
}

TYPED_TEST(LieJetTest, ActBothSides) {
  using G = TypeParam;
  std::mt19937 rng(kSeed + 2);
  for (const Sample<G>& sample : ElementSamples<G>()) {
    SCOPED_TRACE(sample.name);
    const G& g = sample.value;
    const Eigen::Vector3d p = RandomVector(rng, 10.0);
    typename G::PointJacobian j_self;
    Eigen::Matrix3d j_point;
    g.Act(p, &j_self, &j_point);
    const auto on_group = [&p](const auto& x) {
      return x.Act(p.template cast<ScalarOf<decltype(x)>>().eval());
    };
    const auto on_point = [&g](const auto& x) {
      return g.template Cast<ScalarOf<decltype(x)>>().Act(x);
    };
    EXPECT_TRUE(JacobianNear(j_self, AutoDiffJacobian(on_group, g)));
    EXPECT_TRUE(JacobianNear(j_point, AutoDiffJacobian(on_point, p)));
  }
}

TYPED_TEST(LieJetTest, PlusBothSides) {
  using G = TypeParam;
  const std::vector<Sample<G>> elements = ElementSamples<G>();
  const std::vector<Sample<typename G::Tangent>> tangents = TangentSamples<G>();
  for (std::size_t i = 0; i < elements.size(); ++i) {
    SCOPED_TRACE(elements[i].name);
    const G& g = elements[i].value;
    const typename G::Tangent& tau = tangents[(i + 7) % tangents.size()].value;
    typename G::Jacobian j_self, j_tangent;
    g.Plus(tau, &j_self, &j_tangent);
    const auto on_group = [&tau](const auto& x) {
      return x.Plus(tau.template cast<ScalarOf<decltype(x)>>().eval());
    };
    const auto on_tangent = [&g](const auto& t) {
      return g.template Cast<ScalarOf<decltype(t)>>().Plus(t);
    };
    EXPECT_TRUE(JacobianNear(j_self, AutoDiffJacobian(on_group, g)));
    EXPECT_TRUE(JacobianNear(j_tangent, AutoDiffJacobian(on_tangent, tau)));
  }
}

TYPED_TEST(LieJetTest, MinusBothSides) {
  using G = TypeParam;
  const std::vector<Sample<G>> elements = ElementSamples<G>();
  const std::vector<Sample<typename G::Tangent>> tangents = TangentSamples<G>();
  for (std::size_t i = 0; i < elements.size(); ++i) {
    SCOPED_TRACE(elements[i].name);
    // g ⊖ h = τ, a tangent sample (zero, tiny, π − 1e-6 and random included).
    const G& h = elements[i].value;
    const G g = h.Plus(tangents[(i + 11) % tangents.size()].value);
    typename G::Jacobian j_self, j_other;
    g.Minus(h, &j_self, &j_other);
    const auto on_self = [&h](const auto& x) {
      return x.Minus(h.template Cast<ScalarOf<decltype(x)>>());
    };
    const auto on_other = [&g](const auto& x) {
      return g.template Cast<ScalarOf<decltype(x)>>().Minus(x);
    };
    EXPECT_TRUE(JacobianNear(j_self, AutoDiffJacobian(on_self, g)));
    EXPECT_TRUE(JacobianNear(j_other, AutoDiffJacobian(on_other, h)));
  }
}

TYPED_TEST(LieJetTest, BetweenBothSides) {
  const auto check = [](const auto& g, const auto& h) { ExpectBothSidesNear(g, h, kBetween); };
  ForEachPair(ElementSamples<TypeParam>(), 1, check);
}

TEST(SE23JetTest, ActVelocityBothSides) {
  std::mt19937 rng(kSeed + 3);
  for (const Sample<SE23d>& sample : ElementSamples<SE23d>()) {
    SCOPED_TRACE(sample.name);
    const SE23d& g = sample.value;
    const Eigen::Vector3d u = RandomVector(rng, 3.0);
    SE23d::PointJacobian j_self;
    Eigen::Matrix3d j_velocity;
    g.ActVelocity(u, &j_self, &j_velocity);
    const auto on_group = [&u](const auto& x) {
      return x.ActVelocity(u.template cast<ScalarOf<decltype(x)>>().eval());
    };
    const auto on_velocity = [&g](const auto& x) {
      return g.template Cast<ScalarOf<decltype(x)>>().ActVelocity(x);
    };
    EXPECT_TRUE(JacobianNear(j_self, AutoDiffJacobian(on_group, g)));
    EXPECT_TRUE(JacobianNear(j_velocity, AutoDiffJacobian(on_velocity, u)));
  }
}

// The static Jacobians through Jets as well: RightJacobian(τ) is the derivative of Exp, and its
// inverse that of Log, also where the Sim(3) coefficients switch from series to closed form.
TEST(Sim3JetTest, RightJacobianAcrossTheSeriesThreshold) {
  std::mt19937 rng(kSeed + 4);
  const double threshold_angle = std::sqrt(detail::kSim3SeriesAngleSq);
  for (const double angle : {std::nextafter(threshold_angle, 0.0), threshold_angle, 1e-8, 0.0}) {
    for (const double sigma : {-2.0, -1.0, 0.0, 1e-9, 1.0, 2.0}) {
      SCOPED_TRACE(std::to_string(angle) + " " + std::to_string(sigma));
      Sim3d::Tangent tau = TangentWithAngle<Sim3d>(angle, 2.0, rng);
      tau[6] = sigma;
      const auto f = [](const auto& t) { return Sim3<ScalarOf<decltype(t)>>::Exp(t); };
      EXPECT_TRUE(JacobianNear(Sim3d::RightJacobian(tau), AutoDiffJacobian(f, tau)));
    }
  }
}

}  // namespace
}  // namespace cheval::lie
