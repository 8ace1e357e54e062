#pragma once
/// \file
/// Per-pair errors: APE and RPE exactly as evo v1.36.5 computes them (docs/evaluation.md, "Metrics"), KITTI-style
/// drift (the KITTI odometry devkit's segment errors), and the Absolute State Error on SE_2(3) of
/// the C-ASE paper (docs/evaluation.md, "Metrics").
///
/// Notation: Q = reference pose, P = aligned estimate pose, both T = [R t; 0 1] with inverses formed
/// by transposition (never a general matrix inverse). KITTI rotations are used as read.

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "cheval/eval/pairs.h"

namespace cheval::eval {

/// What of a pose error is measured (evo's pose_relation names in the comments).
enum class PoseRelation {
  kTranslation,    ///< "trans_part": |t(E)| (APE: |p_est − p_ref|), metres
  kRotation,       ///< "rot_part": ‖R(E) − I‖_F, unit-less
  kFull,           ///< "full": ‖E − I₄‖_F, unit-less
  kAngleDeg,       ///< "angle_deg": |log R(E)| in degrees (§6)
  kAngleRad,       ///< "angle_rad": |log R(E)| in radians (§6)
  kPointDistance,  ///< "point_distance": APE |p_est − p_ref|; RPE ||Δp_ref| − |Δp_est||, metres
};

/// evo's command-line names: "trans_part", "rot_part", "full", "angle_deg", "angle_rad", "point_distance".
std::string_view ToString(PoseRelation relation);
std::optional<PoseRelation> PoseRelationFromString(std::string_view name);
/// evo's wording for titles: "translation part", "rotation part", "full transformation", ...
std::string_view RelationDescription(PoseRelation relation);
/// Unit of the errors: "m", "deg", "rad", or "" (unit-less).
std::string_view RelationUnit(PoseRelation relation);
/// True when the relation needs the orientation of both trajectories.
bool RelationNeedsOrientation(PoseRelation relation, bool relative);

/// The rotation angle |log R| in radians exactly as evo obtains it: the norm of scipy's rotation
/// vector of `R` (matrix -> quaternion by the largest-diagonal branch, normalised, w >= 0; then
/// θ = 2 atan2(|q_xyz|, q_w) and the rotation vector θ/sin(θ/2)·q_xyz, with its Taylor series for
/// θ <= 1e-3). Well conditioned for small angles, unlike acos((tr R − 1)/2). Accepts slightly
/// non-orthonormal R (KITTI).
double RotationAngle(const Eigen::Matrix3d& R);

/// APE of every pair of `pairs` (aligned estimate against reference), evo's `metrics.APE`:
/// translation/point distance |p_est − p_ref|; otherwise E = P⁻¹·Q. Throws ComputeError when the
/// relation needs orientations a trajectory does not have.
std::vector<double> ApeErrors(const PairedStates& pairs, PoseRelation relation);

/// Unit of the RPE pair distance δ (evo's delta_unit f, m, d, r).
enum class DeltaUnit { kFrames, kMeters, kDegrees, kRadians };
/// "frames", "meters", "degrees", "radians".
std::string_view ToString(DeltaUnit unit);
/// Parses a unit name or evo's letter for it (f, m, d, r); nullopt if unknown.
std::optional<DeltaUnit> DeltaUnitFromString(std::string_view name);
/// evo's unit label: "frames", "m", "deg", "rad".
std::string_view DeltaUnitLabel(DeltaUnit unit);

/// Options of the RPE (evo's defaults).
struct RpeOptions {
  PoseRelation relation = PoseRelation::kTranslation;
  double delta = 1.0;
  DeltaUnit delta_unit = DeltaUnit::kFrames;
  /// Overlapping pairs from every pose instead of consecutive ones.
  bool all_pairs = false;
  /// Relative tolerance on δ in all-pairs mode for meters/degrees/radians (evo's rel_delta_tol).
  double relative_delta_tolerance = 0.1;

