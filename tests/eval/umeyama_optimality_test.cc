// Umeyama's reflection branch is optimal, not merely proper. When the point sets are mirrored (or
// nearly planar and noisy) the best orthogonal map is a reflection (det(U)·det(V) < 0); Umeyama's
// S = diag(1, 1, -1) then gives the best *rotation*. A det = +1 check alone passes for any flip
// (S = diag(-1, 1, 1) is also proper, and wrong), so here the result is compared with an independent
// closed form that can only produce rotations — Horn's unit-quaternion method (Horn 1987, "Closed-
// form solution of absolute orientation using unit quaternions", §4: the eigenvector of the largest
// eigenvalue of the 4 x 4 matrix N) — and its cost with random and perturbed rotations. SE(3),
// Sim(3) (whose scale tr(DS)/σ² depends on S too) and the scale-only alignment.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include "cheval/eval/align.h"
#include "cheval/eval/associate.h"
#include "cheval/eval/pairs.h"
#include "eval_test_util.h"

namespace cheval::eval {
namespace {

// Σ |y_i − (c R x_i + t)|².
double Cost(const Similarity& s, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y) {
  double sum = 0;
  for (Eigen::Index i = 0; i < x.cols(); ++i) sum += (y.col(i) - s.ApplyToPoint(x.col(i))).squaredNorm();
  return sum;
}

// For a fixed rotation R the best translation (and, with scale, the best c >= 0) in closed form:
// c = max(0, Σ y'ᵀ R x' / Σ |x'|²) on centred points, t = ȳ − c R x̄. (A negative c would make c R
// the reflection −|c| R: not a similarity.)
Similarity BestFor(const Eigen::Matrix3d& rotation, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y,
                   bool with_scale) {
  const Eigen::Vector3d mx = x.rowwise().mean(), my = y.rowwise().mean();
  const Eigen::Matrix3Xd xc = x.colwise() - mx, yc = y.colwise() - my;
  Similarity s;
  s.rotation = rotation;
  s.scale = with_scale ? std::max(0.0, (yc.cwiseProduct(rotation * xc)).sum() / xc.squaredNorm()) : 1.0;
  s.translation = my - s.scale * (rotation * mx);
  return s;
}

// Horn's quaternion solution: with M = Σ x' y'ᵀ (centred), the rotation taking x onto y is the unit
// quaternion of the largest eigenvalue of N (Horn 1987, eq. in §4.A). A quaternion is always a
// proper rotation: no SVD, no sign correction.
Eigen::Matrix3d HornRotation(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y) {
  const Eigen::Matrix3Xd xc = x.colwise() - x.rowwise().mean(), yc = y.colwise() - y.rowwise().mean();
  const Eigen::Matrix3d M = xc * yc.transpose();
  const double sxx = M(0, 0), sxy = M(0, 1), sxz = M(0, 2), syx = M(1, 0), syy = M(1, 1), syz = M(1, 2),
               szx = M(2, 0), szy = M(2, 1), szz = M(2, 2);
  Eigen::Matrix4d N;
  N << sxx + syy + szz, syz - szy, szx - sxz, sxy - syx,  //
      syz - szy, sxx - syy - szz, sxy + syx, szx + sxz,     //
      szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy,    //
      sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eigen(N);  // eigenvalues ascending
  const Eigen::Vector4d q = eigen.eigenvectors().col(3);
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
}

// Whether the unconstrained orthogonal optimum is a reflection: det(U)·det(V) < 0 for the SVD of the
// cross-covariance (the case the branch handles). Computed here only to prove the data reach it.
bool BestOrthogonalIsAReflection(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y) {
  const Eigen::Matrix3Xd xc = x.colwise() - x.rowwise().mean(), yc = y.colwise() - y.rowwise().mean();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(yc * xc.transpose(), Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU().determinant() * svd.matrixV().determinant() < 0;
}

Eigen::Matrix3d Exp(const Eigen::Vector3d& w) {
  return w.norm() == 0 ? Eigen::Matrix3d::Identity() : Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
}

// Points with distinct spreads (5, 2, 0.5 m along random axes) so that the singular values are well
// separated and the optimum is unique.
Eigen::Matrix3Xd AnisotropicPoints(std::mt19937_64& rng, Eigen::Index n, double thin = 0.5) {
  std::normal_distribution<double> g;
  const Eigen::Matrix3d axes = testing::RandomRotation(rng).toRotationMatrix();
  Eigen::Matrix3Xd x(3, n);
  for (Eigen::Index i = 0; i < n; ++i) x.col(i) = axes * Eigen::Vector3d(5.0 * g(rng), 2.0 * g(rng), thin * g(rng));
  return x;
}

// y = c R0 (mirror x) + t + noise: a reflection through a random plane, then a random similarity.
Eigen::Matrix3Xd Mirrored(std::mt19937_64& rng, const Eigen::Matrix3Xd& x, double scale, double noise) {
  std::normal_distribution<double> g;
  const Eigen::Vector3d normal = testing::RandomRotation(rng) * Eigen::Vector3d::UnitX();
  const Eigen::Matrix3d mirror = Eigen::Matrix3d::Identity() - 2.0 * normal * normal.transpose();
  const Similarity s = testing::RandomSimilarity(rng, scale);
  Eigen::Matrix3Xd y(3, x.cols());
  for (Eigen::Index i = 0; i < x.cols(); ++i) {
    y.col(i) = s.ApplyToPoint(mirror * x.col(i)) + noise * Eigen::Vector3d(g(rng), g(rng), g(rng));
  }
  return y;
}

// Checks that `s` is a proper rotation equal to Horn's, with Horn's optimal scale and translation,
// and that no random or perturbed rotation (each with its best t and c) does better.
void ExpectOptimalAmongRotations(const Similarity& s, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y,
                                 bool with_scale, std::mt19937_64& rng) {
  EXPECT_NEAR(s.rotation.determinant(), 1.0, 1e-12);
  EXPECT_LT((s.rotation.transpose() * s.rotation - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  // The two closed forms agree to rounding: both are the unique optimum and the eigen- and singular-value
  // gaps of these data are O(1) relative. Measured over every call here: rotation 9.4e-15, scale 1.1e-15
  // relative, translation 3.7e-15 m (points ~10 m); the bounds are ~5x that, since rounding varies with
  // the SVD's and the eigensolver's iteration counts.
  const Similarity horn = BestFor(HornRotation(x, y), x, y, with_scale);
  EXPECT_LT((s.rotation - horn.rotation).norm(), 5e-14);
  EXPECT_NEAR(s.scale, horn.scale, 1e-14 * horn.scale);
  EXPECT_LT((s.translation - horn.translation).norm(), 3e-14);
  const double cost = Cost(s, x, y), slack = 1e-12 * cost + 1e-12;
  EXPECT_LE(cost, Cost(horn, x, y) + slack);
  // Many random rotations, each with its own best translation (and scale): none is better.
  for (int k = 0; k < 2000; ++k) {
    const Similarity other = BestFor(testing::RandomRotation(rng).toRotationMatrix(), x, y, with_scale);
    ASSERT_LE(cost, Cost(other, x, y) + slack) << "random rotation " << k;
  }
  // Local optimality: R·exp(±ε e_k) for ε = 1e-3 rad raises the cost (by ~ε² times the spread).
  for (int axis = 0; axis < 3; ++axis) {
    for (double eps : {1e-3, -1e-3}) {
      const Similarity near = BestFor(s.rotation * Exp(eps * Eigen::Vector3d::Unit(axis)), x, y, with_scale);
      EXPECT_LT(cost, Cost(near, x, y)) << "axis " << axis << " eps " << eps;
    }
  }
}

// The unconstrained optimum U Vᵀ (a reflection here) scores better than any rotation: what a solver
// without the sign correction would return.
Similarity BestOrthogonal(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, bool with_scale) {
  const Eigen::Matrix3Xd xc = x.colwise() - x.rowwise().mean(), yc = y.colwise() - y.rowwise().mean();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(yc * xc.transpose(), Eigen::ComputeFullU | Eigen::ComputeFullV);
  return BestFor(svd.matrixU() * svd.matrixV().transpose(), x, y, with_scale);
}

TEST(UmeyamaOptimalityTest, MirroredPointsSE3AndSim3) {
  std::mt19937_64 rng(21);
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::Matrix3Xd x = AnisotropicPoints(rng, 40);
    const Eigen::Matrix3Xd y = Mirrored(rng, x, 0.5 + 0.2 * trial, 0.05);
    ASSERT_TRUE(BestOrthogonalIsAReflection(x, y)) << "trial " << trial;
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    for (bool with_scale : {false, true}) {
      const Similarity s = UmeyamaAlignment(x, y, with_scale);
      ExpectOptimalAmongRotations(s, x, y, with_scale, rng);
      EXPECT_LT(Cost(BestOrthogonal(x, y, with_scale), x, y), Cost(s, x, y));  // the reflection fits better
    }
  }
}

// Nearly planar points (0.5 mm thick) with 1 cm noise and a proper transform: the noise decides the
// sign of the third singular direction, so some draws fall in the reflection branch and some not.
// Both must be the best rotation.
TEST(UmeyamaOptimalityTest, NearlyPlanarNoisyPointsHitTheBranch) {
  std::mt19937_64 rng(22);
  std::normal_distribution<double> g;
  int reflections = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Eigen::Matrix3Xd x = AnisotropicPoints(rng, 30, 0.0005);
    const Similarity truth = testing::RandomSimilarity(rng, 1.3);
    Eigen::Matrix3Xd y(3, x.cols());
    for (Eigen::Index i = 0; i < x.cols(); ++i) {
      y.col(i) = truth.ApplyToPoint(x.col(i)) + 0.01 * Eigen::Vector3d(g(rng), g(rng), g(rng));
    }
    reflections += BestOrthogonalIsAReflection(x, y) ? 1 : 0;
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    // Measured here: rotation within 5.2e-15 of Horn's, scale 1.0e-15 relative, cost 6.2e-14 relative
    // (the noise, 1 cm against 0.5 mm of thickness, keeps the third singular direction well defined).
    for (bool with_scale : {false, true}) {
      const Similarity s = UmeyamaAlignment(x, y, with_scale);
      const Similarity horn = BestFor(HornRotation(x, y), x, y, with_scale);
      EXPECT_NEAR(s.rotation.determinant(), 1.0, 1e-12);
      EXPECT_LT((s.rotation - horn.rotation).norm(), 5e-14);
      const double cost = Cost(s, x, y);
      EXPECT_LE(cost, Cost(horn, x, y) * (1 + 5e-13));
      EXPECT_NEAR(s.scale, horn.scale, 1e-14 * horn.scale);
      for (int k = 0; k < 200; ++k) {
        ASSERT_LE(cost, Cost(BestFor(testing::RandomRotation(rng).toRotationMatrix(), x, y, with_scale), x, y));
      }
    }
  }
  // The seeded draw gives 14 of 40; enough of both kinds must occur for the test to mean anything.
  EXPECT_GE(reflections, 5);
  EXPECT_LE(reflections, 35);
}

// The scale-only alignment (evo --correct_scale) is Umeyama's Sim(3) scale tr(DS)/σ², so on mirrored
// data it must use S too: it equals the scale of the best Sim(3) among rotations (Horn's).
TEST(UmeyamaOptimalityTest, ScaleOnlyUsesTheCorrectedScale) {
  std::mt19937_64 rng(23);
  const Eigen::Matrix3Xd x = AnisotropicPoints(rng, 40);
  const Eigen::Matrix3Xd y = Mirrored(rng, x, 2.0, 0.05);
  ASSERT_TRUE(BestOrthogonalIsAReflection(x, y));
  std::vector<testing::PoseSpec> ref, est;
  for (Eigen::Index i = 0; i < x.cols(); ++i) {
    ref.push_back({i * 100'000'000, y.col(i)});
    est.push_back({i * 100'000'000, x.col(i)});
  }
  const traj::Trajectory r = testing::MakeTrajectory(ref), e = testing::MakeTrajectory(est);
  const Association association = Associate(r.View(), e.View());
  const PairedStates pairs(r.View(), e.View(), association);
  AlignmentOptions options;
  options.method = AlignmentMethod::kScale;
  const AlignmentResult scale = ComputeAlignment(pairs, options);
  const double horn_scale = BestFor(HornRotation(x, y), x, y, true).scale;
  EXPECT_NEAR(scale.transform.scale, horn_scale, 1e-9 * horn_scale);
  EXPECT_TRUE(scale.transform.rotation.isIdentity(0.0));
  // Without the correction the scale would be Σ singular values / σ² (the reflection's), larger by
  // 2 d₃ / σ²: make sure the data separate the two by far more than the tolerance.
  const Eigen::Matrix3Xd xc = x.colwise() - x.rowwise().mean(), yc = y.colwise() - y.rowwise().mean();
  const double uncorrected =
      Eigen::JacobiSVD<Eigen::Matrix3d>(yc * xc.transpose()).singularValues().sum() / xc.squaredNorm();
  EXPECT_GT(uncorrected - horn_scale, 1e-3 * horn_scale);
  // The same through ComputeAlignment's Sim(3) and SE(3).
  options.method = AlignmentMethod::kSim3;
  const AlignmentResult sim3 = ComputeAlignment(pairs, options);
  ExpectOptimalAmongRotations(sim3.transform, x, y, true, rng);
  options.method = AlignmentMethod::kSE3;
  ExpectOptimalAmongRotations(ComputeAlignment(pairs, options).transform, x, y, false, rng);
}

// Horn's method itself (the test's reference) recovers a known proper transform: a check of the
// helper, so that agreement above means something.
TEST(UmeyamaOptimalityTest, HornReferenceRecoversAKnownRotation) {
  std::mt19937_64 rng(24);
  const Eigen::Matrix3Xd x = AnisotropicPoints(rng, 20);
  const Similarity truth = testing::RandomSimilarity(rng, 1.7);
  Eigen::Matrix3Xd y(3, x.cols());
  for (Eigen::Index i = 0; i < x.cols(); ++i) y.col(i) = truth.ApplyToPoint(x.col(i));
  const Similarity horn = BestFor(HornRotation(x, y), x, y, true);
  EXPECT_LT((horn.rotation - truth.rotation).norm(), 1e-12);
  EXPECT_NEAR(horn.scale, 1.7, 1e-12);
  EXPECT_LT((horn.translation - truth.translation).norm(), 1e-10);
}

}  // namespace
}  // namespace cheval::eval
