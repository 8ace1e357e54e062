// eval/velocity.h against closed forms (docs/velocity.md): central differences and Savitzky–Golay
// on polynomials they reproduce exactly, a fixed-degree Chebyshev fit differentiated exactly, the
// output trajectory (own stamps as read, slerp between neighbours elsewhere), the JSON, and the
// options' validation naming the field.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cheval/common/error.h"
#include "cheval/eval/velocity.h"
#include "cheval/cheb/curve.h"
#include "cheval/sim/motion.h"
#include "cheval/traj/io.h"
#include "eval_test_util.h"
#include "expect_option_error.h"
#include "../support/test_data.h"

namespace cheval::eval {
namespace {

using cheval::testing::ExpectOptionError;
using testing::AxisAngle;
using testing::MakeTrajectory;
using testing::PoseSpec;

// p(t) = (1 + 2t − t³, 3t², −t) at `stamps_ns` (t in s from 0), orientation rotating about z at
// 0.5 rad/s; its velocity is (2 − 3t², 6t, −1).
traj::Trajectory Cubic(const std::vector<int64_t>& stamps_ns, bool orientation = true) {
  std::vector<PoseSpec> poses;
  for (int64_t stamp : stamps_ns) {
    const double t = static_cast<double>(stamp) * 1e-9;
    PoseSpec s;
    s.stamp_ns = stamp;
    s.p = {1 + 2 * t - t * t * t, 3 * t * t, -t};
    s.q = AxisAngle(0.5 * t, Eigen::Vector3d::UnitZ());
    poses.push_back(s);
  }
  return MakeTrajectory(poses, false, orientation);
}

Eigen::Vector3d CubicVelocity(int64_t stamp_ns) {
  const double t = static_cast<double>(stamp_ns) * 1e-9;
  return {2 - 3 * t * t, 6 * t, -1};
}

// n stamps 10 ms apart, every third one 3 ms late (uneven sampling).
std::vector<int64_t> Stamps(int n) {
  std::vector<int64_t> stamps;
  for (int i = 0; i < n; ++i) stamps.push_back(i * 10'000'000 + (i % 3 == 1 ? 3'000'000 : 0));
  return stamps;
}

TEST(VelocityTest, CentralDifferencesAreExactOnAnEvenlySampledQuadratic) {
  // On a quadratic with equal spacing h: (p(t+h) − p(t−h)) / 2h = p'(t) exactly; at the ends the
  // one-sided difference is p' at the midpoint of the two samples.
  std::vector<PoseSpec> poses;
  for (int i = 0; i < 50; ++i) {
    const double t = 0.02 * i;
    poses.push_back({i * 20'000'000, {t * t, 3 * t, 1.0}});
  }
  const traj::Trajectory trajectory = MakeTrajectory(poses);
  VelocityOptions options;
  options.method = VelocityMethod::kCentral;
  const VelocityEstimate e = EstimateVelocity(trajectory.View(), options);
  ASSERT_EQ(e.velocities.cols(), 50);
  EXPECT_FALSE(e.curve.has_value());
  EXPECT_EQ(e.positions.cols(), 0);
  for (int i = 1; i < 49; ++i) {
    EXPECT_NEAR(e.velocities(0, i), 2 * 0.02 * i, 1e-12) << i;
    EXPECT_NEAR(e.velocities(1, i), 3.0, 1e-12);
    EXPECT_NEAR(e.velocities(2, i), 0.0, 1e-12);
  }
  EXPECT_NEAR(e.velocities(0, 0), 2 * 0.01, 1e-12);
  EXPECT_NEAR(e.velocities(0, 49), 2 * (0.02 * 48 + 0.01), 1e-12);
}

TEST(VelocityTest, SavitzkyGolayReproducesACubicOnUnevenStamps) {
  // A local least-squares cubic in time fits a cubic exactly, whatever the spacing.
  const traj::Trajectory trajectory = Cubic(Stamps(100));
  VelocityOptions options;
  options.method = VelocityMethod::kSavitzkyGolay;
  const VelocityEstimate e = EstimateVelocity(trajectory.View(), options);
  for (Eigen::Index i = 0; i < trajectory.size(); ++i) {
    EXPECT_LT((e.velocities.col(i) - CubicVelocity(trajectory.View().stamps_ns()[i])).norm(), 1e-9) << i;
  }
  // The window in seconds: 0.3 s at 100 Hz is 30 samples, the next odd number 31; at least 5.
  std::vector<int64_t> even;
  for (int i = 0; i < 101; ++i) even.push_back(i * 10'000'000);
  EXPECT_EQ(SavitzkyGolaySamples(even, 0.3), 31);
  EXPECT_EQ(SavitzkyGolaySamples(even, 0.21), 21);
  EXPECT_EQ(SavitzkyGolaySamples(even, 0.01), 5);
  options.savgol_window_s = 0.3;
  const VelocityEstimate by_seconds = EstimateVelocity(Cubic(even).View(), options);
  EXPECT_LT((by_seconds.velocities.col(50) - CubicVelocity(even[50])).norm(), 1e-9);
}

TEST(VelocityTest, AFixedDegreeChebyshevFitIsDifferentiatedExactly) {
  // Degree 5 >= 3: one global least-squares fit (no window given) reproduces the cubic, and its
  // derivative is exact at the samples and between them.
  const traj::Trajectory trajectory = Cubic(Stamps(200));
  VelocityOptions options;
  options.curve = CurveOptionsFromNames("5");
  EXPECT_TRUE(options.curve.single_window);
  const VelocityEstimate own = EstimateVelocity(trajectory.View(), options);
  ASSERT_TRUE(own.curve.has_value());
  for (Eigen::Index i = 0; i < trajectory.size(); ++i) {
    EXPECT_LT((own.velocities.col(i) - CubicVelocity(trajectory.View().stamps_ns()[i])).norm(), 1e-8) << i;
    EXPECT_LT((own.positions.col(i) - trajectory.View().positions().col(i)).norm(), 1e-10) << i;
  }
  const std::vector<int64_t> at = {5'000'000, 1'234'567'891, 1'985'000'000};
  const VelocityEstimate between = EstimateVelocity(trajectory.View(), options, std::span<const int64_t>(at));
  ASSERT_EQ(between.velocities.cols(), 3);
  for (size_t k = 0; k < at.size(); ++k) {
    EXPECT_LT((between.velocities.col(static_cast<Eigen::Index>(k)) - CubicVelocity(at[k])).norm(), 1e-8) << k;
  }
}

TEST(VelocityTest, TheOutputTrajectoryKeepsWhatWasReadAndSlerpsElsewhere) {
  const traj::Trajectory trajectory = Cubic(Stamps(200));
  VelocityOptions options;
  options.curve = CurveOptionsFromNames("5");
  const VelocityEstimate own = EstimateVelocity(trajectory.View(), options);
  const traj::Trajectory written = VelocityTrajectory(trajectory.View(), own);
  const traj::TrajectoryView out = written.View(), in = trajectory.View();
  ASSERT_EQ(out.size(), in.size());
  EXPECT_TRUE(out.channels().velocity);
  EXPECT_FALSE(out.channels().angular_velocity);
  for (Eigen::Index i = 0; i < out.size(); ++i) {
    EXPECT_EQ(out.stamps_ns()[i], in.stamps_ns()[i]);
    EXPECT_EQ(out.positions().col(i), in.positions().col(i));  // as read, not fitted
    EXPECT_EQ(out.quaternions().col(i), in.quaternions().col(i));
    EXPECT_EQ(out.velocities().col(i), own.velocities.col(i));
  }
  // Midway between poses 0 (t = 0) and 1 (t = 13 ms): the slerp of the two, rotation 0.5 t about z.
  const std::vector<int64_t> at = {6'500'000};
  const VelocityEstimate mid = EstimateVelocity(trajectory.View(), options, std::span<const int64_t>(at));
  const traj::Trajectory between = VelocityTrajectory(trajectory.View(), mid, std::span<const int64_t>(at));
  ASSERT_EQ(between.size(), 1);
  EXPECT_LT(between.View().UnitQuaternion(0).angularDistance(AxisAngle(0.5 * 0.0065, Eigen::Vector3d::UnitZ())),
            1e-12);
  EXPECT_EQ(between.View().positions().col(0), mid.positions.col(0));  // fitted
  // Without orientation: the identity.
  const traj::Trajectory bare = Cubic(Stamps(200), false);
  const VelocityEstimate no_q = EstimateVelocity(bare.View(), options, std::span<const int64_t>(at));
  EXPECT_EQ(VelocityTrajectory(bare.View(), no_q, std::span<const int64_t>(at)).View().UnitQuaternion(0).coeffs(),
            Eigen::Quaterniond::Identity().coeffs());
}

TEST(VelocityTest, JsonReportsTheCurve) {
  const traj::Trajectory trajectory = Cubic(Stamps(200));
  VelocityOptions options;
  options.curve = CurveOptionsFromNames("5");
  const VelocityEstimate e = EstimateVelocity(trajectory.View(), options);
  const nlohmann::json j =
      nlohmann::json::parse(VelocityJson({"cubic.txt", trajectory.size(), options, 200, 0.5}, e));
  EXPECT_EQ(j["command"], "velocity");
  EXPECT_EQ(j["input"]["path"], "cubic.txt");
  EXPECT_EQ(j["input"]["poses"], 200);
  EXPECT_EQ(j["method"], "chebyshev");
  EXPECT_EQ(j["degree_method"], "5");
  EXPECT_EQ(j["evaluated_at"], 200);
  EXPECT_EQ(j["segments"], 1);
  EXPECT_EQ(j["windows"], 1);
  EXPECT_EQ(j["degrees"], nlohmann::json({5, 5, 5}));
  // 3 n positions over the values the curve stores.
  EXPECT_DOUBLE_EQ(j["compression_ratio"].get<double>(), 600.0 / static_cast<double>(e.curve->stored_values()));
  EXPECT_EQ(j["seconds"], 0.5);
  EXPECT_FALSE(j.contains("angular"));
}

TEST(VelocityTest, DegreeNamesRoundTrip) {
  EXPECT_EQ(CurveOptionsFromNames("auto").degree_method, cheb::DegreeMethod::kCrossValidation);
  EXPECT_EQ(CurveOptionsFromNames("cv").degree_method, cheb::DegreeMethod::kCrossValidation);
  EXPECT_EQ(CurveOptionsFromNames("chop").degree_method, cheb::DegreeMethod::kChop);
  const cheb::CurveOptions fixed = CurveOptionsFromNames("12", 2.0);
  EXPECT_EQ(fixed.degree_method, cheb::DegreeMethod::kFixed);
  EXPECT_EQ(fixed.fixed_degree, 12);
  EXPECT_EQ(fixed.window_s, 2.0);
  EXPECT_FALSE(fixed.single_window);  // a window is given: windowed fits
  for (const char* name : {"auto", "chop", "12"}) EXPECT_EQ(DegreeName(CurveOptionsFromNames(name)), name);
  for (const char* bad : {"foo", "-1", "12x", ""}) {
    ExpectOptionError([&] { (void)CurveOptionsFromNames(bad); }, "CurveOptions", "degree_method");
  }
  for (VelocityMethod m : {VelocityMethod::kChebyshev, VelocityMethod::kCentral, VelocityMethod::kSavitzkyGolay}) {
    EXPECT_EQ(VelocityMethodFromString(ToString(m)), m);
  }
}

TEST(VelocityTest, OptionErrorsNameTheField) {
  VelocityOptions options;
  options.method = VelocityMethod::kSavitzkyGolay;
  options.savgol_window = 4;
  ExpectOptionError([&] { options.Validate(); }, "VelocityOptions", "savgol_window");
  options.savgol_window_s = -1.0;
  ExpectOptionError([&] { options.Validate(); }, "VelocityOptions", "savgol_window_s");
  options = {};
  options.method = VelocityMethod::kSavitzkyGolay;
  options.angular = true;
  ExpectOptionError([&] { options.Validate(); }, "VelocityOptions", "angular");
  // Central differences only at the trajectory's own stamps; angular needs orientations.
  const traj::Trajectory trajectory = Cubic(Stamps(20));
  const std::vector<int64_t> at = {5'000'000};
  options = {};
  options.method = VelocityMethod::kCentral;
  ExpectOptionError([&] { (void)EstimateVelocity(trajectory.View(), options, std::span<const int64_t>(at)); },
                    "VelocityOptions", "method");
  options.angular = true;
  const traj::Trajectory bare = Cubic(Stamps(20), false);
  ExpectOptionError([&] { (void)EstimateVelocity(bare.View(), options); }, "VelocityOptions", "angular");
  // Too few samples for the window is the data's fault: ComputeError.
  options = {};
  options.method = VelocityMethod::kSavitzkyGolay;
  EXPECT_THROW((void)EstimateVelocity(trajectory.View(), options), ComputeError);
}

// TUM fr2/desk's ground truth (a hand-held camera, < 1 m/s) has holes of 20–300 ms in its 300 Hz
// stamps; those under 0.1 s stay inside a segment.
// - A one-sided quintic at a segment's end sample (the local interpolant's, where the window's rate
//   is of higher order) carried the curvature of the samples beyond such a hole back to the end
//   sample: 9.5, 5.0 and 16.8 m/s at the first three samples (central differences 0.03–0.28 m/s).
//   It is taken over evenly spaced samples only.
// - Windows of degree 12–14 over 21–28 samples swung across holes inside them: 29, 37, 1.7, 10 and
//   2.1 m/s at the last five. Their top degree is capped by their holes.
TEST(EstimateVelocity, SamplesNextToHolesInRealGroundTruthStaySane) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const traj::Trajectory trajectory =
      traj::ReadTrajectory(::cheval::testing::SharedDataDir() + "/evo/fr2_desk_groundtruth.txt");
  const VelocityEstimate e = EstimateVelocity(trajectory.View(), VelocityOptions{});
  const auto stamps = trajectory.View().stamps_ns();
  for (const double seconds : {10.3039, 24.3612, 29.8414, 9.3538, 19.7676, 23.6645, 24.9778, 25.0079}) {
    const auto at = std::lower_bound(stamps.begin(), stamps.end(),
                                     stamps.front() + static_cast<int64_t>(std::llround((seconds - 5e-5) * 1e9)));
    ASSERT_NE(at, stamps.end());
    const auto i = static_cast<Eigen::Index>(at - stamps.begin());
    EXPECT_LT(e.velocities.col(i).norm(), 1.0) << "at " << seconds << " s: " << e.velocities.col(i).transpose();
  }
}

// DIDO's motion capture (~410 Hz) has nearly noise-free positions at stamps that alternate steps of
// 0.24–0.7 ms with steps of 4–5 ms, and its noise grows with the speed (0.03 µm at rest, 0.2–0.3 µm
// in motion; the median over the whole flight, 0.16 µm, is the quiet stretches'). Against the
// dataset's own velocity:
// - the 3-point rate at either sample of a close pair carried their noise over the short step:
//   0.13 and 0.15 of central differences' RMS error (0.36 and 0.51 mm/s). Beside a close step the
//   local rate skips the close partner (docs/velocity.md, "Local interpolant");
// - windows in motion failed the residual test on noise alone and gave their samples to the local
//   interpolant: 19 and 28 times the best Savitzky–Golay window's error (0.14 and 0.22 mm/s, the
//   oracle 0.0075 and 0.0078). The noise profile raises σ where a stretch is clearly noisier
//   (docs/velocity.md, "Noise estimate").
TEST(EstimateVelocity, UnevenlyStampedMotionCaptureMatchesTheBestSavitzkyGolayWindow) {
  CHEVAL_REQUIRE_SHARED_DATA();
  for (const char* file : {"circle_a_1.5_v_2.5_r_1.5_2022-02-21-23-46-22.csv", "eight_a_2.2_v_3.5_rx_1.8_2022-02-22-11-50-24.csv"}) {
    traj::ReadOptions read;
    read.format = traj::Format::kCsv;
    read.columns = traj::ColumnMap::Parse("t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz");
    const traj::Trajectory trajectory =
        traj::ReadTrajectory(::cheval::testing::SharedDataDir() + "/dido/csv/" + file, read);
    const Eigen::Matrix3Xd& truth = trajectory.View().velocities();
    auto rms = [&](const VelocityOptions& options) {
      return std::sqrt((EstimateVelocity(trajectory.View(), options).velocities - truth).colwise().squaredNorm().mean());
    };
    const double chebyshev = rms(VelocityOptions{});
    // The noise profile found the noisier stretches in motion.
    const VelocityEstimate estimate = EstimateVelocity(trajectory.View(), VelocityOptions{});
    ASSERT_TRUE(estimate.curve.has_value());
    EXPECT_GT(estimate.curve->noisier_samples(), trajectory.View().size() / 4) << file;
    EXPECT_GT(estimate.curve->noise_sigma_max().maxCoeff(), 1.5 * estimate.curve->noise_sigma().maxCoeff()) << file;
    VelocityOptions central;
    central.method = VelocityMethod::kCentral;
    EXPECT_LT(chebyshev, 0.1 * rms(central)) << file;
    // The best of Savitzky–Golay's windows, chosen with the truth.
    VelocityOptions savgol;
    savgol.method = VelocityMethod::kSavitzkyGolay;
    double best = std::numeric_limits<double>::infinity();
    for (const int window : {21, 31, 41, 51, 71}) {
      savgol.savgol_window = window;
      best = std::min(best, rms(savgol));
    }
    EXPECT_LT(chebyshev, 2.0 * best) << file << ": " << chebyshev << " m/s against the best Savitzky-Golay's " << best;
  }
}

// 240 Hz from 0.4 ms, written in whole milliseconds: steps of 4 and 5 ms.
std::vector<int64_t> MillisecondStamps(int n, std::vector<int64_t>* exact = nullptr) {
  std::vector<int64_t> stamps;
  for (int i = 0; i < n; ++i) {
    const int64_t t = 400'000 + std::llround(i * 1e9 / 240.0);
    if (exact != nullptr) exact->push_back(t);
    stamps.push_back((t + 500'000) / 1'000'000 * 1'000'000);
  }
  return stamps;
}

TEST(RoundedUniformStamps, FindsAUniformRateWrittenInMilliseconds) {
  std::vector<int64_t> exact;
  const std::vector<int64_t> stamps = MillisecondStamps(4801, &exact);
  const std::optional<RoundedStamps> rounded = RoundedUniformStamps(stamps);
  ASSERT_TRUE(rounded.has_value());
  EXPECT_EQ(rounded->resolution_ns, 1'000'000);
  EXPECT_NEAR(1e9 / rounded->period_ns, 240.0, 1e-6);
  ASSERT_EQ(rounded->uniform_ns.size(), stamps.size());
  int64_t worst = 0;
  for (size_t i = 0; i < stamps.size(); ++i) worst = std::max(worst, std::abs(rounded->uniform_ns[i] - exact[i]));
  // The stamps erred by up to 0.5 ms. The rounding's offsets take 6 values here (the pattern
  // repeats every 25 ms), which place the uniform instants to within a twelfth of their spacing.
  EXPECT_LT(worst, 50'000) << "ns from the instants the samples were taken";
}

TEST(RoundedUniformStamps, LeavesEvenIrregularAndGappedStampsAlone) {
  std::vector<int64_t> even;
  for (int i = 0; i < 100; ++i) even.push_back(i * 5'000'000);
  EXPECT_FALSE(RoundedUniformStamps(even).has_value()) << "even";
  EXPECT_FALSE(RoundedUniformStamps(Stamps(100)).has_value()) << "uneven sampling (10 and 13 ms steps, and 7)";
  std::vector<int64_t> dropped = MillisecondStamps(200);
  dropped.erase(dropped.begin() + 100);
  EXPECT_FALSE(RoundedUniformStamps(dropped).has_value()) << "a dropped sample";
  std::vector<int64_t> drifting;  // steps of 4 and 5 ms, but not from one rate: they wander off a line
  for (int i = 0, t = 0; i < 200; ++i) drifting.push_back(int64_t{t += (i < 100 ? (i % 2 ? 4 : 5) : (i % 3 ? 4 : 5))} * 1'000'000);
  EXPECT_FALSE(RoundedUniformStamps(drifting).has_value()) << "two rates";
  std::vector<int64_t> coarse;  // 1.5 ms steps written in ms: the resolution is not finer than the steps
  for (int i = 0; i < 100; ++i) coarse.push_back((i * 1'500'000 + 500'000) / 1'000'000 * 1'000'000);
  EXPECT_FALSE(RoundedUniformStamps(coarse).has_value()) << "1 and 2 ms steps";
  EXPECT_FALSE(RoundedUniformStamps(std::vector<int64_t>(MillisecondStamps(7))).has_value()) << "7 stamps";
}

// Smooth motion (~0.3 m/s) at 240 Hz under 50 µm of noise, its stamps written in whole
// milliseconds: fitted at the stamps as written, their errors of up to 0.5 ms read as noise and as
// motion, and the velocity came out at 0.56x central differences' error (12 mm/s); fitted at the
// uniform instants, below a tenth of it.
TEST(EstimateVelocity, StampsRoundedFromAUniformRateAreFittedAtTheUniformInstants) {
  std::vector<int64_t> exact;
  const std::vector<int64_t> stamps = MillisecondStamps(4801, &exact);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 5e-5);
  std::vector<PoseSpec> poses;
  Eigen::Matrix3Xd truth(3, static_cast<Eigen::Index>(stamps.size()));
  for (size_t i = 0; i < stamps.size(); ++i) {
    const double t = static_cast<double>(exact[i]) * 1e-9;
    PoseSpec pose;
    pose.stamp_ns = stamps[i];
    pose.p = {0.2 * std::sin(1.3 * t) + noise(rng), 0.1 * std::cos(2.1 * t) + noise(rng), 0.05 * std::sin(3.7 * t) + noise(rng)};
    truth.col(static_cast<Eigen::Index>(i)) << 0.26 * std::cos(1.3 * t), -0.21 * std::sin(2.1 * t), 0.185 * std::cos(3.7 * t);
    poses.push_back(pose);
  }
  const traj::Trajectory trajectory = MakeTrajectory(poses, false, false);
  auto rms = [&](const VelocityEstimate& estimate) {
    return std::sqrt((estimate.velocities - truth).colwise().squaredNorm().mean());
  };
  const VelocityEstimate estimate = EstimateVelocity(trajectory.View(), VelocityOptions{});
  ASSERT_TRUE(estimate.rounded_stamps.has_value());
  VelocityOptions central;
  central.method = VelocityMethod::kCentral;
  EXPECT_LT(rms(estimate), 0.1 * rms(EstimateVelocity(trajectory.View(), central)));
  // Asked for at its own stamps as other stamps (a reference's paired samples), the same.
  const VelocityEstimate at_own = EstimateVelocity(trajectory.View(), VelocityOptions{}, std::span<const int64_t>(stamps));
  EXPECT_EQ((at_own.velocities - estimate.velocities).cwiseAbs().maxCoeff(), 0.0);
  const nlohmann::json json = nlohmann::json::parse(VelocityJson({"rounded.txt", 4801, VelocityOptions{}, 4801, 0.0}, estimate));
  EXPECT_DOUBLE_EQ(json["rounded_stamps"]["resolution_s"].get<double>(), 1e-3);
  EXPECT_NEAR(json["rounded_stamps"]["rate_hz"].get<double>(), 240.0, 1e-6);
}

// A slow rotation at 500 Hz with its quaternions written to four decimals (TUM's): about 2e-4 rad a
// sample, the rounding's size, so the chart coordinates form a staircase whose differences read
// little noise (docs/velocity.md, "Rounded positions"). The charts take the quaternions' rounding
// (2 x 1e-4) as their resolution. Before, the body rate followed the staircase: 4.27 mrad/s, 0.14x
// central differences' 30.7; now 0.21.
TEST(EstimateVelocity, QuaternionsRoundedToFourDecimalsGiveTheirChartsTheirNoise) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1.0, 2.0, 2.0) / 3.0;
  const Eigen::Quaterniond origin(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()));
  std::vector<PoseSpec> poses;
  Eigen::Matrix3Xd truth(3, 10001);
  for (int i = 0; i <= 10000; ++i) {
    const double t = i / 500.0, angle = 0.3 * std::sin(0.4 * t);
    PoseSpec pose;
    pose.stamp_ns = int64_t{i} * 2'000'000;
    const Eigen::Quaterniond q = origin * Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis));
    pose.q.coeffs() = (q.coeffs() * 1e4).array().round() / 1e4;  // not normalised, as a file gives it
    truth.col(i) = 0.12 * std::cos(0.4 * t) * axis;
    poses.push_back(pose);
  }
  const traj::Trajectory trajectory = MakeTrajectory(poses, false, true);
  VelocityOptions options;
  options.angular = true;
  const VelocityEstimate estimate = EstimateVelocity(trajectory.View(), options);
  options.method = VelocityMethod::kCentral;
  const VelocityEstimate central = EstimateVelocity(trajectory.View(), options);
  auto rms = [&](const Eigen::Matrix3Xd& rates) { return std::sqrt((rates - truth).colwise().squaredNorm().mean()); };
  const double fit = rms(estimate.angular_velocities), differences = rms(central.angular_velocities);
  EXPECT_LT(fit, 0.05 * differences) << fit << " vs central " << differences;
}

