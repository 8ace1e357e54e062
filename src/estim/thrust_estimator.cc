// The collective rotor speed from positions (+ accelerometer), the measured attitude and the
// translational dynamics (thrust_model.h) on PseudoSpectralProblem; the DIDO CSV readers.
#include "cheval/estim/thrust_estimator.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <string_view>

#include <ceres/ceres.h>

#include "cheval/common/error.h"
#include "cheval/common/input_file.h"
#include "cheval/common/random.h"
#include "cheval/common/options.h"
#include "cheval/estim/problem.h"
#include "cheval/estim/quadrotor_data.h"

namespace cheval::estim {
namespace {

constexpr double kRadPerSecondPerRpm = std::numbers::pi / 30.0;
constexpr double kDidoRotorUnitRpm = 1e4;  // DIDO's kf and D use rotor speeds in 1e4 rpm (docs/estimator_real_data.md)
constexpr double kDidoGravity = 9.8;       // Translation_stage.py: gravity = [0, 0, 9.8]

// A comma-separated file with one header line: the rows as numbers, each with its line number.
struct CsvTable {
  std::vector<std::vector<double>> rows;
  std::vector<int64_t> lines;
};

CsvTable ReadNumericCsv(const std::string& path, const std::vector<std::string_view>& header) {
  const std::string content = ReadInputFile(path, kMaxDataFileBytes, "a DIDO CSV file");
  CsvTable table;
  int64_t number = 0;
  bool seen_header = false;
  for (size_t at = 0; at < content.size();) {
    const size_t newline = content.find('\n', at);
    const size_t line_end = newline == std::string::npos ? content.size() : newline;
    std::string_view line(content.data() + at, line_end - at);
    at = line_end + 1;
    ++number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.empty()) continue;
    // Split at commas, remembering each field's 1-based column.
    std::vector<std::pair<std::string_view, int64_t>> fields;
    const std::string_view text = line;
    size_t start = 0;  // of the field
    while (true) {
      const size_t comma = text.find(',', start);
      const size_t stop = comma == std::string_view::npos ? text.size() : comma;
      fields.emplace_back(text.substr(start, stop - start), static_cast<int64_t>(start) + 1);
      if (comma == std::string_view::npos) break;
      start = comma + 1;
    }
    if (!seen_header) {
      for (size_t i = 0; i < std::max(fields.size(), header.size()); ++i) {
        if (i >= fields.size() || i >= header.size() || fields[i].first != header[i]) {
          const int64_t column = i < fields.size() ? fields[i].second : static_cast<int64_t>(line.size()) + 1;
          std::string got = i < fields.size() ? std::string(fields[i].first.substr(0, 40)) : "(end of line)";
          for (char& c : got) c = (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
          throw InputError(path, number, column,
                           fmt::format("expected the header column '{}', got '{}'",
                                       i < header.size() ? std::string(header[i]) : std::string("(end of line)"),
                                       got));
        }
      }
      seen_header = true;
      continue;
    }
    if (fields.size() != header.size()) {
      throw InputError(path, number, 1, fmt::format("expected {} fields, got {}", header.size(), fields.size()));
    }
    std::vector<double> row(fields.size());
    for (size_t i = 0; i < fields.size(); ++i) {
      const std::string_view f = fields[i].first;
      const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), row[i]);
      if (f.empty() || ec != std::errc() || end != f.data() + f.size() || !std::isfinite(row[i])) {
        std::string got(f.substr(0, 40));
        for (char& c : got) c = (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
        throw InputError(path, number, fields[i].second,
                         fmt::format("expected a finite number for {}, got '{}{}'", header[i], got,
                                     f.size() > 40 ? "..." : ""));
      }
    }
    table.rows.push_back(std::move(row));
    table.lines.push_back(number);
  }
  if (!seen_header) throw InputError(path, 0, 0, "empty file (expected a header line)");
  return table;
}

Eigen::Matrix3d RotX(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix(); }
Eigen::Matrix3d RotY(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix(); }

// The attitude at t by slerp between the bracketing samples (clamped at the ends).
Eigen::Quaterniond AttitudeAt(const std::vector<double>& times, const std::vector<Eigen::Quaterniond>& q, double t) {
  const auto it = std::lower_bound(times.begin(), times.end(), t);
  if (it == times.begin()) return q.front();
  if (it == times.end()) return q.back();
  const size_t j = static_cast<size_t>(it - times.begin());
  const double f = (t - times[j - 1]) / (times[j] - times[j - 1]);
  return q[j - 1].slerp(f, q[j]).normalized();
}

// Linear interpolation of y(t) given at increasing times (clamped at the ends).
template <class V>
V Linear(const std::vector<double>& times, const std::vector<V>& y, double t) {
  const auto it = std::lower_bound(times.begin(), times.end(), t);
  if (it == times.begin()) return y.front();
  if (it == times.end()) return y.back();
  const size_t j = static_cast<size_t>(it - times.begin());
  const double f = (t - times[j - 1]) / (times[j] - times[j - 1]);
  return y[j - 1] + f * (y[j] - y[j - 1]);
}

CollectiveErrors Compare(const std::vector<double>& estimated, const std::vector<double>& measured) {
  CollectiveErrors e;
  e.samples = static_cast<int>(estimated.size());
  if (e.samples == 0) return e;
  double sum_abs = 0, sum_sq = 0, sum = 0, sum_measured = 0;
  for (size_t i = 0; i < estimated.size(); ++i) {
    const double d = estimated[i] - measured[i];
    sum_abs += std::abs(d);
    sum_sq += d * d;
    sum += d;
    sum_measured += measured[i];
  }
  const double n = static_cast<double>(e.samples);
  e.mean_abs_rpm = sum_abs / n;
  e.mean_abs_percent = 100.0 * sum_abs / sum_measured;
  e.rmse_rpm = std::sqrt(sum_sq / n);
  e.bias_rpm = sum / n;
  return e;
}

// (p(t) − measured)/σ on the position block.
struct PositionResidual {
  Eigen::Vector3d measured;
  double sigma;
  template <typename T>
  bool operator()(const T* x, const Eigen::Matrix<T, 3, 3>& /*R*/, T* r) const {
    for (int i = 0; i < 3; ++i) r[i] = (x[i] - T(measured[i])) / T(sigma);
    return true;
  }
};

// (R_world_thrustᵀ (v'(t) − g) − f)/σ: the accelerometer's specific force moved to the thrust frame.
struct SpecificForceResidual {
  Eigen::Matrix3d R_world_thrust;
  Eigen::Vector3d measured;  // thrust frame
  double gravity;
  double sigma;
  template <typename T>
  bool operator()(const T* x_dot, T* r) const {
    const Eigen::Matrix<T, 3, 1> a(x_dot[3], x_dot[4], x_dot[5] + T(gravity));
    const Eigen::Matrix<T, 3, 1> f = R_world_thrust.transpose().cast<T>() * a;
    for (int i = 0; i < 3; ++i) r[i] = (f[i] - T(measured[i])) / T(sigma);
    return true;
  }
};

}  // namespace

