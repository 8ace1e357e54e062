#pragma once
/// \file
/// A smooth orientation curve fitted to noisy rotation samples, and the body angular velocity it
/// implies through the exact Lie-group relation.
///
/// Rotations do not live in a vector space, so they are fitted in local charts: the samples are cut
/// into overlapping pieces, each within `max_chart_angle` of its own origin rotation R_k, and each
/// piece's chart coordinates φ_i = Log(R_kᵀ R_i) are fitted by a windowed Chebyshev curve
/// (cheb::FitCurve, degrees chosen automatically). Inside a piece
///
///   R(t) = R_k · Exp(φ(t)),   ω(t) = J_r(φ(t)) · φ̇(t)   (body frame: Ṙ = R [ω]×),
///
/// which is exact for the fitted curve — not "d/dt of the rotation vector", which is wrong by
/// J_r(φ) − I, i.e. by O(|φ|) relative. Where two pieces overlap they are blended on the group,
/// R = R_a · Exp(s(t) · Log(R_aᵀ R_b)) with a C² smoothstep s, and ω is differentiated through the
/// blend exactly as well (docs/velocity.md, "Angular velocity").

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cheval/cheb/curve.h"

namespace cheval::eval {

/// Options of FitRotationCurve.
struct RotationCurveOptions {
  /// Options of each chart's Chebyshev fit (degrees, windows, noise); default: all automatic.
  cheb::CurveOptions curve;
  /// Largest angle (rad) between a chart's origin and the rotations it fits. Small keeps the
  /// charts close to flat; the fit is exact for any value below π. Pieces are extended beyond it
  /// (up to kMaxChartAngle) only to reach 24 samples, also the charts' smallest window.
  double max_chart_angle = 1.0;
};

/// One chart: an origin rotation and the fitted chart coordinates of the samples it covers.
struct RotationChart {
  Eigen::Quaterniond origin;
  int64_t begin_ns = 0, end_ns = 0;  ///< stamps of the first and last sample it covers
  cheb::Curve curve;                 ///< φ(t), 3 coordinates
};

/// The fitted orientation curve.
class RotationCurve {
 public:
  /// Orientations (R_world_body) and body angular velocities (3 x n, rad/s) at many stamps (any
  /// order). Throws ComputeError when a stamp lies outside the fitted data or inside a gap.
  void EvaluateMany(std::span<const int64_t> stamps_ns, std::vector<Eigen::Quaterniond>* orientations,
                    Eigen::Matrix3Xd* body_rates) const;

  int64_t origin_ns() const { return origin_ns_; }
  const std::vector<RotationChart>& charts() const { return charts_; }
  /// RMS of the angle (rad) between the fitted and the measured rotations, over all samples.
  double residual_rms_rad() const { return residual_rms_rad_; }

 private:
  friend RotationCurve FitRotationCurve(std::span<const int64_t>, std::span<const Eigen::Quaterniond>,
                                        const RotationCurveOptions&);
  int64_t origin_ns_ = 0;
  std::vector<RotationChart> charts_;
  double residual_rms_rad_ = 0;
};

/// Fits rotations (unit or not: they are normalised; either quaternion sign) sampled at stamps (any
/// order). Throws ComputeError when the data cannot support a fit (fewer than 2 samples, all stamps
/// equal, or consecutive rotations so far apart that no chart holds them), UsageError for bad
/// options.
RotationCurve FitRotationCurve(std::span<const int64_t> stamps_ns, std::span<const Eigen::Quaterniond> rotations,
                               const RotationCurveOptions& options = {});

}  // namespace cheval::eval