// The warning about windows accepted unresolved says what is true of them. A literal window that
// cannot follow a tone at a quarter of the rate fails the residual test, and the warning says so
// with its residual. Short clips' windows at the smallest size can be unresolved with a residual
// that passes the residual test (their coefficients could not show the motion resolved): the
// warning then says so, not that it fails (it said "still fail the residual test ... residual
// 1.0x the noise" before).
TEST(VelocityTest, TheUnresolvedWarningSaysWhetherTheResidualFails) {
  {
    const int m = 200;
    std::vector<int64_t> stamps;
    Eigen::MatrixXd z(m, 3);
    for (int i = 0; i < m; ++i) {
      stamps.push_back(int64_t{10'000'000} * i);
      const double t = 0.01 * i;
      z.row(i) << 1e-3 * std::sin(2.0 * M_PI * 24.0 * t), 0.1 * t, 1e-4 * std::cos(7.0 * i);
    }
    cheb::CurveOptions options;
    options.single_window = true;
    const cheb::Curve curve = cheb::FitCurve(stamps, z, options);
    ASSERT_EQ(curve.unresolved_windows(), 1);
    const std::string warning = UnresolvedWarning(curve);
    EXPECT_NE(warning.find("1 window(s) still fail the residual test"), std::string::npos) << warning;
  }
  int within = 0;
  for (uint64_t seed = 1; seed <= 8; ++seed) {
    sim::MotionOptions motion;
    motion.kind = sim::MotionKind::kCar;
    motion.seed = seed;
    motion.duration_s = 0.3;
    motion.rate_hz = 100.0;
    sim::MeasurementOptions measurement;
    measurement.noise_m = 0.5e-3;
    const traj::Trajectory measured = sim::Measure(sim::MotionModel(motion), measurement);
    const cheb::Curve curve = cheb::FitCurve({measured.stamps_ns().begin(), measured.stamps_ns().end()},
                                             Eigen::MatrixXd(measured.positions().transpose()));
    int failing = 0;
    for (const cheb::CurveSegment& segment : curve.segments()) {
      for (const cheb::CurveWindow& w : segment.windows) {
        const bool fails = w.lack_of_fit.size() > 0 && w.lack_of_fit.maxCoeff() > cheb::kLackOfFitLimit;
        failing += w.verdict == cheb::WindowVerdict::kUnresolved && fails ? 1 : 0;
      }
    }
    const std::string warning = UnresolvedWarning(curve);
    if (curve.unresolved_windows() == 0) {
      EXPECT_TRUE(warning.empty()) << warning;
    } else if (failing == 0) {
      ++within;
      EXPECT_EQ(warning.find("fail"), std::string::npos) << "seed " << seed << ": " << warning;
      EXPECT_NE(warning.find("their residual passes the residual test"), std::string::npos) << warning;
    } else {
      EXPECT_NE(warning.find(std::to_string(failing) + " window(s) still fail"), std::string::npos) << warning;
    }
  }
  EXPECT_GT(within, 0) << "no clip had windows unresolved with a residual that passes";
}

