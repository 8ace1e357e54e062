#include "cheval/eval/rotation_curve.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "cheval/common/error.h"
#include "cheval/lie/so3.h"
#include "cheval/sim/motion.h"

namespace cheval::eval {
namespace {

using SO3 = lie::SO3<double>;
constexpr int64_t kEpoch = 1'403'636'580'000'000'000;

// R(t) = Rz(a t) · Rx(b sin t): several turns about z (many charts) with a wobble about x. Body
// rate of a product A·B is Bᵀω_A + ω_B: ω = Rx(b sin t)ᵀ (a e_z) + b cos t e_x.
constexpr double kYawRate = 1.3, kWobble = 0.4;
Eigen::Quaterniond SpinRotation(double t) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(kYawRate * t, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(kWobble * std::sin(t), Eigen::Vector3d::UnitX()));
}
Eigen::Vector3d SpinRate(double t) {
  const Eigen::Matrix3d wobble = Eigen::AngleAxisd(kWobble * std::sin(t), Eigen::Vector3d::UnitX()).toRotationMatrix();
  return wobble.transpose() * Eigen::Vector3d(0, 0, kYawRate) + Eigen::Vector3d(kWobble * std::cos(t), 0, 0);
}

struct Rotations {
  std::vector<int64_t> stamps;
  std::vector<Eigen::Quaterniond> rotations;
};

Rotations SampleSpin(double duration, double rate, double sigma, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  Rotations r;
  const auto m = static_cast<int64_t>(duration * rate) + 1;
  for (int64_t i = 0; i < m; ++i) {
    const int64_t offset = std::llround(static_cast<double>(i) * 1e9 / rate);
    const double t = static_cast<double>(offset) * 1e-9;
    Eigen::Quaterniond q = SpinRotation(t);
    if (sigma > 0) q = q * SO3::Exp(Eigen::Vector3d(noise(rng), noise(rng), noise(rng))).quaternion();
    r.stamps.push_back(kEpoch + offset);
    r.rotations.push_back(i % 2 == 0 ? q : Eigen::Quaterniond(-q.coeffs()));  // either sign is the same rotation
  }
  return r;
}

double RateRmse(const std::vector<int64_t>& stamps, const Eigen::Matrix3Xd& rates) {
  double sum = 0;
  for (size_t i = 0; i < stamps.size(); ++i) {
    sum += (rates.col(static_cast<Eigen::Index>(i)) - SpinRate(static_cast<double>(stamps[i] - kEpoch) * 1e-9))
               .squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(stamps.size()));
}

// Angular velocity by central differences on the group: Log(R_{i-1}ᵀ R_{i+1}) / (t_{i+1} − t_{i-1}).
double CentralDifferenceRmse(const Rotations& r) {
  double sum = 0;
  const size_t n = r.stamps.size();
  for (size_t i = 1; i + 1 < n; ++i) {
    const Eigen::Vector3d rate = (SO3(r.rotations[i - 1]).Inverse() * SO3(r.rotations[i + 1])).Log() /
                                 (static_cast<double>(r.stamps[i + 1] - r.stamps[i - 1]) * 1e-9);
    sum += (rate - SpinRate(static_cast<double>(r.stamps[i] - kEpoch) * 1e-9)).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(n - 2));
}

TEST(RotationCurve, NoiseFreeSpinIsExactAcrossManyChartsAndBlends) {
  const Rotations r = SampleSpin(20.0, 100.0, 0.0, 1);  // 26 rad of yaw
  const RotationCurve curve = FitRotationCurve(r.stamps, r.rotations);
  EXPECT_GE(curve.charts().size(), 10u);
  // Between the samples too (midpoints), where no data pins the curve.
  std::vector<int64_t> queries;
  for (size_t i = 0; i + 1 < r.stamps.size(); ++i) queries.push_back((r.stamps[i] + r.stamps[i + 1]) / 2);
  std::vector<Eigen::Quaterniond> orientations;
  Eigen::Matrix3Xd rates;
  curve.EvaluateMany(queries, &orientations, &rates);
  double worst_angle = 0;
  for (size_t i = 0; i < queries.size(); ++i) {
    const double t = static_cast<double>(queries[i] - kEpoch) * 1e-9;
    worst_angle = std::max(worst_angle, (SO3(orientations[i]).Inverse() * SO3(SpinRotation(t))).Log().norm());
  }
  // Measured 2.1e-9 rad between the samples, 6.1e-9 rad/s, residual 2.5e-10 rad: the charts' fits are
  // exact but for truncation and rounding, which move with the degrees selected; bounds ~5x.
  EXPECT_LT(worst_angle, 1e-8);
  EXPECT_LT(RateRmse(queries, rates), 3e-8);
  EXPECT_LT(curve.residual_rms_rad(), 1e-9);
}

// The blend across charts is differentiated exactly: the rate equals the derivative of the fitted
// orientation itself, Log(R(t)ᵀR(t + h)) / h, also inside the overlaps.
TEST(RotationCurve, RateIsTheDerivativeOfTheFittedOrientation) {
  const Rotations r = SampleSpin(12.0, 50.0, 0.003, 2);
  const RotationCurve curve = FitRotationCurve(r.stamps, r.rotations);
  ASSERT_GE(curve.charts().size(), 3u);
  int checked_in_overlap = 0;
  for (size_t k = 1; k < curve.charts().size(); ++k) {
    const int64_t middle = (curve.charts()[k].begin_ns + curve.charts()[k - 1].end_ns) / 2;
    constexpr int64_t kStep = 1000;  // 1 µs
    const std::vector<int64_t> stamps{middle - kStep, middle, middle + kStep};
    std::vector<Eigen::Quaterniond> q;
    Eigen::Matrix3Xd rates;
    curve.EvaluateMany(stamps, &q, &rates);
    const Eigen::Vector3d numeric = (SO3(q[0]).Inverse() * SO3(q[2])).Log() / (2e-9 * kStep);
    EXPECT_LT((numeric - rates.col(1)).norm(), 1e-5 * (1.0 + rates.col(1).norm())) << "overlap " << k;
    ++checked_in_overlap;
  }
  EXPECT_GE(checked_in_overlap, 2);
}

TEST(RotationCurve, NoisyRotationsBeatCentralDifferencesByFar) {
  const Rotations r = SampleSpin(30.0, 100.0, 0.005, 3);  // 0.3° noise per axis
  const RotationCurve curve = FitRotationCurve(r.stamps, r.rotations);
  std::vector<Eigen::Quaterniond> orientations;
  Eigen::Matrix3Xd rates;
  curve.EvaluateMany(r.stamps, &orientations, &rates);
  const double fitted = RateRmse(r.stamps, rates), central = CentralDifferenceRmse(r);
  EXPECT_LT(fitted, 0.2 * central) << fitted << " vs central " << central;
  // The residual is the noise: the angle of a N(0, σ²I₃) rotation vector has RMS σ·sqrt(3).
  EXPECT_NEAR(curve.residual_rms_rad(), 0.005 * std::sqrt(3.0), 0.0005);
}

// On the simulator's drone (exact orientation and body rate), with motion-capture-like noise.
TEST(RotationCurve, SimulatedDroneBodyRate) {
  sim::MotionOptions options;
  options.kind = sim::MotionKind::kDrone;
  options.duration_s = 20.0;
  options.seed = 4;
  const sim::MotionModel model(options);
  const traj::Trajectory measured = sim::Measure(model, {.noise_m = 0.0005, .rotation_noise_rad = 0.004});
  const traj::Trajectory truth = sim::SampleMotion(model, measured.stamps_ns());
  const auto view = measured.View();
  std::vector<Eigen::Quaterniond> rotations;
  for (Eigen::Index i = 0; i < view.size(); ++i) rotations.push_back(view.UnitQuaternion(i));
  const RotationCurve curve = FitRotationCurve(view.stamps_ns(), rotations);
  std::vector<Eigen::Quaterniond> orientations;
  Eigen::Matrix3Xd rates;
  curve.EvaluateMany(view.stamps_ns(), &orientations, &rates);
  const Eigen::Matrix3Xd exact = truth.View().angular_velocities();
  const double rmse = std::sqrt((rates - exact).colwise().squaredNorm().mean());
  const double scale = std::sqrt(exact.colwise().squaredNorm().mean());
  EXPECT_LT(rmse, 0.05 * scale) << rmse << " rad/s against an RMS rate of " << scale;
}

TEST(RotationCurve, UnsortedInputGivesTheSortedResult) {
  const Rotations r = SampleSpin(5.0, 50.0, 0.002, 5);
  Rotations shuffled = r;
  std::vector<size_t> order(r.stamps.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937_64(6));
  for (size_t i = 0; i < order.size(); ++i) {
    shuffled.stamps[i] = r.stamps[order[i]];
    shuffled.rotations[i] = r.rotations[order[i]];
  }
  const RotationCurve a = FitRotationCurve(r.stamps, r.rotations), b = FitRotationCurve(shuffled.stamps, shuffled.rotations);
  std::vector<Eigen::Quaterniond> qa, qb;
  Eigen::Matrix3Xd wa, wb;
  a.EvaluateMany(r.stamps, &qa, &wa);
  b.EvaluateMany(r.stamps, &qb, &wb);
  EXPECT_EQ(wa, wb);
}

TEST(RotationCurve, ErrorsOnWhatCannotBeFitted) {
  const Rotations r = SampleSpin(2.0, 50.0, 0.0, 7);
  const RotationCurve curve = FitRotationCurve(r.stamps, r.rotations);
  std::vector<Eigen::Quaterniond> q;
  Eigen::Matrix3Xd w;
  const std::vector<int64_t> before{kEpoch - 1'000'000'000};
  EXPECT_THROW(curve.EvaluateMany(before, &q, &w), ComputeError);
  const std::vector<int64_t> one{kEpoch};
  const std::vector<Eigen::Quaterniond> identity{Eigen::Quaterniond::Identity()};
  EXPECT_THROW(FitRotationCurve(one, identity), ComputeError);
  // Consecutive samples half a turn apart: no chart can hold them.
  const std::vector<int64_t> two{kEpoch, kEpoch + 10'000'000, kEpoch + 20'000'000};
  const std::vector<Eigen::Quaterniond> flips{Eigen::Quaterniond::Identity(),
                                              Eigen::Quaterniond(Eigen::AngleAxisd(3.0, Eigen::Vector3d::UnitZ())),
                                              Eigen::Quaterniond::Identity()};
  EXPECT_THROW(FitRotationCurve(two, flips), ComputeError);
  const std::vector<Eigen::Quaterniond> zero{Eigen::Quaterniond(0, 0, 0, 0), Eigen::Quaterniond::Identity(),
                                             Eigen::Quaterniond::Identity()};
  EXPECT_THROW(FitRotationCurve(two, zero), ComputeError);
  RotationCurveOptions too_wide;
  too_wide.max_chart_angle = 3.0;
  EXPECT_THROW(FitRotationCurve(r.stamps, r.rotations, too_wide), UsageError);
}

}  // namespace
}  // namespace cheval::eval
