// Invariants and closed-form values of the Lie groups SO3, SE3, Sim3 and SE23: one typed suite that
// every group passes, then group-specific values. Samples: identity, tiny (1e-8) angles, angles
// within 1e-6 of π, exactly π, and seeded random elements.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <unsupported/Eigen/MatrixFunctions>

#include "cheval/common/error.h"
#include "cheval/lie/detail.h"
#include "cheval/lie/se23.h"
#include "cheval/lie/se3.h"
#include "cheval/lie/sim3.h"
#include "cheval/lie/so3.h"

#include "lie_test_util.h"

// Compile every member for float too (the typed tests use double, the Jet test uses ceres::Jet),
// those each group inherits from LieGroupBase included.
template class cheval::lie::SO3<float>;
template class cheval::lie::SE3<float>;
template class cheval::lie::Sim3<float>;
template class cheval::lie::SE23<float>;
template class cheval::lie::LieGroupBase<cheval::lie::SO3<float>, float, 3, 3>;
template class cheval::lie::LieGroupBase<cheval::lie::SE3<float>, float, 6, 4>;
template class cheval::lie::LieGroupBase<cheval::lie::Sim3<float>, float, 7, 4>;
template class cheval::lie::LieGroupBase<cheval::lie::SE23<float>, float, 9, 5>;