void ThrustEstimateOptions::Validate() const {
  const OptionCheck check("ThrustEstimateOptions");
  const auto positive = [](double x) { return x > 0 && std::isfinite(x); };
  check(degree >= 2 && degree <= 64, "degree", "must be in [2, 64], got {}", degree);
  check(positive(segment_s), "segment_s", "must be a positive number, got {}", segment_s);
  check(positive(position_rate_hz), "position_rate_hz", "must be a positive number, got {}", position_rate_hz);
  check(positive(position_sigma_m), "position_sigma_m", "must be a positive number, got {}", position_sigma_m);
  check(position_noise_m >= 0 && std::isfinite(position_noise_m), "position_noise_m", "must be >= 0, got {}",
        position_noise_m);
  check(positive(imu_sigma_mps2), "imu_sigma_mps2", "must be a positive number, got {}", imu_sigma_mps2);
  check(positive(sigma_position_rate), "sigma_position_rate", "must be a positive number, got {}", sigma_position_rate);
  check(positive(sigma_acceleration), "sigma_acceleration", "must be a positive number, got {}", sigma_acceleration);
  check(sigma_rotor_rate >= 0 && std::isfinite(sigma_rotor_rate), "sigma_rotor_rate", "must be >= 0, got {}",
        sigma_rotor_rate);
  check(std::abs(rotor_delay_s) <= 1.0, "rotor_delay_s", "must be within [-1, 1] s, got {}", rotor_delay_s);
  check(max_iterations >= 1, "max_iterations", "must be >= 1, got {}", max_iterations);
  check(threads >= 1, "threads", "must be >= 1, got {}", threads);
}

