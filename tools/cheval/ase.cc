// `cheval ase REF EST [EST2 ...]`: Absolute State Error on SE_2(3) (rotation, position, velocity), with
// the reference velocity from its columns or from its positions (C-ASE).
#include "eval_command.h"

namespace cheval::cli {

void RegisterAse(CLI::App& app, Action* action) {
  RegisterEvalCommand(
      app, action, eval::MetricKind::kAse,
      "Absolute state error on SE_2(3): rotation, position and velocity in one number (C-ASE)",
      [](CLI::App* command, EvalFlags* flags) {
        command->add_option("--gt-velocity", flags->gt_velocity,
                            "Reference velocity: given (its columns), chebyshev or central (from its positions); "
                            "auto = given if present, else chebyshev")
            ->check(CLI::IsMember({"auto", "given", "chebyshev", "central"}))
            ->capture_default_str();
        command->add_option("--velocity-frame", flags->velocity_frame,
                            "Frame of the estimate's velocity columns; body is rotated by the estimate's orientation")
            ->check(CLI::IsMember({"world", "body"}))
            ->capture_default_str();
        command->add_flag("--pose-only", flags->pose_only,
                          "Pose-only ASE (rotation + position) for estimates without velocity");
      });
}

}  // namespace cheval::cli
