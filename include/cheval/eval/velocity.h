#pragma once
/// \file
/// Linear velocity from positions: the Chebyshev method of the C-ASE paper (windowed least-squares
/// fits, degrees chosen automatically, differentiated exactly) and the two baselines users reach
/// for, central differences and Savitzky–Golay.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "cheval/cheb/curve.h"
#include "cheval/eval/rotation_curve.h"
#include "cheval/traj/trajectory.h"

namespace cheval::eval {

/// How velocity is computed from positions.
enum class VelocityMethod {
  kChebyshev,      ///< windowed Chebyshev least squares, differentiated (default)
  kCentral,        ///< (p_{i+1} - p_{i-1}) / (t_{i+1} - t_{i-1}); one-sided at the ends
  kSavitzkyGolay,  ///< local cubic least squares over a window of samples, differentiated at the centre
};

std::string_view ToString(VelocityMethod method);
std::optional<VelocityMethod> VelocityMethodFromString(std::string_view name);

/// Options of EstimateVelocity.
struct VelocityOptions {
  VelocityMethod method = VelocityMethod::kChebyshev;
  /// kChebyshev: the curve fit's options (degree method, window, noise ...).
  cheb::CurveOptions curve;
  /// kSavitzkyGolay: window length in samples (odd, >= 5); the polynomial is cubic. Uses the
  /// actual stamps (a local fit in time), so uneven sampling is handled.
  int savgol_window = 21;
  /// kSavitzkyGolay: the window in seconds instead of savgol_window: the nearest odd number of
  /// samples at the trajectory's mean rate, at least 5 (SavitzkyGolaySamples).
  std::optional<double> savgol_window_s;
  /// Also body angular velocity from the orientations (kChebyshev: a RotationCurve fitted with the
  /// same curve options; kCentral: central differences on the group). Needs orientations.
  bool angular = false;
  /// kChebyshev with stamps to evaluate at: leave out those the fit does not cover (before the
  /// first sample, after the last, inside a gap: cheb::Curve::Covers) instead of throwing
  /// ComputeError, and list them in VelocityEstimate::skipped (all of them, where none is covered).
  bool skip_uncovered = false;

  /// Throws OptionError for a Savitzky–Golay window that is not an odd number >= 5 of samples or not
  /// a positive number of seconds, for angular with kSavitzkyGolay, and for a fixed Chebyshev degree
  /// of 0 (a constant: its velocity is zero whatever the motion).
  void Validate() const;
};

/// Curve options from the names the faces take: `degree` "auto" (= "cv", cross-validation), "chop"
/// or a non-negative integer (a fixed degree, fitted over each gap-free segment at once
/// when no window is given); `window_s` the fixed window length (s), nullopt for adaptive windows.
/// Throws OptionError naming CurveOptions::degree_method for any other degree.
cheb::CurveOptions CurveOptionsFromNames(std::string_view degree, std::optional<double> window_s = std::nullopt);

/// The name of the curve's degree choice as CurveOptionsFromNames takes it: "auto", "chop" or the
/// fixed degree.
std::string DegreeName(const cheb::CurveOptions& options);

/// The Savitzky–Golay window of `window_s` seconds in samples at the mean rate of `stamps_ns`
/// ((n - 1) / duration): the nearest odd number, at least 5.
int SavitzkyGolaySamples(std::span<const int64_t> stamps_ns, double window_s);

/// Stamps rounded to a resolution from a uniform rate (RoundedUniformStamps).
struct RoundedStamps {
  /// The rounding's resolution (ns) and the uniform period (ns) the stamps were rounded from.
  int64_t resolution_ns = 0;
  double period_ns = 0.0;
  /// The uniform stamps (ns), one per input stamp: the instants the samples were taken.
  std::vector<int64_t> uniform_ns;