std::vector<ThrustSample> ReadDidoCsv(const std::string& path) {
  static const std::vector<std::string_view> kHeader = {
      "t_s",       "p_x",       "p_y",       "p_z",       "q_w",       "q_x",       "q_y",       "q_z",
      "v_x",       "v_y",       "v_z",       "gt_gyr_x",  "gt_gyr_y",  "gt_gyr_z",  "gt_acc_x",  "gt_acc_y",
      "gt_acc_z",  "gt_alpha_x", "gt_alpha_y", "gt_alpha_z", "imu_acc_x", "imu_acc_y", "imu_acc_z", "imu_gyr_x",
      "imu_gyr_y", "imu_gyr_z", "rpm_1",     "rpm_2",     "rpm_3",     "rpm_4"};
  const CsvTable table = ReadNumericCsv(path, kHeader);
  std::vector<ThrustSample> out;
  out.reserve(table.rows.size());
  for (size_t i = 0; i < table.rows.size(); ++i) {
    const std::vector<double>& r = table.rows[i];
    const int64_t line = table.lines[i];
    ThrustSample s;
    s.t = r[0];
    if (!out.empty() && !(s.t > out.back().t)) {
      throw InputError(path, line, 1, fmt::format("time stamps must increase: {:.6f} after {:.6f}", s.t, out.back().t));
    }
    // Bounds of docs/estimator.md ("Limits"): every value of a DIDO row within 1e6 of 0 (the
    // time within kMaxDataTime), so nothing computed from them overflows.
    if (!(std::abs(s.t) <= kMaxDataTime)) {
      throw InputError(path, line, 1,
                       fmt::format("t_s must be within [-{:g}, {:g}] s, got {}", kMaxDataTime, kMaxDataTime, s.t));
    }
    for (size_t c = 1; c < r.size(); ++c) {
      if (!(std::abs(r[c]) <= kMaxDataRate)) {
        throw InputError(path, line, 1, fmt::format("{} must be within [-{:g}, {:g}], got {}", kHeader[c], kMaxDataRate,
                                                    kMaxDataRate, r[c]));
      }
    }
    s.p = Eigen::Vector3d(r[1], r[2], r[3]);
    const Eigen::Quaterniond q(r[4], r[5], r[6], r[7]);
    if (!(q.squaredNorm() > 1e-12)) throw InputError(path, line, 1, "zero quaternion (q_w, q_x, q_y, q_z)");
    s.q = q.normalized();
    s.v = Eigen::Vector3d(r[8], r[9], r[10]);
    s.w = Eigen::Vector3d(r[11], r[12], r[13]);
    s.a = Eigen::Vector3d(r[14], r[15], r[16]);
    s.alpha = Eigen::Vector3d(r[17], r[18], r[19]);
    s.accelerometer = Eigen::Vector3d(r[20], r[21], r[22]);
    for (int k = 0; k < 4; ++k) {
      if (r[26 + k] < 0) throw InputError(path, line, 1, fmt::format("rpm_{} must be >= 0, got {}", k + 1, r[26 + k]));
      s.rotor[k] = r[26 + k] * kRadPerSecondPerRpm;
    }
    out.push_back(s);
  }
  if (out.size() < 2) throw InputError(path, 0, 0, "needs at least 2 samples");
  return out;
}

