// `cheval info FILE...`: what is in a trajectory file, like `evo_traj --full_check`.
#include <algorithm>
#include <cstdio>

#include <vector>

#include <fmt/format.h>

#include "cheval/bag/bag.h"
#include "cheval/traj/stamp.h"
#include "cheval/traj/summary.h"
#include "common.h"

namespace cheval::cli {
namespace {

struct InfoFlags {
  std::vector<std::string> paths;
  InputFlags input;
  std::string json_path;
  bool full_check = false;  // evo_traj --full_check: accepted, every check always runs
};

void PrintSummary(const std::string& path, const std::string& format, const traj::TrajectorySummary& s) {
  auto line = [](std::string_view key, const std::string& value) { fmt::print("  {:<22}{}\n", key, value); };
  fmt::print("{} ({})\n", path, format);
  line("poses", fmt::format("{}", s.poses));
  if (s.has_stamps) {
    line("duration", fmt::format("{} s  ({} .. {})", traj::FormatSeconds(s.last_stamp_ns - s.first_stamp_ns),
                                 traj::FormatSeconds(s.first_stamp_ns), traj::FormatSeconds(s.last_stamp_ns)));
    line("rate", fmt::format("{:.3f} Hz mean; dt median {:.3f} ms, jitter (std) {:.3f} ms, min {:.3f} ms, max {:.3f} ms",
                             s.rate_hz, 1e3 * s.dt_s.median, 1e3 * s.dt_s.std, 1e3 * s.dt_s.min, 1e3 * s.dt_s.max));
    line("gaps (> 2x median dt)", s.gaps == 0 ? std::string("none")
                                              : fmt::format("{}, largest {:.3f} s after {}", s.gaps, s.largest_gap_s,
                                                            traj::FormatSeconds(s.largest_gap_after_ns)));
    line("stamps", s.non_increasing_stamps == 0 && s.duplicate_stamps == 0
                       ? std::string("strictly increasing")
                       : fmt::format("NOT strictly increasing: {} duplicate, {} non-increasing (kept in file order)",
                                     s.duplicate_stamps, s.non_increasing_stamps));
  } else {
    line("stamps", "none (KITTI without --kitti-times)");
  }
  line("path length", fmt::format("{:.3f} m", s.path_length_m));
  if (s.speed_mps.n > 0) {
    line(s.speed_from_velocity ? "speed (velocity cols)" : "speed (finite diff.)",
         fmt::format("mean {:.3f}, median {:.3f}, max {:.3f} m/s", s.speed_mps.mean, s.speed_mps.median,
                     s.speed_mps.max));
  }
  if (!s.has_orientation) {
    line("orientation", "none (position only)");
  } else if (s.max_orthonormality_error > 0) {
    line("orientation", fmt::format("rotation matrices, max |RᵀR - I| {:.2e} (used as read)",
                                    s.max_orthonormality_error));
  } else {
    line("orientation", fmt::format("quaternions, {} non-unit (|‖q‖-1| > {:g}; max {:.2e}), normalised on use",
                                    s.non_unit_quaternions, traj::kQuaternionNormTolerance,
                                    s.max_quaternion_norm_error));
  }
  line("velocity", s.has_velocity ? "yes (world frame)" : "no");
  line("angular velocity", s.has_angular_velocity ? "yes (body frame)" : "no");
}

// A recording without --topic: its topics.
void PrintTopics(const std::string& path, bag::Container container, const std::vector<bag::TopicInfo>& topics) {
  fmt::print("{} ({} recording, {} topics)\n", path, bag::ToString(container), topics.size());
  size_t width = 5;
  for (const bag::TopicInfo& t : topics) width = std::max(width, t.name.size());
  for (const bag::TopicInfo& t : topics) fmt::print("  {:<{}}  {:>8}  {} ({})\n", t.name, width, t.count, t.type, t.encoding);
}

}  // namespace

void RegisterInfo(CLI::App& app, Action* action) {
  auto flags = std::make_shared<InfoFlags>();
  CLI::App* command = app.add_subcommand("info", "Summarise trajectory files: poses, duration, rate, gaps, stamps, "
                                                 "path length, speed, quaternion norms");
  command->add_option("files", flags->paths, "Trajectory files")->required();
  AddInputFlags(command, &flags->input);
  command->add_option("--json", flags->json_path, "Also write the summary as JSON (an array for several files)");
  command->add_flag("--full-check,--full_check", flags->full_check,
                    "Accepted for evo_traj's --full_check: info always runs every check");
  command->callback([flags, action] {
    *action = [flags] {
      std::vector<std::string> inputs = flags->paths;
      inputs.push_back(flags->input.kitti_times);
      RefuseSharedPaths(inputs, {{"--json", flags->json_path}});
      const traj::ReadOptions options = flags->input.ToReadOptions();
      std::vector<traj::FileSummary> all;
      for (const std::string& path : flags->paths) {
        const bag::Container container = bag::DetectContainer(path);
        if (container != bag::Container::kNone && options.topic.empty()) {
          PrintTopics(path, container, bag::ListTopics(path));
          continue;
        }
        traj::FileSummary& file = all.emplace_back(traj::FileSummary{path, options.format, {}});
        const traj::Trajectory trajectory = traj::ReadTrajectory(path, options, &file.format);
        file.summary = traj::Summarize(trajectory.View());
        PrintSummary(path,
                     container == bag::Container::kNone
                         ? std::string(traj::ToString(file.format))
                         : fmt::format("{} recording, topic {}", bag::ToString(container), options.topic),
                     file.summary);
      }
      if (!flags->json_path.empty()) WriteOutput(flags->json_path, traj::SummaryJson(all));
    };
  });
}

}  // namespace cheval::cli
