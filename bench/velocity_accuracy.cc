// Velocity-from-positions accuracy, the table of docs/velocity.md. For every synthetic kind at
// noise 0, 0.5 mm and 2 mm, and for the real EuRoC ground truths of ../shared/data/ov_data and
// DIDO's unevenly stamped motion capture (velocity from positions against each file's own
// velocity), the velocity RMSE over the FULL range (ends included) of: cheval's automatic
// Chebyshev fit (default: 5-fold cross-validation per window; the standardChop alternative beside it), central differences, Savitzky–Golay with the
// best window of a grid (an oracle choice: it is told the truth), the running median of five
// central differences, a cubic smoothing spline with GCV (smoothing_spline.h), and one global
// Chebyshev fit of fixed degree 400 (the C-ASE paper's choice for CARLA). Besides the simulator's
// kinds: hand tremor on a handheld motion, velocity steps (impacts) on a noise-free legged one, a
// vibration near a quarter of the rate, bursts of noise, stamps off by white errors and a slow
// motion's positions written to the millimetre.
// Ratios are against the baselines measured in the same run. A second table: body angular velocity
// from noisy orientations.
//   build/bench/velocity_accuracy [DATA_DIR [SEEDS [FIRST_SEED [ROWS]]]]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "cheval/common/error.h"
#include "cheval/eval/velocity.h"
#include "cheval/sim/motion.h"
#include "cheval/traj/io.h"
#include "smoothing_spline.h"

namespace {

using namespace cheval;

double Rmse(const Eigen::Matrix3Xd& estimate, const Eigen::Matrix3Xd& truth) {
  return std::sqrt((estimate - truth).colwise().squaredNorm().mean());
}

struct Row {
  std::string name;
  double cheb = 0, central = 0, savgol = 0, global = 0, chop = 0, median5 = 0, spline = 0;
  int savgol_window = 0;
  double inner_cheb = 0;
  double seconds = 0;
};

// Per coordinate, the median of the five central differences centred on each sample (fewer at
// the ends): a robust baseline against isolated glitches.
Eigen::Matrix3Xd RunningMedian5(const Eigen::Matrix3Xd& v) {
  Eigen::Matrix3Xd out(3, v.cols());
  for (Eigen::Index i = 0; i < v.cols(); ++i) {
    const Eigen::Index lo = std::max<Eigen::Index>(0, i - 2), hi = std::min<Eigen::Index>(v.cols() - 1, i + 2);
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<double> w;
      for (Eigen::Index j = lo; j <= hi; ++j) w.push_back(v(axis, j));
      std::nth_element(w.begin(), w.begin() + w.size() / 2, w.end());
      out(axis, i) = w[w.size() / 2];
    }
  }
  return out;
}

Row Evaluate(const std::string& name, const traj::TrajectoryView& measured, const Eigen::Matrix3Xd& truth) {
  Row row;
  row.name = name;
  eval::VelocityOptions options;
  const auto start = std::chrono::steady_clock::now();
  const eval::VelocityEstimate cheb = eval::EstimateVelocity(measured, options);
  row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  row.cheb = Rmse(cheb.velocities, truth);
  const Eigen::Index n = truth.cols(), skip = n / 20;
  row.inner_cheb = Rmse(cheb.velocities.middleCols(skip, n - 2 * skip), truth.middleCols(skip, n - 2 * skip));
  options.curve.degree_method = cheb::DegreeMethod::kChop;
  row.chop = Rmse(eval::EstimateVelocity(measured, options).velocities, truth);
  options.curve.degree_method = cheb::DegreeMethod::kCrossValidation;
  options.method = eval::VelocityMethod::kCentral;
  const Eigen::Matrix3Xd central = eval::EstimateVelocity(measured, options).velocities;
  row.central = Rmse(central, truth);
  row.median5 = Rmse(RunningMedian5(central), truth);
  row.spline = Rmse(bench::SmoothingSplineVelocity(measured.stamps_ns(), measured.positions()), truth);
  options.method = eval::VelocityMethod::kSavitzkyGolay;
  row.savgol = std::numeric_limits<double>::infinity();
  for (int window : {5, 7, 9, 11, 15, 21, 31, 41, 51, 71, 101, 151, 201, 301, 401, 601, 801}) {
    if (window > measured.size()) break;
    options.savgol_window = window;
    const double e = Rmse(eval::EstimateVelocity(measured, options).velocities, truth);
    if (e < row.savgol) row.savgol = e, row.savgol_window = window;
  }
  options.method = eval::VelocityMethod::kChebyshev;
  options.curve.degree_method = cheb::DegreeMethod::kFixed;
  options.curve.fixed_degree = 400;
  options.curve.single_window = true;
  try {
    row.global = Rmse(eval::EstimateVelocity(measured, options).velocities, truth);
  } catch (const ComputeError&) {
    row.global = std::numeric_limits<double>::quiet_NaN();  // singular: too few samples for degree 400
  }
  return row;
}

