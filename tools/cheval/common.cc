#include "common.h"

#include <fmt/format.h>

#include "cheval/common/error.h"

namespace cheval::cli {

traj::ReadOptions InputFlags::ToReadOptions() const {
  traj::ReadOptions options;
  const auto parsed = traj::FormatFromString(format);
  if (!parsed) throw UsageError(fmt::format("--format: unknown format '{}'", format));
  options.format = *parsed;
  if (!columns.empty()) {
    if (options.format != traj::Format::kCsv && options.format != traj::Format::kAuto) {
      throw UsageError(fmt::format("--columns is only for --format csv (got --format {})", format));
    }
    options.format = traj::Format::kCsv;  // a column map implies the generic format
    options.columns = traj::ColumnMap::Parse(columns);
  } else if (options.format == traj::Format::kCsv) {
    throw UsageError("--format csv needs --columns (e.g. --columns t,px,py,pz,qx,qy,qz,qw)");
  }
  if (!kitti_times.empty() && options.format != traj::Format::kKitti && options.format != traj::Format::kAuto) {
    throw UsageError("--kitti-times is only for KITTI files");
  }
  options.kitti_times_path = kitti_times;
  return options;
}

void AddInputFlags(CLI::App* command, InputFlags* flags, const std::string& prefix) {
  command
      ->add_option("--" + prefix + "format", flags->format,
                   "Input format; auto decides by extension and content")
      ->check(CLI::IsMember({"auto", "tum", "tumv", "euroc", "kitti", "vins", "csv"}))
      ->capture_default_str();
  command->add_option("--" + prefix + "columns", flags->columns,
                      "Column map for --format csv, e.g. t_ns,px,py,pz,qw,qx,qy,qz,vx,vy,vz (_ skips a column)");
  command->add_option("--" + prefix + "kitti-times", flags->kitti_times,
                      "KITTI: file with one stamp (seconds) per pose");
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

}  // namespace cheval::cli
