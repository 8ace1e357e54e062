#pragma once
/// \file
/// Alignment of an estimate onto a reference (docs/evaluation.md, "Alignment"): a similarity S found from the
/// associated pairs and applied to every estimate state — orientation, position and velocity:
/// R' = R·R_i, p' = c·R·p_i + t, v' = c·R·v_i.
///
/// | method   | what is solved (est x_i onto ref y_i, i < N)                                 | DoF |
/// |----------|------------------------------------------------------------------------------|-----|
/// | none     | nothing (evo's default)                                                      | 0   |
/// | origin   | T = T_ref,0 · T_est,0⁻¹ (first pair; needs both orientations)                 | 6   |
/// | se3      | Umeyama (1991) without scale: min Σ|y_i - R x_i - t|² (evo's align)          | 6   |
/// | sim3     | Umeyama with scale: min Σ|y_i - c R x_i - t|² (evo's align + correct_scale) | 7   |
/// | scale    | the Sim(3) Umeyama scale c alone: p' = c·p (evo's correct_scale)              | 1   |
/// | posyaw   | rotation restricted to yaw about the reference z (gravity) axis, then t      | 4   |
/// | full     | SE(3) minimising the ASE itself: Σ ‖R_q,iᵀ R R_p,i − I‖² + |R p_i + t − q_i|² + |R v_i − u_i|² | 6 |
///
/// Umeyama follows evo's `geometry.umeyama_alignment` (v1.36.5): means, C = (1/n) Σ (y_i − ȳ)(x_i − x̄)ᵀ,
/// U D Vᵀ = svd(C), S = diag(1, 1, ±1) with −1 when det(U)·det(V) < 0, R = U S Vᵀ,
/// c = tr(D S) / σ_x² with σ_x² = (1/n) Σ |x_i − x̄|², t = ȳ − c R x̄; fewer than two singular values
/// above machine epsilon is degenerate.

#include <optional>
#include <string_view>

#include <Eigen/Core>

#include "cheval/eval/pairs.h"

namespace cheval::eval {

/// Alignment methods (see the file comment).
enum class AlignmentMethod { kNone, kOrigin, kSE3, kSim3, kScale, kPosYaw, kFull };

/// "none", "origin", "se3", "sim3", "scale", "posyaw", "full".
std::string_view ToString(AlignmentMethod method);
/// Parses a method name; nullopt if unknown.
std::optional<AlignmentMethod> AlignmentMethodFromString(std::string_view name);
/// evo's title line, e.g. "(with SE(3) Umeyama alignment)", "(not aligned)".
std::string_view AlignmentTitle(AlignmentMethod method);

/// Umeyama's least-squares similarity taking the points `est` (3 x n) onto `ref` (3 x n).
/// Throws ComputeError when fewer than 3 points are given or the covariance is degenerate (all points
/// on a line or at one place).
Similarity UmeyamaAlignment(const Eigen::Ref<const Eigen::Matrix3Xd>& est, const Eigen::Ref<const Eigen::Matrix3Xd>& ref,
                            bool with_scale);

/// The 4-DoF (x, y, z, yaw) alignment: the rotation about the reference z axis by θ maximising
/// tr(R_z(θ)ᵀ C) with C as in Umeyama, i.e. θ = atan2(C₁₀ − C₀₁, C₀₀ + C₁₁) (this minimises
/// Σ|y_i − R_z x_i − t|² over θ and t), then t = ȳ − R_z x̄. Throws ComputeError for fewer than 3
/// points or no horizontal extent.
Similarity PositionYawAlignment(const Eigen::Ref<const Eigen::Matrix3Xd>& est,
                                const Eigen::Ref<const Eigen::Matrix3Xd>& ref);

/// Options of ComputeAlignment.
struct AlignmentOptions {
  AlignmentMethod method = AlignmentMethod::kNone;
  /// Solve from the first n_align pairs only (all when 0 or more than there are); apply to all.
  Eigen::Index n_align = 0;

  /// Throws OptionError for a negative n_align, or n_align > 0 with method kNone.
  void Validate() const;
};

/// The alignment and how it was obtained.
struct AlignmentResult {
  AlignmentMethod method = AlignmentMethod::kNone;
  Similarity transform;
  /// Pairs the solution used (0 for none).
  Eigen::Index pairs_used = 0;
  /// kFull: the cost Σ ASE_i² over the pairs used, of the full solution and of the SE(3) position-only
  /// solution it is guaranteed not to exceed (when the closed form loses to it on inexact, non-
  /// orthonormal input the position-only solution is returned).
  double full_cost = 0, position_only_cost = 0;
};

/// Solves the alignment of the estimate of `pairs` (raw estimate states; the alignment already set
/// on `pairs` is ignored) onto its reference. kFull uses every channel both sides have: rotation,
/// position, velocity (set the reference velocities / the body-frame flag on `pairs` first).
/// Throws OptionError for bad options (Validate(); not checked for method kNone) and ComputeError on
/// degenerate input (fewer than 3 pairs, collinear positions, origin or full
/// without orientation where needed) with a message saying what is missing.
AlignmentResult ComputeAlignment(const PairedStates& pairs, const AlignmentOptions& options);

}  // namespace cheval::eval