void Print(const Row& r) {
  std::printf(
      "| %-28s | %10.4f | %10.4f | %10.4f | %10.4f | %10.4f | %10.4f (%3d) | %10.4f | %10.4f | %6.3f | %6.3f | %6.3f | "
      "%6.3f |\n",
      r.name.c_str(), 1e3 * r.cheb, 1e3 * r.inner_cheb, 1e3 * r.chop, 1e3 * r.central, 1e3 * r.median5,
      1e3 * r.savgol, r.savgol_window, 1e3 * r.spline, 1e3 * r.global, r.cheb / r.central, r.cheb / r.savgol,
      r.cheb / r.spline, r.seconds);
}

// Cases unlike the simulator's kinds, built on one of its motions: the motion plus a term with a
// known derivative, added to the measured positions (the noise is additive, so adding after
// sim::Measure is the same as before it) and to the true velocity.
struct Case {
  std::string name;
  traj::Trajectory measured{traj::Channels{traj::OrientationKind::kNone}};
  Eigen::Matrix3Xd truth;
};

template <typename Extra>  // Extra(t_s, position, velocity) adds its term to both
Case Perturbed(std::string name, sim::MotionKind kind, double rate_hz, double duration_s,
               const sim::MeasurementOptions& measurement, Extra extra) {
  sim::MotionOptions options;
  options.kind = kind;
  options.rate_hz = rate_hz;
  options.duration_s = duration_s;
  const sim::MotionModel model(options);
  const traj::Trajectory base = sim::Measure(model, measurement);
  const traj::Trajectory exact = sim::SampleMotion(model, base.stamps_ns());
  Case c;
  c.name = std::move(name);
  c.truth = exact.View().velocities();
  c.measured.Reserve(base.size());
  for (Eigen::Index i = 0; i < base.size(); ++i) {
    const double t = 1e-9 * static_cast<double>(base.stamps_ns()[i] - options.start_stamp_ns);
    Eigen::Vector3d p = base.positions().col(i), v = c.truth.col(i);
    extra(t, p, v);
    c.measured.Append(base.stamps_ns()[i], p.data());
    c.truth.col(i) = v;
  }
  return c;
}

// Hand tremor: ~1 mm at 5-10 Hz on a handheld motion, 100 Hz with sub-millisecond stamp jitter.
Case Tremor(double noise_m) {
  sim::MeasurementOptions measurement;
  measurement.noise_m = noise_m;
  measurement.jitter_s = 3e-4;
  const Eigen::Vector3d amplitude(1e-3, 0.8e-3, 0.6e-3), hz(7.0, 5.3, 9.1), phase(0.0, 1.0, 2.0);
  return Perturbed(fmt::format("tremor, {:.1f} mm", 1e3 * noise_m), sim::MotionKind::kHandheld, 100, 20, measurement,
                   [&](double t, Eigen::Vector3d& p, Eigen::Vector3d& v) {
                     for (int k = 0; k < 3; ++k) {
                       const double w = 2 * M_PI * hz[k];
                       p[k] += amplitude[k] * std::sin(w * t + phase[k]);
                       v[k] += amplitude[k] * w * std::cos(w * t + phase[k]);
                     }
                   });
}

