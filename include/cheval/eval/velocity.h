#pragma once
/// \file
/// Linear velocity from positions: the Chebyshev method of the C-ASE paper (windowed least-squares
/// fits, degrees chosen automatically, differentiated exactly) and the two baselines users reach
/// for, central differences and Savitzky–Golay.

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

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
  /// Also body angular velocity from the orientations (kChebyshev: a RotationCurve fitted with the
  /// same curve options; kCentral: central differences on the group). Needs orientations.
  bool angular = false;
};

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
};

/// Estimates world-frame velocity at `at_ns` (nullopt: at the trajectory's own stamps) from its
/// positions. Central differences and Savitzky–Golay work only at the trajectory's own stamps
/// (UsageError otherwise); they need stamps in increasing order (ComputeError otherwise).
/// Throws ComputeError when the data cannot support the method (too few samples, equal stamps...).
VelocityEstimate EstimateVelocity(const traj::TrajectoryView& trajectory, const VelocityOptions& options,
                                  std::optional<std::span<const int64_t>> at_ns = std::nullopt);

}  // namespace cheval::eval
