// APE, RPE, drift, ASE and statistics from their definitions (docs/evaluation.md, "Metrics" and "Statistics"): hand-checkable
// cases, a trajectory against itself is 0, invariances (SE(3)-aligned APE under a rigid motion of
// the estimate, Sim(3) also under scale, RPE under any rigid motion without alignment), and the RPE
// pair selection against brute-force transcriptions of evo's filters.
#include "cheval/eval/metrics.h"

#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "cheval/common/error.h"
#include "cheval/eval/align.h"
#include "cheval/eval/evaluate.h"
#include "cheval/eval/statistics.h"
#include "cheval/sim/motion.h"
#include "eval_test_util.h"

namespace cheval::eval {
namespace {

using testing::AxisAngle;
using testing::MakeTrajectory;
using testing::PoseSpec;
constexpr double kPi = std::numbers::pi;
constexpr int64_t kSecond = 1'000'000'000;

// Poses along x at 1 m a step, 1 s apart, each turned `yaw_step` further about z.
std::vector<PoseSpec> Line(int n, double yaw_step = 0.0, double step = 1.0) {
  std::vector<PoseSpec> poses(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    poses[static_cast<size_t>(i)].stamp_ns = i * kSecond;
    poses[static_cast<size_t>(i)].p = Eigen::Vector3d(step * i, 0, 0);
    poses[static_cast<size_t>(i)].q = AxisAngle(yaw_step * i, Eigen::Vector3d::UnitZ());
  }
  return poses;
}

std::vector<double> Ape(const traj::Trajectory& ref, const traj::Trajectory& est, PoseRelation relation,
                        AlignmentMethod align = AlignmentMethod::kNone) {
  EvaluationOptions options;
  options.relation = relation;
  options.alignment.method = align;
  return Evaluate(ref.View(), est.View(), options).errors;
}

TEST(RotationAngleTest, MatchesTheAxisAngleEverywhere) {
  std::mt19937_64 rng(1);
  for (double angle : {0.0, 1e-12, 1e-8, 1e-4, 1e-3, 1.001e-3, 0.5, 2.0, kPi - 1e-6, kPi}) {
    for (int k = 0; k < 5; ++k) {
      const Eigen::Vector3d axis = testing::RandomRotation(rng).vec().normalized();
      const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
      // Relative 1e-12 away from zero (the formula is well conditioned down to tiny angles, unlike
      // acos((tr R - 1)/2) whose error at 1e-8 rad would be ~1e-8 absolute), absolute 1e-15 at zero.
      EXPECT_NEAR(RotationAngle(R), angle, 1e-12 * angle + 1e-15) << angle;
    }
  }
}

TEST(StatisticsTest, HandChecked) {
  const std::vector<double> e = {3, 1, 4, 2};
  const ErrorStatistics s = ComputeStatistics(e);
  EXPECT_EQ(s.n, 4);
  EXPECT_DOUBLE_EQ(s.sse, 30.0);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);                // mean of the two middle values
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));       // population: Σ(e - 2.5)² / 4
  EXPECT_EQ(s.min, 1.0);
  EXPECT_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(ComputeStatistics(std::vector<double>{5, 1, 3}).median, 3.0);
  EXPECT_EQ(ComputeStatistics({}).n, 0);
}

