// Synthetic motion: the derivatives are exact (checked against high-order central differences of the
// exact functions), every kind moves as docs/sim.md says, the seed fixes everything, and the measured
// copy has the asked noise, jitter, dropouts and gaps while staying the truth at its own stamps.
#include "cheval/sim/motion.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <string>
#include <vector>

#include "cheval/common/error.h"

namespace cheval::sim {
namespace {

constexpr MotionKind kAllKinds[] = {MotionKind::kCar, MotionKind::kLegged, MotionKind::kDrone, MotionKind::kHandheld};

MotionModel Model(MotionKind kind, uint64_t seed = 1) {
  MotionOptions options;
  options.kind = kind;
  options.seed = seed;
  return MotionModel(options);
}

Eigen::Matrix3d RotationAt(const MotionModel& model, int64_t stamp) {
  return model.StateAt(stamp).orientation.toRotationMatrix();
}

// Fourth-order central difference f'(t) ≈ (-f(t+2h) + 8 f(t+h) - 8 f(t-h) + f(t-2h)) / (12 h), with
// truncation error h⁴ |f⁽⁵⁾| / 30 and rounding error ~ 1.5 ε |f| / h.
constexpr int64_t kStepNs = 1'000'000;  // h = 1 ms
constexpr double kStepS = 1e-3;

template <class F>
auto CentralDifference(const F& f, int64_t stamp) -> decltype(f(stamp)) {  // evaluated, not an Eigen expression
  return ((f(stamp - 2 * kStepNs) - f(stamp + 2 * kStepNs)) + 8.0 * (f(stamp + kStepNs) - f(stamp - kStepNs))) /
         (12.0 * kStepS);
}

// A few hundred stamps spread over the duration, plus some before the start and after the end (the
// model is defined for every time, and measured stamps may be jittered outside the nominal span).
std::vector<int64_t> CheckStamps(const MotionModel& model) {
  const int64_t start = model.options().start_stamp_ns;
  const auto duration_ns = static_cast<int64_t>(*model.options().duration_s * 1e9);
  std::vector<int64_t> stamps;
  for (int i = 0; i < 300; ++i) stamps.push_back(start + duration_ns * (2 * i + 1) / 600 + 12'345 * i);
  // Stencils straddling the whole seconds where the position quadrature caches its integral.
  for (int64_t k = 1; k <= 5; ++k) stamps.push_back(start + k * 1'000'000'000 + 500'000);
  for (const int64_t outside :
       {-3'000'000'000LL, -10'000'000LL, duration_ns + 10'000'000LL, duration_ns + 2'500'000'000LL}) {
    stamps.push_back(start + outside);
  }
  return stamps;
}

class EveryKind : public ::testing::TestWithParam<MotionKind> {};

INSTANTIATE_TEST_SUITE_P(Motion, EveryKind, ::testing::ValuesIn(kAllKinds),
                         [](const ::testing::TestParamInfo<MotionKind>& kind) {
                           return std::string(ToString(kind.param));
                         });

TEST_P(EveryKind, VelocityIsTheDerivativeOfPosition) {
  // Tolerance 1e-7 m/s: the truncation term is below h⁴/30 · max|p⁽⁵⁾| ≈ 3.3e-14 · (a ω⁵ of the fastest
  // position oscillation: legged 1.5 cm at 3 Hz → 3.6e4 m/s⁵) ≈ 1.2e-9 m/s; rounding is ~1.5 ε |p| / h
  // ≈ 3.3e-13 · 2 km ≈ 7e-10 m/s for the car (also covers the quadrature's rounding). So the check
  // would see any real derivative error (even 1e-7 of a 1 m/s speed) while passing with ~50x margin.
  for (uint64_t seed : {1, 2, 3}) {
    const MotionModel model = Model(GetParam(), seed);
    double worst = 0.0;
    for (const int64_t stamp : CheckStamps(model)) {
      const Eigen::Vector3d fd =
          CentralDifference([&](int64_t s) { return Eigen::Vector3d(model.StateAt(s).position); }, stamp);
      worst = std::max(worst, (fd - model.StateAt(stamp).velocity).norm());
    }
    EXPECT_LT(worst, 1e-7) << "seed " << seed;
  }
}

TEST_P(EveryKind, AngularVelocityIsTheRotationsDerivative) {
  // ω = vee(Rᵀ Ṙ) with Ṙ from the fourth-order difference. Tolerance 1e-7 rad/s: truncation below
  // h⁴/30 · max|R⁽⁵⁾| ≈ 3.3e-14 · (legged roll 0.035 rad at 3 Hz → 8.4e4 rad/s⁵) ≈ 3e-9 rad/s;
  // rounding ≈ 1.5 ε / h ≈ 3e-13 rad/s.
  for (uint64_t seed : {1, 2, 3}) {
    const MotionModel model = Model(GetParam(), seed);
    double worst = 0.0;
    for (const int64_t stamp : CheckStamps(model)) {
      const Eigen::Matrix3d R = RotationAt(model, stamp);
      const Eigen::Matrix3d W =
          R.transpose() * CentralDifference([&](int64_t s) { return RotationAt(model, s); }, stamp);
      const Eigen::Vector3d fd = 0.5 * Eigen::Vector3d(W(2, 1) - W(1, 2), W(0, 2) - W(2, 0), W(1, 0) - W(0, 1));
      worst = std::max(worst, (fd - model.StateAt(stamp).angular_velocity).norm());
      // Rᵀ Ṙ is antisymmetric: its symmetric part is only difference error.
      EXPECT_LT((W + W.transpose()).norm(), 1e-7);
    }
    EXPECT_LT(worst, 1e-7) << "seed " << seed;
  }
}

TEST_P(EveryKind, TruthOnTheNominalGridHasUnitContinuousQuaternions) {
  const MotionModel model = Model(GetParam());
  const traj::Trajectory truth = GenerateMotion(model);
  const MotionDefaults defaults = DefaultsFor(GetParam());
  ASSERT_EQ(truth.size(), static_cast<Eigen::Index>(std::llround(defaults.duration_s * defaults.rate_hz)) + 1);
  EXPECT_TRUE(truth.View().has_velocity());
  EXPECT_TRUE(truth.View().has_angular_velocity());
  const std::vector<int64_t> nominal = model.NominalStamps();
  EXPECT_TRUE(std::equal(nominal.begin(), nominal.end(), truth.stamps_ns().begin(), truth.stamps_ns().end()));
  EXPECT_EQ(truth.stamps_ns().front(), model.options().start_stamp_ns);
  EXPECT_EQ(truth.stamps_ns().back() - truth.stamps_ns().front(), static_cast<int64_t>(defaults.duration_s * 1e9));
  const auto q = truth.View().quaternions();
  EXPECT_GE(q(3, 0), 0.0);
  for (Eigen::Index i = 0; i < truth.size(); ++i) {
    ASSERT_NEAR(q.col(i).norm(), 1.0, 1e-15) << i;  // normalised in double: within an ulp or two
    if (i > 0) {
      ASSERT_GE(q.col(i).dot(q.col(i - 1)), 0.0) << i;
    }
  }
  // The truth at its own stamps is the model at those stamps, bit for bit.
  const MotionState state = model.StateAt(truth.stamps_ns()[123]);
  EXPECT_EQ(Eigen::Vector3d(truth.positions().col(123)), state.position);
  EXPECT_EQ(Eigen::Vector3d(truth.View().velocities().col(123)), state.velocity);
  EXPECT_EQ(Eigen::Vector3d(truth.View().angular_velocities().col(123)), state.angular_velocity);
}

TEST_P(EveryKind, SameSeedSameOutputOtherSeedOtherShape) {
  MotionOptions options;
  options.kind = GetParam();
  options.seed = 42;
  const MeasurementOptions measurement{0.001, 0.0005, 0.1, 1, 0.5};
  const MotionModel a(options), b(options);
  const traj::Trajectory truth_a = GenerateMotion(a), truth_b = GenerateMotion(b);
  EXPECT_EQ(truth_a.raw_positions(), truth_b.raw_positions());
  EXPECT_EQ(truth_a.raw_orientations(), truth_b.raw_orientations());
  EXPECT_EQ(truth_a.raw_velocities(), truth_b.raw_velocities());
  EXPECT_EQ(truth_a.raw_angular_velocities(), truth_b.raw_angular_velocities());
  const traj::Trajectory measured_a = Measure(a, measurement), measured_b = Measure(b, measurement);
  EXPECT_TRUE(std::ranges::equal(measured_a.stamps_ns(), measured_b.stamps_ns()));
  EXPECT_EQ(measured_a.raw_positions(), measured_b.raw_positions());
  options.seed = 43;
  const traj::Trajectory other = GenerateMotion(options);
  EXPECT_GT((other.positions() - truth_a.positions()).cwiseAbs().maxCoeff(), 0.1);
}

TEST(MotionKind, NamesRoundTrip) {
  for (MotionKind kind : kAllKinds) EXPECT_EQ(MotionKindFromString(ToString(kind)), kind);
  EXPECT_EQ(ToString(MotionKind::kHandheld), "handheld");
  EXPECT_EQ(MotionKindFromString("Car"), std::nullopt);
  EXPECT_EQ(MotionKindFromString("boat"), std::nullopt);
}

TEST(MotionOptions, KindDefaultsAndOverrides) {
  EXPECT_EQ(*Model(MotionKind::kCar).options().duration_s, 100.0);
  EXPECT_EQ(*Model(MotionKind::kCar).options().rate_hz, 50.0);
  EXPECT_EQ(*Model(MotionKind::kLegged).options().duration_s, 10.0);
  EXPECT_EQ(*Model(MotionKind::kLegged).options().rate_hz, 200.0);
  EXPECT_EQ(*Model(MotionKind::kDrone).options().duration_s, 60.0);
  EXPECT_EQ(*Model(MotionKind::kDrone).options().rate_hz, 200.0);
  EXPECT_EQ(*Model(MotionKind::kHandheld).options().duration_s, 30.0);
  EXPECT_EQ(*Model(MotionKind::kHandheld).options().rate_hz, 100.0);
  MotionOptions options;
  options.kind = MotionKind::kCar;
  options.rate_hz = 20.0;
  const traj::Trajectory car = GenerateMotion(options);
  EXPECT_EQ(car.size(), 2001);  // 100 s at 20 Hz, both ends included
  options.duration_s = 0.29;    // 0.29 · 100 = 28.999999999999996 in doubles: still 30 samples
  options.rate_hz = 100.0;
  EXPECT_EQ(GenerateMotion(options).size(), 30);
}

// Speeds over the default duration and rate, for a few seeds.
struct SpeedStats {
  double max = 0.0, mean = 0.0, min_horizontal = 1e300, max_rate = 0.0;
};

SpeedStats Speeds(const traj::Trajectory& truth) {
  SpeedStats s;
  const auto v = truth.View().velocities();
  const auto w = truth.View().angular_velocities();
  for (Eigen::Index i = 0; i < truth.size(); ++i) {
    s.max = std::max(s.max, v.col(i).norm());
    s.mean += v.col(i).head<2>().norm() / static_cast<double>(truth.size());
    s.min_horizontal = std::min(s.min_horizontal, v.col(i).head<2>().norm());
    s.max_rate = std::max(s.max_rate, w.col(i).norm());
  }
  return s;
}

// Amplitude spectrum of the vertical position (mean removed): the frequency in [0.5, 10] Hz with the
// largest |2/N Σ z_i e^{-2πi f t_i}|, scanned in 0.01 Hz steps, and that amplitude.
std::pair<double, double> VerticalPeak(const traj::Trajectory& truth) {
  const auto p = truth.positions();
  const double mean = p.row(2).mean();
  double best_f = 0.0, best_a = 0.0;
  for (double f = 0.5; f <= 10.0; f += 0.01) {
    std::complex<double> sum = 0.0;
    for (Eigen::Index i = 0; i < truth.size(); ++i) {
      const double t = static_cast<double>(truth.stamps_ns()[i] - truth.stamps_ns()[0]) * 1e-9;
      sum += (p(2, i) - mean) * std::polar(1.0, -2.0 * std::numbers::pi * f * t);
    }
    const double amplitude = 2.0 * std::abs(sum) / static_cast<double>(truth.size());
    if (amplitude > best_a) {
      best_a = amplitude;
      best_f = f;
    }
  }
  return {best_f, best_a};
}

TEST(MotionKinds, CarDrivesAtRoadSpeedsWithGentleRotation) {
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    const SpeedStats s = Speeds(GenerateMotion(Model(MotionKind::kCar, seed)));
    EXPECT_LE(s.max, 15.0) << seed;
    EXPECT_GE(s.max, 8.0) << seed;
    EXPECT_GE(s.min_horizontal, 1.5 - 1e-9) << seed;  // never stops: the heading stays defined
    EXPECT_LT(s.max_rate, 0.5) << seed;
  }
}

TEST(MotionKinds, DronePeakSpeedIsEight) {
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    const SpeedStats s = Speeds(GenerateMotion(Model(MotionKind::kDrone, seed)));
    // 8 m/s by construction (peak over one period, found to ~1e-7); 200 Hz sampling of 60 s
    // (>= 3 periods) lands within (ω_max · 5 ms)² / 8 ~ 1e-5 of it.
    EXPECT_NEAR(s.max, 8.0, 1e-3) << seed;
    EXPECT_LE(s.max, 8.0 + 1e-5) << seed;
  }
}

TEST(MotionKinds, LeggedTrotsAtTwoToThreeHertz) {
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    const traj::Trajectory truth = GenerateMotion(Model(MotionKind::kLegged, seed));
    const SpeedStats s = Speeds(truth);
    EXPECT_GE(s.mean, 0.3) << seed;
    EXPECT_LE(s.mean, 1.0) << seed;
    EXPECT_LE(s.max, 1.2) << seed;
    // The vertical oscillation is a pure sinusoid at the gait frequency drawn in [2, 3] Hz; over 10 s
    // the scan finds its peak within the 0.01 Hz step (symmetric leakage), the amplitude within 1 %.
    const auto [frequency, amplitude] = VerticalPeak(truth);
    EXPECT_GE(frequency, 2.0 - 0.01) << seed;
    EXPECT_LE(frequency, 3.0 + 0.01) << seed;
    EXPECT_GE(amplitude, 0.0099) << seed;
    EXPECT_LE(amplitude, 0.0152) << seed;
  }
}