// Foot impacts: velocity steps of ±0.1 m/s (vertical) and 0.05 m/s (forward) every 0.37 s on a
// noise-free legged motion at 200 Hz for 5 s: the position gains a ramp at each impact. The impacts
// fall between samples (at a sample the velocity has no value to compare with).
Case Impacts() {
  const sim::MeasurementOptions measurement;
  return Perturbed("impacts, 0.0 mm", sim::MotionKind::kLegged, 200, 5, measurement,
                   [](double t, Eigen::Vector3d& p, Eigen::Vector3d& v) {
                     for (int k = 1; 0.37 * k + 0.0013 < t; ++k) {
                       const double since = t - (0.37 * k + 0.0013), sign = k % 2 ? 1.0 : -1.0;
                       p += since * Eigen::Vector3d(0.05 * sign, 0, 0.1 * sign);
                       v += Eigen::Vector3d(0.05 * sign, 0, 0.1 * sign);
                     }
                   });
}

// Under-resolved vibration: 0.5/0.3/0.4 mm at 22/19/24 Hz, near a quarter of the 100 Hz rate, on a
// noise-free handheld motion. Its 4th differences read the vibration as noise (docs/velocity.md,
// "Under-resolved motion").
Case Vibration() {
  const sim::MeasurementOptions measurement;
  const Eigen::Vector3d amplitude(0.5e-3, 0.3e-3, 0.4e-3), hz(22.0, 19.0, 24.0), phase(0.5, 1.5, 2.5);
  return Perturbed("vibration, 0.0 mm", sim::MotionKind::kHandheld, 100, 20, measurement,
                   [&](double t, Eigen::Vector3d& p, Eigen::Vector3d& v) {
                     for (int k = 0; k < 3; ++k) {
                       const double w = 2 * M_PI * hz[k];
                       p[k] += amplitude[k] * std::sin(w * t + phase[k]);
                       v[k] += amplitude[k] * w * std::cos(w * t + phase[k]);
                     }
                   });
}

// Bursts of noise, as in hand-held motion capture (TUM fr2/desk: tens of samples at ~10x the
// recording's noise): a hand-held motion at 300 Hz with 0.1 mm of noise, and 0.2 s (60 samples) at
// 0.6 mm every 2 s (docs/velocity.md, "Noise profile").
Case Bursts() {
  sim::MeasurementOptions measurement;
  measurement.noise_m = 1e-4;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> burst(0.0, 6e-4);
  return Perturbed("bursts, 0.1 mm", sim::MotionKind::kHandheld, 300, 30, measurement,
                   [&](double t, Eigen::Vector3d& p, Eigen::Vector3d&) {
                     if (std::fmod(t, 2.0) >= 1.0 && std::fmod(t, 2.0) < 1.2) {
                       for (int k = 0; k < 3; ++k) p[k] += burst(rng);
                     }
                   });
}

// A short clip: the first half second of a hand-held motion at 100 Hz (50 samples) under 2 mm,
// whose noise level comes from few differences (docs/velocity.md, "Residual test").
Case ShortClip() {
  sim::MeasurementOptions measurement;
  measurement.noise_m = 2e-3;
  return Perturbed("short 0.5 s, 2.0 mm", sim::MotionKind::kHandheld, 100, 0.5, measurement,
                   [](double, Eigen::Vector3d&, Eigen::Vector3d&) {});
}

// The simulator's handheld motion at `rate_hz`.
sim::MotionModel Handheld(double rate_hz) {
  sim::MotionOptions options;
  options.kind = sim::MotionKind::kHandheld;
  options.rate_hz = rate_hz;
  return sim::MotionModel(options);
}

