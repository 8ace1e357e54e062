// `cheval rpe REF EST [EST2 ...]`: relative pose error, evo_rpe's numbers, and KITTI-style drift.
#include "eval_command.h"

namespace cheval::cli {

void RegisterRpe(CLI::App& app, Action* action) {
  RegisterEvalCommand(
      app, action, eval::MetricKind::kRpe,
      "Relative pose error of estimates against a reference (evo_rpe's definitions and numbers)",
      [](CLI::App* command, EvalFlags* flags) {
        AddRelationFlag(command, flags);
        command->add_option(Names("RpeOptions::delta", "", "-d"), flags->options.rpe.delta,
                            "Distance between the poses of a pair, in --delta-unit")
            ->capture_default_str();
        command->add_option(Names("RpeOptions::delta_unit", "", "-u"), flags->delta_unit,
                            "Unit of --delta (or evo's letters f, m, d, r)")
            ->check(CLI::IsMember({"frames", "meters", "degrees", "radians", "f", "m", "d", "r"}))
            ->capture_default_str();
        command->add_flag(Names("RpeOptions::all_pairs"), flags->options.rpe.all_pairs,
                          "Overlapping pairs from every pose instead of consecutive ones");
        command->add_flag(Flag("EvaluationOptions::kitti_drift"), flags->options.kitti_drift,
                          "Also the KITTI odometry drift: mean translation % and rotation deg/m over 100..800 m");
      });
}

}  // namespace cheval::cli