TEST(ApeTest, HandCheckedRelations) {
  // Reference at the origin, identity; estimate at (3, 4, 0), turned 90° about z.
  const traj::Trajectory ref = MakeTrajectory({PoseSpec{0}, PoseSpec{kSecond}});
  PoseSpec e0{0, Eigen::Vector3d(3, 4, 0), AxisAngle(kPi / 2, Eigen::Vector3d::UnitZ())};
  PoseSpec e1 = e0;
  e1.stamp_ns = kSecond;
  const traj::Trajectory est = MakeTrajectory({e0, e1});
  EXPECT_DOUBLE_EQ(Ape(ref, est, PoseRelation::kTranslation)[0], 5.0);
  EXPECT_DOUBLE_EQ(Ape(ref, est, PoseRelation::kPointDistance)[0], 5.0);
  // ‖R - I‖_F = 2√2 sin(θ/2) = 2 for θ = 90°.
  EXPECT_NEAR(Ape(ref, est, PoseRelation::kRotation)[0], 2.0, 1e-15);
  EXPECT_NEAR(Ape(ref, est, PoseRelation::kAngleDeg)[0], 90.0, 1e-13);
  EXPECT_NEAR(Ape(ref, est, PoseRelation::kAngleRad)[0], kPi / 2, 1e-15);
  // E = P⁻¹Q has |t(E)| = 5, so ‖E − I₄‖_F = sqrt(2² + 5²).
  EXPECT_NEAR(Ape(ref, est, PoseRelation::kFull)[0], std::sqrt(29.0), 1e-14);
}

TEST(ApeTest, ATrajectoryAgainstItselfIsZero) {
  const traj::Trajectory t = testing::DroneTruth(5.0);
  for (PoseRelation r : {PoseRelation::kTranslation, PoseRelation::kRotation, PoseRelation::kFull,
                         PoseRelation::kAngleDeg, PoseRelation::kAngleRad, PoseRelation::kPointDistance}) {
    // Positions cancel exactly; RᵀR of a rotation formed from a quaternion is I to a few ulps.
    const double rounding = RelationNeedsOrientation(r, false) ? 1e-15 : 0.0;
    for (double e : Ape(t, t, r)) ASSERT_LE(e, rounding) << ToString(r);
    // The SE(3) alignment of a trajectory onto itself is the identity to rounding: measured 4.1e-15 at
    // most (kFull, metres and radians on a ~10 m flight); ~7x.
    for (double e : Ape(t, t, r, AlignmentMethod::kSE3)) ASSERT_LT(e, 3e-14) << ToString(r);
  }
}

// SE(3)-aligned APE does not depend on where the estimate's frame is; Sim(3)-aligned also not on its
// scale. 1e-9 relative: the aligned positions differ from the untransformed case by rounding only.
TEST(ApeTest, AlignedApeIsInvariantToMovingTheEstimate) {
  const traj::Trajectory ref = testing::DroneTruth(20.0);
  const traj::Trajectory est = testing::Noisy(ref.View(), 0.1, 0.05, 0.0, 3);
  std::mt19937_64 rng(2);
  for (PoseRelation r : {PoseRelation::kTranslation, PoseRelation::kAngleDeg, PoseRelation::kFull}) {
    const ErrorStatistics se3 = ComputeStatistics(Ape(ref, est, r, AlignmentMethod::kSE3));
    const traj::Trajectory moved = testing::Transformed(est.View(), testing::RandomSimilarity(rng));
    EXPECT_NEAR(ComputeStatistics(Ape(ref, moved, r, AlignmentMethod::kSE3)).rmse, se3.rmse, 1e-9 * se3.rmse);
    const ErrorStatistics sim3 = ComputeStatistics(Ape(ref, est, r, AlignmentMethod::kSim3));
    const traj::Trajectory scaled = testing::Transformed(est.View(), testing::RandomSimilarity(rng, 0.37));
    EXPECT_NEAR(ComputeStatistics(Ape(ref, scaled, r, AlignmentMethod::kSim3)).rmse, sim3.rmse, 1e-9 * sim3.rmse);
  }
}

TEST(ApeTest, OrientationRelationsNeedOrientation) {
  const traj::Trajectory ref = MakeTrajectory(Line(5), false, false);
  const traj::Trajectory est = MakeTrajectory(Line(5));
  EXPECT_EQ(Ape(ref, est, PoseRelation::kTranslation).size(), 5u);
  EXPECT_THROW(Ape(ref, est, PoseRelation::kRotation), ComputeError);
}

RpeOptions Rpe(double delta, DeltaUnit unit, bool all_pairs = false, PoseRelation r = PoseRelation::kTranslation) {
  RpeOptions o;
  o.delta = delta;
  o.delta_unit = unit;
  o.all_pairs = all_pairs;
  o.relation = r;
  return o;
}

