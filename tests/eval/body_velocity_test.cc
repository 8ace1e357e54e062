// --velocity-frame body (EvaluationOptions::estimate_velocity_body_frame): the estimate's velocity
// columns are v_body and the world velocity is R_world_body · v_body. The reference carries the
// world velocity worked out by hand below, so the ASE's velocity part is zero only if the rotation
// is applied, in that direction: R_world_bodyᵀ (the inverse) or no rotation leave errors of metres
// per second. (A reference at rest cannot tell: |R v| = |Rᵀ v| = |v|.)
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "cheval/eval/evaluate.h"
#include "eval_test_util.h"

namespace cheval::eval {
namespace {

using testing::AxisAngle;
using testing::PoseSpec;

// Four orientations whose action on v_body = (1, 2, 3) is worked out by hand (columns of R are the
// body axes in the world):
//   Rz(90°): x -> y, y -> -x        R v = (-2, 1, 3)     Rᵀ v = (2, -1, 3)
//   Rx(90°): y -> z, z -> -y        R v = (1, -3, 2)     Rᵀ v = (1, 3, -2)
//   Rz(90°)·Rx(90°) (Rx first):     R v = Rz (1, -3, 2) = (3, 1, 2)
//   Ry(180°): x -> -x, z -> -z      R v = (-1, 2, -3)    (Rᵀ = R: only "no rotation" is wrong here)
struct Case {
  Eigen::Quaterniond q;
  Eigen::Vector3d world_velocity;
};

std::vector<Case> HandCases() {
  const double half_pi = std::acos(0.0);
  const Eigen::Quaterniond z90 = AxisAngle(half_pi, Eigen::Vector3d::UnitZ());
  const Eigen::Quaterniond x90 = AxisAngle(half_pi, Eigen::Vector3d::UnitX());
  return {{z90, {-2, 1, 3}},
          {x90, {1, -3, 2}},
          {z90 * x90, {3, 1, 2}},
          {AxisAngle(2 * half_pi, Eigen::Vector3d::UnitY()), {-1, 2, -3}}};
}

const Eigen::Vector3d kBodyVelocity(1, 2, 3);

// Reference and estimate share orientations and (non-collinear) positions; the reference has the
// hand-derived world velocity, the estimate the body velocity (1, 2, 3) at every pose.
void MakePair(traj::Trajectory* ref, traj::Trajectory* est) {
  std::vector<PoseSpec> r, e;
  const std::vector<Case> cases = HandCases();
  for (size_t i = 0; i < cases.size(); ++i) {
    const int64_t stamp = static_cast<int64_t>(i) * 1'000'000'000;
    const Eigen::Vector3d p(static_cast<double>(i), static_cast<double>(i * i), i == 2 ? 1.0 : 0.0);
    r.push_back({stamp, p, cases[i].q, cases[i].world_velocity});
    e.push_back({stamp, p, cases[i].q, kBodyVelocity});
  }
  *ref = testing::MakeTrajectory(r, true);
  *est = testing::MakeTrajectory(e, true);
}

TEST(BodyVelocityTest, HandDerivedWorldVelocity) {
  // The hand table itself, against Eigen (a check of the test's arithmetic, not of cheval).
  for (const Case& c : HandCases()) EXPECT_LT((c.q * kBodyVelocity - c.world_velocity).norm(), 1e-15);

  traj::Trajectory ref, est;
  MakePair(&ref, &est);
  EvaluationOptions options;
  options.metric = MetricKind::kAse;
  options.estimate_velocity_body_frame = true;
  const EvaluationResult body = Evaluate(ref.View(), est.View(), options);
  ASSERT_EQ(body.ase->velocity.size(), 4u);
  // R_world_body v_body equals the reference's world velocity to rounding (|v| ~ 4 m/s; measured 1.3e-15).
  for (double e : body.ase->velocity) EXPECT_LT(e, 1e-14);
  for (double e : body.errors) EXPECT_LT(e, 1e-14);

  // As world-frame columns (no rotation), the velocity part is |R_qᵀ (v_body − v_world)|
  // = |v_body − v_world|: by hand |(3, 1, 0)|, |(0, 5, 1)|, |(-2, 1, 1)|, |(2, 0, 6)|.
  options.estimate_velocity_body_frame = false;
  const EvaluationResult world = Evaluate(ref.View(), est.View(), options);
  const double no_rotation[] = {std::sqrt(10.0), std::sqrt(26.0), std::sqrt(6.0), std::sqrt(40.0)};
  for (size_t i = 0; i < 4; ++i) EXPECT_NEAR(world.ase->velocity[i], no_rotation[i], 1e-14) << i;
}

// The rotation into the world uses the estimate's own, unaligned orientation; an SE(3) alignment then
// rotates that world velocity with everything else. An estimate expressed in another world frame
// (moved rigidly) and aligned back gives zero velocity error again — with the inverse rotation it would
// not.
TEST(BodyVelocityTest, ConvertedBeforeTheAlignment) {
  traj::Trajectory ref, est;
  MakePair(&ref, &est);
  std::mt19937_64 rng(31);
  const Similarity moved = testing::RandomSimilarity(rng);
  std::vector<PoseSpec> poses = testing::PosesOf(est.View());
  for (PoseSpec& p : poses) {  // body velocity stays body velocity: only the pose moves
    p.p = moved.ApplyToPoint(p.p);
    p.q = Eigen::Quaterniond(moved.rotation) * p.q;
  }
  const traj::Trajectory other_world = testing::MakeTrajectory(poses, true);
  EvaluationOptions options;
  options.metric = MetricKind::kAse;
  options.estimate_velocity_body_frame = true;
  options.alignment.method = AlignmentMethod::kSE3;
  const EvaluationResult r = Evaluate(ref.View(), other_world.View(), options);
  // Umeyama recovers the rigid motion to rounding on these ~10 m points: measured 1.9e-15 m/s and
  // 1.1e-15 rad.
  for (double e : r.ase->velocity) EXPECT_LT(e, 1e-14);
  for (double e : r.ase->rotation) EXPECT_LT(e, 1e-14);
}

}  // namespace
}  // namespace cheval::eval