// Exact positions at a low rate (the simulator's car and drone, 30 s at 20 Hz, no noise) leave
// windows at the smallest size whose coefficients could not show the motion resolved, though they
// reproduce their samples to the values' rounding level: their velocity is below 0.0001 mm/s off, and
// the warning that it "may miss fast motion there" (6 and 3 windows before) misled. No warning.
TEST(VelocityTest, NoUnresolvedWarningForWindowsThatReproduceTheirSamples) {
  for (const sim::MotionKind kind : {sim::MotionKind::kCar, sim::MotionKind::kDrone}) {
    sim::MotionOptions motion;
    motion.kind = kind;
    motion.duration_s = 30.0;
    motion.rate_hz = 20.0;
    const traj::Trajectory measured = sim::Measure(sim::MotionModel(motion), sim::MeasurementOptions{});
    const cheb::Curve curve = cheb::FitCurve({measured.stamps_ns().begin(), measured.stamps_ns().end()},
                                             Eigen::MatrixXd(measured.positions().transpose()));
    EXPECT_GT(curve.unresolved_windows(), 0) << sim::ToString(kind) << ": the case no longer tests anything";
    EXPECT_EQ(UnresolvedWarning(curve), "") << sim::ToString(kind);
  }
}

}  // namespace
}  // namespace cheval::eval
