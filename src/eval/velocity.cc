#include "cheval/eval/velocity.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cheval/common/error.h"
#include "cheval/common/options.h"
#include "cheval/lie/so3.h"

namespace cheval::eval {
namespace {

void RequireIncreasing(std::span<const int64_t> stamps, std::string_view method) {
  for (size_t i = 1; i < stamps.size(); ++i) {
    if (stamps[i] <= stamps[i - 1]) {
      throw ComputeError(fmt::format("{} needs strictly increasing stamps; pose {} has a stamp <= the previous one "
                                     "(use VelocityOptions::method chebyshev, which handles them)",
                                     method, i + 1));
    }
  }
}

Eigen::Matrix3Xd CentralDifferences(const traj::TrajectoryView& trajectory) {
  const Eigen::Index n = trajectory.size();
  if (n < 2) throw ComputeError("central differences need at least 2 poses");
  RequireIncreasing(trajectory.stamps_ns(), "central differences");
  const auto p = trajectory.positions();
  const auto s = trajectory.stamps_ns();
  Eigen::Matrix3Xd v(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Index a = std::max<Eigen::Index>(i - 1, 0), b = std::min<Eigen::Index>(i + 1, n - 1);
    v.col(i) = (p.col(b) - p.col(a)) / (static_cast<double>(s[b] - s[a]) * 1e-9);
  }
  return v;
}

// Body angular velocity by central differences on the group: Log(R_aᵀ R_b) / (t_b − t_a) with
// a = i − 1, b = i + 1 (one-sided at the ends).
Eigen::Matrix3Xd CentralAngularDifferences(const traj::TrajectoryView& trajectory) {
  using SO3 = lie::SO3<double>;
  const Eigen::Index n = trajectory.size();
  const auto s = trajectory.stamps_ns();
  Eigen::Matrix3Xd w(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Index a = std::max<Eigen::Index>(i - 1, 0), b = std::min<Eigen::Index>(i + 1, n - 1);
    w.col(i) = (SO3(trajectory.UnitQuaternion(a)).Inverse() * SO3(trajectory.UnitQuaternion(b))).Log() /
               (static_cast<double>(s[b] - s[a]) * 1e-9);
  }
  return w;
}

Eigen::Matrix3Xd SavitzkyGolay(const traj::TrajectoryView& trajectory, int window) {
  const Eigen::Index n = trajectory.size();
  if (n < window) {
    throw ComputeError(fmt::format("Savitzky-Golay with a {}-sample window needs at least {} poses, got {}", window,
                                   window, n));
  }
  RequireIncreasing(trajectory.stamps_ns(), "Savitzky-Golay");
  const auto p = trajectory.positions();
  const auto s = trajectory.stamps_ns();
  constexpr int kOrder = 3;
  Eigen::Matrix3Xd v(3, n);
  const int half = window / 2;
  for (Eigen::Index i = 0; i < n; ++i) {
    // Centred window, shifted inward at the ends.
    const Eigen::Index first = std::clamp<Eigen::Index>(i - half, 0, n - window);
    // Local cubic in u = (t - t_i) / h, h the window's half-span, for conditioning.
    const double h = 0.5 * static_cast<double>(s[first + window - 1] - s[first]) * 1e-9;
    Eigen::Matrix<double, kOrder + 1, kOrder + 1> normal = Eigen::Matrix<double, kOrder + 1, kOrder + 1>::Zero();
    Eigen::Matrix<double, kOrder + 1, 3> rhs = Eigen::Matrix<double, kOrder + 1, 3>::Zero();
    for (Eigen::Index k = first; k < first + window; ++k) {
      const double u = static_cast<double>(s[k] - s[i]) * 1e-9 / h;
      Eigen::Matrix<double, kOrder + 1, 1> basis;
      basis << 1.0, u, u * u, u * u * u;
      normal += basis * basis.transpose();
      rhs += basis * p.col(k).transpose();
    }
    const Eigen::Matrix<double, kOrder + 1, 3> coefficients = normal.ldlt().solve(rhs);
    v.col(i) = coefficients.row(1).transpose() / h;  // d/dt at u = 0
  }
  return v;
}

}  // namespace

std::string_view ToString(VelocityMethod method) {
  switch (method) {
    case VelocityMethod::kChebyshev: return "chebyshev";
    case VelocityMethod::kCentral: return "central";
    case VelocityMethod::kSavitzkyGolay: return "savgol";
  }
  return "?";
}

std::optional<VelocityMethod> VelocityMethodFromString(std::string_view name) {
  for (VelocityMethod m : {VelocityMethod::kChebyshev, VelocityMethod::kCentral, VelocityMethod::kSavitzkyGolay}) {
    if (ToString(m) == name) return m;
  }
  return std::nullopt;
}

void VelocityOptions::Validate() const {
  const OptionCheck check("VelocityOptions");
  if (method == VelocityMethod::kSavitzkyGolay) {
    if (savgol_window_s) {
      check(*savgol_window_s > 0 && std::isfinite(*savgol_window_s), "savgol_window_s",
            "must be a positive number of seconds, got {}", *savgol_window_s);
    } else {
      check(savgol_window >= 5 && savgol_window % 2 == 1, "savgol_window",
            "must be an odd number of samples >= 5, got {}", savgol_window);
    }
  }
  check(!angular || method != VelocityMethod::kSavitzkyGolay, "angular",
        "works with VelocityOptions::method chebyshev or central, not {}", ToString(method));
  // A constant has no rate: degree 0 would give zero velocity everywhere, whatever the motion.
  OptionCheck("CurveOptions")(method != VelocityMethod::kChebyshev ||
                                  curve.degree_method != cheb::DegreeMethod::kFixed || curve.fixed_degree >= 1,
        "fixed_degree", "must be >= 1 for a velocity (degree 0 is a constant, its rate is zero), got {}",
        curve.fixed_degree);
}

namespace {

// The degree names of CurveOptionsFromNames besides a fixed degree ("cv" is read as "auto").
constexpr std::pair<std::string_view, cheb::DegreeMethod> kDegreeNames[] = {
    {"auto", cheb::DegreeMethod::kCrossValidation},
    {"chop", cheb::DegreeMethod::kChop},
};

}  // namespace

cheb::CurveOptions CurveOptionsFromNames(std::string_view degree, std::optional<double> window_s) {
  cheb::CurveOptions options;
  options.window_s = window_s;
  const std::string_view name = degree == "cv" ? "auto" : degree;
  for (const auto& [text, method] : kDegreeNames) {
    if (text == name) {
      options.degree_method = method;
      return options;
    }
  }
  int fixed = -1;
  const auto [end, ec] = std::from_chars(degree.data(), degree.data() + degree.size(), fixed);
  const OptionCheck check("CurveOptions");
  check(ec == std::errc() && end == degree.data() + degree.size() && fixed >= 0, "degree_method",
        "must be auto, cv, chop or a non-negative integer, got '{}'", degree);
  options.degree_method = cheb::DegreeMethod::kFixed;
  options.fixed_degree = fixed;
  options.single_window = !window_s.has_value();  // a fixed degree alone: one global fit
  return options;
}

std::string DegreeName(const cheb::CurveOptions& options) {
  for (const auto& [text, method] : kDegreeNames) {
    if (method == options.degree_method) return std::string(text);
  }
  return std::to_string(options.fixed_degree);
}

int SavitzkyGolaySamples(std::span<const int64_t> stamps_ns, double window_s) {
  if (stamps_ns.empty()) return 5;
  const double duration = static_cast<double>(stamps_ns.back() - stamps_ns.front()) * 1e-9;
  const double rate = duration > 0 ? static_cast<double>(stamps_ns.size() - 1) / duration : 0.0;
  int samples = static_cast<int>(std::lround(window_s * rate));
  if (samples % 2 == 0) ++samples;
  return std::max(samples, 5);
}

std::optional<RoundedStamps> RoundedUniformStamps(std::span<const int64_t> stamps_ns) {
  const auto n = static_cast<int64_t>(stamps_ns.size());
  if (n < 8) return std::nullopt;
  int64_t shortest = std::numeric_limits<int64_t>::max(), longest = std::numeric_limits<int64_t>::min();
  for (int64_t i = 1; i < n; ++i) {
    const int64_t step = stamps_ns[i] - stamps_ns[i - 1];
    shortest = std::min(shortest, step);
    longest = std::max(longest, step);
  }
  // Two step values q apart, the shorter at least 2q (a resolution coarser than the steps is not a
  // rounding of them), and no third value.
  const int64_t q = longest - shortest;
  if (shortest <= 0 || q <= 0 || shortest < 2 * q) return std::nullopt;
  for (int64_t i = 1; i < n; ++i) {
    const int64_t step = stamps_ns[i] - stamps_ns[i - 1];
    if (step != shortest && step != longest) return std::nullopt;
  }
  const double period = static_cast<double>(stamps_ns[n - 1] - stamps_ns[0]) / static_cast<double>(n - 1);
  double low = 0.0, high = 0.0;  // the stamps' offsets from the line through the first and last
  for (int64_t i = 0; i < n; ++i) {
    const double offset = static_cast<double>(stamps_ns[i] - stamps_ns[0]) - period * static_cast<double>(i);
    low = std::min(low, offset), high = std::max(high, offset);
  }
  if (high - low > static_cast<double>(q) + 1.0) return std::nullopt;  // 1 ns: the line's own rounding
  RoundedStamps rounded{q, period, std::vector<int64_t>(static_cast<size_t>(n))};
  const double centre = 0.5 * (low + high);
  for (int64_t i = 0; i < n; ++i) {
    rounded.uniform_ns[static_cast<size_t>(i)] =
        stamps_ns[0] + std::llround(centre + period * static_cast<double>(i));
  }
  return rounded;
}

VelocityEstimate EstimateVelocity(const traj::TrajectoryView& trajectory, const VelocityOptions& options,
                                  std::optional<std::span<const int64_t>> at_ns) {
  options.Validate();
  VelocityEstimate estimate;
  if (!trajectory.has_stamps()) {
    throw ComputeError("velocity needs stamps; give the KITTI times with ReadOptions::kitti_times_path");
  }
  const OptionCheck check("VelocityOptions");
  check(!options.angular || trajectory.has_orientation(), "angular",
        "needs orientations, but the trajectory has positions only");
  if (options.method != VelocityMethod::kChebyshev) {
    check(!at_ns, "method", "must be chebyshev to evaluate at other stamps: {} gives velocity only at the input's own "
          "stamps", ToString(options.method));
    const int savgol_window = options.savgol_window_s
                                  ? SavitzkyGolaySamples(trajectory.stamps_ns(), *options.savgol_window_s)
                                  : options.savgol_window;
    estimate.velocities = options.method == VelocityMethod::kCentral ? CentralDifferences(trajectory)
                                                                      : SavitzkyGolay(trajectory, savgol_window);
    if (options.angular) estimate.angular_velocities = CentralAngularDifferences(trajectory);
    return estimate;
  }
  const Eigen::MatrixXd positions = trajectory.positions().transpose();
  // Rounded stamps err by up to half their resolution, the motion times that read as noise and
  // jumps: the fit takes the uniform instants they were rounded from (docs/velocity.md, "Rounded
  // stamps").
  estimate.rounded_stamps = RoundedUniformStamps(trajectory.stamps_ns());
  const std::span<const int64_t> stamps =
      estimate.rounded_stamps ? std::span<const int64_t>(estimate.rounded_stamps->uniform_ns) : trajectory.stamps_ns();
  cheb::Curve curve = cheb::FitCurve(stamps, positions, options.curve);
  // Query stamps that are the trajectory's own (a reference's paired samples) are its samples'
  // uniform instants too; others are taken as given.
  std::vector<int64_t> mapped;
  if (estimate.rounded_stamps && at_ns) {
    const std::span<const int64_t> own = trajectory.stamps_ns();
    mapped.assign(at_ns->begin(), at_ns->end());
    for (int64_t& stamp : mapped) {
      const auto it = std::lower_bound(own.begin(), own.end(), stamp);
      if (it != own.end() && *it == stamp) stamp = estimate.rounded_stamps->uniform_ns[static_cast<size_t>(it - own.begin())];
    }
  }
  std::span<const int64_t> query = !at_ns ? stamps : mapped.empty() ? *at_ns : std::span<const int64_t>(mapped);
  std::vector<int64_t> covered;
  if (at_ns && options.skip_uncovered) {
    for (size_t i = 0; i < query.size(); ++i) {
      if (curve.Covers(query[i])) {
        covered.push_back(query[i]);
      } else {
        estimate.skipped.push_back(i);
      }
    }
    if (!estimate.skipped.empty()) query = covered;
  }
  Eigen::MatrixXd values, derivatives;
  curve.EvaluateMany(query, 1, &values, &derivatives);
  estimate.positions = values.transpose();
  estimate.velocities = derivatives.transpose();
  estimate.curve = std::move(curve);
  if (options.angular) {
    std::vector<Eigen::Quaterniond> rotations(static_cast<size_t>(trajectory.size()));
    for (Eigen::Index i = 0; i < trajectory.size(); ++i) rotations[i] = trajectory.UnitQuaternion(i);
    RotationCurveOptions rotation_options;
    rotation_options.curve = options.curve;
    // Quaternions rounded to a step δ (TUM's four decimals) put each chart coordinate within 2δ's
    // rounding noise (δθ = 2 Im(q̄ δq)), on no lattice of its own ("Rounded positions").
    if (trajectory.channels().orientation == traj::OrientationKind::kQuaternion && options.curve.resolution == 0.0) {
      double step = 0.0;  // a component that hardly moves shows none
      for (Eigen::Index k = 0; k < 4; ++k) {
        const Eigen::VectorXd component = trajectory.quaternions().row(k).transpose();
        const double q = cheb::FindResolution(component);
        if (cheb::IsRounded(component, q)) step = std::max(step, q);  // false where q is 0
      }
      rotation_options.curve.resolution = 2.0 * step;
    }
    // The charts' noise varies along them: a choice by one σ is not reliable there (docs/velocity.md).
    rotation_options.curve.local_regression = false;
    RotationCurve rotation = FitRotationCurve(stamps, rotations, rotation_options);
    rotation.EvaluateMany(query, &estimate.orientations, &estimate.angular_velocities);
    estimate.rotation_curve = std::move(rotation);
  }
  return estimate;
}

traj::Trajectory VelocityTrajectory(const traj::TrajectoryView& input, const VelocityEstimate& estimate,
                                    std::optional<std::span<const int64_t>> at_ns) {
  const bool own = !at_ns.has_value();
  const std::span<const int64_t> stamps = own ? input.stamps_ns() : *at_ns;
  const bool angular = estimate.angular_velocities.cols() > 0;
  traj::Trajectory out(traj::Channels{traj::OrientationKind::kQuaternion, true, angular, true});
  out.Reserve(static_cast<Eigen::Index>(stamps.size() - estimate.skipped.size()));
  auto skipped = estimate.skipped.begin();
  for (size_t i = 0, column = 0; i < stamps.size(); ++i) {
    if (skipped != estimate.skipped.end() && *skipped == i) {
      ++skipped;
      continue;
    }
    const size_t r = column++;  // the estimate's column
    const auto k = static_cast<Eigen::Index>(r);
    Eigen::Vector3d position;
    Eigen::Vector4d q(0, 0, 0, 1);
    if (own) {
      position = input.positions().col(k);
      if (input.channels().orientation == traj::OrientationKind::kQuaternion) {
        q = input.quaternions().col(k);
      } else if (input.has_orientation()) {
        q = input.UnitQuaternion(k).coeffs();
      }
    } else {
      position = estimate.positions.col(k);
      if (!estimate.orientations.empty()) {
        q = estimate.orientations[r].coeffs();  // the fitted orientation curve
      } else if (input.has_orientation()) {
        // Slerp between the input's neighbouring orientations.
        const auto s = input.stamps_ns();
        const auto upper = std::upper_bound(s.begin(), s.end(), stamps[i]) - s.begin();
        const Eigen::Index j1 = std::clamp<Eigen::Index>(upper, 1, input.size() - 1), j0 = j1 - 1;
        const double span = static_cast<double>(s[j1] - s[j0]);
        const double f = span > 0 ? std::clamp(static_cast<double>(stamps[i] - s[j0]) / span, 0.0, 1.0) : 0.0;
        q = input.UnitQuaternion(j0).slerp(f, input.UnitQuaternion(j1)).coeffs();
      }
    }
    const Eigen::Vector3d v = estimate.velocities.col(k);
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    if (angular) w = estimate.angular_velocities.col(k);
    out.Append(stamps[i], position.data(), q.data(), v.data(), w.data());
  }
  return out;
}

std::string UnresolvedWarning(const cheb::Curve& curve) {
  // The largest residual over the noise among the unresolved windows whose residual fails the
  // test, or among all unresolved windows where none fails: a window at the smallest size can also
  // be unresolved with a residual that passes the test: its coefficients could not show the motion
  // resolved.
  struct Worst {
    const cheb::CurveWindow* window = nullptr;
    double ratio = 0.0;
    void Offer(const cheb::CurveWindow& w, double r) {
      if (window == nullptr || r > ratio) window = &w, ratio = r;
    }
  } failing_worst, any_worst;
  // A window that reproduces its samples to their rounding level (CurveWindow::reproduces_samples)
  // has missed nothing its samples show, whatever its coefficients: exact data at a low rate (a
  // simulator's file) leave such windows, and a warning about them would only mislead (motion
  // between the samples that they do not resolve, no method can tell).
  Eigen::Index failing = 0, undecided = 0;
  for (const cheb::CurveSegment& segment : curve.segments()) {
    for (const cheb::CurveWindow& w : segment.windows) {
      if (w.verdict != cheb::WindowVerdict::kUnresolved || w.residual_rms.size() != curve.dimension()) continue;
      const bool fails = w.lack_of_fit.size() > 0 && w.lack_of_fit.maxCoeff() > cheb::kLackOfFitLimit;
      if (!fails && w.reproduces_samples) continue;
      failing += fails ? 1 : 0;
      undecided += fails ? 0 : 1;
      // Against the σ the window was tested against (the noise profile's), where it has one.
      const Eigen::VectorXd& sigma = w.noise_sigma.size() == w.residual_rms.size() ? w.noise_sigma : curve.noise_sigma();
      for (Eigen::Index c = 0; c < w.residual_rms.size(); ++c) {
        const double ratio = sigma[c] > 0.0 ? w.residual_rms[c] / sigma[c] : 0.0;
        any_worst.Offer(w, ratio);
        if (fails) failing_worst.Offer(w, ratio);
      }
    }
  }
  const Worst& worst_of = failing > 0 ? failing_worst : any_worst;
  if (worst_of.window == nullptr) return {};
  const cheb::CurveWindow* worst = worst_of.window;
  const double worst_ratio = worst_of.ratio;
  if (failing == 0) {
    return fmt::format(
        "{} window(s) at the smallest size could not show the motion resolved, though their residual passes the "
        "residual test (at most {:.1f}x the noise, {:.3f}..{:.3f} s from the first sample): their velocity may miss "
        "fast motion there (--json lists them)",
        undecided, worst_ratio, worst->fit_begin, worst->fit_end);
  }
  const std::string where = fmt::format(
      "{} window(s) still fail the residual test at the smallest window; the worst, {:.3f}..{:.3f} s from the first "
      "sample, has a residual {:.1f}x the noise",
      failing, worst->fit_begin, worst->fit_end, worst_ratio);
  if (curve.local_samples() == 0) return where + ": its velocity may miss motion there (--json lists them)";
  return fmt::format("{}: where the residual is clearly above the noise the velocity comes from the samples' local "
                     "interpolant ({} samples; --json lists the windows)",
                     where, curve.local_samples());
}

std::string VelocityJson(const VelocityRun& run, const VelocityEstimate& estimate) {
  nlohmann::json j;  // keys sorted, as the file has always been written
  j["command"] = "velocity";
  j["input"] = {{"path", run.input_path}, {"poses", run.input_poses}};
  j["method"] = std::string(ToString(run.options.method));
  j["evaluated_at"] = run.evaluated_at;
  if (estimate.curve) {
    const cheb::Curve& curve = *estimate.curve;
    nlohmann::json windows = nlohmann::json::array();
    std::vector<int> degrees;
    for (const cheb::CurveSegment& segment : curve.segments()) {
      for (const cheb::CurveWindow& w : segment.windows) {
        nlohmann::json window = {{"begin_s", w.fit_begin}, {"end_s", w.fit_end}, {"samples", w.samples},
                                 {"degrees", w.degrees}, {"accepted", std::string(cheb::ToString(w.verdict))}};
        if (w.residual_rms.size() == curve.dimension()) {  // end caps are chosen otherwise (docs/velocity.md)
          window["residual_rms_m"] = std::vector<double>(w.residual_rms.data(), w.residual_rms.data() + w.residual_rms.size());
          window["lack_of_fit"] = std::vector<double>(w.lack_of_fit.data(), w.lack_of_fit.data() + w.lack_of_fit.size());
          window["noise_sigma_m"] = std::vector<double>(w.noise_sigma.data(), w.noise_sigma.data() + w.noise_sigma.size());
          window["reproduces_samples"] = w.reproduces_samples;
        }
        windows.push_back(std::move(window));
        degrees.insert(degrees.end(), w.degrees.begin(), w.degrees.end());
      }
    }
    j["degree_method"] = DegreeName(run.options.curve);
    j["segments"] = curve.segments().size();
    j["windows"] = windows.size();
    j["degrees"] = degrees;
    j["window_list"] = windows;
    j["noise_sigma_m"] = std::vector<double>(curve.noise_sigma().data(), curve.noise_sigma().data() + 3);
    j["noise_sigma_max_m"] = std::vector<double>(curve.noise_sigma_max().data(), curve.noise_sigma_max().data() + 3);
    j["noisier_samples"] = curve.noisier_samples();
    j["stamp_noise_s"] = curve.stamp_noise_s();
    j["skipped_at"] = estimate.skipped.size();
    j["position_resolution_m"] = std::vector<double>(curve.resolution().data(), curve.resolution().data() + 3);
    j["position_staircase"] = curve.staircase();
    if (estimate.rounded_stamps) {
      j["rounded_stamps"] = {{"resolution_s", estimate.rounded_stamps->resolution_s()},
                             {"rate_hz", estimate.rounded_stamps->rate_hz()}};
    }
    j["residual_rmse_m"] = std::vector<double>(curve.residual_rms().data(), curve.residual_rms().data() + 3);
    j["compression_ratio"] = static_cast<double>(3 * run.input_poses) / static_cast<double>(curve.stored_values());
    j["unresolved_windows"] = curve.unresolved_windows();
    j["local_samples"] = curve.local_samples();
    j["regression_samples"] = curve.regression_samples();
    j["outliers"] = curve.outlier_times().size();
    j["jumps"] = curve.jump_times().size();
    j["steps"] = curve.step_times().size();
  }
  if (estimate.rotation_curve) {
    j["angular"] = {{"charts", estimate.rotation_curve->charts().size()},
                    {"residual_rms_rad", estimate.rotation_curve->residual_rms_rad()}};
  }
  j["seconds"] = run.seconds;
  return j.dump(2) + "\n";
}

}  // namespace cheval::eval