  /// Throws OptionError unless δ is positive and finite, an integer for frames and at most 180° (π
  /// rad) for an angle.
  void Validate() const;
};

/// A pair (i, j) of positions in the list of associated pairs.
struct IndexPair {
  Eigen::Index i = 0, j = 0;
  bool operator==(const IndexPair&) const = default;
};

/// The RPE's index pairs, chosen on the aligned estimate as evo's `filters` do (docs/evaluation.md, "Metrics"):
/// - frames, consecutive: ids 0, δ, 2δ, ... and the pairs of neighbouring ids; all pairs: (i, i + δ);
/// - meters, consecutive: walk the path summing |p_i − p_prev|; when the sum reaches δ, i is an id
///   and the sum restarts (index 0 is not an id); pairs of neighbouring ids. All pairs: for each i the
///   first j > i whose path distance from i is nearest δ, kept if within δ·tol — O(n log n) by binary
///   search on the accumulated distances (evo scans, O(n²); the pairs are the same);
/// - degrees/radians (δ within [0, 180] deg / [0, π] rad), consecutive: sum the angles between
///   neighbouring orientations; when the sum reaches δ, emit (start, i) and restart at i; all pairs:
///   every (i, j > i) whose relative angle is within δ ± δ·tol — O(n²), as evo.
/// Throws UsageError for a bad δ and ComputeError when no pair results or orientation is missing.
std::vector<IndexPair> RpeIndexPairs(const PairedStates& pairs, const RpeOptions& options);

/// RPE errors of `index_pairs`: E_ij = (Q_i⁻¹ Q_j)⁻¹ (P_i⁻¹ P_j), then the relation (point distance:
/// ||q_j − q_i| − |p_j − p_i||). Throws ComputeError when orientation is needed and missing.
std::vector<double> RpeErrors(const PairedStates& pairs, std::span<const IndexPair> index_pairs,
                              PoseRelation relation);

/// KITTI odometry drift (the devkit's evaluate_odometry): from every 10th pair, for each segment
/// length L in 100, 200, ..., 800 m of *reference* path, the first pair j whose path distance from
/// the start exceeds L; the error E = (P_i⁻¹ P_j)⁻¹ (Q_i⁻¹ Q_j) gives |t(E)| / L and the angle
/// acos(clamp((tr R(E) − 1)/2)) / L. Reported as means over all segments.
struct DriftResult {
  /// Mean translation error, percent of the segment length.
  double translation_percent = 0;
  /// Mean rotation error, degrees per metre.
  double rotation_deg_per_m = 0;
  /// Number of segments; 0 when the reference path is shorter than 100 m.
  Eigen::Index segments = 0;
  /// Per segment length (100..800 m): the same means, and the count (0 when none fits).
  struct Length {
    double length_m = 0, translation_percent = 0, rotation_deg_per_m = 0;
    Eigen::Index segments = 0;
  };
  std::vector<Length> lengths;
};

/// Computes the KITTI-style drift of the aligned estimate. Needs orientation on both sides
/// (ComputeError otherwise).
DriftResult KittiDrift(const PairedStates& pairs);

/// The Absolute State Error of every pair (docs/evaluation.md, "Metrics"): E_i = Q_i⁻¹ · S(P_i) in SE_2(3) with
/// composition (R1R2, R1p2 + p1, R1v2 + v1), ASE_i = ‖E_i − I₅‖_F, and its parts
/// rotation ‖R_qᵀ R_p − I‖_F, position |R_qᵀ (p_p − p_q)|, velocity |R_qᵀ (v_p − v_q)|
/// (ASE_i² is the sum of their squares). Channels one side lacks are left out and flagged:
/// a position-only reference gives the position + velocity state error (R_q = I), a pose-only
/// evaluation the rotation + position error.
struct AseErrors {
  std::vector<double> total, rotation, position, velocity;
  bool has_rotation = false;
  bool has_velocity = false;
};

/// Computes the ASE. With `use_velocity` both sides must have velocity (ComputeError naming the side
/// that lacks it); without, the pose-only ASE (rotation + position) is computed.
AseErrors AseErrorsOf(const PairedStates& pairs, bool use_velocity = true);

}  // namespace cheval::eval