std::vector<IndexPair> PairsOf(const traj::Trajectory& t, const RpeOptions& options) {
  const Association a = Associate(t.View(), t.View());
  const PairedStates pairs(t.View(), t.View(), a);
  return RpeIndexPairs(pairs, options);
}

TEST(RpeTest, FramePairs) {
  const traj::Trajectory t = MakeTrajectory(Line(10));
  // consecutive: ids 0, 3, 6, 9 -> floor((n - 1)/δ) = 3 pairs; all pairs: (i, i + 3) for i < 7.
  EXPECT_EQ(PairsOf(t, Rpe(3, DeltaUnit::kFrames)), (std::vector<IndexPair>{{0, 3}, {3, 6}, {6, 9}}));
  EXPECT_EQ(PairsOf(t, Rpe(3, DeltaUnit::kFrames, true)).size(), 7u);
  EXPECT_EQ(PairsOf(t, Rpe(4, DeltaUnit::kFrames)), (std::vector<IndexPair>{{0, 4}, {4, 8}}));
  EXPECT_THROW(PairsOf(t, Rpe(2.5, DeltaUnit::kFrames)), UsageError);
  EXPECT_THROW(PairsOf(t, Rpe(0, DeltaUnit::kFrames)), UsageError);
  EXPECT_THROW(PairsOf(t, Rpe(20, DeltaUnit::kFrames)), ComputeError);  // no pair
}

TEST(RpeTest, MeterPairsConsecutiveSkipIndexZero) {
  const traj::Trajectory t = MakeTrajectory(Line(10));
  // Path 1 m a step, δ = 2.5 m: the sum reaches 3 m at i = 3 and restarts, then at 6 and 9.
  EXPECT_EQ(PairsOf(t, Rpe(2.5, DeltaUnit::kMeters)), (std::vector<IndexPair>{{3, 6}, {6, 9}}));
  EXPECT_EQ(PairsOf(t, Rpe(2.0, DeltaUnit::kMeters)), (std::vector<IndexPair>{{2, 4}, {4, 6}, {6, 8}}));
}

// evo's filter_pairs_by_path (all pairs): for each i the j > i minimising |(d_j − d_i) − δ|, first
// on ties, kept when within tol — written here as the O(n²) scan.
std::vector<IndexPair> PathPairsBruteForce(const std::vector<double>& d, double delta, double tol) {
  std::vector<IndexPair> out;
  for (size_t i = 0; i + 1 < d.size(); ++i) {
    size_t best = i + 1;
    for (size_t j = i + 1; j < d.size(); ++j) {
      if (std::abs((d[j] - d[i]) - delta) < std::abs((d[best] - d[i]) - delta)) best = j;
    }
    if (!(std::abs((d[best] - d[i]) - delta) > tol)) {
      out.push_back({static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(best)});
    }
  }
  return out;
}

TEST(RpeTest, MeterAllPairsMatchTheScan) {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> steps(0, 4);
  for (int trial = 0; trial < 50; ++trial) {
    // Steps of 0 .. 2 m in quarter metres: stops (repeated distances) and exact ties are common.
    std::vector<PoseSpec> poses(40);
    std::vector<double> d(poses.size(), 0.0);
    double x = 0;
    for (size_t i = 0; i < poses.size(); ++i) {
      if (i > 0) x += 0.5 * steps(rng);
      poses[i].stamp_ns = static_cast<int64_t>(i) * kSecond;
      poses[i].p = Eigen::Vector3d(x, 0, 0);
      d[i] = x;
    }
    const traj::Trajectory t = MakeTrajectory(poses);
    for (double delta : {1.0, 2.5, 4.0}) {
      std::vector<IndexPair> expected = PathPairsBruteForce(d, delta, 0.1 * delta);
      if (expected.empty()) {
        EXPECT_THROW(PairsOf(t, Rpe(delta, DeltaUnit::kMeters, true)), ComputeError);
      } else {
        EXPECT_EQ(PairsOf(t, Rpe(delta, DeltaUnit::kMeters, true)), expected) << trial << " " << delta;
      }
    }
  }
}

