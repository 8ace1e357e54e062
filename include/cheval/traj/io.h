#pragma once
/// \file
/// Reading and writing trajectory files. Formats (docs/formats.md has the full reference):
///
/// | Format | Layout of a row                                        | Separator | Stamps        |
/// |--------|--------------------------------------------------------|-----------|---------------|
/// | tum    | t x y z qx qy qz qw                                     | spaces    | seconds       |
/// | tumv   | t x y z qx qy qz qw vx vy vz                            | spaces    | seconds       |
/// | euroc  | t p(3) q(w x y z) [v(3) [bw(3) ba(3)]], `#` header      | commas    | nanoseconds   |
/// | kitti  | r00 r01 r02 tx r10 r11 r12 ty r20 r21 r22 tz            | spaces    | times file or none |
/// | vins   | t p(3) q(w x y z) [v(3)], trailing comma allowed         | commas    | nanoseconds   |
/// | csv    | any, described by a ColumnMap (`--columns`)             | either    | as mapped     |
///
/// Lines starting with `#` are comments; blank lines are skipped; one header row of names (no
/// number in it) is skipped. Quaternions are stored as read and normalised when a rotation is
/// formed, as evo does; a quaternion of (near) zero norm is an error. Stamps are kept in file order,
/// duplicates included (evo keeps them too). Every problem throws cheval::InputError with
/// `path:line:column`.

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cheval/traj/trajectory.h"

namespace cheval::traj {

/// Trajectory file formats. kAuto decides from the extension and the content.
enum class Format { kAuto, kTum, kTumV, kEuroc, kKitti, kVins, kCsv };

/// Lower-case name of a format ("auto", "tum", "tumv", "euroc", "kitti", "vins", "csv").
std::string_view ToString(Format format);
/// Parses a format name; nullopt if unknown.
std::optional<Format> FormatFromString(std::string_view name);

/// What one column of a generic CSV/whitespace file holds.
enum class ColumnRole {
  kSkip,
  kTimeSeconds, kTimeMilliseconds, kTimeMicroseconds, kTimeNanoseconds,
  kPx, kPy, kPz,
  kQx, kQy, kQz, kQw,
  kRoll, kPitch, kYaw,  ///< radians; R = Rz(yaw)·Ry(pitch)·Rx(roll)
  kVx, kVy, kVz,        ///< world frame, m/s
  kWx, kWy, kWz,        ///< body frame, rad/s
};

/// A column map for the generic `csv` format: the role of each column, left to right; columns
/// after the last one listed are ignored. Written as a comma-separated list of role names:
/// `t` (seconds), `t_ms`, `t_us`, `t_ns`, `px py pz`, `qx qy qz qw`, `roll pitch yaw`, `vx vy vz`,
/// `wx wy wz`, and `_` (or `skip`) for a column to ignore, e.g. `t_ns,px,py,pz,qw,qx,qy,qz`.
struct ColumnMap {
  std::vector<ColumnRole> roles;

  /// Parses and validates a map: exactly one time column; px, py, pz; either none or all of qx..qw,
  /// either none or all of roll/pitch/yaw (not both); none or all of vx..vz and of wx..wz; no role
  /// twice. Throws UsageError naming the problem.
  static ColumnMap Parse(std::string_view spec);
  /// The map written back as a spec string.
  std::string ToString() const;
};

/// Options of ReadTrajectory.
struct ReadOptions {
  Format format = Format::kAuto;
  /// Required for Format::kCsv; ignored otherwise.
  std::optional<ColumnMap> columns;
  /// KITTI only: a file with one stamp (seconds) per pose. Without it, KITTI poses have no stamps.
  std::string kitti_times_path;
  /// Recordings (ROS 1 bags, ROS 2 bag folders, MCAP; recognised by their magic bytes whatever the
  /// format, docs/bags.md): the topic to read, e.g. `groundtruth` or `/tf:odom.base_link`. Required
  /// for a recording, refused for a text file.
  std::string topic;
  /// Recordings: stamps from the recorder's log time instead of the message headers.
  bool record_time = false;

