// Invariants of the Ceres manifold of include/cheval/estim/manifold.h (RightQuaternionManifold) and
// of its helpers QuaternionPlusJacobian and LiftRotationJacobian: Plus(x, 0) = x,
// Minus(Plus(x, δ), x) = δ, Plus(x, Minus(y, x)) = y, Minus(x, x) = 0, PlusJacobian and
// MinusJacobian against central differences, MinusJacobian · PlusJacobian = I, and agreement with
// lie::SO3's right plus and minus (the manifold is SO3 on Eigen's x, y, z, w storage). Points:
// identity, tiny and near-π rotations, a quaternion with w < 0 and seeded random ones.

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cheval/estim/manifold.h"
#include "cheval/lie/so3.h"

namespace cheval::estim {
namespace {

using Vector4 = Eigen::Vector4d;  // a quaternion's coefficients x, y, z, w
using PlusJacobianMatrix = Eigen::Matrix<double, 4, 3, Eigen::RowMajor>;
using MinusJacobianMatrix = Eigen::Matrix<double, 3, 4, Eigen::RowMajor>;

constexpr unsigned kSeed = 20240614;  // fixed, and every sample list restarts from it
constexpr double kPi = std::numbers::pi;

// Identities between unit quaternions and rotation vectors of size ≤ π: each side is a few dozen
// flops on numbers ≤ π, so rounding leaves ~1e-15; 1e-13 keeps a margin while a wrong sign or
// convention (left instead of right perturbation) changes entries by O(1) on the random samples.
constexpr double kTol = 1e-13;

// Central differences with step 1e-5: truncation h²/6 · |f'''| and rounding ε/h are both ~1e-11 for
// these unit-size functions; 1e-8 leaves a margin of 1000.
constexpr double kStep = 1e-5;
constexpr double kDiffTol = 1e-8;

struct Sample {
  std::string name;
  Vector4 x;
};

Eigen::Vector3d RandomUnitVector(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
}

Vector4 Coefficients(const Eigen::Vector3d& omega) {
  return lie::SO3d::Exp(omega).quaternion().coeffs();
}

std::vector<Sample> Points() {
  std::mt19937 rng(kSeed);
  std::normal_distribution<double> normal;
  std::vector<Sample> s;
  s.push_back({"identity", Vector4(0, 0, 0, 1)});
  s.push_back({"tiny", Coefficients(1e-8 * RandomUnitVector(rng))});
  s.push_back({"pi - 1e-6", Coefficients((kPi - 1e-6) * RandomUnitVector(rng))});
  const Eigen::Vector3d u = RandomUnitVector(rng);
  s.push_back({"pi", Vector4(u.x(), u.y(), u.z(), 0.0)});
  s.push_back({"w < 0", -Coefficients(Eigen::Vector3d(0.3, -0.5, 0.2))});
  for (int i = 0; i < 50; ++i) {
    s.push_back({"random " + std::to_string(i),
                 Vector4(normal(rng), normal(rng), normal(rng), normal(rng)).normalized()});
  }
  return s;
}

// Rotation vectors with |δ| < π (where Minus(Plus(x, δ), x) = δ holds): zero, tiny, π − 1e-6 and
// random ones.
std::vector<Eigen::Vector3d> Deltas() {
  std::mt19937 rng(kSeed + 1);
  std::vector<Eigen::Vector3d> d = {Eigen::Vector3d::Zero(), 1e-8 * RandomUnitVector(rng),
                                    (kPi - 1e-6) * RandomUnitVector(rng)};
  std::uniform_real_distribution<double> angle(0.0, kPi - 1e-6);
  while (d.size() < 55) d.push_back(angle(rng) * RandomUnitVector(rng));
  return d;
}

// Calls f(x, δ, y) for each point x, with a delta and the next point y (cyclically), under a
// SCOPED_TRACE of x's name.
template <typename F>
void ForEachCase(const F& f) {
  const std::vector<Sample> points = Points();
  const std::vector<Eigen::Vector3d> deltas = Deltas();
  for (std::size_t i = 0; i < points.size(); ++i) {
    SCOPED_TRACE(points[i].name);
    f(points[i].x, deltas[i % deltas.size()], points[(i + 1) % points.size()].x);
  }
}

Vector4 Plus(const Vector4& x, const Eigen::Vector3d& delta) {
  Vector4 out;
  EXPECT_TRUE(RightQuaternionManifold().Plus(x.data(), delta.data(), out.data()));
  return out;
}

Eigen::Vector3d Minus(const Vector4& y, const Vector4& x) {
  Eigen::Vector3d out;
  EXPECT_TRUE(RightQuaternionManifold().Minus(y.data(), x.data(), out.data()));
  return out;
}

lie::SO3d Rotation(const Vector4& x) {
  return lie::SO3d(Eigen::Quaterniond(x[3], x[0], x[1], x[2]));
}

// ∂f(x + h)/∂h at h = 0 by central differences, for f from R^kIn to R^kOut (row-major, as Ceres).
template <int kOut, int kIn, typename F>
Eigen::Matrix<double, kOut, kIn, Eigen::RowMajor> CentralDifferences(
    const F& f, const Eigen::Matrix<double, kIn, 1>& x) {
  Eigen::Matrix<double, kOut, kIn, Eigen::RowMajor> j;
  for (int i = 0; i < kIn; ++i) {
    const Eigen::Matrix<double, kIn, 1> step = kStep * Eigen::Matrix<double, kIn, 1>::Unit(i);
    j.col(i) = (f(x + step) - f(x - step)) / (2.0 * kStep);
  }
  return j;
}

// max |a − b| ≤ tol, printing both on failure.
template <typename A, typename B>
::testing::AssertionResult Near(const A& a, const B& b, double tol) {
  const double error = (a - b).cwiseAbs().maxCoeff();
  if (error <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "max error " << error << " > " << tol << "\nactual:\n"
                                       << a << "\nexpected:\n"
                                       << b;
}

TEST(RightQuaternionManifoldTest, Sizes) {
  const RightQuaternionManifold manifold;
  EXPECT_EQ(manifold.AmbientSize(), 4);
  EXPECT_EQ(manifold.TangentSize(), 3);
}

TEST(RightQuaternionManifoldTest, PlusZeroIsTheIdentity) {
  for (const auto& [name, x] : Points()) {
    SCOPED_TRACE(name);
    // Exact up to the re-normalisation of x (1 ulp), and the sign of x is kept.
    EXPECT_TRUE(Near(Plus(x, Eigen::Vector3d::Zero()), x, 4e-16));
  }
}

TEST(RightQuaternionManifoldTest, MinusOfItselfIsZero) {
  for (const auto& [name, x] : Points()) {
    SCOPED_TRACE(name);
    EXPECT_TRUE(Near(Minus(x, x), Eigen::Vector3d::Zero(), 1e-15));
  }
}

TEST(RightQuaternionManifoldTest, MinusUndoesPlusAndPlusUndoesMinus) {
  ForEachCase([](const Vector4& x, const Eigen::Vector3d& delta, const Vector4& y) {
    EXPECT_TRUE(Near(Minus(Plus(x, delta), x), delta, kTol));
    // y and −y are the same rotation: Plus(x, Minus(y, x)) is y up to sign.
    const Vector4 back = Plus(x, Minus(y, x));
    EXPECT_TRUE(Near(back.dot(y) < 0.0 ? Vector4(-back) : back, y, kTol));
  });
}

TEST(RightQuaternionManifoldTest, AgreesWithSO3RightPlusAndMinus) {
  ForEachCase([](const Vector4& x, const Eigen::Vector3d& delta, const Vector4& y) {
    // The same computation: equal to the last bit.
    EXPECT_EQ(Plus(x, delta), Rotation(x).Plus(delta).quaternion().coeffs());
    EXPECT_EQ(Minus(y, x), Rotation(y).Minus(Rotation(x)));
    // The right perturbation: R(x ⊞ δ) = R(x) Exp(δ), not Exp(δ) R(x).
    EXPECT_TRUE(Near(Rotation(Plus(x, delta)).Matrix(),
                     (Rotation(x).Matrix() * lie::SO3d::Exp(delta).Matrix()).eval(), kTol));
  });
}

TEST(RightQuaternionManifoldTest, PlusJacobianMatchesCentralDifferences) {
  const RightQuaternionManifold manifold;
  for (const auto& [name, x] : Points()) {
    SCOPED_TRACE(name);
    PlusJacobianMatrix analytic;
    ASSERT_TRUE(manifold.PlusJacobian(x.data(), analytic.data()));
    const auto plus = [&x](const Eigen::Vector3d& delta) { return Plus(x, delta); };
    const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
    EXPECT_TRUE(Near(analytic, CentralDifferences<4>(plus, zero), kDiffTol));
    EXPECT_EQ(analytic, PlusJacobianMatrix(QuaternionPlusJacobian(x.data())));
  }
}

TEST(RightQuaternionManifoldTest, MinusJacobianMatchesCentralDifferences) {
  // ∂Minus(y, x)/∂y at y = x in the 4 ambient coordinates: y off the unit sphere is normalised by
  // Minus, so the derivative along x itself is zero, as the analytic 4 Mᵀ (Mᵀx = 0) has it.
  const RightQuaternionManifold manifold;
  for (const auto& [name, x] : Points()) {
    SCOPED_TRACE(name);
    MinusJacobianMatrix analytic;
    ASSERT_TRUE(manifold.MinusJacobian(x.data(), analytic.data()));
    const auto minus = [&x](const Vector4& y) { return Minus(y, x); };
    EXPECT_TRUE(Near(analytic, CentralDifferences<3>(minus, x), kDiffTol));
  }
}

TEST(RightQuaternionManifoldTest, MinusJacobianTimesPlusJacobianIsTheIdentity) {
  const RightQuaternionManifold manifold;
  for (const auto& [name, x] : Points()) {
    SCOPED_TRACE(name);
    PlusJacobianMatrix plus;
    MinusJacobianMatrix minus;
    ASSERT_TRUE(manifold.PlusJacobian(x.data(), plus.data()));
    ASSERT_TRUE(manifold.MinusJacobian(x.data(), minus.data()));
    // 4 MᵀM = (x·x) I: exact up to the rounding of |x|² = 1.
    EXPECT_TRUE(Near((minus * plus).eval(), Eigen::Matrix3d::Identity(), 1e-15));
  }
}

TEST(LiftRotationJacobianTest, LiftedJacobianTimesPlusJacobianIsTheOriginal) {
  std::mt19937 rng(kSeed + 2);
  std::normal_distribution<double> normal;
  for (const auto& [name, x] : Points()) {
    SCOPED_TRACE(name);
    // A 2 x 3 Jacobian with respect to the right perturbation δ (row-major, as Ceres stores it).
    Eigen::Matrix<double, 2, 3, Eigen::RowMajor> j_delta;
    for (int k = 0; k < 6; ++k) j_delta.data()[k] = normal(rng);
    Eigen::Matrix<double, 2, 4, Eigen::RowMajor> j_q;
    LiftRotationJacobian(x.data(), j_delta.data(), 2, j_q.data());
    // J_q · M = J_δ · 4 MᵀM = J_δ (|x| = 1 to rounding); J_q · x = 0 (no change along x).
    EXPECT_TRUE(Near((j_q * QuaternionPlusJacobian(x.data())).eval(), j_delta, 1e-14));
    EXPECT_TRUE(Near((j_q * x).eval(), Eigen::Vector2d::Zero(), 1e-14));
  }
}

}  // namespace
}  // namespace cheval::estim