TEST(RpeTest, AnglePairs) {
  const traj::Trajectory t = MakeTrajectory(Line(10, 10.0 * kPi / 180.0));
  // 10° a step, δ = 25°: the sum reaches 30° at 3 -> (0, 3), then (3, 6), (6, 9).
  EXPECT_EQ(PairsOf(t, Rpe(25, DeltaUnit::kDegrees)), (std::vector<IndexPair>{{0, 3}, {3, 6}, {6, 9}}));
  EXPECT_EQ(PairsOf(t, Rpe(25 * kPi / 180, DeltaUnit::kRadians)), (std::vector<IndexPair>{{0, 3}, {3, 6}, {6, 9}}));
  // All pairs: direct angle 30° ± 3°: (i, i + 3).
  EXPECT_EQ(PairsOf(t, Rpe(30, DeltaUnit::kDegrees, true)).size(), 7u);
  EXPECT_THROW(PairsOf(t, Rpe(200, DeltaUnit::kDegrees)), UsageError);
}

TEST(RpeTest, HandCheckedScaleDrift) {
  // Estimate 10 % too long a step: every frame-to-frame translation error is 0.1 m; angles agree.
  const traj::Trajectory ref = MakeTrajectory(Line(6, 0.1));
  const traj::Trajectory est = MakeTrajectory(Line(6, 0.1, 1.1));
  EvaluationOptions options;
  options.metric = MetricKind::kRpe;
  const EvaluationResult r = Evaluate(ref.View(), est.View(), options);
  ASSERT_EQ(r.errors.size(), 5u);
  for (double e : r.errors) EXPECT_NEAR(e, 0.1, 1e-14);
  EXPECT_EQ(r.stamps_ns[1], kSecond);
  EXPECT_EQ(r.stamps_end_ns[1], 2 * kSecond);
  options.relation = PoseRelation::kAngleDeg;
  for (double e : Evaluate(ref.View(), est.View(), options).errors) EXPECT_NEAR(e, 0.0, 1e-12);
  options.relation = PoseRelation::kPointDistance;
  for (double e : Evaluate(ref.View(), est.View(), options).errors) EXPECT_NEAR(e, 0.1, 1e-14);
}

// Without alignment, RPE compares motions: moving the whole estimate rigidly changes nothing.
TEST(RpeTest, InvariantToARigidMotionOfTheEstimate) {
  const traj::Trajectory ref = testing::DroneTruth(20.0);
  const traj::Trajectory est = testing::Noisy(ref.View(), 0.02, 0.01, 0.0, 5);
  std::mt19937_64 rng(12);
  const traj::Trajectory moved = testing::Transformed(est.View(), testing::RandomSimilarity(rng));
  for (DeltaUnit unit : {DeltaUnit::kFrames, DeltaUnit::kMeters}) {
    EvaluationOptions options;
    options.metric = MetricKind::kRpe;
    options.rpe = Rpe(unit == DeltaUnit::kFrames ? 10 : 5, unit);
    for (PoseRelation r : {PoseRelation::kTranslation, PoseRelation::kAngleRad, PoseRelation::kFull}) {
      options.relation = r;
      const ErrorStatistics a = Evaluate(ref.View(), est.View(), options).stats;
      const ErrorStatistics b = Evaluate(ref.View(), moved.View(), options).stats;
      EXPECT_EQ(a.n, b.n);
      EXPECT_NEAR(a.rmse, b.rmse, 1e-9 * a.rmse) << ToString(r);
    }
  }
}