  double resolution_s() const { return static_cast<double>(resolution_ns) * 1e-9; }
  double rate_hz() const { return 1e9 / period_ns; }
};

/// Whether `stamps_ns` are a uniform rate rounded to a coarser resolution q (a recorder writing
/// 240 Hz in whole milliseconds: steps of 4 and 5 ms), and then the uniform stamps. Exact: every
/// step is one of two values q apart, both occur, and the stamps stay within q of the straight
/// line through the first and last (rounding moves each by at most q/2); the uniform stamps are
/// that line centred on them. Such stamps err by up to q/2, which for motion at v reads as noise of
/// v·q/sqrt(12) with a pattern that repeats (0.1 mm at 0.3 m/s and 1 ms) and as jumps where the
/// pattern steps. Nullopt for fewer than 8 stamps, for even or irregular stamps, a dropped sample
/// or a gap.
std::optional<RoundedStamps> RoundedUniformStamps(std::span<const int64_t> stamps_ns);

/// Velocities and what the Chebyshev fit chose.
struct VelocityEstimate {
  /// 3 x n world-frame velocities (m/s) at the query stamps.
  Eigen::Matrix3Xd velocities;
  /// kChebyshev only: 3 x n fitted positions at the query stamps; empty otherwise.
  Eigen::Matrix3Xd positions;
  /// kChebyshev only: the fitted curve (windows, degrees, noise, residuals); empty otherwise.
  std::optional<cheb::Curve> curve;
  /// With `angular`: 3 x n body angular velocities (rad/s) at the query stamps.
  Eigen::Matrix3Xd angular_velocities;
  /// With `angular` and kChebyshev: the fitted orientations at the query stamps and the curve.
  std::vector<Eigen::Quaterniond> orientations;
  std::optional<RotationCurve> rotation_curve;
  /// kChebyshev: where the stamps were rounded from a uniform rate (RoundedUniformStamps), the
  /// uniform stamps the curves were fitted and evaluated at (at the trajectory's own stamps).
  std::optional<RoundedStamps> rounded_stamps;
  /// With VelocityOptions::skip_uncovered: the positions in `at_ns` of the stamps left out,
  /// ascending; the columns above belong to the others, in order.
  std::vector<size_t> skipped;
};

/// Estimates world-frame velocity at `at_ns` (nullopt: at the trajectory's own stamps) from its
/// positions. With kChebyshev, stamps rounded from a uniform rate (RoundedUniformStamps) are
/// replaced by the uniform ones for the fit and for evaluating at the trajectory's own stamps
/// (`at_ns` that are among them too: a reference's paired samples). Central differences and
/// Savitzky–Golay work only at the trajectory's own stamps (OptionError naming
/// VelocityOptions::method otherwise); they need stamps in increasing order
/// (ComputeError otherwise). Throws OptionError for bad options (options.Validate()) and for
/// angular on a trajectory without orientation, ComputeError for a trajectory without stamps and
/// when the data cannot support the method (too few samples, equal stamps...).
VelocityEstimate EstimateVelocity(const traj::TrajectoryView& trajectory, const VelocityOptions& options,
                                  std::optional<std::span<const int64_t>> at_ns = std::nullopt);

/// One line saying where a fit still fails its residual test (WindowVerdict::kUnresolved: the
/// worst window, its residual against the noise), or empty when every window passed.
std::string UnresolvedWarning(const cheb::Curve& curve);

/// The trajectory of an estimate (what `cheval velocity -o` writes, docs/velocity.md): at the
/// trajectory's own stamps (`at_ns` nullopt) its positions and orientations as read; at other
/// stamps the fitted positions and orientations (the fitted orientation curve with `angular`, else
/// slerp between the neighbouring orientations of the input, whose stamps must be sorted); the
/// identity where the input has no orientation. Velocities, and the angular velocities when the
/// estimate has them.
traj::Trajectory VelocityTrajectory(const traj::TrajectoryView& trajectory, const VelocityEstimate& estimate,
                                    std::optional<std::span<const int64_t>> at_ns = std::nullopt);

/// What VelocityJson reports besides the estimate: the input as the caller names it and the run.
struct VelocityRun {
  std::string input_path;
  Eigen::Index input_poses = 0;
  VelocityOptions options;
  /// Number of stamps the velocity was evaluated at.
  size_t evaluated_at = 0;
  /// Wall-clock time of the run as the caller measured it.
  double seconds = 0;
};

/// The JSON of `cheval velocity --json` (docs/velocity.md): command, input {path, poses}, method,
/// evaluated_at; with a Chebyshev curve degree_method (DegreeName), segments, windows, degrees (per
/// window and coordinate), window_list (begin_s, end_s, samples, degrees), noise_sigma_m,
/// residual_rmse_m, compression_ratio (3 n / stored values), and rounded_stamps {resolution_s,
/// rate_hz} where the stamps were rounded (RoundedUniformStamps); with a rotation curve angular
/// {charts, residual_rms_rad}; seconds. 2-space indentation and a final newline. (docs/velocity.md,
/// "Output, `--json` and messages", lists every field.)
std::string VelocityJson(const VelocityRun& run, const VelocityEstimate& estimate);

}  // namespace cheval::eval
