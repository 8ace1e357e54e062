#pragma once
// Shared pieces of the CLI faces: input-format options and the registration functions of the
// subcommands. The CLI holds no logic of its own: it parses flags and calls the library.

#include <functional>
#include <string>

#include <CLI/CLI.hpp>

#include "cheval/traj/io.h"

namespace cheval::cli {

/// Flags every command that reads a trajectory takes: --format, --columns, --kitti-times.
struct InputFlags {
  std::string format = "auto";
  std::string columns;
  std::string kitti_times;

  /// Validates the combination and converts to library options (UsageError on a bad combination).
  traj::ReadOptions ToReadOptions() const;
};

/// Adds the input flags to `command`; `prefix` allows e.g. --ref-format (empty for --format).
void AddInputFlags(CLI::App* command, InputFlags* flags, const std::string& prefix = "");

/// The action a subcommand registers; main runs it after parsing, inside its error mapping.
using Action = std::function<void()>;

void RegisterInfo(CLI::App& app, Action* action);
void RegisterConvert(CLI::App& app, Action* action);
void RegisterSim(CLI::App& app, Action* action);
void RegisterVelocity(CLI::App& app, Action* action);
void RegisterApe(CLI::App& app, Action* action);
void RegisterRpe(CLI::App& app, Action* action);
void RegisterAse(CLI::App& app, Action* action);

}  // namespace cheval::cli
