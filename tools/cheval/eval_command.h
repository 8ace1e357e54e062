#pragma once
// What `cheval ape`, `cheval rpe` and `cheval ase` share: the reference/estimate arguments, the input,
// association, alignment and output flags, and the action (read, eval::Evaluate each estimate, print
// evo's table, a comparison table for several estimates, --json, --errors). Each command's own file
// adds its metric's flags.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "cheval/eval/evaluate.h"
#include "common.h"

namespace cheval::cli {

/// Flags of the evaluation commands (the metric-specific ones are set by ape.cc, rpe.cc, ase.cc).
struct EvalFlags {
  std::string reference;
  std::vector<std::string> estimates;
  InputFlags both, ref, est;
  std::string align = "none";
  int64_t n_align = 0;
  double t_max_diff = 0.01;
  double t_offset = 0.0;
  std::string association = "nearest";
  std::string relation = "trans_part";
  double delta = 1.0;
  std::string delta_unit = "frames";
  bool all_pairs = false;
  bool kitti_drift = false;
  std::string gt_velocity = "auto";
  std::string velocity_frame = "world";
  bool pose_only = false;
  std::string json_path;
  std::string errors_path;
};

/// Adds `-r,--relation` (APE and RPE).
void AddRelationFlag(CLI::App* command, EvalFlags* flags);

/// Adds the arguments and flags every evaluation command takes (also `cheval report`): the reference
/// and estimate files, the input flags for both and per side, --align (its default is the current
/// value of flags->align), --n-align, --t-max-diff, --t-offset, --association.
void AddEvalInputFlags(CLI::App* command, EvalFlags* flags);

/// Adds the ASE's velocity flags --gt-velocity and --velocity-frame.
void AddStateVelocityFlags(CLI::App* command, EvalFlags* flags);

/// The library options of an evaluation of `metric` from the flags; UsageError on a bad combination.
eval::EvaluationOptions ToEvaluationOptions(eval::MetricKind metric, const EvalFlags& flags);

/// The files of an evaluation, read.
struct EvalInputs {
  traj::Trajectory reference;
  std::vector<traj::Trajectory> estimates;
};

/// Reads the reference and the estimates concurrently with the read options of each side (errors
/// are reported in argument order).
EvalInputs ReadEvalInputs(CLI::App* command, const EvalFlags& flags);

/// Registers the evaluation subcommand of `metric` (named by eval::ToString): the flags every
/// evaluation command has, the metric's own flags added by `add_flags`, and the action.
void RegisterEvalCommand(CLI::App& app, Action* action, eval::MetricKind metric, const std::string& description,
                         const std::function<void(CLI::App*, EvalFlags*)>& add_flags);

}  // namespace cheval::cli
