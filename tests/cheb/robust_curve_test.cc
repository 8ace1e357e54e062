// The residual test, jumps and glitches, and the jitter-robust noise estimate of FitCurve
// (docs/velocity.md, "Residual test" and "Jumps and glitches"). Each case failed before those
// existed: the tremor was smoothed away, a jump spread over its window, a glitch bent it, and the
// even-spacing noise estimate took stamp jitter for noise.
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "cheval/cheb/curve.h"
#include "cheval/cheb/degree.h"

namespace cheval::cheb {
namespace {

struct Motion {
  std::vector<int64_t> stamps;
  Eigen::VectorXd t;            // seconds
  Eigen::MatrixXd positions;    // m x 3
  Eigen::MatrixXd velocities;   // m x 3, exact
};

// Samples f (position and velocity at t) at `rate` for `duration`, with Gaussian noise and stamp
// jitter (the samples are taken at the jittered times, which the stamps record exactly).
Motion Sample(const std::function<void(double, Eigen::Vector3d*, Eigen::Vector3d*)>& f, double duration, double rate,
              double noise, double jitter, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const auto m = static_cast<Eigen::Index>(duration * rate);
  Motion s;
  s.t.resize(m);
  s.positions.resize(m, 3);
  s.velocities.resize(m, 3);
  for (Eigen::Index i = 0; i < m; ++i) {
    const double t = static_cast<double>(i) / rate + jitter * gauss(rng);
    s.stamps.push_back(std::llround(t * 1e9));
    s.t[i] = static_cast<double>(s.stamps.back()) * 1e-9;
    Eigen::Vector3d p, v;
    f(s.t[i], &p, &v);
    for (int c = 0; c < 3; ++c) p[c] += noise * gauss(rng);
    s.positions.row(i) = p.transpose();
    s.velocities.row(i) = v.transpose();
  }
  return s;
}

void Smooth(double t, Eigen::Vector3d* p, Eigen::Vector3d* v) {
  *p = {std::sin(0.4 * t), 0.5 * std::cos(0.3 * t), 0.2 * std::sin(0.7 * t + 1.0)};
  *v = {0.4 * std::cos(0.4 * t), -0.15 * std::sin(0.3 * t), 0.14 * std::cos(0.7 * t + 1.0)};
}

// A 1 mm hand tremor at 7–8.4 Hz on the smooth motion.
void Tremor(double t, Eigen::Vector3d* p, Eigen::Vector3d* v) {
  Smooth(t, p, v);
  for (int c = 0; c < 3; ++c) {
    const double w = 2.0 * M_PI * 7.0 * (1.0 + 0.1 * c), phase = 1.1 * c;
    (*p)[c] += 1e-3 * std::sin(w * t + phase);
    (*v)[c] += 1e-3 * w * std::cos(w * t + phase);
  }
}

double VelocityRmse(const Curve& curve, const Motion& s) {
  Eigen::MatrixXd values, velocities;
  curve.EvaluateMany(s.stamps, 1, &values, &velocities);
  return std::sqrt((velocities - s.velocities).rowwise().squaredNorm().mean());
}

double CentralRmse(const Motion& s) {
  double sum = 0.0;
  const Eigen::Index m = s.t.size();
  for (Eigen::Index i = 1; i + 1 < m; ++i) {
    const Eigen::RowVector3d v = (s.positions.row(i + 1) - s.positions.row(i - 1)) / (s.t[i + 1] - s.t[i - 1]);
    sum += (v - s.velocities.row(i)).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(m - 2));
}

// Small fast motion above the noise: the coefficients of a long window look like noise (the tremor
// lies above its top degree), its residual does not.
TEST(ResidualTest, AHandTremorAboveTheNoiseIsFollowed) {
  const Motion s = Sample(Tremor, 30.0, 100.0, 0.5e-3, 0.3e-3, 1);
  const Curve curve = FitCurve(s.stamps, s.positions);
  const double rmse = VelocityRmse(curve, s), central = CentralRmse(s);
  EXPECT_LT(rmse, 0.55 * central) << rmse << " m/s against central differences' " << central;
  // The tremor's velocity amplitude is 44–53 mm/s per axis: smoothed away, the error is about that.
  EXPECT_LT(rmse, 0.035);
}

// σ → 0: the same tremor without noise is followed to far below central differences' error.
TEST(ResidualTest, NoiseFreeFineMotionConvergesToALocalInterpolant) {
  const Motion s = Sample(Tremor, 30.0, 100.0, 0.0, 0.3e-3, 2);
  const Curve curve = FitCurve(s.stamps, s.positions);
  const double rmse = VelocityRmse(curve, s), central = CentralRmse(s);
  EXPECT_LT(rmse, 0.05 * central) << rmse << " m/s against central differences' " << central;
}

// A ground-truth relocalisation (the positions jump 3 cm and stay, the motion goes on) is taken
// out as a step: the velocity is wrong nowhere (the jump is no motion), instead of along a whole
// window, and the curve's values keep the step.
TEST(Jumps, APositionJumpStaysLocal) {
  Motion s = Sample(Smooth, 10.0, 200.0, 0.0, 0.0, 3);
  const Eigen::Index at = 1000;
  for (Eigen::Index i = at; i < s.t.size(); ++i) s.positions.row(i) += Eigen::RowVector3d(0.03, -0.01, 0.02);
  const Curve curve = FitCurve(s.stamps, s.positions);
  ASSERT_EQ(curve.step_times().size(), 1U);
  EXPECT_TRUE(curve.jump_times().empty());
  EXPECT_GT(curve.step_times()[0], s.t[at - 1] - s.t[0]);
  EXPECT_LT(curve.step_times()[0], s.t[at] - s.t[0]);
  EXPECT_LT(VelocityRmse(curve, s), 1e-4);
  Eigen::MatrixXd values;
  curve.EvaluateMany(s.stamps, 0, &values);
  EXPECT_LT((values - s.positions).cwiseAbs().maxCoeff(), 1e-6);
}

// Filtered ground truth (EuRoC's): the positions are corrected by a few tenths of a millimetre at
// every 20th sample while the motion goes on. Each correction is taken out as a step and the
// velocity stays far better than central differences (a split at each one left 20-sample
// segments with one-sided ends everywhere, and one local scale from the first look hid most).
TEST(Jumps, DenseCorrectionsOfFilteredGroundTruthAreTakenOut) {
  Motion s = Sample(Smooth, 20.0, 200.0, 1e-6, 0.0, 8);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> size(1e-4, 3e-4);
  int corrections = 0;
  for (Eigen::Index at = 20; at < s.t.size(); at += 20, ++corrections) {
    const Eigen::RowVector3d step(size(rng) * (at % 40 ? 1 : -1), -size(rng), size(rng) * (at % 60 ? 1 : -1));
    for (Eigen::Index i = at; i < s.t.size(); ++i) s.positions.row(i) += step;
  }
  const Curve curve = FitCurve(s.stamps, s.positions);
  EXPECT_GE(static_cast<int>(curve.step_times().size()), corrections * 9 / 10);
  EXPECT_LT(VelocityRmse(curve, s), 0.05 * CentralRmse(s));
}

// An impact: the velocity steps by 0.8 m/s between two samples. The fit is split there, so the
// error stays at the samples next to the step, not over a window.
TEST(Jumps, AVelocityStepStaysLocal) {
  const double step_time = 5.0023;  // between samples
  auto kinked = [&](double t, Eigen::Vector3d* p, Eigen::Vector3d* v) {
    Smooth(t, p, v);
    if (t > step_time) {
      (*p)[1] += 0.8 * (t - step_time);
      (*v)[1] += 0.8;
    }
  };
  const Motion s = Sample(kinked, 10.0, 200.0, 0.0, 0.0, 4);
  const Curve curve = FitCurve(s.stamps, s.positions);
  EXPECT_EQ(curve.jump_times().size(), 1U);
  Eigen::MatrixXd values, velocities;
  curve.EvaluateMany(s.stamps, 1, &values, &velocities);
  int wrong = 0;
  for (Eigen::Index i = 0; i < s.t.size(); ++i) wrong += (velocities.row(i) - s.velocities.row(i)).norm() > 1e-3 ? 1 : 0;
  EXPECT_LE(wrong, 2) << "samples with a velocity error above 1 mm/s";
  EXPECT_LT(VelocityRmse(curve, s), 0.5 * CentralRmse(s));
}

// A single displaced sample (a glitch) is left out: it bends nothing.
TEST(Jumps, AGlitchIsLeftOut) {
  Motion s = Sample(Smooth, 10.0, 200.0, 0.0, 0.0, 5);
  s.positions.row(700) += Eigen::RowVector3d(0.05, 0.0, -0.02);
  const Curve curve = FitCurve(s.stamps, s.positions);
  ASSERT_EQ(curve.outlier_times().size(), 1U);
  EXPECT_NEAR(curve.outlier_times()[0], s.t[700] - s.t[0], 1e-9);
  EXPECT_TRUE(curve.jump_times().empty());
  EXPECT_LT(VelocityRmse(curve, s), 1e-4);
  CurveOptions literal;
  literal.robust = false;
  EXPECT_GT(VelocityRmse(FitCurve(s.stamps, s.positions, literal), s), 1e-3);
}

// Noisy data without defects: nothing is found.
TEST(Jumps, NothingIsFoundInCleanNoisyData) {
  const Motion s = Sample(Smooth, 60.0, 200.0, 1e-3, 0.0, 6);
  const Curve curve = FitCurve(s.stamps, s.positions);
  EXPECT_TRUE(curve.outlier_times().empty());
  EXPECT_TRUE(curve.jump_times().empty());
}

// Stamp jitter: samples of a 1 m/s motion taken at times jittered by 0.5 ms. The even-spacing
// 4th differences see v·δt = 0.5 mm of "noise"; divided differences on the stamps see the 0.1 mm.
TEST(EstimateNoiseSigma, DividedDifferencesAreHonestUnderStampJitter) {
  auto fast = [](double t, Eigen::Vector3d* p, Eigen::Vector3d* v) {
    *p = {t, 0.5 * std::sin(t), 0.0};
    *v = {1.0, 0.5 * std::cos(t), 0.0};
  };
  const Motion s = Sample(fast, 20.0, 100.0, 1e-4, 0.5e-3, 7);
  const Eigen::VectorXd stamped = EstimateNoiseSigma(s.t, s.positions);
  EXPECT_NEAR(stamped[0], 1e-4, 2e-5);
  EXPECT_NEAR(stamped[2], 1e-4, 2e-5);
  EXPECT_GT(EstimateNoiseSigma(s.positions)[0], 3e-4);  // the even-spacing estimate
}

}  // namespace
}  // namespace cheval::cheb
