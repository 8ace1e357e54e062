// `cheval ase REF EST [EST2 ...]`: Absolute State Error on SE_2(3) (rotation, position, velocity), with
// the reference velocity from its columns or from its positions (C-ASE).
#include "eval_command.h"

namespace cheval::cli {

void RegisterAse(CLI::App& app, Action* action) {
  RegisterEvalCommand(
      app, action, eval::MetricKind::kAse,
      "Absolute state error on SE_2(3): rotation, position and velocity in one number (C-ASE)",
      [](CLI::App* command, EvalFlags* flags) {
        AddStateVelocityFlags(command, flags);
        command->add_flag(Flag("EvaluationOptions::pose_only"), flags->options.pose_only,
                          "Pose-only ASE (rotation + position) for estimates without velocity");
        command->add_flag_callback(
            "--ref-has-orientation",
            [flags] { flags->options.identity_reference_is_position_only = false; },
            "Take a reference whose orientations are all the identity as real orientations (by default it is "
            "position-only, as written for position-only sources, and the rotation part is left out)");
      });
}

}  // namespace cheval::cli
