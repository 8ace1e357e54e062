#pragma once
// What `cheval ape`, `cheval rpe` and `cheval ase` share: the reference/estimate arguments, the input,
// association, alignment and output flags bound to eval::EvaluationOptions, and the action (read,
// eval::Evaluate each estimate, print evo's table, a comparison table for several estimates, the
// JSON and the per-pair CSV of the library). Each command's own file adds its metric's flags.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cheval/eval/evaluate.h"
#include "common.h"

namespace cheval::cli {

/// Flags of the evaluation commands (the metric-specific ones are set by ape.cc, rpe.cc, ase.cc).
/// Numbers and switches are bound to `options` directly; the flags whose text names an enum value,
/// or which are in other units than the field (seconds for nanoseconds), are kept as given and
/// converted by ToEvaluationOptions. Every default is the library's.
struct EvalFlags {
  std::string reference;
  std::vector<std::string> estimates;
  InputFlags both, ref, est;
  eval::EvaluationOptions options;
  std::string align{eval::ToString(options.alignment.method)};
  std::optional<Eigen::Index> n_align;  // --n-align: unset means all pairs (the library's 0)
  double t_max_diff = options.association.max_diff_s();
  double t_offset = options.association.offset_s();
  std::string association = options.continuous_reference ? "continuous" : "nearest";
  std::string relation{eval::ToString(options.relation)};
  std::string delta_unit{eval::ToString(options.rpe.delta_unit)};
  std::string gt_velocity{eval::ToString(options.reference_velocity)};
  std::string velocity_frame = options.estimate_velocity_body_frame ? "body" : "world";
  std::string json_path;
  std::string errors_path;
  // evo's alignment flags (docs/cli.md, "evo's flags"), resolved into `align` by ToEvaluationOptions.
  bool evo_align = false;         // -a (or --align without a method)
  bool evo_scale = false;         // -s, --correct_scale
  bool evo_align_origin = false;  // --align_origin
  bool align_given = false;       // --align METHOD given
  bool verbose = false;           // -v: accepted, cheval always prints evo's verbose lines
  // Extrinsic files (eval/extrinsic.h) applied to the estimates / the reference after reading.
  std::string transform_left, transform_right, ref_transform_left, ref_transform_right;
  // --label NAME per estimate, in order (EvalInputs::estimate_labels).
  std::vector<std::string> labels;
  std::string save_results;  // --save-results: evo's result zip (eval/res_file.h), one estimate
};

/// The method of `flags`: --align, or evo's -a / -s / --align_origin (-a -s = sim3, -a = se3, -s =
/// scale). Throws UsageError when they contradict each other.
std::string ResolvedAlignment(const EvalFlags& flags);

/// The "did you mean" message of main() for arguments the parsed command did not take.
std::string UnknownFlags(const CLI::App& app, const std::vector<std::string>& arguments);

/// Adds `-r,--relation` (APE and RPE).
void AddRelationFlag(CLI::App* command, EvalFlags* flags);

/// Adds the arguments and flags every evaluation command takes (also `cheval report`): the reference
/// and estimate files, the input flags for both and per side, --align (its default is the current
/// value of flags->align), --n-align, --t-max-diff, --t-offset, --association.
void AddEvalInputFlags(CLI::App* command, EvalFlags* flags);

/// Adds the ASE's velocity flags --gt-velocity and --velocity-frame.
void AddStateVelocityFlags(CLI::App* command, EvalFlags* flags);

/// The library options of an evaluation of `metric` from the flags, validated (OptionError).
eval::EvaluationOptions ToEvaluationOptions(eval::MetricKind metric, const EvalFlags& flags);

/// The files of an evaluation, read.
struct EvalInputs {
  traj::Trajectory reference;
  std::vector<traj::Trajectory> estimates;
  std::vector<std::string> estimate_names;  ///< the paths (PATH:TOPIC for several --est-topic)
  /// The names to show for the estimates: the --label values in order, else each file's name
  /// without its folders (NAME:TOPIC for several --est-topic). For tables, JSON and the report.
  std::vector<std::string> estimate_labels;
  traj::Format reference_format = traj::Format::kAuto;  ///< the formats read (never kAuto once read)
  std::vector<traj::Format> estimate_formats;
};

/// `options` for estimate `k` of `inputs`: the association decides ties on the float seconds evo
/// would read from each file's format (eval::EvoStampSeconds).
eval::EvaluationOptions OptionsForEstimate(eval::EvaluationOptions options, const EvalInputs& inputs, size_t k);

/// Every file an evaluation reads: the reference, the estimates and the KITTI times files of both sides
/// (empty when not given), for RefuseSharedPaths.
std::vector<std::string> EvalInputPaths(const EvalFlags& flags);

/// Reads the reference and the estimates concurrently with the read options of each side (errors
/// are reported in argument order).
EvalInputs ReadEvalInputs(CLI::App* command, const EvalFlags& flags);

/// Registers the evaluation subcommand of `metric` (named by eval::ToString): the flags every
/// evaluation command has, the metric's own flags added by `add_flags`, and the action.
void RegisterEvalCommand(CLI::App& app, Action* action, eval::MetricKind metric, const std::string& description,
                         const std::function<void(CLI::App*, EvalFlags*)>& add_flags);

}  // namespace cheval::cli