DidoParameters ReadDidoParameters(const std::string& path) {
  static const std::vector<std::string_view> kHeader = {"kf_massnorm",     "D_x",          "D_y",
                                                        "D_z",             "t_imu_to_body_x", "t_imu_to_body_y",
                                                        "t_imu_to_body_z", "pitch_ex_deg", "roll_ex_deg"};
  const CsvTable table = ReadNumericCsv(path, kHeader);
  if (table.rows.size() != 1) {
    throw InputError(path, 0, 0, fmt::format("expected one row of parameters, got {}", table.rows.size()));
  }
  const std::vector<double>& r = table.rows[0];
  if (!(r[0] > 0)) throw InputError(path, table.lines[0], 1, fmt::format("kf_massnorm must be > 0, got {}", r[0]));
  const double per_rad_s = kRadPerSecondPerRpm * kDidoRotorUnitRpm;  // 1e4 rpm in rad/s
  DidoParameters d;
  d.parameters.thrust_per_mass = r[0] / (per_rad_s * per_rad_s);
  d.parameters.rotor_drag = Eigen::Vector3d(r[1], r[2], r[3]) / per_rad_s;
  d.parameters.quadratic_drag_per_mass = 0.0;
  d.parameters.gravity_mps2 = kDidoGravity;
  d.t_imu_thrust = Eigen::Vector3d(r[4], r[5], r[6]);
  const double deg = std::numbers::pi / 180.0;
  d.R_imu_thrust = (RotY(r[7] * deg) * RotX(r[8] * deg)).transpose();
  return d;
}

ThrustFlight ReadDidoFlight(const std::string& csv_path, std::string params_path) {
  if (params_path.empty()) {
    const std::string suffix = ".csv";
    params_path = csv_path.size() > suffix.size() && csv_path.ends_with(suffix)
                      ? csv_path.substr(0, csv_path.size() - suffix.size()) + ".dynamic_params.csv"
                      : csv_path + ".dynamic_params.csv";
  }
  ThrustFlight flight;
  flight.name = csv_path;
  flight.samples = ReadDidoCsv(csv_path);
  const DidoParameters d = ReadDidoParameters(params_path);
  flight.parameters = d.parameters;
  flight.t_imu_thrust = d.t_imu_thrust;
  flight.R_imu_thrust = d.R_imu_thrust;
  return flight;
}

double CollectiveRotorSpeed(const Eigen::Vector4d& rotor) { return std::sqrt(0.25 * rotor.squaredNorm()); }

double CollectiveFromAcceleration(const ThrustParameters& k, const Eigen::Vector3d& a, const Eigen::Vector3d& v,
                                  const Eigen::Matrix3d& R) {
  const Eigen::Vector3d g(0, 0, -k.gravity_mps2);
  const double s = R.col(2).dot(a - g + k.quadratic_drag_per_mass * v.norm() * v);
  const double bz = k.rotor_drag.z() * R.col(2).dot(v);
  // 4k Ω² − 4 bz Ω − s = 0.
  const double A = 4.0 * k.thrust_per_mass, B = -4.0 * bz, C = -s;
  const double disc = B * B - 4.0 * A * C;
  if (disc < 0) return 0.0;
  return std::max(0.0, (-B + std::sqrt(disc)) / (2.0 * A));
}

