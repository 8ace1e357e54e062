#include "cheval/eval/velocity.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <fmt/format.h>

#include "cheval/common/error.h"
#include "cheval/lie/so3.h"

namespace cheval::eval {
namespace {

void RequireIncreasing(std::span<const int64_t> stamps, std::string_view method) {
  for (size_t i = 1; i < stamps.size(); ++i) {
    if (stamps[i] <= stamps[i - 1]) {
      throw ComputeError(fmt::format("{} needs strictly increasing stamps; pose {} has a stamp <= the previous one "
                                     "(use --method chebyshev, which handles them)",
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
  if (window < 5 || window % 2 == 0) {
    throw UsageError(fmt::format("the Savitzky-Golay window must be an odd number of samples >= 5, got {}", window));
  }
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

VelocityEstimate EstimateVelocity(const traj::TrajectoryView& trajectory, const VelocityOptions& options,
                                  std::optional<std::span<const int64_t>> at_ns) {
  VelocityEstimate estimate;
  if (options.angular && !trajectory.has_orientation()) {
    throw UsageError("--angular needs orientations, but the trajectory has positions only");
  }
  if (options.method != VelocityMethod::kChebyshev) {
    if (at_ns) {
      throw UsageError(fmt::format("--at needs --method chebyshev: {} gives velocity only at the input's own stamps",
                                   ToString(options.method)));
    }
    if (options.angular && options.method != VelocityMethod::kCentral) {
      throw UsageError(fmt::format("--angular works with --method chebyshev or central, not {}",
                                   ToString(options.method)));
    }
    estimate.velocities = options.method == VelocityMethod::kCentral ? CentralDifferences(trajectory)
                                                                      : SavitzkyGolay(trajectory, options.savgol_window);
    if (options.angular) estimate.angular_velocities = CentralAngularDifferences(trajectory);
    return estimate;
  }
  const Eigen::MatrixXd positions = trajectory.positions().transpose();
  cheb::Curve curve = cheb::FitCurve(trajectory.stamps_ns(), positions, options.curve);
  const std::span<const int64_t> query = at_ns ? *at_ns : trajectory.stamps_ns();
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
    RotationCurve rotation = FitRotationCurve(trajectory.stamps_ns(), rotations, rotation_options);
    rotation.EvaluateMany(query, &estimate.orientations, &estimate.angular_velocities);
    estimate.rotation_curve = std::move(rotation);
  }
  return estimate;
}

}  // namespace cheval::eval
