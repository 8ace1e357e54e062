// Trajectory writers and atomic file output.
#include <algorithm>
#include <future>
#include <span>
#include <system_error>
#include <thread>
#include <vector>

#include <fmt/compile.h>
#include <fmt/format.h>

#include "cheval/common/error.h"
#include "cheval/common/output.h"
#include "cheval/traj/io.h"
#include "cheval/traj/stamp.h"
#include "cheval/traj/validate.h"

namespace cheval::traj {
namespace {

// The orientation of pose i as (x, y, z, w): the stored values as read, or the matrix's.
Eigen::Vector4d QuaternionAsStored(const TrajectoryView& trajectory, Eigen::Index i) {
  if (trajectory.channels().orientation == OrientationKind::kQuaternion) return trajectory.quaternions().col(i);
  return trajectory.UnitQuaternion(i).coeffs();
}

// FormatSeconds(stamp_ns) appended to `out` without a temporary string (the writers' hot loop).
void AppendSeconds(std::string& out, int64_t stamp_ns) {
  const bool negative = stamp_ns < 0;
  const uint64_t magnitude = negative ? (~static_cast<uint64_t>(stamp_ns) + 1) : static_cast<uint64_t>(stamp_ns);
  fmt::format_to(std::back_inserter(out), FMT_COMPILE("{}{}.{:09}"), negative ? "-" : "", magnitude / 1'000'000'000ULL,
                 magnitude % 1'000'000'000ULL);
}

void RequireOrientation(const TrajectoryView& trajectory, Format format) {
  if (!trajectory.has_orientation()) {
    throw ComputeError(fmt::format("cannot write {}: the trajectory has no orientation (position only)",
                                   ToString(format)));
  }
}

// Throws what FormatTrajectory documents for a trajectory that `format` cannot hold or that would not
// read back, before any text is made.
void CheckWritable(const TrajectoryView& trajectory, Format format) {
  // Only what the readers read back: a file with a NaN, a zero quaternion, stamps beyond int64's
  // span or no pose at all would be refused by ReadTrajectory, so it is not written.
  if (trajectory.empty()) {
    throw ComputeError(fmt::format("cannot write {}: the trajectory has no poses (a file without poses does not read back)",
                                   ToString(format)));
  }
  if (const auto problem = FindPoseProblem(trajectory)) {
    throw ComputeError(fmt::format("cannot write {}: row {}: {} (the file would not read back)", ToString(format),
                                   problem->row, problem->what));
  }
  switch (format) {
    case Format::kTum:
    case Format::kEuroc:
    case Format::kKitti:
      RequireOrientation(trajectory, format);
      return;
    case Format::kTumV:
      RequireOrientation(trajectory, format);
      if (!trajectory.has_velocity()) {
        throw ComputeError("cannot write tumv: the trajectory has no velocity (use `cheval velocity` to add it)");
      }
      return;
    default:
      throw UsageError(fmt::format("cannot write format '{}'; expected tum, tumv, euroc or kitti", ToString(format)));
  }
}

// Appends the lines of rows [begin, end) to `out` (EuRoC's header before row 0); CheckWritable first.
void AppendRows(const TrajectoryView& trajectory, Format format, Eigen::Index begin, Eigen::Index end,
                std::string& out) {
  auto it = std::back_inserter(out);
  const auto p = trajectory.positions();
  switch (format) {
    case Format::kTum:
    case Format::kTumV:
      for (Eigen::Index i = begin; i < end; ++i) {
        const Eigen::Vector4d q = QuaternionAsStored(trajectory, i);
        // Compiled format strings: parsing "{}" at run time per value cost as much as the digits.
        AppendSeconds(out, trajectory.stamps_ns()[i]);
        fmt::format_to(it, FMT_COMPILE(" {} {} {} {} {} {} {}"), p(0, i), p(1, i), p(2, i), q[0], q[1], q[2], q[3]);
        if (format == Format::kTumV) {
          const auto v = trajectory.velocities().col(i);
          fmt::format_to(it, FMT_COMPILE(" {} {} {}"), v[0], v[1], v[2]);
          if (trajectory.has_angular_velocity()) {
            const auto w = trajectory.angular_velocities().col(i);
            fmt::format_to(it, FMT_COMPILE(" {} {} {}"), w[0], w[1], w[2]);
          }
        }
        out.push_back('\n');
      }
      return;
    case Format::kEuroc:
      if (begin == 0) {
        fmt::format_to(it, "#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],"
                           "q_RS_z []");
        if (trajectory.has_velocity()) {
          fmt::format_to(it, ",v_RS_R_x [m s^-1],v_RS_R_y [m s^-1],v_RS_R_z [m s^-1]");
        }
        out.push_back('\n');
      }
      for (Eigen::Index i = begin; i < end; ++i) {
        const Eigen::Vector4d q = QuaternionAsStored(trajectory, i);
        fmt::format_to(it, FMT_COMPILE("{},{},{},{},{},{},{},{}"), trajectory.stamps_ns()[i], p(0, i), p(1, i), p(2, i), q[3],
                       q[0], q[1], q[2]);
        if (trajectory.has_velocity()) {
          const auto v = trajectory.velocities().col(i);
          fmt::format_to(it, FMT_COMPILE(",{},{},{}"), v[0], v[1], v[2]);
        }
        out.push_back('\n');
      }
      return;
    case Format::kKitti:
      for (Eigen::Index i = begin; i < end; ++i) {
        const Eigen::Matrix3d R = trajectory.Rotation(i);
        fmt::format_to(it, FMT_COMPILE("{} {} {} {} {} {} {} {} {} {} {} {}\n"), R(0, 0), R(0, 1), R(0, 2), p(0, i), R(1, 0),
                       R(1, 1), R(1, 2), p(1, i), R(2, 0), R(2, 1), R(2, 2), p(2, i));
      }
      return;
    default:
      return;  // refused by CheckWritable
  }
}

// The longest line of `trajectory` in any format: a shortest round-trip double has at most 24
// characters, a stamp at most 21.
size_t LongestLine(const TrajectoryView& trajectory) {
  const size_t values = 1 + 12 + (trajectory.has_velocity() ? 3 : 0) + (trajectory.has_angular_velocity() ? 3 : 0);
  return values * 25;
}

}  // namespace

void FormatTrajectory(const TrajectoryView& trajectory, Format format,
                      const std::function<void(std::string_view)>& sink) {
  CheckWritable(trajectory, format);
  // Rows are formatted into blocks of about kBlockBytes, reused, and handed over block by block in
  // order. With a second core, a worker formats every other block while the caller formats and
  // hands over the one before it: the digits are most of a large output's time.
  constexpr size_t kBlockBytes = size_t{1} << 20;
  const Eigen::Index n = trajectory.size();
  const Eigen::Index rows = static_cast<Eigen::Index>(std::max<size_t>(1, kBlockBytes / LongestLine(trajectory)));
  const size_t reserve = static_cast<size_t>(rows) * LongestLine(trajectory) + 256;
  std::string block, next;
  block.reserve(reserve);
  const bool paired = n > rows && std::thread::hardware_concurrency() > 1;
  if (paired) next.reserve(reserve);
  for (Eigen::Index begin = 0; begin < n; begin += paired ? 2 * rows : rows) {
    const Eigen::Index middle = std::min(n, begin + rows), end = std::min(n, middle + rows);
    const bool second = paired && middle < end;
    auto format_second = [&, middle, end] {
      next.clear();
      AppendRows(trajectory, format, middle, end, next);
    };
    // Declared after the blocks: its destructor waits for the worker before they go.
    std::future<void> worker;
    if (second) {
      try {
        worker = std::async(std::launch::async, format_second);
      } catch (const std::system_error&) {  // no thread to be had: the caller formats it below
      }
    }
    block.clear();
    AppendRows(trajectory, format, begin, middle, block);
    sink(block);
    if (worker.valid()) {
      worker.get();
    } else if (second) {
      format_second();
    }
    if (second) sink(next);
  }
}

std::string FormatTrajectory(const TrajectoryView& trajectory, Format format) {
  CheckWritable(trajectory, format);
  // Formatted straight into the string that is returned, reserved once for the longest possible
  // lines so that it is never regrown: each regrowth copies the text.
  std::string out;
  out.reserve(static_cast<size_t>(trajectory.size()) * LongestLine(trajectory) + 256);
  AppendRows(trajectory, format, 0, trajectory.size(), out);
  return out;
}

void WriteTrajectory(const std::string& path, const TrajectoryView& trajectory, Format format) {
  if (path.find('\0') != std::string::npos) {
    throw UsageError(fmt::format("{}: the file name contains a NUL byte (\\0); expected a path", QuoteField(path, std::string::npos)));
  }
  const OutputFile file{path, [&](const TextSink& sink) { FormatTrajectory(trajectory, format, sink); }};
  WriteOutputs(std::span<const OutputFile>(&file, 1));
}

}  // namespace cheval::traj