// Stamps off by white errors of 0.3 ms RMS (a recorder that stamps samples on arrival) on a
// noise-free handheld motion at 200 Hz: each sample lies v·δ from the motion at its stamp
// (docs/velocity.md, "Stamp noise"). Scored at the stamps against the velocity at the instants the
// samples were taken.
Case StampErrors() {
  const sim::MotionModel model = Handheld(200);
  const traj::Trajectory taken = sim::Measure(model, sim::MeasurementOptions{});
  std::mt19937_64 rng(12);
  std::normal_distribution<double> error(0.0, 3e-4);
  Case c;
  c.name = "stamp errors, 0.0 mm";
  c.truth = sim::SampleMotion(model, taken.stamps_ns()).View().velocities();
  c.measured.Reserve(taken.size());
  for (Eigen::Index i = 0; i < taken.size(); ++i) {
    const Eigen::Vector3d p = taken.positions().col(i);
    c.measured.Append(taken.stamps_ns()[i] + std::llround(1e9 * error(rng)), p.data());
  }
  return c;
}

// Positions written to the millimetre of a slow motion (the handheld one at a tenth of its size
// and speed) at 1000 Hz: a staircase, about 30 samples a step, whose differences read no noise
// (docs/velocity.md, "Rounded positions"). With `before`, white noise of that σ added before the
// rounding: the steps' edges flip back and forth, and the values' noise is about
// sqrt(step²/12 + before²).
Case RoundedSlow(double before) {
  const sim::MotionModel model = Handheld(1000);
  sim::MeasurementOptions measurement;
  measurement.noise_m = before / 0.1;  // a tenth of it once shrunk
  const traj::Trajectory taken = sim::Measure(model, measurement);
  Case c;
  c.name = before > 0.0 ? fmt::format("rounded 1 mm, slow, {:.1f} mm", 1e3 * before) : "rounded 1 mm, slow";
  c.truth = 0.1 * sim::SampleMotion(model, taken.stamps_ns()).View().velocities();
  c.measured.Reserve(taken.size());
  for (Eigen::Index i = 0; i < taken.size(); ++i) {
    const Eigen::Vector3d p = (0.1e3 * taken.positions().col(i)).array().round() * 1e-3;
    c.measured.Append(taken.stamps_ns()[i], p.data());
  }
  return c;
}

