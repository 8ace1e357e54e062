// KITTI drift (rpe --kitti-drift) on a path whose drift is known in closed form, with a rotation error
// and a translation error that both vary with the segment length, so that the choice of segments
// (every 10th start, the first end whose *reference* path distance exceeds L) and the averaging over
// all segments (not over the eight lengths) are each visible. The definition (docs/evaluation.md,
// "KITTI drift"; the KITTI odometry devkit's evaluate_odometry.cpp: calcSequenceErrors with
// step_size 10 and lengths 100..800, rotationError, translationError, the means in saveStats):
//   for first = 0, 10, 20, ... and L = 100, ..., 800: last = the first index with dist[last] > dist[first] + L
//   (dist = accumulated reference path length), E = (P_first⁻¹ P_last)⁻¹ (Q_first⁻¹ Q_last),
//   t_err = |t(E)| / L, r_err = acos(clamp((tr R(E) − 1) / 2)) / L, averaged over every segment.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "cheval/eval/evaluate.h"
#include "eval_test_util.h"

namespace cheval::eval {
namespace {

// A planar arc of curvature κ (rad/m) through the origin heading +x, at arc length s: the position
// (sin κs / κ, (1 − cos κs) / κ, 0) and the heading Rz(κs).
Eigen::Vector3d ArcPoint(double curvature, double s) {
  return {std::sin(curvature * s) / curvature, (1 - std::cos(curvature * s)) / curvature, 0.0};
}
testing::PoseSpec ArcPose(int64_t stamp_ns, double curvature, double s) {
  return {stamp_ns, ArcPoint(curvature, s), testing::AxisAngle(curvature * s, Eigen::Vector3d::UnitZ())};
}

// Reference: an arc of radius 500 m sampled every h = 2.9 m of arc (0.1 s apart, KITTI's 10 Hz;
// 29 m/s, a car on a highway).
// Estimate: the same number of poses on an arc whose curvature is larger by δκ = 2e-5 rad/m (a yaw-rate
// bias) and whose steps are 3 % longer (a scale drift).
constexpr double kRefCurvature = 1.0 / 500.0, kCurvatureBias = 2e-5, kStep = 2.9, kScale = 1.03;
constexpr int kPoses = 1001;  // 2900 m of arc, 5.8 rad of turn

struct Expected {
  std::vector<int> segments;  // per length
  std::vector<double> translation_percent, rotation_deg_per_m;
  int total_segments = 0;
  double translation_percent_mean = 0, rotation_deg_per_m_mean = 0;
};

// The drift derived by hand. Every segment of the same number of steps k has the same error, because
// an arc looks the same from each of its points: P_i⁻¹ P_{i+k} = (Rz(κ D), ArcPoint(κ, D)) with D = k h
// for the reference and D = k h (1 + 3 %) for the estimate. Hence
//   R(E) = Rz(κ_ref D_ref − κ_est D_est)                 -> angle |κ_ref D_ref − κ_est D_est|
//   t(E) = Rz(−κ_est D_est)(ArcPoint(κ_ref, D_ref) − ArcPoint(κ_est, D_est)) -> the norm of the difference.
// The segment's end: the reference's polygonal path advances by the chord 2 sin(κh/2)/κ per step, so
// k_L = floor(L / chord) + 1 (the first path distance strictly above L; no L / chord here is within
// 0.03 of an integer, i.e. 9 cm of path, far from rounding). The step does not divide 100 m, so
// k_L h / L varies with L (1.015 at 100 m, 1.0005 at 200 m) and so does the rotation error per metre. Starts 0, 10, ... with start + k_L <= n − 1.
Expected ByHand() {
  const double chord = 2 * std::sin(kRefCurvature * kStep / 2) / kRefCurvature;
  const double est_curvature = kRefCurvature + kCurvatureBias;
  Expected e;
  double t_sum = 0, r_sum = 0;
  for (int length_index = 1; length_index <= 8; ++length_index) {
    const double length = 100.0 * length_index;
    const int k = static_cast<int>(std::floor(length / chord)) + 1;
    const int segments = (kPoses - 1 - k) / 10 + 1;
    const double d_ref = k * kStep, d_est = k * kStep * kScale;
    const double t_err = (ArcPoint(kRefCurvature, d_ref) - ArcPoint(est_curvature, d_est)).norm() / length;
    const double r_err = std::abs(kRefCurvature * d_ref - est_curvature * d_est) / length;
    e.segments.push_back(segments);
    e.translation_percent.push_back(100 * t_err);
    e.rotation_deg_per_m.push_back(r_err * 180 / std::numbers::pi);
    e.total_segments += segments;
    t_sum += segments * t_err;
    r_sum += segments * r_err;
  }
  e.translation_percent_mean = 100 * t_sum / e.total_segments;
  e.rotation_deg_per_m_mean = r_sum / e.total_segments * 180 / std::numbers::pi;
  return e;
}

TEST(KittiDriftTest, CurvedPathWithYawRateBiasAndScaleDrift) {
  std::vector<testing::PoseSpec> ref, est;
  for (int i = 0; i < kPoses; ++i) {
    ref.push_back(ArcPose(i * 100'000'000LL, kRefCurvature, i * kStep));
    est.push_back(ArcPose(i * 100'000'000LL, kRefCurvature + kCurvatureBias, i * kStep * kScale));
  }
  const traj::Trajectory r = testing::MakeTrajectory(ref), e = testing::MakeTrajectory(est);
  EvaluationOptions options;
  options.metric = MetricKind::kRpe;
  options.kitti_drift = true;
  const EvaluationResult result = Evaluate(r.View(), e.View(), options);
  ASSERT_TRUE(result.drift.has_value());
  const DriftResult& drift = *result.drift;
  const Expected expected = ByHand();
  // The hand values, for the reader: 100 m segments are 35 steps long (97 of them), 800 m segments 276
  // steps (73 of them), 680 in all; translation 3.05 % at 100 m to 3.46 % at 800 m, mean 3.1923 %;
  // rotation 0.004620-0.004687 deg/m, mean 0.0046356 deg/m.
  EXPECT_EQ(expected.segments.front(), 97);
  EXPECT_EQ(expected.segments.back(), 73);
  EXPECT_EQ(expected.total_segments, 680);
  ASSERT_EQ(drift.lengths.size(), 8u);
  // Measured relative differences: translation 1.4e-14, rotation 8.5e-12 — the angle (8e-3 rad at 100 m
  // to 6e-2 rad at 800 m) comes from acos of a cosine just below 1, which turns the trace's rounding into
  // an angle error of ~1e-16 / sin(angle), i.e. 1e-12 relative and more. Bounds ~6x those.
  for (size_t i = 0; i < 8; ++i) {
    SCOPED_TRACE(::testing::Message() << "L = " << drift.lengths[i].length_m);
    EXPECT_EQ(drift.lengths[i].length_m, 100.0 * (i + 1));
    EXPECT_EQ(drift.lengths[i].segments, expected.segments[i]);
    EXPECT_NEAR(drift.lengths[i].translation_percent, expected.translation_percent[i],
                1e-13 * expected.translation_percent[i]);
    EXPECT_NEAR(drift.lengths[i].rotation_deg_per_m, expected.rotation_deg_per_m[i],
                5e-11 * expected.rotation_deg_per_m[i]);
  }
  EXPECT_EQ(drift.segments, expected.total_segments);
  EXPECT_NEAR(drift.translation_percent, expected.translation_percent_mean, 1e-13 * expected.translation_percent_mean);
  EXPECT_NEAR(drift.rotation_deg_per_m, expected.rotation_deg_per_m_mean, 5e-11 * expected.rotation_deg_per_m_mean);
  // The mean over segments differs from the mean of the eight per-length means (fewer long segments):
  // this construction tells the two apart.
  double per_length_mean = 0;
  for (double v : expected.rotation_deg_per_m) per_length_mean += v / 8;
  EXPECT_GT(std::abs(per_length_mean - expected.rotation_deg_per_m_mean), 1e-6 * expected.rotation_deg_per_m_mean);
}

}  // namespace
}  // namespace cheval::eval