  /// The options from the names the faces take: `format` a Format name ("auto", "tum", ...), `columns`
  /// a column map spec (ColumnMap::Parse; implies csv; empty for none), `kitti_times_path` as the
  /// field. Throws OptionError naming ReadOptions::format for an unknown format or csv without a
  /// column map, ReadOptions::columns for a map with a format other than csv or auto,
  /// ReadOptions::kitti_times_path for times with a format other than kitti or auto; UsageError from
  /// ColumnMap::Parse.
  static ReadOptions FromNames(std::string_view format, std::string_view columns, std::string kitti_times_path);
};

/// Decides the format of a file from its name and content (the text, not a path): `#timestamp`
/// header with commas -> euroc; comma-separated integer nanosecond stamps with 8 or 11 values ->
/// vins; whitespace-separated rows of 8 -> tum, 11 -> tumv, 12 -> kitti. Throws InputError
/// explaining what was seen when no format fits (suggesting format csv with a column map).
Format DetectFormat(const std::string& path, std::string_view content);

/// Default largest input file the readers accept, 8 GiB (see MaxInputFileBytes).
inline constexpr uint64_t kMaxInputFileBytes = uint64_t{8} << 30;
/// Longest line of an input file, 1 MiB: a line with no newline within it (a binary file, a device)
/// is refused as soon as that much of it has been read.
inline constexpr size_t kMaxInputLineBytes = size_t{1} << 20;

/// The largest input file the readers accept: the smaller of kMaxInputFileBytes and half the
/// machine's physical memory (the poses read take up to about twice the file's size).
uint64_t MaxInputFileBytes();

/// Reads a trajectory file. Throws InputError (`path:line:column: error: ...`) on any problem:
/// missing or unreadable file, empty file, wrong field count, non-number, NaN/Inf, truncated last
/// line, zero-norm quaternion (or one whose squared norm overflows), a non-rotation KITTI matrix
/// (determinant or R·Rᵀ off from 1 / I by more than 0.1), a KITTI times file of another length,
/// stamps spanning more than int64 nanoseconds (traj/validate.h, StampSpan), a file larger than
/// MaxInputFileBytes(), a line longer than kMaxInputLineBytes, a NUL byte, a path containing a NUL
/// byte, and a file that does not fit in the memory left (std::bad_alloc while reading). The input is
/// read in blocks of 1 MiB, each checked as it arrives, so a FIFO or device is never read without bound,
/// and only the lines not parsed yet are held, never the whole text.
/// If `format_read` is given, it receives the format used (the detected one for kAuto).
Trajectory ReadTrajectory(const std::string& path, const ReadOptions& options = {}, Format* format_read = nullptr);

/// Parses trajectory text already in memory; `path` is used in messages and for detection.
Trajectory ParseTrajectory(std::string_view content, const std::string& path, const ReadOptions& options = {},
                           Format* format_read = nullptr);

/// Reads a file of one stamp per line (seconds, e.g. a KITTI times file); InputError on problems
/// (the same limits as ReadTrajectory).
std::vector<int64_t> ReadStampsFile(const std::string& path);

/// The text of `trajectory` in `format` (kTum, kTumV, kEuroc or kKitti). Numbers are written in the
/// shortest form that reads back to the same double; stamps as seconds with nine decimals (TUM) or
/// integer nanoseconds (EuRoC). Quaternions are written as read. Throws ComputeError if the
/// trajectory lacks what the format needs (orientation; velocity for tumv) or holds what the readers
/// would refuse (no pose, FindPoseProblem of traj/validate.h: NaN, zero quaternion, stamp span), so
/// that whatever is written reads back; UsageError for a format that cannot be written.
std::string FormatTrajectory(const TrajectoryView& trajectory, Format format);

/// FormatTrajectory's text handed to `sink` a block of about 1 MiB at a time, for an output too large
/// to hold whole (OutputFile::write). Every check is made, and throws, before the first block. The
/// blocks come in order on the caller's thread; with a second core, a worker thread formats the next
/// one meanwhile, so `sink` must not change the trajectory. What `sink` throws ends the call.
void FormatTrajectory(const TrajectoryView& trajectory, Format format,
                      const std::function<void(std::string_view)>& sink);

/// Writes FormatTrajectory() to `path`, a block at a time, atomically: a temporary file beside it is written, flushed
/// and renamed, so a failure leaves no partial file. `-`, a FIFO or a device is written in place and a
/// symlink's target is replaced (cheval/common/output.h, WriteOutputs). Throws OutputError.
void WriteTrajectory(const std::string& path, const TrajectoryView& trajectory, Format format);

}  // namespace cheval::traj
