// `cheval ape REF EST [EST2 ...]`: absolute pose error, evo_ape's numbers (docs/evaluation.md).
#include "eval_command.h"

namespace cheval::cli {

void RegisterApe(CLI::App& app, Action* action) {
  RegisterEvalCommand(app, action, eval::MetricKind::kApe,
                      "Absolute pose error of estimates against a reference (evo_ape's definitions and numbers)",
                      AddRelationFlag);
}

}  // namespace cheval::cli