namespace cheval::lie {
namespace {

using namespace ::cheval::lie::testing;

// Fixed, and every sample list restarts from it, so a failure reproduces even under a test filter.
constexpr unsigned kSeed = 20240611;

// Tolerance of identities between group elements and tangents. Each side is a few dozen flops on
// numbers of size ≤ 10 (translations up to 5 per axis, scales up to e²), so rounding leaves ~1e-14;
// 1e-12 keeps a margin of 100 while a wrong formula, sign or block shows far above it on the
// random samples. (Wrong high-order series terms are invisible at θ = 1e-8 by nature; the threshold
// tests at the end check those.)
constexpr double kTol = 1e-12;

Eigen::Quaterniond RandomQuaternion(std::mt19937& rng) {
  std::normal_distribution<double> normal;  // normalised Gaussian 4-vector: uniform on SO(3)
  return Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized();
}

// identity, tiny, tiny rotation with O(1) rest, within 1e-6 of π, exactly π (w = 0), random.
template <typename G>
std::vector<Sample<G>> ElementSamples() {
  std::mt19937 rng(kSeed);
  std::vector<Sample<G>> s;
  s.push_back({"identity", G::Identity()});
  s.push_back({"tiny", WithRotation<G>(SO3d::Exp(1e-8 * RandomUnitVector(rng)), 1e-8, rng)});
  s.push_back(
      {"tiny rotation", WithRotation<G>(SO3d::Exp(1e-8 * RandomUnitVector(rng)), 5.0, rng)});
  s.push_back(
      {"pi - 1e-6", WithRotation<G>(SO3d::Exp((kPi - 1e-6) * RandomUnitVector(rng)), 5.0, rng)});
  const Eigen::Vector3d axis = RandomUnitVector(rng);
  s.push_back({"pi", WithRotation<G>(SO3d(Eigen::Quaterniond(0.0, axis.x(), axis.y(), axis.z())),
                                     5.0, rng)});
  for (int i = 0; i < kRandomSamples; ++i) {
    s.push_back(
        {"random " + std::to_string(i), WithRotation<G>(SO3d(RandomQuaternion(rng)), 5.0, rng)});
  }
  return s;
}

// Tangents with |ω| < π (where Log(Exp(τ)) = τ holds).
template <typename G>
std::vector<Sample<typename G::Tangent>> TangentSamples() {
  return MakeTangentSamples<G>(kSeed + 1, TangentWithAngle<G>);
}

// ‖a − b‖_F ≤ tol · max(1, ‖b‖_F): for group matrices, whose rotation block has norm √3.
template <typename A, typename B>
::testing::AssertionResult MatrixNear(const A& a, const B& b, double tol) {
  const double error = (a - b).norm();
  if (error <= tol * std::max(1.0, b.norm())) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "error " << error << " > " << tol << " · max(1, " << b.norm() << ")\nactual:\n"
         << a << "\nexpected:\n"
         << b;
}

// ‖a − b‖ ≤ tol · ‖b‖: relative, so tiny (1e-8) tangents are checked at their own scale.
template <typename A, typename B>
::testing::AssertionResult VectorNear(const A& a, const B& b, double tol) {
  const double error = (a - b).norm();
  if (error <= tol * b.norm()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "error " << error << " > " << tol << " · " << b.norm()
         << "\nactual:   " << a.transpose() << "\nexpected: " << b.transpose();
}

// [p; 1] for 4x4 groups, [p; 1; 0] for SE23 (a point, not a velocity), p for SO3.
template <typename G>
Eigen::Matrix<double, G::kMatrixDim, 1> HomogeneousPoint(const Eigen::Vector3d& p) {
  Eigen::Matrix<double, G::kMatrixDim, 1> h = Eigen::Matrix<double, G::kMatrixDim, 1>::Zero();
  h.template head<3>() = p;
  if constexpr (G::kMatrixDim > 3) h[3] = 1.0;
  return h;
}

template <typename G>
class LieGroupTest : public ::testing::Test {};

TYPED_TEST_SUITE(LieGroupTest, Groups, GroupName);

TYPED_TEST(LieGroupTest, IdentityIsIdentityMatrixWithZeroLog) {
  using G = TypeParam;
  EXPECT_EQ(G::Identity().Matrix(), G::MatrixType::Identity());
  EXPECT_EQ(G::Identity().Log(), G::Tangent::Zero());
  EXPECT_EQ(G::Exp(G::Tangent::Zero()).Matrix(), G::MatrixType::Identity());
}

TYPED_TEST(LieGroupTest, ExpOfLogIsTheElement) {
  using G = TypeParam;
  for (const auto& [name, g] : ElementSamples<G>()) {
    SCOPED_TRACE(name);
    const typename G::Tangent tau = g.Log();
    // Log returns the principal rotation vector, |ω| ≤ π (ulp margin for the rounding of π).
    EXPECT_LE(tau.template head<3>().norm(), kPi * (1.0 + 1e-15));
    EXPECT_TRUE(MatrixNear(G::Exp(tau).Matrix(), g.Matrix(), kTol));
  }
}

TYPED_TEST(LieGroupTest, LogOfExpIsTheTangent) {
  using G = TypeParam;
  for (const auto& [name, tau] : TangentSamples<G>()) {
    SCOPED_TRACE(name);
    const typename G::Tangent log = G::Exp(tau).Log();
    if (tau.isZero(0.0)) {
      EXPECT_EQ(log, tau);  // exact: no rounding happens at zero
      continue;
    }
    if constexpr (G::kDoF == 7) {
      // Sim3's σ goes through the stored scale s = e^σ, which holds it to 1 ulp of 1 (1.1e-16)
      // absolute only: for σ = 1e-8 that is 1e-8 relative. The rest is relative as elsewhere.
      EXPECT_TRUE(VectorNear(log.template head<6>(), tau.template head<6>(), kTol));
      EXPECT_NEAR(log[6], tau[6], kTol * std::abs(tau[6]) + 2.3e-16);
    } else {
      EXPECT_TRUE(VectorNear(log, tau, kTol));
    }
  }
}

TYPED_TEST(LieGroupTest, LogAtExactlyPiReturnsAnAngleOfPi) {
  using G = TypeParam;
  std::mt19937 rng(kSeed);
  for (int i = 0; i < 10; ++i) {
    // Exp(π u) and the quaternion (0, u) are both rotations by π; Log may return ±π u.
    const typename G::Tangent tau = TangentWithAngle<G>(kPi, 2.0, rng);
    const G g = G::Exp(tau);
    const typename G::Tangent log = g.Log();
    // Components of size ≤ π, each rounded in Exp (sin, product) and in Log (θ/|v|, product):
    // ~4 ulps of π (ulp(π) = 4.4e-16) per component, 4e-15 on the vector.
    const Eigen::Vector3d omega = tau.template head<3>();
    const Eigen::Vector3d log_omega = log.template head<3>();
    EXPECT_NEAR(log_omega.norm(), kPi, 4e-15);
    EXPECT_LE(std::min((log_omega - omega).norm(), (log_omega + omega).norm()), 4e-15);
    EXPECT_TRUE(MatrixNear(G::Exp(log).Matrix(), g.Matrix(), kTol));
  }
}

TYPED_TEST(LieGroupTest, ExpMatchesTheMatrixExponential) {
  using G = TypeParam;
  for (const auto& [name, tau] : TangentSamples<G>()) {
    SCOPED_TRACE(name);
    // Eigen's Padé scaling-and-squaring exponential is accurate to ~1e-15 relative for these
    // norms (≤ 7); it is an independent check of Rodrigues, V and W.
    const typename G::MatrixType expected = G::Hat(tau).exp();
    EXPECT_TRUE(MatrixNear(G::Exp(tau).Matrix(), expected, kTol));
  }
}

TYPED_TEST(LieGroupTest, InverseComposesToIdentity) {
  using G = TypeParam;
  for (const auto& [name, g] : ElementSamples<G>()) {
    SCOPED_TRACE(name);
    const typename G::MatrixType eye = G::MatrixType::Identity();
    EXPECT_TRUE(MatrixNear((g * g.Inverse()).Matrix(), eye, kTol));
    EXPECT_TRUE(MatrixNear((g.Inverse() * g).Matrix(), eye, kTol));
    EXPECT_TRUE(MatrixNear(g.Inverse().Matrix(), g.Matrix().inverse().eval(), kTol));
  }
}

TYPED_TEST(LieGroupTest, CompositionIsAssociative) {
  using G = TypeParam;
  const std::vector<Sample<G>> s = ElementSamples<G>();
  for (std::size_t i = 0; i < s.size(); ++i) {
    SCOPED_TRACE(s[i].name);
    const G& g = s[i].value;
    const G& h = s[(i + 1) % s.size()].value;
    const G& k = s[(i + 2) % s.size()].value;
    // Entries grow to ~3 · 5 · e² ≈ 100 for Sim3 triples; MatrixNear is relative to that size.
    EXPECT_TRUE(MatrixNear(((g * h) * k).Matrix(), (g * (h * k)).Matrix(), kTol));
  }
}

TYPED_TEST(LieGroupTest, MatrixOfCompositionIsProductOfMatrices) {
  using G = TypeParam;
  const std::vector<Sample<G>> s = ElementSamples<G>();
  for (std::size_t i = 0; i < s.size(); ++i) {
    SCOPED_TRACE(s[i].name);
    const G& g = s[i].value;
    const G& h = s[(i + 3) % s.size()].value;
    EXPECT_TRUE(MatrixNear((g * h).Matrix(), (g.Matrix() * h.Matrix()).eval(), kTol));
    EXPECT_TRUE(MatrixNear(g.Compose(h).Matrix(), (g * h).Matrix(), 0.0));  // the same function
  }
}

TYPED_TEST(LieGroupTest, ActMatchesMatrixTimesHomogeneousPoint) {
  using G = TypeParam;
  std::mt19937 rng(kSeed);
  for (const auto& [name, g] : ElementSamples<G>()) {
    SCOPED_TRACE(name);
    const Eigen::Vector3d p = RandomVector(rng, 10.0);
    const Eigen::Matrix<double, G::kMatrixDim, 1> expected = g.Matrix() * HomogeneousPoint<G>(p);
    EXPECT_TRUE(MatrixNear(g.Act(p), expected.template head<3>().eval(), kTol));
  }
}

TYPED_TEST(LieGroupTest, PlusAndMinusRoundTrip) {
  using G = TypeParam;
  std::mt19937 rng(kSeed);
  const std::vector<Sample<G>> s = ElementSamples<G>();
  for (std::size_t i = 0; i < s.size(); ++i) {
    SCOPED_TRACE(s[i].name);
    const G& g = s[i].value;
    const G& h = s[(i + 1) % s.size()].value;
    const typename G::Tangent tau = TangentWithAngle<G>(Uniform(rng, 0.0, 3.0), 2.0, rng);
    EXPECT_TRUE(VectorNear(g.Plus(tau).Minus(g), tau, kTol));
    EXPECT_TRUE(MatrixNear(g.Plus(h.Minus(g)).Matrix(), h.Matrix(), kTol));
    EXPECT_TRUE(MatrixNear(g.Plus(tau).Matrix(), (g * G::Exp(tau)).Matrix(), kTol));
    EXPECT_TRUE(VectorNear(h.Minus(g), (g.Inverse() * h).Log(), kTol));
  }
}

TYPED_TEST(LieGroupTest, PlusZeroAndMinusSelf) {
  using G = TypeParam;
  for (const auto& [name, g] : ElementSamples<G>()) {
    SCOPED_TRACE(name);
    // Exp(0) is exactly the identity; the product is re-normalised (1 ulp).
    EXPECT_TRUE(MatrixNear(g.Plus(G::Tangent::Zero()).Matrix(), g.Matrix(), kTol));
    EXPECT_TRUE(MatrixNear(g.Minus(g), G::Tangent::Zero().eval(), kTol));
  }
}

TYPED_TEST(LieGroupTest, BetweenIsTheRelativeElement) {
  using G = TypeParam;
  ForEachPair(ElementSamples<G>(), 1, [](const G& g, const G& h) {
    const G between = g.Between(h);
    // The same operations in the same order: equal to the last bit.
    EXPECT_TRUE(MatrixNear(between.Matrix(), (g.Inverse() * h).Matrix(), 0.0));
    EXPECT_EQ(h.Minus(g), between.Log());
    EXPECT_TRUE(MatrixNear((g * between).Matrix(), h.Matrix(), kTol));
    EXPECT_TRUE(MatrixNear(g.Between(g).Matrix(), G::MatrixType::Identity(), kTol));
    // g_a_b.Between(g_a_c) = g_b_c, and Between reversed is its inverse.
    EXPECT_TRUE(MatrixNear(h.Between(g).Matrix(), between.Inverse().Matrix(), kTol));
  });
}

TYPED_TEST(LieGroupTest, AdjointConjugatesTheAlgebra) {
  using G = TypeParam;
  std::mt19937 rng(kSeed);
  for (const auto& [name, g] : ElementSamples<G>()) {
    SCOPED_TRACE(name);
    const typename G::Tangent tau = TangentWithAngle<G>(Uniform(rng, 0.0, 1.0), 1.0, rng);
    const typename G::MatrixType m = g.Matrix();
    const typename G::Tangent expected = G::Vee(m * G::Hat(tau) * m.inverse());
    EXPECT_TRUE(VectorNear((g.Adj() * tau).eval(), expected, kTol));
    // The group form of the same identity: g Exp(τ) g⁻¹ = Exp(Adj(g) τ).
    EXPECT_TRUE(
        MatrixNear(G::Exp(g.Adj() * tau).Matrix(), (g * G::Exp(tau) * g.Inverse()).Matrix(), kTol));
  }
}

TYPED_TEST(LieGroupTest, HatAndVeeAreInverse) {
  using G = TypeParam;
  std::mt19937 rng(kSeed);
  for (int i = 0; i < 10; ++i) {
    const typename G::Tangent tau = TangentWithAngle<G>(Uniform(rng, 0.0, 3.0), 5.0, rng);
    EXPECT_EQ(G::Vee(G::Hat(tau)), tau);  // exact: entries are copied (σ: 3σ/3 is exact here)
  }
}

TYPED_TEST(LieGroupTest, SmallAdjIsTheLieBracket) {
  using G = TypeParam;
  std::mt19937 rng(kSeed);
  for (int i = 0; i < 10; ++i) {
    const typename G::Tangent a = TangentWithAngle<G>(Uniform(rng, 0.0, 3.0), 2.0, rng);
    const typename G::Tangent b = TangentWithAngle<G>(Uniform(rng, 0.0, 3.0), 2.0, rng);
    const typename G::Tangent bracket = G::Vee(G::Hat(a) * G::Hat(b) - G::Hat(b) * G::Hat(a));
    EXPECT_TRUE(VectorNear((G::SmallAdj(a) * b).eval(), bracket, kTol));
  }
}

// J_r(τ) = Σ_k (−ad_τ)^k/(k+1)!, summed here to 80 terms (‖ad_τ‖ ≤ 8 for these samples, so the
// omitted terms are < 8⁸⁰/81! ≈ 1e-48). Terms peak near e^‖ad‖ ≈ 3e3, so the series itself carries
// ~1e-12 relative rounding: 1e-11 is the tolerance.
TYPED_TEST(LieGroupTest, RightJacobianEqualsAdjointSeries) {
  using G = TypeParam;
  for (const auto& [name, tau] : TangentSamples<G>()) {
    SCOPED_TRACE(name);
    const typename G::AdjointMatrix minus_ad = -G::SmallAdj(tau);
    typename G::Jacobian series = G::Jacobian::Zero();
    typename G::Jacobian power = G::Jacobian::Identity();  // (−ad)^k / (k+1)!
    for (int k = 0; k < 80; ++k) {
      series += power;
      power = (power * minus_ad / double(k + 2)).eval();
    }
    EXPECT_TRUE(MatrixNear(G::RightJacobian(tau), series, 1e-11));
  }
}

TYPED_TEST(LieGroupTest, InverseRightJacobianIsTheInverse) {
  using G = TypeParam;
  for (const auto& [name, tau] : TangentSamples<G>()) {
    SCOPED_TRACE(name);
    // J_r has condition number ≤ ~10 for |ω| < π and these translations: 1e-12 on the product.
    EXPECT_TRUE(MatrixNear((G::RightJacobian(tau) * G::InverseRightJacobian(tau)).eval(),
                           G::Jacobian::Identity(), kTol));
  }
}

TYPED_TEST(LieGroupTest, LeftAndRightJacobiansAreRelatedByTheAdjoint) {
  using G = TypeParam;
  for (const auto& [name, tau] : TangentSamples<G>()) {
    SCOPED_TRACE(name);
    // J_l(τ) = J_r(−τ) = Adj(Exp(τ)) J_r(τ).
    EXPECT_TRUE(MatrixNear((G::Exp(tau).Adj() * G::RightJacobian(tau)).eval(),
                           G::RightJacobian(-tau), kTol));
    EXPECT_EQ(G::LeftJacobian(tau), G::RightJacobian(-tau));
    EXPECT_EQ(G::InverseLeftJacobian(tau), G::InverseRightJacobian(-tau));
    EXPECT_TRUE(MatrixNear((G::LeftJacobian(tau) * G::InverseLeftJacobian(tau)).eval(),
                           G::Jacobian::Identity(), kTol));
  }
}

TYPED_TEST(LieGroupTest, CastKeepsTheElement) {
  using G = TypeParam;
  for (const auto& [name, g] : ElementSamples<G>()) {
    SCOPED_TRACE(name);
    // float has 24 bits (6e-8); the cast and re-normalisation round each entry once or twice.
    const auto as_float = g.template Cast<float>().Matrix().template cast<double>().eval();
    EXPECT_TRUE(MatrixNear(as_float, g.Matrix(), 3e-7));
    const auto back = g.template Cast<float>().template Cast<double>();
    EXPECT_TRUE(MatrixNear(back.Matrix(), g.Matrix(), 3e-7));
  }
}

// ------------------------------------------------------------------------------------------------
// SO3

TEST(SO3Test, ExpMatchesAngleAxis) {
  std::mt19937 rng(kSeed);
  for (const double angle : {0.0, 1e-8, 1e-3, 0.1, 1.0, 2.0, kPi - 1e-6, kPi, 4.0, 10.0}) {
    SCOPED_TRACE(angle);
    const Eigen::Vector3d axis = RandomUnitVector(rng);
    const Eigen::Matrix3d expected = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    // Both are Rodrigues to rounding: entries ≤ 1, a few flops each.
    EXPECT_TRUE(MatrixNear(SO3d::Exp(angle * axis).Matrix(), expected, 1e-15 * 4));
  }
}

TEST(SO3Test, QuarterTurnAboutZMapsXToY) {
  const Eigen::Vector3d y = SO3d::Exp(Eigen::Vector3d(0, 0, kPi / 2)).Act(Eigen::Vector3d::UnitX());
  // Entries 1 − 2(y² + z²) etc. of the matrix of q = (cos π/4, 0, 0, sin π/4): 2 ulps of 1.
  EXPECT_NEAR(y.x(), 0.0, 4.5e-16);
  EXPECT_NEAR(y.y(), 1.0, 4.5e-16);
  EXPECT_EQ(y.z(), 0.0);
}

TEST(SO3Test, LogNearPiIsAccurate) {
  std::mt19937 rng(kSeed);
  for (const double gap : {1e-3, 1e-6, 1e-9, 1e-12}) {
    SCOPED_TRACE(gap);
    const Eigen::Vector3d omega = (kPi - gap) * RandomUnitVector(rng);
    // The quaternion path keeps the angle to ~1 ulp of π even at 1e-12 from π, where the trace
    // formula acos((tr R − 1)/2) would lose ~6 of 16 digits.
    EXPECT_TRUE(VectorNear(SO3d::Exp(omega).Log(), omega, 2e-16 * 4));
  }
}

TEST(SO3Test, LogOfAHalfTurnQuaternionIsPiTimesTheAxis) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, -2, 2) / 3.0;
  const Eigen::Vector3d log = SO3d(Eigen::Quaterniond(0, axis.x(), axis.y(), axis.z())).Log();
  EXPECT_TRUE(VectorNear(log, (kPi * axis).eval(), 4e-16));
}

TEST(SO3Test, RotationMatrixConstructorCoversAllPivots) {
  std::mt19937 rng(kSeed);
  // The largest of w, x, y, z picks the branch: a small rotation (w), half turns about x, y, z.
  const std::vector<Eigen::Vector3d> omegas = {
      Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d(3.0, 0.1, -0.2),
      Eigen::Vector3d(0.1, 3.0, 0.2), Eigen::Vector3d(-0.2, 0.1, 3.0),
      Eigen::Vector3d(kPi, 0.0, 0.0)};
  for (const Eigen::Vector3d& omega : omegas) {
    SCOPED_TRACE(omega.transpose());
    const SO3d r = SO3d::Exp(omega);
    const SO3d from_matrix(r.Matrix());
    EXPECT_TRUE(MatrixNear(from_matrix.Matrix(), r.Matrix(), 1e-15 * 4));
    // The same quaternion up to sign.
    EXPECT_NEAR(std::abs(from_matrix.quaternion().coeffs().dot(r.quaternion().coeffs())), 1.0,
                1e-15);
  }
  for (int i = 0; i < 20; ++i) {
    const SO3d r(RandomQuaternion(rng));
    EXPECT_TRUE(MatrixNear(SO3d(r.Matrix()).Matrix(), r.Matrix(), 1e-15 * 4));
  }
}

TEST(SO3Test, QuaternionConstructorNormalises) {
  const Eigen::Quaterniond q(0.5, -0.5, 0.5, 0.5);  // unit
  const SO3d r(Eigen::Quaterniond(3.0 * q.coeffs()));
  EXPECT_NEAR((r.quaternion().coeffs() - q.coeffs()).norm(), 0.0, 2e-16);
  EXPECT_EQ(SO3d(Eigen::Quaterniond(2.0, 0, 0, 0)).Matrix(), Eigen::Matrix3d::Identity());
}

// ------------------------------------------------------------------------------------------------
// SE3

TEST(SE3Test, ExpOfScrewMotionHasKnownTranslation) {
  // ω = (0, 0, θ), ρ = (1, 0, 0): t = J_l(ω) ρ = (sin θ/θ, (1 − cos θ)/θ, 0) = (2/π, 2/π, 0).
  SE3d::Tangent tau;
  tau << 0, 0, kPi / 2, 1, 0, 0;
  const SE3d g = SE3d::Exp(tau);
  EXPECT_TRUE(VectorNear(g.translation(), Eigen::Vector3d(2 / kPi, 2 / kPi, 0), 4e-16));
}

TEST(SE3Test, ExpOfPureTranslationIsThatTranslation) {
  SE3d::Tangent tau;
  tau << 0, 0, 0, 1.5, -2, 3;
  EXPECT_EQ(SE3d::Exp(tau).translation(), Eigen::Vector3d(1.5, -2, 3));
  EXPECT_EQ(SE3d::Exp(tau).rotation().Matrix(), Eigen::Matrix3d::Identity());
}

TEST(SE3Test, MatrixConstructorsAgree) {
  std::mt19937 rng(kSeed);
  const Eigen::Quaterniond q = RandomQuaternion(rng);
  const Eigen::Vector3d t(1, 2, 3);
  const SE3d from_q(q, t);
  const SE3d from_r(q.toRotationMatrix(), t);
  EXPECT_TRUE(MatrixNear(from_q.Matrix(), from_r.Matrix(), 1e-15 * 4));
  EXPECT_EQ(from_q.translation(), t);
}

// ------------------------------------------------------------------------------------------------
// Sim3

TEST(Sim3Test, ExpOfPureScaleAndOfTranslationWithScale) {
  Sim3d::Tangent tau;
  tau << 0, 0, 0, 0, 0, 0, std::log(2.0);
  const Sim3d s = Sim3d::Exp(tau);
  EXPECT_NEAR(s.scale(), 2.0, 4e-16);
  EXPECT_EQ(s.translation(), Eigen::Vector3d::Zero());
  // Without rotation W = (e^σ − 1)/σ I.
  tau << 0, 0, 0, 1, -2, 0.5, 0.7;
  EXPECT_TRUE(VectorNear(Sim3d::Exp(tau).translation(),
                         (std::expm1(0.7) / 0.7 * Eigen::Vector3d(1, -2, 0.5)).eval(), 4e-16));
}

TEST(Sim3Test, ZeroLogScaleReducesToSE3) {
  std::mt19937 rng(kSeed);
  for (int i = 0; i < 20; ++i) {
    const SE3d::Tangent xi = TangentWithAngle<SE3d>(Uniform(rng, 0.0, 3.0), 2.0, rng);
    Sim3d::Tangent tau;
    tau << xi, 0.0;
    EXPECT_TRUE(MatrixNear(Sim3d::Exp(tau).Matrix(), SE3d::Exp(xi).Matrix(), kTol));
    const Sim3d::Jacobian j = Sim3d::RightJacobian(tau);
    EXPECT_TRUE(MatrixNear(j.topLeftCorner<6, 6>().eval(), SE3d::RightJacobian(xi), kTol));
  }
}

TEST(Sim3Test, NonPositiveScaleIsRejected) {
  const Eigen::Vector3d t = Eigen::Vector3d::Zero();
  EXPECT_THROW(Sim3d(SO3d(), t, 0.0), ComputeError);
  EXPECT_THROW(Sim3d(SO3d(), t, -1.0), ComputeError);
  EXPECT_THROW(Sim3d(SO3d(), t, std::nan("")), ComputeError);
  try {
    Sim3d(SO3d(), t, -0.5);
    FAIL() << "no exception";
  } catch (const ComputeError& e) {
    EXPECT_STREQ(e.what(), "Sim3: the scale must be positive, got -0.5");
  }
}

// ------------------------------------------------------------------------------------------------
// SE23

TEST(SE23Test, FrobeniusErrorSplitsIntoRotationPositionVelocity) {
  // docs/lie.md (the ASE): for E = Q⁻¹ P, ‖E − I₅‖²_F = ‖R_Qᵀ R_P − I‖²_F + |p_P − p_Q|² +
  // |v_P − v_Q|².
  const std::vector<Sample<SE23d>> s = ElementSamples<SE23d>();
  for (std::size_t i = 0; i < s.size(); ++i) {
    SCOPED_TRACE(s[i].name);
    const SE23d& q = s[i].value;
    const SE23d& p = s[(i + 1) % s.size()].value;
    const SE23d e = q.Inverse() * p;
    const double lhs = (e.Matrix() - Eigen::Matrix<double, 5, 5>::Identity()).squaredNorm();
    const double rotation =
        (q.rotation().Matrix().transpose() * p.rotation().Matrix() - Eigen::Matrix3d::Identity())
            .squaredNorm();
    const double rhs = rotation + (p.position() - q.position()).squaredNorm() +
                       (p.velocity() - q.velocity()).squaredNorm();
    // Sums of ~15 squares of size ≤ 20: rounding ~1e-14 relative.
    EXPECT_NEAR(lhs, rhs, 1e-13 * std::max(1.0, rhs));
  }
}

TEST(SE23Test, ActVelocityMatchesMatrixTimesVelocityVector) {
  std::mt19937 rng(kSeed);
  for (const auto& [name, g] : ElementSamples<SE23d>()) {
    SCOPED_TRACE(name);
    const Eigen::Vector3d u = RandomVector(rng, 3.0);
    Eigen::Matrix<double, 5, 1> h;
    h << u, 0.0, 1.0;
    const Eigen::Matrix<double, 5, 1> expected = g.Matrix() * h;
    EXPECT_TRUE(MatrixNear(g.ActVelocity(u), expected.head<3>().eval(), kTol));
  }
}

TEST(SE23Test, PoseAndVelocityPartsComposeLikeSE3) {
  const std::vector<Sample<SE23d>> s = ElementSamples<SE23d>();
  for (std::size_t i = 0; i < s.size(); ++i) {
    SCOPED_TRACE(s[i].name);
    const SE23d& a = s[i].value;
    const SE23d& b = s[(i + 1) % s.size()].value;
    const SE23d ab = a * b;
    const SE3d pose = SE3d(a.rotation(), a.position()) * SE3d(b.rotation(), b.position());
    const SE3d vel = SE3d(a.rotation(), a.velocity()) * SE3d(b.rotation(), b.velocity());
    EXPECT_TRUE(MatrixNear(SE3d(ab.rotation(), ab.position()).Matrix(), pose.Matrix(), kTol));
    EXPECT_TRUE(MatrixNear(SE3d(ab.rotation(), ab.velocity()).Matrix(), vel.Matrix(), kTol));
  }
}

TEST(SE23Test, ExpUsesTheSameLeftJacobianForPositionAndVelocity) {
  SE23d::Tangent tau;
  tau << 0.3, -1.2, 0.8, 1, 2, 3, 1, 2, 3;
  const SE23d g = SE23d::Exp(tau);
  EXPECT_EQ(g.position(), g.velocity());
  SE3d::Tangent xi;
  xi << tau.head<6>();
  EXPECT_TRUE(MatrixNear(g.position(), SE3d::Exp(xi).translation(), 0.0));
}

// ------------------------------------------------------------------------------------------------
// Series / closed-form thresholds: the branch is chosen by `x < threshold`, so the threshold itself
// takes the closed form and the next double below it the series. There the two branches must agree
// to rounding, which checks every coefficient of every series (an error in the θ⁸ coefficient of a
// series with threshold θ² = 1e-2 shows as ~1e-10). Tolerances: the closed forms lose up to 3
// digits to cancellation at the threshold (detail.h), so 1e-13 relative.

double Below(double threshold) { return std::nextafter(threshold, 0.0); }

TEST(LieDetailTest, RotationSeriesMatchClosedFormsAtTheThreshold) {
  const double below = Below(detail::kSeriesAngleSq);
  const double above = detail::kSeriesAngleSq;
  const auto h0 = detail::ComputeHalfAngle(below);
  const auto h1 = detail::ComputeHalfAngle(above);
  EXPECT_NEAR(h0.cos_half, h1.cos_half, 1e-13);
  EXPECT_NEAR(h0.sin_half_by_th, h1.sin_half_by_th, 1e-13 * 0.5);
  const auto r0 = detail::ComputeRotationCoefficients(below);
  const auto r1 = detail::ComputeRotationCoefficients(above);
  EXPECT_NEAR(r0.a, r1.a, 1e-13 * 0.5);
  EXPECT_NEAR(r0.b, r1.b, 1e-13 / 6);
  // D = 1/θ² − cot(θ/2)/(2θ) cancels 100 − 99.92 at θ² = 1e-2: 3.1 digits, so 3e-13 relative.
  EXPECT_NEAR(detail::ComputeInverseJacobianCoefficient(below),
              detail::ComputeInverseJacobianCoefficient(above), 3e-13 / 12);
  const auto q0 = detail::ComputeQCoefficients(Below(detail::kQSeriesAngleSq));
  const auto q1 = detail::ComputeQCoefficients(detail::kQSeriesAngleSq);
  EXPECT_NEAR(q0.c2, q1.c2, 1e-13 / 24);
  EXPECT_NEAR(q0.c3, q1.c3, 1e-13 / 120);
}

TEST(LieDetailTest, LogSeriesMatchesClosedFormAtTheThreshold) {
  for (const double v_sq : {Below(detail::kLogSeriesSinSq), detail::kLogSeriesSinSq}) {
    const double w = std::sqrt(1.0 - v_sq);
    const double expected = 2.0 * std::atan2(std::sqrt(v_sq), w) / std::sqrt(v_sq);
    EXPECT_NEAR(detail::ComputeAngleOverSinHalf(w, v_sq), expected, 1e-15 * 2);  // θ/|v| ≈ 2
  }
}

TEST(LieDetailTest, ExpMomentsAgreeAcrossBranches) {
  // M_k(σ) = ∫₀¹ s^k e^(σs) ds; the series (σ² < 1) and the recurrence (σ² ≥ 1) meet at ±1.
  for (const double sigma : {-1.0, 1.0}) {
    SCOPED_TRACE(sigma);
    const auto series = detail::ComputeExpMoments<20>(std::nextafter(sigma, 0.0));
    const auto recurrence = detail::ComputeExpMoments<20>(sigma);
    // The recurrence amplifies the rounding of M_0 (1e-16) by up to k!/|σ|^k = k! here, and the
    // moments enter the Sim(3) coefficients with weights 1/k! (detail.h): |ΔM_k| ≤ 1e-15 · k!.
    double factorial = 1.0;
    for (int k = 0; k < 20; ++k) {
      if (k > 0) factorial *= k;
      EXPECT_NEAR(series[k], recurrence[k], 1e-15 * factorial) << "k = " << k;
    }
    EXPECT_NEAR(recurrence[0], std::expm1(sigma) / sigma, 1e-15);
    EXPECT_NEAR(recurrence[1], (std::exp(sigma) * (sigma - 1) + 1) / (sigma * sigma), 1e-15);
  }
}

TEST(LieDetailTest, Sim3CoefficientsAgreeAcrossTheThreshold) {
  for (const double sigma : {-3.0, -1.0, -0.3, 0.0, 1e-9, 0.5, 1.0, 2.5}) {
    SCOPED_TRACE(sigma);
    const auto c0 = detail::ComputeSim3Coefficients(Below(detail::kSim3SeriesAngleSq), sigma);
    const auto c1 = detail::ComputeSim3Coefficients(detail::kSim3SeriesAngleSq, sigma);
    // Values ≤ e^2.5 ≈ 12; the closed forms at θ² = 0.25 lose ~1 digit (division by 2θ² twice).
    const double tol = 1e-13 * std::exp(std::max(sigma, 0.0));
    EXPECT_NEAR(c0.a0, c1.a0, tol);
    EXPECT_NEAR(c0.a1, c1.a1, tol);
    EXPECT_NEAR(c0.a2, c1.a2, tol);
    EXPECT_NEAR(c0.da0_dsigma, c1.da0_dsigma, tol);
    EXPECT_NEAR(c0.da1_dsigma, c1.da1_dsigma, tol);
    EXPECT_NEAR(c0.da2_dsigma, c1.da2_dsigma, tol);
    EXPECT_NEAR(c0.da1_dtheta_sq, c1.da1_dtheta_sq, tol);
    EXPECT_NEAR(c0.da2_dtheta_sq, c1.da2_dtheta_sq, tol);
  }
}

TEST(LieDetailTest, Sim3CoefficientsAtZeroScaleAreTheRotationOnes) {
  for (const double theta_sq : {0.0, 1e-16, 1e-3, 0.2, 0.3, 2.0, 9.0}) {
    SCOPED_TRACE(theta_sq);
    const auto c = detail::ComputeSim3Coefficients(theta_sq, 0.0);
    const auto r = detail::ComputeRotationCoefficients(theta_sq);
    EXPECT_NEAR(c.a0, 1.0, 1e-16);
    EXPECT_NEAR(c.a1, r.a, 1e-15);  // W(ω, 0) = J_l(ω)
    EXPECT_NEAR(c.a2, r.b, 1e-15);
  }
}

}  // namespace
}  // namespace cheval::lie