TEST(DriftTest, ScaleErrorGivesItsPercentAndNoRotation) {
  // A 1 km straight line, 1 m steps; the estimate's steps are 1 % longer: 1 % drift on every segment.
  const traj::Trajectory ref = MakeTrajectory(Line(1001));
  const traj::Trajectory est = MakeTrajectory(Line(1001, 0.0, 1.01));
  const Association a = Associate(ref.View(), est.View());
  const PairedStates pairs(ref.View(), est.View(), a);
  const DriftResult drift = KittiDrift(pairs);
  ASSERT_GT(drift.segments, 0);
  // Segment 100 m: the first j with distance > 100 m is 101 m away, error 1.01 m over 100 m.
  EXPECT_NEAR(drift.lengths[0].translation_percent, 1.01, 1e-9);
  EXPECT_EQ(drift.lengths[0].segments, 90);  // starts 0, 10, ..., 890 have a pose 101 m further
  EXPECT_NEAR(drift.rotation_deg_per_m, 0.0, 1e-12);
  EXPECT_EQ(drift.lengths.size(), 8u);
}

TEST(AseTest, HandChecked) {
  // Reference: turned 90° about z, at the origin, at rest. Estimate: same orientation, 1 m off along
  // the reference's x, moving 2 m/s along world y.
  const Eigen::Quaterniond q = AxisAngle(kPi / 2, Eigen::Vector3d::UnitZ());
  const traj::Trajectory ref = MakeTrajectory({PoseSpec{0, {0, 0, 0}, q, {0, 0, 0}}}, true);
  const traj::Trajectory est = MakeTrajectory({PoseSpec{0, {0, 1, 0}, q, {0, 2, 0}}}, true);
  EvaluationOptions options;
  options.metric = MetricKind::kAse;
  const EvaluationResult r = Evaluate(ref.View(), est.View(), options);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_NEAR(r.errors[0], std::sqrt(5.0), 1e-15);
  EXPECT_NEAR(r.ase->rotation[0], 0.0, 1e-15);
  EXPECT_NEAR(r.ase->position[0], 1.0, 1e-15);
  EXPECT_NEAR(r.ase->velocity[0], 2.0, 1e-15);
  EXPECT_EQ(r.velocity_source, "given");
  EXPECT_EQ(r.relation, "state");
  // Turning the estimate by 90° more adds ‖R − I‖_F = 2 in quadrature.
  const traj::Trajectory turned = MakeTrajectory({PoseSpec{0, {0, 1, 0}, q * q, {0, 2, 0}}}, true);
  EXPECT_NEAR(Evaluate(ref.View(), turned.View(), options).errors[0], 3.0, 1e-15);
  // Body-frame estimate velocity: (2, 0, 0) in a body turned 90° about z is (0, 2, 0) in the world.
  const traj::Trajectory body = MakeTrajectory({PoseSpec{0, {0, 1, 0}, q, {2, 0, 0}}}, true);
  options.estimate_velocity_body_frame = true;
  EXPECT_NEAR(Evaluate(ref.View(), body.View(), options).errors[0], std::sqrt(5.0), 1e-15);
}

TEST(AseTest, ItselfIsZeroAndMissingVelocityIsAnError) {
  const traj::Trajectory t = testing::DroneTruth(5.0);
  EvaluationOptions options;
  options.metric = MetricKind::kAse;
  for (double e : Evaluate(t.View(), t.View(), options).errors) ASSERT_LE(e, 1e-15);  // RᵀR = I to a few ulps
  const traj::Trajectory poses = MakeTrajectory(testing::PosesOf(t.View()), false);
  testing::ExpectThrowWith<ComputeError>([&] { Evaluate(t.View(), poses.View(), options); }, {"EvaluationOptions::pose_only"});
  options.pose_only = true;
  const EvaluationResult pose_only = Evaluate(t.View(), poses.View(), options);
  EXPECT_EQ(pose_only.relation, "rotation+position");
  EXPECT_EQ(pose_only.velocity_source, "none");
  options.pose_only = false;
  options.reference_velocity = ReferenceVelocitySource::kGiven;
  EXPECT_THROW(Evaluate(poses.View(), t.View(), options), ComputeError);
}

