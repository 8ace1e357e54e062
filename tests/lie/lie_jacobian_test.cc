// Every analytic Jacobian of SO3, SE3, Sim3 and SE23 (Exp, Log, Inverse, Compose, Act, Plus, Minus,
// Between, the left Jacobian; SE23's ActVelocity) against central differences on the manifold: the
// argument is perturbed by Plus (or +) and the result differenced by Minus (or −), as GTSAM's
// numericalDerivative does.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cheval/lie/se23.h"
#include "cheval/lie/se3.h"
#include "cheval/lie/sim3.h"
#include "cheval/lie/so3.h"

#include "lie_test_util.h"

namespace cheval::lie {
namespace {

using namespace ::cheval::lie::testing;

constexpr unsigned kSeed = 20240612;  // fixed, and every sample list restarts from it

// Central differences with step h have truncation error h²/6 · |f'''| and rounding error ε|f|/h;
// with h = 1e-5 and |f|, |f'''| ≤ ~10 on these samples both are ~1e-10 (the largest error observed
// is 3e-10 relative). The tolerance 1e-7, relative to max(1, largest entry), leaves a margin of 300
// while a wrong sign, block or coefficient changes entries by far more on the random samples.
// (Exactness at tiny angles, where a finite difference cannot resolve higher-order terms, is the
// Jet test's job.)
constexpr double kStep = 1e-5;
constexpr double kTol = 1e-7;

template <typename T>
using Delta = Eigen::Matrix<double, Dim<T>(), 1>;

// ∂(f(x ⊕ δ) ⊖ f(x))/∂δ at δ = 0 by central differences.
template <typename In, typename F>
auto NumericalJacobian(const F& f, const In& x) {
  using Out = std::decay_t<decltype(f(x))>;
  Eigen::Matrix<double, Dim<Out>(), Dim<In>()> j;
  const Out y = f(x);
  for (int i = 0; i < Dim<In>(); ++i) {
    Delta<In> d = Delta<In>::Zero();
    d[i] = kStep;
    j.col(i) =
        (Difference<Out>(f(Perturb(x, d)), y) - Difference<Out>(f(Perturb(x, Delta<In>(-d))), y)) /
        (2.0 * kStep);
  }
  return j;
}

template <typename A, typename B>
::testing::AssertionResult JacobianNear(const A& analytic, const B& numeric, double tol = kTol) {
  return MaxEntryNear(analytic, numeric, tol, "numeric");
}

// Tangents (for Exp and Plus): |ω| < π, ρ in ±2, log-scale σ in ±1 (±2 for "tiny rotation").
template <typename G>
std::vector<Sample<typename G::Tangent>> TangentSamples() {
  // The random ones then redraw σ in ±1 (one more draw each).
  const auto redraw_sigma = [](typename G::Tangent& tau, std::mt19937& rng) {
    if constexpr (G::kDoF == 7) tau[6] = Uniform(rng, -1.0, 1.0);
  };
  return MakeTangentSamples<G>(kSeed, TangentWithAngle<G>, redraw_sigma);
}

// Elements: Exp of the tangent samples plus exactly π. For Log, whose finite differences must not
// straddle the cut at θ = π, `log_safe` is false within 1e-3 of π (a 1e-5 step then stays inside);
// the Jet test checks Log at π − 1e-6 and at π.
template <typename G>
struct Element {
  std::string name;
  G value;
  bool log_safe;
};

template <typename G>
std::vector<Element<G>> ElementSamples() {
  std::vector<Element<G>> s;
  for (const auto& [name, tau] : TangentSamples<G>()) {
    s.push_back({name, G::Exp(tau), tau.template head<3>().norm() < kPi - 1e-3});
  }
  std::mt19937 rng(kSeed + 1);
  s.push_back({"pi", G::Exp(TangentWithAngle<G>(kPi, 2.0, rng)), false});
  s.push_back({"pi - 1e-3", G::Exp(TangentWithAngle<G>(kPi - 1e-3, 2.0, rng)), true});
  return s;
}

template <typename G>
class LieJacobianTest : public ::testing::Test {};

TYPED_TEST_SUITE(LieJacobianTest, Groups, GroupName);

TYPED_TEST(LieJacobianTest, Exp) {
  using G = TypeParam;
  for (const auto& [name, tau] : TangentSamples<G>()) {
    SCOPED_TRACE(name);
    typename G::Jacobian j;
    G::Exp(tau, &j);
    EXPECT_TRUE(JacobianNear(j, NumericalJacobian([](const auto& t) { return G::Exp(t); }, tau)));
    EXPECT_EQ(j, G::RightJacobian(tau));
  }
}

TYPED_TEST(LieJacobianTest, Log) {
  using G = TypeParam;
  for (const auto& [name, g, log_safe] : ElementSamples<G>()) {
    if (!log_safe) continue;
    SCOPED_TRACE(name);
    typename G::Jacobian j;
    const typename G::Tangent tau = g.Log(&j);
    EXPECT_TRUE(JacobianNear(j, NumericalJacobian([](const G& x) { return x.Log(); }, g)));
    EXPECT_EQ(j, G::InverseRightJacobian(tau));
  }
}

TYPED_TEST(LieJacobianTest, Inverse) {
  using G = TypeParam;
  for (const auto& [name, g, log_safe] : ElementSamples<G>()) {
    SCOPED_TRACE(name);
    typename G::Jacobian j;
    g.Inverse(&j);
    EXPECT_TRUE(JacobianNear(j, NumericalJacobian([](const G& x) { return x.Inverse(); }, g)));
  }
}

// The Jacobians of op(a, b, J_a*, J_b*) (kCompose, kBetween) at (g, h) against central differences
// in each argument.
template <typename G, typename Op>
void ExpectBothSidesNear(const G& g, const G& h, const Op& op) {
  typename G::Jacobian j_self, j_other;
  op(g, h, &j_self, &j_other);
  const auto on_self = [&](const G& x) { return op(x, h, nullptr, nullptr); };
  const auto on_other = [&](const G& x) { return op(g, x, nullptr, nullptr); };
  EXPECT_TRUE(JacobianNear(j_self, NumericalJacobian(on_self, g)));
  EXPECT_TRUE(JacobianNear(j_other, NumericalJacobian(on_other, h)));
}

TYPED_TEST(LieJacobianTest, ComposeBothSides) {
  const auto check = [](const auto& g, const auto& h) { ExpectBothSidesNear(g, h, kCompose); };
  ForEachPair(ElementSamples<TypeParam>(), 1, check);
}

TYPED_TEST(LieJacobianTest, ActBothSides) {
  using G = TypeParam;
  std::mt19937 rng(kSeed + 2);
  for (const Element<G>& sample : ElementSamples<G>()) {
    SCOPED_TRACE(sample.name);
    const G& g = sample.value;
    const Eigen::Vector3d p = RandomVector(rng, 10.0);
    typename G::PointJacobian j_self;
    Eigen::Matrix3d j_point;
    g.Act(p, &j_self, &j_point);
    EXPECT_TRUE(JacobianNear(j_self, NumericalJacobian([&p](const G& x) { return x.Act(p); }, g)));
    EXPECT_TRUE(JacobianNear(
        j_point, NumericalJacobian([&g](const Eigen::Vector3d& x) { return g.Act(x); }, p)));
  }
}

TYPED_TEST(LieJacobianTest, PlusBothSides) {
  using G = TypeParam;
  const std::vector<Element<G>> elements = ElementSamples<G>();
  const std::vector<Sample<typename G::Tangent>> tangents = TangentSamples<G>();
  for (std::size_t i = 0; i < elements.size(); ++i) {
    SCOPED_TRACE(elements[i].name);
    const G& g = elements[i].value;
    const typename G::Tangent& tau = tangents[(i + 7) % tangents.size()].value;
    typename G::Jacobian j_self, j_tangent;
    g.Plus(tau, &j_self, &j_tangent);
    EXPECT_TRUE(
        JacobianNear(j_self, NumericalJacobian([&tau](const G& x) { return x.Plus(tau); }, g)));
    EXPECT_TRUE(JacobianNear(
        j_tangent,
        NumericalJacobian([&g](const typename G::Tangent& t) { return g.Plus(t); }, tau)));
  }
}

TYPED_TEST(LieJacobianTest, MinusBothSides) {
  using G = TypeParam;
  const std::vector<Element<G>> elements = ElementSamples<G>();
  const std::vector<Sample<typename G::Tangent>> tangents = TangentSamples<G>();
  for (std::size_t i = 0; i < elements.size(); ++i) {
    SCOPED_TRACE(elements[i].name);
    // g ⊖ h = τ, a tangent sample; those within 1e-3 of the cut at |ω| = π are skipped so that the
    // finite differences of Log stay on one side of it.
    const G& h = elements[i].value;
    const typename G::Tangent& tau = tangents[(i + 11) % tangents.size()].value;
    if (tau.template head<3>().norm() > kPi - 1e-3) continue;
    const G g = h.Plus(tau);
    typename G::Jacobian j_self, j_other;
    g.Minus(h, &j_self, &j_other);
    EXPECT_TRUE(
        JacobianNear(j_self, NumericalJacobian([&h](const G& x) { return x.Minus(h); }, g)));
    EXPECT_TRUE(
        JacobianNear(j_other, NumericalJacobian([&g](const G& x) { return g.Minus(x); }, h)));
  }
}

TYPED_TEST(LieJacobianTest, BetweenBothSides) {
  const auto check = [](const auto& g, const auto& h) { ExpectBothSidesNear(g, h, kBetween); };
  ForEachPair(ElementSamples<TypeParam>(), 1, check);
}

TYPED_TEST(LieJacobianTest, LeftJacobianIsTheLeftDerivativeOfExp) {
  using G = TypeParam;
  for (const auto& [name, tau] : TangentSamples<G>()) {
    SCOPED_TRACE(name);
    // Exp(τ + δ) = Exp(J_l(τ) δ) Exp(τ): J_l(τ) = ∂ Log(Exp(τ + δ) Exp(τ)⁻¹)/∂δ at δ = 0.
    const G exp_inverse = G::Exp(tau).Inverse();
    const auto f = [&exp_inverse](const typename G::Tangent& t) {
      return (G::Exp(t) * exp_inverse).Log();
    };
    EXPECT_TRUE(JacobianNear(G::LeftJacobian(tau), NumericalJacobian(f, tau)));
  }
}

TEST(SE23JacobianTest, ActVelocityBothSides) {
  std::mt19937 rng(kSeed + 3);
  for (const Element<SE23d>& sample : ElementSamples<SE23d>()) {
    SCOPED_TRACE(sample.name);
    const SE23d& g = sample.value;
    const Eigen::Vector3d u = RandomVector(rng, 3.0);
    SE23d::PointJacobian j_self;
    Eigen::Matrix3d j_velocity;
    g.ActVelocity(u, &j_self, &j_velocity);
    EXPECT_TRUE(JacobianNear(
        j_self, NumericalJacobian([&u](const SE23d& x) { return x.ActVelocity(u); }, g)));
    EXPECT_TRUE(JacobianNear(
        j_velocity,
        NumericalJacobian([&g](const Eigen::Vector3d& x) { return g.ActVelocity(x); }, u)));
  }
}

}  // namespace
}  // namespace cheval::lie
