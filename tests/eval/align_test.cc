// Alignment: Umeyama recovers a known SE(3) / Sim(3) exactly from noise-free points, handles the
// reflection case, rejects degenerate input; position + yaw, origin and full-state alignment; the
// alignment is applied to orientation, position and velocity.
#include "cheval/eval/align.h"

#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "cheval/common/error.h"
#include "cheval/eval/metrics.h"
#include "cheval/eval/statistics.h"
#include "eval_test_util.h"

namespace cheval::eval {
namespace {

using testing::AxisAngle;
using testing::MakeTrajectory;
using testing::PoseSpec;

Eigen::Matrix3Xd RandomPoints(std::mt19937_64& rng, Eigen::Index n) {
  std::normal_distribution<double> g;
  Eigen::Matrix3Xd x(3, n);
  for (Eigen::Index i = 0; i < n; ++i) x.col(i) = Eigen::Vector3d(g(rng), g(rng), g(rng)) * 5.0;
  return x;
}

Eigen::Matrix3Xd Apply(const Similarity& s, const Eigen::Matrix3Xd& x) {
  Eigen::Matrix3Xd y(3, x.cols());
  for (Eigen::Index i = 0; i < x.cols(); ++i) y.col(i) = s.ApplyToPoint(x.col(i));
  return y;
}

// Noise-free points: Umeyama returns the transform that made them (to rounding, 1e-12 on unit-size
// quantities: the SVD of a 3x3 is accurate to a few ulps times the condition number, here < 10).
TEST(AlignTest, UmeyamaRecoversKnownTransforms) {
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Matrix3Xd x = RandomPoints(rng, 50);
    const Similarity truth = testing::RandomSimilarity(rng, 0.5 + trial * 0.1);
    const Similarity sim3 = UmeyamaAlignment(x, Apply(truth, x), true);
    EXPECT_LT((sim3.rotation - truth.rotation).norm(), 1e-12);
    EXPECT_LT((sim3.translation - truth.translation).norm(), 1e-11);
    EXPECT_NEAR(sim3.scale, truth.scale, 1e-12);
    Similarity rigid = truth;
    rigid.scale = 1.0;
    const Similarity se3 = UmeyamaAlignment(x, Apply(rigid, x), false);
    EXPECT_LT((se3.rotation - rigid.rotation).norm(), 1e-12);
    EXPECT_LT((se3.translation - rigid.translation).norm(), 1e-11);
    EXPECT_EQ(se3.scale, 1.0);
  }
}

// A mirrored point set: the best orthogonal map is a reflection; Umeyama's S = diag(1, 1, -1) keeps a
// proper rotation (det +1).
TEST(AlignTest, UmeyamaReturnsARotationForMirroredPoints) {
  std::mt19937_64 rng(4);
  const Eigen::Matrix3Xd x = RandomPoints(rng, 30);
  Eigen::Matrix3Xd y = x;
  y.row(2) *= -1;
  const Similarity s = UmeyamaAlignment(x, y, false);
  EXPECT_NEAR(s.rotation.determinant(), 1.0, 1e-12);
  EXPECT_LT((s.rotation.transpose() * s.rotation - Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

TEST(AlignTest, DegenerateInputThrows) {
  Eigen::Matrix3Xd line(3, 5);
  for (int i = 0; i < 5; ++i) line.col(i) = Eigen::Vector3d(i, 2.0 * i, 0.0);
  testing::ExpectThrowWith<ComputeError>([&] { UmeyamaAlignment(line, line, false); }, {"degenerate"});
  Eigen::Matrix3Xd two(3, 2);
  two << 0, 1, 0, 1, 0, 1;
  testing::ExpectThrowWith<ComputeError>([&] { UmeyamaAlignment(two, two, true); },
                                         {"at least 3 associated pairs, got 2"});
  Eigen::Matrix3Xd vertical(3, 4);
  vertical << 0, 0, 0, 0, 0, 0, 0, 0, 1, 2, 3, 4;
  EXPECT_THROW(PositionYawAlignment(vertical, vertical), ComputeError);
}

// Yaw-only motion between the frames: posyaw finds it exactly, as SE(3) does.
TEST(AlignTest, PositionYawRecoversAYawAndTranslation) {
  std::mt19937_64 rng(5);
  const Eigen::Matrix3Xd x = RandomPoints(rng, 40);
  for (double yaw : {0.3, -2.5, std::numbers::pi - 1e-3}) {
    Similarity truth;
    truth.rotation = AxisAngle(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    truth.translation = Eigen::Vector3d(1, -2, 3);
    const Similarity s = PositionYawAlignment(x, Apply(truth, x));
    EXPECT_LT((s.rotation - truth.rotation).norm(), 1e-12) << yaw;
    EXPECT_LT((s.translation - truth.translation).norm(), 1e-11) << yaw;
  }
  // With a roll as well, posyaw keeps z up: its rotation is about z only.
  Similarity tilted;
  tilted.rotation = (AxisAngle(0.7, Eigen::Vector3d::UnitZ()) * AxisAngle(0.2, Eigen::Vector3d::UnitX())).toRotationMatrix();
  const Similarity s = PositionYawAlignment(x, Apply(tilted, x));
  EXPECT_NEAR((s.rotation * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-15);
}

// ComputeAlignment on trajectories: the transform is applied to rotation, position and velocity, so
// an estimate that is a moved copy of the reference has zero error in every channel after se3/sim3.
TEST(AlignTest, AppliedToOrientationPositionAndVelocity) {
  const traj::Trajectory ref = testing::DroneTruth(10.0);
  std::mt19937_64 rng(6);
  for (AlignmentMethod method : {AlignmentMethod::kSE3, AlignmentMethod::kSim3, AlignmentMethod::kFull}) {
    const double scale = method == AlignmentMethod::kSim3 ? 2.5 : 1.0;
    const Similarity moved = testing::RandomSimilarity(rng, scale);
    const traj::Trajectory est = testing::Transformed(ref.View(), moved);
    const Association association = Associate(ref.View(), est.View());
    PairedStates pairs(ref.View(), est.View(), association);
    const AlignmentResult alignment = ComputeAlignment(pairs, {method});
    pairs.SetAlignment(alignment.transform);
    EXPECT_EQ(alignment.pairs_used, pairs.size());
    double worst_p = 0, worst_r = 0, worst_v = 0;
    for (Eigen::Index k = 0; k < pairs.size(); ++k) {
      worst_p = std::max(worst_p, (pairs.EstimatePosition(k) - pairs.ReferencePosition(k)).norm());
      worst_r = std::max(worst_r, (pairs.EstimateRotation(k) - pairs.ReferenceRotation(k)).norm());
      worst_v = std::max(worst_v, (pairs.EstimateVelocity(k) - pairs.ReferenceVelocity(k)).norm());
    }
    // Positions of ~30 m moved by ~10 m: rounding of a few 1e-14 m per operation.
    EXPECT_LT(worst_p, 1e-11) << ToString(method);
    EXPECT_LT(worst_r, 1e-12) << ToString(method);
    EXPECT_LT(worst_v, 1e-11) << ToString(method);
  }
}

// --n-align: solved from the first N pairs only. A copy whose second half is shifted is aligned
// exactly on its first half when N covers only that half.
TEST(AlignTest, NAlignUsesTheFirstPairsOnly) {
  const traj::Trajectory ref = testing::DroneTruth(10.0);
  std::vector<PoseSpec> poses = testing::PosesOf(ref.View());
  for (size_t i = poses.size() / 2; i < poses.size(); ++i) poses[i].p += Eigen::Vector3d(5, 0, 0);
  const traj::Trajectory est = MakeTrajectory(poses, true);
  const Association association = Associate(ref.View(), est.View());
  PairedStates pairs(ref.View(), est.View(), association);
  AlignmentOptions options{AlignmentMethod::kSE3, static_cast<Eigen::Index>(poses.size() / 2)};
  const AlignmentResult first_half = ComputeAlignment(pairs, options);
  EXPECT_EQ(first_half.pairs_used, static_cast<Eigen::Index>(poses.size() / 2));
  EXPECT_LT((first_half.transform.rotation - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_LT(first_half.transform.translation.norm(), 1e-11);
  EXPECT_GT(ComputeAlignment(pairs, {AlignmentMethod::kSE3}).transform.translation.norm(), 1.0);
  EXPECT_THROW(ComputeAlignment(pairs, {AlignmentMethod::kSE3, 2}), ComputeError);
}

TEST(AlignTest, OriginAlignsTheFirstPose) {
  const traj::Trajectory ref = testing::DroneTruth(5.0);
  std::mt19937_64 rng(8);
  const traj::Trajectory est = testing::Noisy(testing::Transformed(ref.View(), testing::RandomSimilarity(rng)).View(),
                                              0.01, 0.01, 0.0, 9);
  const Association association = Associate(ref.View(), est.View());
  PairedStates pairs(ref.View(), est.View(), association);
  pairs.SetAlignment(ComputeAlignment(pairs, {AlignmentMethod::kOrigin}).transform);
  EXPECT_LT((pairs.EstimatePosition(0) - pairs.ReferencePosition(0)).norm(), 1e-12);
  EXPECT_LT((pairs.EstimateRotation(0) - pairs.ReferenceRotation(0)).norm(), 1e-14);
  // Position-only reference: origin alignment is impossible.
  const traj::Trajectory positions = MakeTrajectory(testing::PosesOf(ref.View()), false, false);
  PairedStates no_rotation(positions.View(), est.View(), association);
  EXPECT_THROW(ComputeAlignment(no_rotation, {AlignmentMethod::kOrigin}), ComputeError);
}

// Full-state alignment minimises Σ ASE²: on a noisy estimate it is never worse than the position-only
// SE(3) alignment, on every seed, and it beats it when the noise makes them differ.
TEST(AlignTest, FullAlignmentNeverScoresWorseThanPositionOnly) {
  const traj::Trajectory ref = testing::DroneTruth(20.0);
  std::mt19937_64 rng(10);
  int strictly_better = 0;
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    const traj::Trajectory moved = testing::Transformed(ref.View(), testing::RandomSimilarity(rng));
    const traj::Trajectory est = testing::Noisy(moved.View(), 0.05, 0.02, 0.1, seed);
    const Association association = Associate(ref.View(), est.View());
    PairedStates pairs(ref.View(), est.View(), association);
    auto ase_rmse = [&](AlignmentMethod method) {
      pairs.SetAlignment(ComputeAlignment(pairs, {method}).transform);
      return ComputeStatistics(AseErrorsOf(pairs).total).rmse;
    };
    const double se3 = ase_rmse(AlignmentMethod::kSE3), full = ase_rmse(AlignmentMethod::kFull);
    EXPECT_LE(full, se3) << "seed " << seed;
    if (full < se3 * (1 - 1e-9)) ++strictly_better;
    const AlignmentResult result = ComputeAlignment(pairs, {AlignmentMethod::kFull});
    EXPECT_LE(result.full_cost, result.position_only_cost);
    EXPECT_NEAR(result.full_cost, full * full * static_cast<double>(pairs.size()), 1e-9 * result.full_cost);
  }
  EXPECT_GT(strictly_better, 5);
}

TEST(AlignTest, NamesRoundTrip) {
  for (AlignmentMethod m : {AlignmentMethod::kNone, AlignmentMethod::kOrigin, AlignmentMethod::kSE3,
                            AlignmentMethod::kSim3, AlignmentMethod::kScale, AlignmentMethod::kPosYaw,
                            AlignmentMethod::kFull}) {
    EXPECT_EQ(AlignmentMethodFromString(ToString(m)), m);
  }
  EXPECT_FALSE(AlignmentMethodFromString("umeyama"));
  EXPECT_EQ(AlignmentTitle(AlignmentMethod::kSE3), "(with SE(3) Umeyama alignment)");
}

}  // namespace
}  // namespace cheval::eval
