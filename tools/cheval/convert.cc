// `cheval convert IN -o OUT [--to tum|tumv|euroc|kitti]`: rewrite a trajectory in another format.
#include <fmt/format.h>

#include <vector>

#include "cheval/common/error.h"
#include "cheval/traj/stamp.h"
#include "common.h"
#include "progress.h"

namespace cheval::cli {
namespace {

struct ConvertFlags {
  std::string input;
  std::string output;
  std::string to;
  std::string times_output;
  InputFlags format;
};

// Default output format when --to is not given: EuRoC for a .csv name, TUM otherwise.
traj::Format DefaultOutputFormat(const std::string& path) {
  const bool csv = path.size() >= 4 && path.compare(path.size() - 4, 4, ".csv") == 0;
  return csv ? traj::Format::kEuroc : traj::Format::kTum;
}

}  // namespace

void RegisterConvert(CLI::App& app, Action* action) {
  auto flags = std::make_shared<ConvertFlags>();
  CLI::App* command = app.add_subcommand("convert", "Convert a trajectory to another file format");
  command->add_option("input", flags->input, "Trajectory file to read")->required();
  command->add_option("-o,--output", flags->output, "File to write (written atomically)")->required();
  command->add_option("--to", flags->to, "Output format (default: euroc for *.csv, else tum)")
      ->check(CLI::IsMember({"tum", "tumv", "euroc", "kitti"}));
  command->add_option("--times-output", flags->times_output,
                      "With --to kitti: also write the stamps (seconds, one per line) to this file");
  AddInputFlags(command, &flags->format);
  command->callback([flags, action] {
    *action = [flags] {
      const traj::Format to = flags->to.empty() ? DefaultOutputFormat(flags->output)
                                                : *traj::FormatFromString(flags->to);
      if (!flags->times_output.empty() && to != traj::Format::kKitti) {
        throw UsageError("--times-output is only for --to kitti");
      }
      RefuseSharedPaths({flags->input, flags->format.kitti_times},
                        {{"-o", flags->output}, {"--times-output", flags->times_output}});
      const traj::Trajectory trajectory = traj::ReadTrajectory(flags->input, flags->format.ToReadOptions());
      std::string times;
      if (!flags->times_output.empty()) {
        if (!trajectory.channels().has_stamps) throw ComputeError("--times-output: the input has no stamps");
        for (int64_t stamp : trajectory.stamps_ns()) times += traj::FormatSeconds(stamp) + "\n";
      }
      // Formatted a block at a time as it is written; a file is replaced only when whole, and
      // FormatTrajectory checks everything before its first block, so an error leaves no file behind.
      std::vector<OutputFile> files{{flags->output, [&](const TextSink& sink) {
                                       traj::FormatTrajectory(trajectory.View(), to, sink);
                                     }}};
      if (!times.empty()) files.push_back({flags->times_output, times});
      WriteOutputs(files);
      if (!Quiet()) fmt::print(stderr, "wrote {} poses to {} ({})\n", trajectory.size(), flags->output, traj::ToString(to));
    };
  });
}

}  // namespace cheval::cli