// Body angular velocity from noisy orientations: the RotationCurve against central differences on
// the group, full range, on the simulator's exact body rates.
void AngularTable() {
  std::printf("\nbody angular velocity RMSE in mrad/s, full range (positions 0.5 mm noise)\n\n");
  std::printf("| %-28s | %12s | %12s | %6s | %7s | %6s |\n", "trajectory", "cheval", "central", "/cent", "charts",
              "s");
  std::printf("|---|---|---|---|---|---|\n");
  for (sim::MotionKind kind :
       {sim::MotionKind::kCar, sim::MotionKind::kLegged, sim::MotionKind::kDrone, sim::MotionKind::kHandheld}) {
    for (double noise : {0.0, 0.002, 0.005}) {
      sim::MotionOptions options;
      options.kind = kind;
      options.seed = 1;
      const sim::MotionModel model(options);
      sim::MeasurementOptions measurement;
      measurement.noise_m = 0.0005;
      measurement.rotation_noise_rad = noise;
      const traj::Trajectory measured = sim::Measure(model, measurement);
      const traj::Trajectory truth = sim::SampleMotion(model, measured.stamps_ns());
      eval::VelocityOptions velocity;
      velocity.angular = true;
      const auto start = std::chrono::steady_clock::now();
      const eval::VelocityEstimate cheb = eval::EstimateVelocity(measured.View(), velocity);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      velocity.method = eval::VelocityMethod::kCentral;
      const eval::VelocityEstimate central = eval::EstimateVelocity(measured.View(), velocity);
      const Eigen::Matrix3Xd exact = truth.View().angular_velocities();
      const double e_cheb = Rmse(cheb.angular_velocities, exact), e_central = Rmse(central.angular_velocities, exact);
      char name[64];
      std::snprintf(name, sizeof(name), "%s, %.3f rad", std::string(sim::ToString(kind)).c_str(), noise);
      std::printf("| %-28s | %12.4f | %12.4f | %6.3f | %7zu | %6.3f |\n", name, 1e3 * e_cheb, 1e3 * e_central,
                  e_cheb / e_central, cheb.rotation_curve->charts().size(), seconds);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  const std::string data = argc > 1 ? argv[1] : "../shared/data";
  // Optional: the number of simulator seeds per kind and noise (default 1), to see that the
  // figures are not one lucky draw.
  const uint64_t seeds = argc > 2 ? std::stoull(argv[2]) : 1;
  // Optional: the first seed (default 1), to test on seeds the tables of docs/velocity.md do not use.
  const uint64_t first_seed = argc > 3 ? std::stoull(argv[3]) : 1;
  // Optional: only the rows whose name contains this text (e.g. "tremor" or "legged, 2.0"); the
  // angular table only without it.
  const std::string only = argc > 4 ? argv[4] : "";
  auto wanted = [&only](const std::string& name) { return name.find(only) != std::string::npos; };
  std::printf("velocity RMSE in mm/s, full range unless marked inner (middle 90 %%)\n\n");
  std::printf("| %-28s | %10s | %10s | %10s | %10s | %10s | %16s | %10s | %10s | %6s | %6s | %6s | %6s |\n",
              "trajectory", "cheval (cv)", "inner", "chop", "central", "median-5", "SG best (win)", "spline GCV",
              "global 400", "/cent", "/SG", "/spline", "s");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (sim::MotionKind kind :
       {sim::MotionKind::kCar, sim::MotionKind::kLegged, sim::MotionKind::kDrone, sim::MotionKind::kHandheld}) {
    for (double noise : {0.0, 0.0005, 0.002}) {
      for (uint64_t seed = first_seed; seed < first_seed + seeds; ++seed) {
        sim::MotionOptions options;
        options.kind = kind;
        options.seed = seed;
        const sim::MotionModel model(options);
        sim::MeasurementOptions measurement;
        measurement.noise_m = noise;
        const traj::Trajectory measured = sim::Measure(model, measurement);
        const traj::Trajectory truth = sim::SampleMotion(model, measured.stamps_ns());
        char name[64];
        std::snprintf(name, sizeof(name), "%s, %.1f mm%s", std::string(sim::ToString(kind)).c_str(), 1e3 * noise,
                      seeds > 1 || first_seed > 1 ? fmt::format(", seed {}", seed).c_str() : "");
        if (wanted(name)) Print(Evaluate(name, measured.View(), truth.View().velocities()));
      }
    }
  }
  for (const Case& c : {Tremor(0.0005), Tremor(0.0), Impacts(), Vibration(), Bursts(), StampErrors(), RoundedSlow(0.0),
                        RoundedSlow(0.3e-3), ShortClip()}) {
    if (wanted(c.name)) Print(Evaluate(c.name, c.measured.View(), c.truth));
  }
  for (const char* file : {"MH_05_difficult.csv", "V1_01_easy.csv", "V1_02_medium.csv", "V2_02_medium.csv"}) {
    const std::string path = data + "/ov_data/euroc_mav/" + file;
    if (!wanted(std::string("EuRoC ") + file)) continue;
    if (!std::filesystem::exists(path)) {
      std::printf("(missing %s)\n", path.c_str());
      continue;
    }
    const traj::Trajectory gt = traj::ReadTrajectory(path);
    Print(Evaluate(std::string("EuRoC ") + file, gt.View(), gt.View().velocities()));
  }
  // DIDO's quadrotor flights: motion capture at ~410 Hz with uneven stamps (steps of 0.24–9 ms),
  // against the dataset's own velocity.
  for (const auto& [name, file] : {std::pair{"DIDO circle", "circle_a_1.5_v_2.5_r_1.5_2022-02-21-23-46-22.csv"},
                                   std::pair{"DIDO eight", "eight_a_2.2_v_3.5_rx_1.8_2022-02-22-11-50-24.csv"}}) {
    const std::string path = data + "/dido/csv/" + file;
    if (!wanted(name)) continue;
    if (!std::filesystem::exists(path)) {
      std::printf("(missing %s)\n", path.c_str());
      continue;
    }
    traj::ReadOptions options;
    options.format = traj::Format::kCsv;
    options.columns = traj::ColumnMap::Parse("t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz");
    const traj::Trajectory gt = traj::ReadTrajectory(path, options);
    Print(Evaluate(name, gt.View(), gt.View().velocities()));
  }
  if (only.empty()) AngularTable();
  return 0;
}