TEST(MotionKinds, HandheldWalksWithStepBounceAndFastRotations) {
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    const traj::Trajectory truth = GenerateMotion(Model(MotionKind::kHandheld, seed));
    const SpeedStats s = Speeds(truth);
    EXPECT_GE(s.mean, 0.7) << seed;
    EXPECT_LE(s.mean, 1.3) << seed;
    const auto [frequency, amplitude] = VerticalPeak(truth);
    EXPECT_GE(frequency, 1.5 - 0.01) << seed;
    EXPECT_LE(frequency, 2.0 + 0.01) << seed;
    EXPECT_GE(amplitude, 0.0198) << seed;  // a few cm
    EXPECT_LE(amplitude, 0.0402) << seed;
    EXPECT_GT(s.max_rate, 1.0) << seed;  // larger and faster than the car's < 0.5 rad/s (1.3–2.0 measured)
    EXPECT_LT(s.max_rate, 3.0) << seed;
  }
}

// ---------------------------------------------------------------------------------------------
// The measured copy.

TEST(Measure, PositionsAreTheTruthAtTheMeasuredStampsPlusNoiseOfTheAskedSigma) {
  const MotionModel model = Model(MotionKind::kDrone, 9);  // 12,001 samples x 3 axes
  const double sigma = 0.002;
  const traj::Trajectory measured = Measure(model, {sigma, 0.0005, 0.0, 0, 0.0});
  EXPECT_FALSE(measured.View().has_velocity());
  const traj::Trajectory truth = SampleMotion(model, measured.stamps_ns());
  const Eigen::Matrix3Xd error = measured.positions() - truth.positions();
  const auto n = static_cast<double>(error.size());
  ASSERT_GE(n, 30'000);
  const double mean = error.mean();
  const double std = std::sqrt((error.array() - mean).square().sum() / (n - 1.0));
  // The sample std of 36k normals has relative sd 1/sqrt(2n) ≈ 0.4 %, so 5 % is > 10 sd.
  EXPECT_NEAR(std, sigma, 0.05 * sigma);
  EXPECT_NEAR(mean, 0.0, 5.0 * sigma / std::sqrt(n));
  EXPECT_EQ(measured.View().quaternions(), truth.View().quaternions());

  // Without noise the measured positions are the truth at the measured stamps, bit for bit.
  const traj::Trajectory exact = Measure(model, {0.0, 0.0005, 0.0, 0, 0.0});
  EXPECT_EQ(exact.positions(), SampleMotion(model, exact.stamps_ns()).positions());
}

TEST(Measure, NoiseDoesNotMoveStampsOrDropouts) {
  const MotionModel model = Model(MotionKind::kCar, 4);
  const traj::Trajectory a = Measure(model, {0.0, 0.001, 0.2, 2, 3.0});
  const traj::Trajectory b = Measure(model, {0.05, 0.001, 0.2, 2, 3.0});
  EXPECT_TRUE(std::ranges::equal(a.stamps_ns(), b.stamps_ns()));
}

TEST(Measure, JitterHasTheAskedSigmaAndStampsStrictlyIncrease) {
  const MotionModel model = Model(MotionKind::kDrone, 5);  // 200 Hz: period 5 ms
  const std::vector<int64_t> nominal = model.NominalStamps();
  const double jitter = 0.0005;  // period / 10: neighbours never swap (would need a 7σ difference)
  const traj::Trajectory measured = Measure(model, {0.0, jitter, 0.0, 0, 0.0});
  ASSERT_EQ(measured.size(), static_cast<Eigen::Index>(nominal.size()));
  double sum2 = 0.0;
  for (Eigen::Index i = 0; i < measured.size(); ++i) {
    const double d = static_cast<double>(measured.stamps_ns()[i] - nominal[static_cast<size_t>(i)]) * 1e-9;
    sum2 += d * d;
    if (i > 0) {
      ASSERT_GT(measured.stamps_ns()[i], measured.stamps_ns()[i - 1]) << i;
    }
  }
  // 12,001 samples: relative sd of the std estimate ≈ 0.65 %, so 5 % is > 7 sd.
  EXPECT_NEAR(std::sqrt(sum2 / static_cast<double>(measured.size())), jitter, 0.05 * jitter);

  // A jitter of several periods reorders samples; the sort keeps the stamps strictly increasing and
  // the positions still are the truth at the final stamps.
  const traj::Trajectory wild = Measure(model, {0.0, 0.02, 0.0, 0, 0.0});
  for (Eigen::Index i = 1; i < wild.size(); ++i) ASSERT_GT(wild.stamps_ns()[i], wild.stamps_ns()[i - 1]) << i;
  EXPECT_EQ(wild.positions(), SampleMotion(model, wild.stamps_ns()).positions());
}

TEST(Measure, DropoutsRemoveAboutTheAskedFraction) {
  const MotionModel model = Model(MotionKind::kCar, 6);  // 5,001 samples
  for (const double p : {0.05, 0.2, 0.5}) {
    const traj::Trajectory measured = Measure(model, {0.0, 0.0, p, 0, 0.0});
    const double removed = 1.0 - static_cast<double>(measured.size()) / 5001.0;
    // Binomial sd sqrt(p(1-p)/n) ≤ 0.0071 at n = 5001: 0.03 is > 4 sd.
    EXPECT_NEAR(removed, p, 0.03) << p;
    for (Eigen::Index i = 1; i < measured.size(); ++i) ASSERT_GT(measured.stamps_ns()[i], measured.stamps_ns()[i - 1]);
  }
}

TEST(Measure, GapsAppearWithTheAskedCountAndLength) {
  const MotionModel model = Model(MotionKind::kDrone, 7);  // 60 s at 200 Hz
  const traj::Trajectory measured = Measure(model, {0.0, 0.0, 0.0, 3, 2.0});
  std::vector<double> gaps;
  for (Eigen::Index i = 1; i < measured.size(); ++i) {
    const double dt = static_cast<double>(measured.stamps_ns()[i] - measured.stamps_ns()[i - 1]) * 1e-9;
    if (dt > 0.0051) {
      gaps.push_back(dt);
    } else {
      EXPECT_NEAR(dt, 0.005, 1e-9);
    }
  }
  ASSERT_EQ(gaps.size(), 3u);
  // Each gap removes the nominal samples in [begin, begin + 2 s): the kept neighbours are 2 s plus
  // at most one period apart. One gap per 20 s slot.
  for (const double g : gaps) {
    EXPECT_GT(g, 2.0);
    EXPECT_LE(g, 2.005 + 1e-9);
  }
  EXPECT_EQ(measured.size(), 12001 - 3 * 400);  // each gap removes exactly 2 s · 200 Hz samples
}

struct BadMeasurement {
  MeasurementOptions options;
  std::string field;
  std::string message;
};

// Bad values are OptionErrors naming the struct and field (the CLI and Python spell the field their way).
TEST(Measure, RejectsBadOptionsNamingTheField) {
  const MotionModel model = Model(MotionKind::kLegged);  // 10 s at 200 Hz
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<BadMeasurement> cases = {
      {{-0.1, 0, 0, 0, 0}, "noise_m", "must be a non-negative number of metres, got -0.1"},
      {{nan, 0, 0, 0, 0}, "noise_m", "must be a non-negative number of metres, got nan"},
      {{0, -1, 0, 0, 0}, "jitter_s", "must be a non-negative number of seconds, got -1"},
      {{0, 10, 0, 0, 0}, "jitter_s", "must be below the duration (10 s), got 10"},
      {{0, 0, 1, 0, 0}, "dropout_probability", "must be a probability in [0, 1), got 1"},
      {{0, 0, -0.5, 0, 0}, "dropout_probability", "must be a probability in [0, 1), got -0.5"},
      {{0, 0, 0, -2, 1}, "gap_count", "must be non-negative, got -2"},
      {{0, 0, 0, 2, 0}, "gap_s", "must be a positive number of seconds when there are gaps, got 0"},
      {{0, 0, 0, 0, 1.5}, "gap_s", "must be 0 when the gap count is 0, got 1.5"},
      {{0, 0, 0, 4, 2.5},
       "gap_s",
       "must fit 4 gaps in the duration (10 s): each needs a slot of duration / gap count longer than the gap plus "
       "two sample periods, got 2.5"},
      {{0, 0, 0.9999999, 1, 9.98},
       "dropout_probability",
       "must leave, with the gaps, at least 2 of the 2001 samples (it left 0), got 0.9999999"},
      {{0, 0, 0, 0, 0, -0.1}, "rotation_noise_rad", "must be a non-negative number of radians, got -0.1"},
  };
  for (const BadMeasurement& c : cases) {
    try {
      Measure(model, c.options);
      ADD_FAILURE() << "no error for: " << c.message;
    } catch (const OptionError& e) {
      EXPECT_EQ(e.options(), "MeasurementOptions");
      EXPECT_EQ(e.field(), c.field);
      EXPECT_EQ(e.rule(), c.message);
      EXPECT_EQ(std::string(e.what()), "MeasurementOptions::" + c.field + " " + c.message);
    }
  }
}

TEST(MotionModel, RejectsBadOptionsNamingTheField) {
  auto message = [](MotionOptions options) {
    try {
      MotionModel model(options);
    } catch (const OptionError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  MotionOptions o;
  o.rate_hz = -1.0;
  EXPECT_EQ(message(o), "MotionOptions::rate_hz must be a positive number of Hz, got -1");
  o.rate_hz = std::numeric_limits<double>::infinity();
  EXPECT_EQ(message(o), "MotionOptions::rate_hz must be a positive number of Hz, got inf");
  o = {};
  o.duration_s = 0.0;
  EXPECT_EQ(message(o), "MotionOptions::duration_s must be a positive number of seconds, got 0");
  o.duration_s = 2e6;
  EXPECT_EQ(message(o), "MotionOptions::duration_s must be at most 1e6 s, got 2000000");
  o.duration_s = 1e6;
  o.rate_hz = 1000.0;
  EXPECT_EQ(message(o), "MotionOptions::rate_hz must give at most 1e8 samples over the duration (1000000 s), got 1000 Hz");
  o = {};
  o.start_stamp_ns = 5'000'000'000'000'000'000;
  EXPECT_EQ(message(o), "MotionOptions::start_stamp_ns must be within ±4e18 ns, got 5000000000000000000");
  o = {};
  o.kind = static_cast<MotionKind>(7);
  EXPECT_EQ(message(o), "MotionOptions::kind must be one of car, legged, drone, handheld, got 7");
  // Validate() alone checks the fields that are set; unset duration and rate are the kind's defaults.
  EXPECT_NO_THROW(MotionOptions{}.Validate());
}

TEST(AddPositionNoise, KeepsStampsAndOrientationsAndAddsTheAskedSigma) {
  const traj::Trajectory truth = GenerateMotion(Model(MotionKind::kDrone, 3));
  const traj::Trajectory noisy = AddPositionNoise(truth.View(), 0.01, 11);
  EXPECT_FALSE(noisy.View().has_velocity());
  EXPECT_TRUE(std::ranges::equal(noisy.stamps_ns(), truth.stamps_ns()));
  EXPECT_EQ(noisy.View().quaternions(), truth.View().quaternions());
  const Eigen::Matrix3Xd error = noisy.positions() - truth.positions();
  EXPECT_NEAR(std::sqrt(error.array().square().mean()), 0.01, 0.0005);  // 36k normals: 5 % is > 10 sd
  EXPECT_THROW(AddPositionNoise(truth.View(), -1.0, 1), UsageError);
}

}  // namespace
}  // namespace cheval::sim

namespace cheval::sim {
namespace {

// The simulated estimator: its stamps, that with no error it is the truth, that its position drift is
// exactly the integral of its velocity error (as in a filter), determinism, streams, bad values.
TEST(SimulateEstimate, NoErrorIsTheTruthAtItsOwnRate) {
  const MotionModel model = Model(MotionKind::kDrone, 3);
  EstimatorSimOptions options;
  options.rate_hz = 20;
  options.velocity_random_walk = options.position_noise_m = options.velocity_noise_mps = 0;
  options.rotation_random_walk_rad = 0;
  options.delay_s = 0.5;
  const traj::Trajectory estimate = SimulateEstimate(model, options);
  ASSERT_TRUE(estimate.channels().velocity);
  const double duration = *model.options().duration_s;
  EXPECT_EQ(estimate.size(), static_cast<Eigen::Index>(std::floor((duration - 0.5) * 20)) + 1);
  EXPECT_EQ(estimate.stamps_ns()[0], model.options().start_stamp_ns + 500'000'000);
  EXPECT_EQ(estimate.stamps_ns()[1] - estimate.stamps_ns()[0], 50'000'000);
  const traj::Trajectory truth = SampleMotion(model, estimate.stamps_ns());
  EXPECT_LT((estimate.positions() - truth.positions()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((estimate.View().velocities() - truth.View().velocities()).cwiseAbs().maxCoeff(), 1e-12);
  for (Eigen::Index i = 0; i < estimate.size(); ++i) {
    EXPECT_LT((estimate.Rotation(i) - truth.Rotation(i)).norm(), 1e-12) << i;
  }
}

TEST(SimulateEstimate, PositionDriftIsTheIntegralOfTheVelocityError) {
  const MotionModel model = Model(MotionKind::kCar, 2);
  EstimatorSimOptions options;
  options.position_noise_m = options.velocity_noise_mps = 0;  // drift only
  options.velocity_random_walk = 0.01;
  const traj::Trajectory estimate = SimulateEstimate(model, options);
  const traj::Trajectory truth = SampleMotion(model, estimate.stamps_ns());
  const Eigen::Matrix3Xd position_error = estimate.positions() - truth.positions();
  const Eigen::Matrix3Xd velocity_error = estimate.View().velocities() - truth.View().velocities();
  EXPECT_LT(position_error.col(0).norm(), 1e-12);  // starts without error
  for (Eigen::Index i = 0; i + 1 < estimate.size(); ++i) {
    const double dt = static_cast<double>(estimate.stamps_ns()[i + 1] - estimate.stamps_ns()[i]) * 1e-9;
    ASSERT_LT((position_error.col(i + 1) - position_error.col(i) - dt * velocity_error.col(i)).norm(), 1e-9) << i;
  }
  // A random walk of 0.01 m/s per sqrt(s) over 100 s: the velocity error is some cm/s at the end, not 0.
  const double final_velocity_error = velocity_error.col(estimate.size() - 1).norm();
  EXPECT_GT(final_velocity_error, 1e-3);
  EXPECT_LT(final_velocity_error, 1.0);
}

TEST(SimulateEstimate, DeterministicPerSeedAndStream) {
  const MotionModel model = Model(MotionKind::kHandheld, 5);
  EstimatorSimOptions options;
  const traj::Trajectory a = SimulateEstimate(model, options), again = SimulateEstimate(model, options);
  EXPECT_EQ(a.raw_positions(), again.raw_positions());
  EXPECT_EQ(a.raw_velocities(), again.raw_velocities());
  options.stream = 1;
  const traj::Trajectory b = SimulateEstimate(model, options);
  EXPECT_NE(a.raw_positions(), b.raw_positions());
}

TEST(SimulateEstimate, BadValuesNameTheField) {
  const MotionModel model = Model(MotionKind::kDrone);
  auto message = [&model](auto change) {
    EstimatorSimOptions options;
    change(options);
    try {
      SimulateEstimate(model, options);
    } catch (const OptionError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message([](EstimatorSimOptions& o) { o.rate_hz = 0; }),
            "EstimatorSimOptions::rate_hz must be a positive number of Hz, got 0");
  EXPECT_EQ(message([](EstimatorSimOptions& o) { o.velocity_random_walk = -1; }),
            "EstimatorSimOptions::velocity_random_walk must be a non-negative finite number, got -1");
  EXPECT_EQ(message([](EstimatorSimOptions& o) { o.rotation_random_walk_rad = std::nan(""); }),
            "EstimatorSimOptions::rotation_random_walk_rad must be a non-negative finite number, got nan");
  EXPECT_EQ(message([](EstimatorSimOptions& o) { o.position_noise_m = -0.5; }),
            "EstimatorSimOptions::position_noise_m must be a non-negative finite number, got -0.5");
  EXPECT_EQ(message([](EstimatorSimOptions& o) { o.velocity_noise_mps = std::nan(""); }),
            "EstimatorSimOptions::velocity_noise_mps must be a non-negative finite number, got nan");
  EXPECT_EQ(message([](EstimatorSimOptions& o) { o.delay_s = -1; }),
            "EstimatorSimOptions::delay_s must be a non-negative number of seconds, got -1");
  EXPECT_EQ(message([](EstimatorSimOptions& o) { o.delay_s = 60; }),
            "EstimatorSimOptions::delay_s must be below the duration (60 s), got 60");
  EXPECT_EQ(message([](EstimatorSimOptions& o) { o.rate_hz = 0.01; }),
            "EstimatorSimOptions::rate_hz must give 2 to 1e8 poses over 60 s (it gives 1), got 0.01");
}

}  // namespace
}  // namespace cheval::sim
