#include "common.h"

#include <fmt/format.h>

#include "cheval/common/error.h"

namespace cheval::cli {

void AddInputFlags(CLI::App* command, InputFlags* flags, const std::string& prefix) {
  command
      ->add_option(Flag("ReadOptions::format", prefix), flags->format,
                   "Input format; auto decides by extension and content")
      ->check(CLI::IsMember({"auto", "tum", "tumv", "euroc", "kitti", "vins", "csv"}))
      ->capture_default_str();
  command->add_option(Flag("ReadOptions::columns", prefix), flags->columns,
                      "Column map for --format csv, e.g. t_ns,px,py,pz,qw,qx,qy,qz,vx,vy,vz (_ skips a column)");
  command->add_option(Flag("ReadOptions::kitti_times_path", prefix), flags->kitti_times,
                      "KITTI: file with one stamp (seconds) per pose");
  command->add_option(Flag("ReadOptions::topic", prefix), flags->topics,
                      "Recordings (ROS 1/2 bag, MCAP): the topic, or /tf:PARENT.CHILD for a tf chain (docs/bags.md)");
  command->add_flag(Flag("ReadOptions::record_time", prefix), flags->bag_time,
                    "Recordings: stamps from the record (log) time instead of the message headers");
}

traj::ReadOptions InputFlags::ToReadOptions() const {
  if (topics.size() > 1) {
    throw UsageError(fmt::format("{} given {} times; only the estimates of ape/rpe/ase/report take several",
                                 Flag("ReadOptions::topic"), topics.size()));
  }
  traj::ReadOptions options = traj::ReadOptions::FromNames(format, columns, kitti_times);
  if (!topics.empty()) options.topic = topics.front();
  options.record_time = bag_time;
  return options;
}

std::vector<int64_t> ReadQueryStamps(const std::string& path) {
  try {
    return traj::ReadStampsFile(path);
  } catch (const InputError& as_stamps) {
    try {
      const traj::Trajectory trajectory = traj::ReadTrajectory(path);
      return {trajectory.stamps_ns().begin(), trajectory.stamps_ns().end()};
    } catch (const InputError&) {
      throw as_stamps;  // report the simpler expectation
    }
  }
}

void RefuseSharedPaths(const std::vector<std::string>& inputs, const std::vector<OutputPath>& outputs) {
  CheckOutputs(inputs, outputs);
}

}  // namespace cheval::cli
