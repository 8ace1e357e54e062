#pragma once
// Shared pieces of the CLI faces: input-format options and the registration functions of the
// subcommands. The CLI holds no logic of its own: it parses flags and calls the library.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cheval/common/output.h"
#include "cheval/traj/io.h"
#include "option_names.h"

namespace cheval::cli {

/// Flags every command that reads a trajectory takes: --format, --columns, --kitti-times, and for
/// recordings --topic (several only for the estimates of an evaluation) and --bag-time.
struct InputFlags {
  std::string format = "auto";
  std::string columns;
  std::string kitti_times;
  std::vector<std::string> topics;
  bool bag_time = false;

  /// The library's options (traj::ReadOptions::FromNames, which validates the combination) with the
  /// first topic; UsageError for several topics.
  traj::ReadOptions ToReadOptions() const;
};

/// Adds the input flags to `command`; `prefix` allows e.g. --ref-format (empty for --format).
void AddInputFlags(CLI::App* command, InputFlags* flags, const std::string& prefix = "");

/// Stamps to evaluate at (`--at FILE`): a file of one stamp (seconds) per line, or any trajectory
/// file (its stamps). InputError with the stamps file's message when it is neither.
std::vector<int64_t> ReadQueryStamps(const std::string& path);

/// Refuses, before any work, an output that is one of the command's `inputs` or the same file as another
/// output: UsageError (exit 1) naming both (common/output.h, CheckOutputs; each output labelled with its
/// flag). Empty paths are options not given and are skipped.
void RefuseSharedPaths(const std::vector<std::string>& inputs, const std::vector<OutputPath>& outputs);

/// Gives every numeric option of `app` and its subcommands (recursively) a check of its text before
/// CLI11 converts it (CLI11 2.1 would accept "-1" for an unsigned option and wrap it, saturate
/// "99999999999999999999", read "010" as octal, and take "nan", "inf" and "1e400" for a double):
/// - integer options (CLI11 type INT / UINT): decimal digits with an optional sign ('-' only for INT),
///   within the range of a 64-bit integer (narrower types are range-checked by CLI11);
/// - floating-point options (FLOAT): a decimal number whose value is finite (no nan, no inf, no
///   overflow).
/// Anything else is a parse error naming the flag (exit 1): "--max-points: must be a whole number >= 0,
/// got -1". Called once by main after every subcommand is registered.
void CheckNumericOptions(CLI::App* app);

/// The action a subcommand registers; main runs it after parsing, inside its error mapping.
using Action = std::function<void()>;

void RegisterInfo(CLI::App& app, Action* action);
void RegisterConvert(CLI::App& app, Action* action);
void RegisterSim(CLI::App& app, Action* action);
void RegisterVelocity(CLI::App& app, Action* action);
void RegisterCompress(CLI::App& app, Action* action);
void RegisterSample(CLI::App& app, Action* action);
void RegisterApe(CLI::App& app, Action* action);
void RegisterRpe(CLI::App& app, Action* action);
void RegisterAse(CLI::App& app, Action* action);
/// `cheval report REF EST [EST2 ...] -o report.html` (tools/cheval/report.cc).
void RegisterReport(CLI::App& app, Action* action);
/// `cheval sim quadrotor` (needs RegisterSim first) and `cheval estimate quadrotor` (tools/cheval/quadrotor.cc).
void RegisterSimQuadrotor(CLI::App& app, Action* action);
void RegisterEstimate(CLI::App& app, Action* action);
/// `cheval estimate thrust` (needs RegisterEstimate first; tools/cheval/estimate_thrust.cc).
void RegisterEstimateThrust(CLI::App& app, Action* action);
/// `cheval table EXPERIMENT -o table.md` (tools/cheval/table.cc).
void RegisterTable(CLI::App& app, Action* action);

}  // namespace cheval::cli
namespace cheval::cli {
/// `cheval estimate rotors` (needs RegisterEstimate first) and `cheval identify rotors` (tools/cheval/rotors.cc).
void RegisterEstimateRotors(CLI::App& app, Action* action);
void RegisterIdentifyRotors(CLI::App& app, Action* action);
}  // namespace cheval::cli
namespace cheval::cli {
/// `cheval res FILE...` (tools/cheval/res.cc): evo_res's table of result files.
void RegisterRes(CLI::App& app, Action* action);
}  // namespace cheval::cli