ThrustEstimate EstimateThrust(const ThrustFlight& flight, const ThrustEstimateOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  options.Validate();
  const ThrustParameters& k = flight.parameters;
  if (!(k.thrust_per_mass > 0) || !(k.gravity_mps2 > 0)) throw UsageError("the thrust coefficient and |g| must be > 0");
  const std::vector<ThrustSample>& samples = flight.samples;
  if (samples.size() < 3) throw ComputeError("a flight needs at least 3 samples");
  const double t_first = samples.front().t;
  const int n = static_cast<int>(samples.size());

  // Per sample, in the thrust frame: attitude, origin, velocity and the accelerometer moved there
  // (rigid lever: a_thrust = a_imu + α × t + ω × (ω × t), DIDO's Translation_stage.py).
  std::vector<double> t(n), measured_rpm(n);
  std::vector<Eigen::Matrix3d> R(n);
  std::vector<Eigen::Quaterniond> q_thrust(n);
  std::vector<Eigen::Vector3d> p(n), v(n), f(n), a(n);
  const Eigen::Vector3d& lever = flight.t_imu_thrust;
  for (int i = 0; i < n; ++i) {
    const ThrustSample& s = samples[i];
    t[i] = s.t - t_first;
    const Eigen::Matrix3d R_wi = s.q.toRotationMatrix();
    R[i] = R_wi * flight.R_imu_thrust;
    q_thrust[i] = Eigen::Quaterniond(R[i]).normalized();
    p[i] = s.p + R_wi * lever;
    v[i] = s.v + R_wi * s.w.cross(lever);
    a[i] = s.a + R_wi * (s.alpha.cross(lever) + s.w.cross(s.w.cross(lever)));
    f[i] = flight.R_imu_thrust.transpose() * (s.accelerometer + s.alpha.cross(lever) + s.w.cross(s.w.cross(lever)));
    measured_rpm[i] = CollectiveRotorSpeed(s.rotor) / kRadPerSecondPerRpm;
  }

  // The positions used: the first sample at or after each tick of the position rate, plus noise.
  // The project's generator with the engine seeded as before; the normals come from the standard
  // library's distribution (as they always did here), so they may differ between standard libraries.
  Random random = Random::FromEngineSeed(options.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<double> tp;
  std::vector<Eigen::Vector3d> pp;
  const double period = 1.0 / options.position_rate_hz;
  double next = 0.0;
  for (int i = 0; i < n; ++i) {
    if (t[i] + 1e-9 < next) continue;
    Eigen::Vector3d noisy = p[i];
    if (options.position_noise_m > 0) {
      for (int axis = 0; axis < 3; ++axis) noisy[axis] += options.position_noise_m * normal(random);
    }
    tp.push_back(t[i]);
    pp.push_back(noisy);
    // A rate far above the samples' would take ~1e11 steps to the next sample: jump there at once.
    if (t[i] + 1e-9 - next > 1000.0 * period) next += std::floor((t[i] + 1e-9 - next) / period - 1.0) * period;
    while (next <= t[i] + 1e-9) next += period;
  }
  if (tp.size() < 3) throw ComputeError(fmt::format("only {} position measurements: need at least 3", tp.size()));
  // Finite-difference velocities and accelerations at the used positions (non-uniform central
  // differences; one-sided copies at the ends).
  const int m = static_cast<int>(tp.size());
  std::vector<Eigen::Vector3d> vd(m), ad(m);
  for (int j = 1; j + 1 < m; ++j) {
    const double h0 = tp[j] - tp[j - 1], h1 = tp[j + 1] - tp[j];
    const Eigen::Vector3d d0 = (pp[j] - pp[j - 1]) / h0, d1 = (pp[j + 1] - pp[j]) / h1;
    vd[j] = (h1 * d0 + h0 * d1) / (h0 + h1);
    ad[j] = 2.0 * (d1 - d0) / (h0 + h1);
  }
  vd[0] = vd[1], ad[0] = ad[1], vd[m - 1] = vd[m - 2], ad[m - 1] = ad[m - 2];

  // The problem over [0, T].
  const double T = t.back();
  const int segments = SegmentCount("ThrustEstimateOptions", T, options.segment_s, options.degree);
  std::vector<double> breakpoints(segments + 1);
  for (int s = 0; s <= segments; ++s) breakpoints[s] = T * s / segments;
  using Problem = PseudoSpectralProblem<ThrustModel>;
  Problem problem(ThrustModel{k}, breakpoints, options.degree);
  const double hover = k.HoverRotorSpeed();
  Eigen::Quaterniond previous = Eigen::Quaterniond::Identity();
  for (int g = 0; g < problem.num_nodes(); ++g) {
    const double tg = problem.NodeTime(g);
    Eigen::VectorXd x(6), u(5);
    x << Linear(tp, pp, tg), Linear(tp, vd, tg);
    Eigen::Quaterniond q = AttitudeAt(t, q_thrust, tg);
    if (g > 0 && q.coeffs().dot(previous.coeffs()) < 0) q.coeffs() = -q.coeffs();  // continuous sign
    previous = q;
    u << hover, q.x(), q.y(), q.z(), q.w();
    problem.SetNode(g, x, Eigen::Matrix3d::Identity(), u);
  }
  Eigen::Matrix<double, 6, 1> sigma;
  sigma << Eigen::Vector3d::Constant(options.sigma_position_rate), Eigen::Vector3d::Constant(options.sigma_acceleration);
  problem.AddCollocation(sigma);
  // The rate prior also covers the held attitude entries of the control: a constant term of the cost
  // that changes neither gradient nor solution.
  if (options.sigma_rotor_rate > 0) problem.AddControlRatePrior(options.sigma_rotor_rate);
  for (int j = 0; j < m; ++j) {
    problem.AddMeasurement(tp[j], PositionResidual{pp[j], options.position_sigma_m}, 3, 3, {0});
  }
  int imu = 0;
  if (options.use_imu) {  // every sample of a segment in one compressed block (AddDerivativeMeasurements)
    std::vector<SpecificForceResidual> forces;
    for (int i = 0; i < n; ++i) forces.push_back({R[i], f[i], k.gravity_mps2, options.imu_sigma_mps2});
    problem.AddDerivativeMeasurements(t, std::move(forces), 3, 3, {1});
    imu = n;
  }
  problem.HoldControlEntries({1, 2, 3, 4});  // the attitude entries of every control are known inputs

  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = options.threads;
  const ceres::Solver::Summary summary = problem.Solve(solver);

  ThrustEstimate out;
  out.states = problem.num_nodes();
  out.segments = segments;
  out.degree = options.degree;
  out.iterations = static_cast<int>(summary.iterations.size()) - 1;
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.solver_report = summary.BriefReport();
  out.position_measurements = m;
  out.imu_measurements = imu;

  // Errors at every sample of the flight, against the log shifted by the assumed delay.
  if (options.rotor_delay_s != 0.0) {
    const std::vector<double> logged = measured_rpm;
    for (int i = 0; i < n; ++i) measured_rpm[i] = Linear(t, logged, t[i] + options.rotor_delay_s);
  }
  std::vector<double> estimated(n), flat(n), accel(n), oracle(n);
  double position_sq = 0, velocity_sq = 0;
  const Eigen::Vector3d gravity(0, 0, -k.gravity_mps2);
  for (int i = 0; i < n; ++i) {
    const StateSample x = problem.Interpolate(t[i]);
    estimated[i] = x.control[0] / kRadPerSecondPerRpm;
    position_sq += (x.vector.head<3>() - p[i]).squaredNorm();
    velocity_sq += (x.vector.tail<3>() - v[i]).squaredNorm();
    flat[i] = CollectiveFromAcceleration(k, Linear(tp, ad, t[i]), Linear(tp, vd, t[i]), R[i]) / kRadPerSecondPerRpm;
    // The accelerometer alone, with the true velocity for the (small) drag term.
    accel[i] = CollectiveFromAcceleration(k, R[i] * f[i] + gravity, v[i], R[i]) / kRadPerSecondPerRpm;
    oracle[i] = CollectiveFromAcceleration(k, a[i], v[i], R[i]) / kRadPerSecondPerRpm;
  }
  out.estimate = Compare(estimated, measured_rpm);
  out.flatness = Compare(flat, measured_rpm);
  out.accelerometer = Compare(accel, measured_rpm);
  out.model_floor = Compare(oracle, measured_rpm);
  double sum = 0;
  for (double r : measured_rpm) sum += r;
  out.mean_measured_rpm = sum / n;
  if (!(out.mean_measured_rpm > 0)) {
    throw ComputeError(fmt::format("{}: the measured rotor speeds (rpm_1 to rpm_4) are 0 at every sample: the "
                                   "collective error relative to them is undefined (the log holds no flight)",
                                   flight.name));
  }
  out.position_rmse_m = std::sqrt(position_sq / n);
  out.velocity_rmse_mps = std::sqrt(velocity_sq / n);
  out.t = t;
  out.estimated_rpm = std::move(estimated);
  out.measured_rpm = std::move(measured_rpm);
  for (const CollectiveErrors* e : {&out.estimate, &out.flatness, &out.accelerometer, &out.model_floor}) {
    if (!std::isfinite(e->mean_abs_rpm) || !std::isfinite(e->mean_abs_percent) || !std::isfinite(e->rmse_rpm) ||
        !std::isfinite(e->bias_rpm)) {
      throw ComputeError(fmt::format("{}: a collective error is not finite (mean {} rpm, {} %): the estimate or a "
                                     "baseline diverged",
                                     flight.name, e->mean_abs_rpm, e->mean_abs_percent));
    }
  }
  if (!std::isfinite(out.position_rmse_m) || !std::isfinite(out.velocity_rmse_mps)) {
    throw ComputeError(fmt::format("{}: the estimated positions or velocities are not finite (RMSE {} m, {} m/s)",
                                   flight.name, out.position_rmse_m, out.velocity_rmse_mps));
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace cheval::estim