// C-ASE: a reference without velocity gets it from its positions (Chebyshev by default); on a smooth
// flight sampled at 100 Hz that velocity is close to the true one, so the ASE of a perfect estimate
// is small, and far smaller than with central differences of noisy positions.
TEST(AseTest, ChebyshevReferenceVelocity) {
  const traj::Trajectory truth = testing::DroneTruth(20.0);
  const traj::Trajectory mocap =
      MakeTrajectory(testing::PosesOf(testing::Noisy(truth.View(), 0.0005, 0.0, 0.0, 2).View()), false);
  EvaluationOptions options;
  options.metric = MetricKind::kAse;
  const EvaluationResult cheb = Evaluate(mocap.View(), truth.View(), options);
  EXPECT_EQ(cheb.velocity_source, "chebyshev");
  options.reference_velocity = ReferenceVelocitySource::kCentral;
  const EvaluationResult central = Evaluate(mocap.View(), truth.View(), options);
  EXPECT_EQ(central.velocity_source, "central");
  // 0.5 mm noise at 100 Hz: measured 0.061 m/s with central differences, 0.00055 m/s with Chebyshev
  // (seeded noise; the figure moves with the degrees the fit selects): Chebyshev < 3x its figure, and
  // at least 30x better than central differences (measured 111x).
  EXPECT_LT(cheb.velocity_stats.rmse, 0.0015);
  EXPECT_GT(central.velocity_stats.rmse, 30 * cheb.velocity_stats.rmse);
  // Position-only reference: position + velocity state error, labelled as such.
  const traj::Trajectory positions = MakeTrajectory(testing::PosesOf(mocap.View()), false, false);
  options.reference_velocity = ReferenceVelocitySource::kAuto;
  const EvaluationResult pv = Evaluate(positions.View(), truth.View(), options);
  EXPECT_EQ(pv.relation, "position+velocity");
  EXPECT_TRUE(pv.ase->rotation.empty() || pv.rotation_stats.max == 0.0);
  EXPECT_NE(pv.title.find("reference without orientation"), std::string::npos);
}

// --association continuous: the reference's curve at the exact estimate stamps. An estimate that is
// the exact state 3 ms after every reference sample is far from its nearest reference pose (a drone
// at up to 8 m/s moves ~2 cm in 3 ms) but matches the continuous reference to the curve's accuracy.
TEST(ContinuousReferenceTest, EvaluatesTheReferenceAtTheEstimateStamps) {
  const sim::MotionModel model = testing::DroneModel(20.0);
  const traj::Trajectory ref = sim::GenerateMotion(model);
  std::vector<int64_t> stamps;
  for (int64_t s : ref.stamps_ns()) stamps.push_back(s + 3'000'000);
  stamps.push_back(ref.stamps_ns().back() + 1'000'000'000);  // after the reference: left out
  const traj::Trajectory est = sim::SampleMotion(model, stamps);
  EvaluationOptions nearest;
  nearest.metric = MetricKind::kAse;
  EvaluationOptions continuous = nearest;
  continuous.continuous_reference = true;
  const EvaluationResult a = Evaluate(ref.View(), est.View(), nearest);
  const EvaluationResult b = Evaluate(ref.View(), est.View(), continuous);
  EXPECT_EQ(b.association.size(), static_cast<Eigen::Index>(stamps.size()) - 2);  // the last two are beyond
  EXPECT_EQ(b.association.est.front(), 0);
  EXPECT_EQ(b.velocity_source, "chebyshev (continuous)");
  EXPECT_GT(a.position_stats.rmse, 0.005);
  // Noise-free 100 Hz samples: the curve is accurate to rounding and truncation, measured 4.5e-10 m and
  // 3.3e-9 m/s (the degrees the fit selects decide it; bounds ~7-10x); the orientation is slerped
  // between samples 10 ms apart, which leaves 8.9e-6 rad on this flight (bound ~3x).
  EXPECT_LT(b.position_stats.rmse, 3e-9);
  EXPECT_LT(b.velocity_stats.rmse, 3e-8);
  EXPECT_LT(b.rotation_stats.rmse, 3e-5);
  continuous.reference_velocity = ReferenceVelocitySource::kGiven;
  EXPECT_THROW(Evaluate(ref.View(), est.View(), continuous), UsageError);
}

}  // namespace
}  // namespace cheval::eval
