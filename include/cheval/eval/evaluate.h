#pragma once
/// \file
/// One evaluation end to end, the data flow of an evaluation: two trajectories -> association (index
/// pairs) -> reference velocity if the metric needs it -> alignment (a similarity applied to R, p, v)
/// -> per-pair errors -> statistics. The CLI's `ape`, `rpe` and `ase` are this call plus printing
/// (docs/evaluation.md).

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cheval/eval/align.h"
#include "cheval/eval/associate.h"
#include "cheval/eval/metrics.h"
#include "cheval/eval/statistics.h"
#include "cheval/eval/velocity.h"

namespace cheval::eval {

/// The metric of an evaluation.
enum class MetricKind { kApe, kRpe, kAse };
/// "ape", "rpe", "ase".
std::string_view ToString(MetricKind metric);

/// Where the reference velocity of the ASE comes from.
enum class ReferenceVelocitySource {
  kAuto,       ///< its own velocity columns if it has them, else kChebyshev (C-ASE)
  kGiven,      ///< its own velocity columns (ComputeError without them)
  kChebyshev,  ///< the derivative of a windowed Chebyshev fit of its positions (C-ASE)
  kCentral,    ///< central differences of its positions (a baseline)
};
/// "auto", "given", "chebyshev", "central".
std::string_view ToString(ReferenceVelocitySource source);
std::optional<ReferenceVelocitySource> ReferenceVelocitySourceFromString(std::string_view name);

/// Everything an evaluation needs besides the two trajectories.
struct EvaluationOptions {
  MetricKind metric = MetricKind::kApe;
  AssociationOptions association;
  /// Instead of pairing each estimate pose with the nearest reference pose, evaluate the reference
  /// at the exact estimate stamps (plus the association offset): positions and velocity from a Chebyshev curve fitted to its
  /// positions (options `velocity.curve`), orientation by slerp between the two reference poses
  /// around the stamp. Estimate poses outside the curve (before, after, or inside a gap of the
  /// reference) are left out. Needs reference stamps in non-decreasing order.
  bool continuous_reference = false;
  AlignmentOptions alignment;
  /// APE and RPE: the pose relation; RPE: δ, its unit and all-pairs mode (rpe.relation is ignored).
  PoseRelation relation = PoseRelation::kTranslation;
  RpeOptions rpe;
  /// RPE: also compute the KITTI-style drift over 100..800 m.
  bool kitti_drift = false;
  /// ASE: the reference velocity, and the options of EstimateVelocity when it is derived.
  ReferenceVelocitySource reference_velocity = ReferenceVelocitySource::kAuto;
  VelocityOptions velocity;
  /// ASE: the estimate's velocity columns are body-frame (rotated by its own orientation).
  bool estimate_velocity_body_frame = false;
  /// ASE without velocity (rotation + position only) instead of an error when velocity is missing.
  bool pose_only = false;
  /// ASE: a reference whose orientations are all exactly the identity (what a position-only source
  /// written with identity quaternions looks like) is treated as position-only, with a warning in
  /// EvaluationResult::warnings; false takes those orientations as real.
  bool identity_reference_is_position_only = true;

  /// Checks the fields and combinations a caller can get wrong, before any work (Evaluate calls it):
  /// association, alignment, RPE (metric kRpe) and velocity options, pose_only together with a
  /// body-frame estimate velocity, continuous_reference with a reference velocity other than auto
  /// or chebyshev. Throws OptionError naming the first bad field.
  void Validate() const;
};

/// The result of Evaluate: what was paired, how it was aligned, the errors and their statistics.
struct EvaluationResult {
  MetricKind metric = MetricKind::kApe;
  /// The pairs. With continuous_reference, `ref[k]` indexes the reference evaluated at the estimate
  /// stamps (`continuous_reference`), not the reference file.
  Association association;
  std::optional<traj::Trajectory> continuous_reference;
  AlignmentResult alignment;
  /// evo-style title, one line per item, e.g. "APE w.r.t. translation part (m)\n(not aligned)".
  std::string title;
  /// Name of the metric's relation ("trans_part", ... ; for ASE "state", "position+velocity",
  /// "rotation+position") and unit of the errors ("m", "deg", "rad", "" for unit-less).
  std::string relation;
  std::string unit;
  /// One error per pair (APE, ASE) or per index pair (RPE), and their statistics.
  std::vector<double> errors;
  ErrorStatistics stats;
  /// Estimate stamp of each error (RPE: of its first pose; stamps_end: of its second).
  std::vector<int64_t> stamps_ns;
  std::vector<int64_t> stamps_end_ns;
  /// RPE: the index pairs (positions in the association).
  std::vector<IndexPair> rpe_pairs;
  /// ASE: the parts and their statistics (rotation empty for a position-only reference, velocity
  /// empty for a pose-only ASE), and where the reference velocity came from ("given", "chebyshev",
  /// "central", or "none").
  std::optional<AseErrors> ase;
  ErrorStatistics rotation_stats, position_stats, velocity_stats;
  std::string velocity_source;
  /// RPE with kitti_drift (segments 0 when the reference path is shorter than 100 m: no drift).
  std::optional<DriftResult> drift;
  /// What the caller should show the user, one line each (e.g. an identity-orientation reference
  /// taken as position-only).
  std::vector<std::string> warnings;
};

/// Evaluates `est` against `ref`. Throws OptionError for bad options (options.Validate()) and
/// ComputeError when the evaluation is impossible (no pairs, degenerate alignment, missing
/// orientation or velocity), with a message saying what to change.
EvaluationResult Evaluate(const traj::TrajectoryView& ref, const traj::TrajectoryView& est,
                          const EvaluationOptions& options);

/// One evaluated estimate with what its JSON names besides the result: the inputs and the options.
struct EvaluationReport {
  /// The reference and the estimate as the caller names them (file paths) and their pose counts.
  std::string reference_path;
  Eigen::Index reference_poses = 0;
  std::string estimate_path;
  /// The estimate's name in tables (`--label`, default the file name); in the JSON as
  /// `estimate.label` when not empty.
  std::string estimate_label;
  Eigen::Index estimate_poses = 0;
  EvaluationOptions options;
  EvaluationResult result;
};

/// The JSON of evaluations (docs/evaluation.md, "Output"): per report
/// `command`, `reference`, `estimate`, `association`, `alignment`, `metric`, `stats`, and for RPE
/// `metric.delta`, `metric.delta_unit`, `metric.all_pairs` (+ `drift`), for ASE `parts` and
/// `velocity_source`; `association.max_diff` and `offset` in seconds (AssociationOptions::max_diff_s()).
/// One object for one report, an array for several; 2-space indentation and a final newline;
/// doubles in the shortest form that reads back to the same double. What the CLI's `ape`, `rpe`
/// and `ase` write with their JSON option and the Python module returns (as a dict).
std::string EvaluationJson(std::span<const EvaluationReport> reports);

/// The per-pair errors of evaluations as CSV (docs/evaluation.md, "Output"): a header row, then per
/// error the estimate stamp (s), for RPE the pair's second stamp (`stamp_end`), the error and for ASE
/// its parts (rotation when both sides have orientation, position, velocity unless pose-only). With
/// several reports a first column `estimate` names each report's estimate_path. Numbers in the
/// shortest form that reads back to the same double; stamps exactly (traj::FormatSeconds).
std::string EvaluationErrorsCsv(std::span<const EvaluationReport> reports);

}  // namespace cheval::eval
