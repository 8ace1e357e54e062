#pragma once
/// \file
/// What a trajectory's values must satisfy, in one place for every way a trajectory comes in: the
/// file readers (traj/io.h) and the array constructor of the Python face check with these functions
/// and say the same words, a reader naming `line N` of a file and the arrays `row N`. The writers
/// refuse what the readers would refuse, so a written file always reads back.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "cheval/traj/trajectory.h"

namespace cheval::traj {

/// Characters of a quoted field shown in a message before it is cut with "…".
inline constexpr size_t kQuotedFieldLength = 40;

/// `text` (bytes read from a file, or a value given by a caller) as every message quotes it: in
/// single quotes, at most `max_length` characters then "…", with what could garble a terminal
/// or hide in it escaped: `\0`, `\t`, `\n`, `\r`, `\\`, `\'`, other control bytes and bytes that are
/// not UTF-8 as `\xNN`, and the invisible or reordering code points (C1 controls, U+200B..U+200F,
/// U+2028..U+202E, U+2066..U+2069, the byte-order mark U+FEFF) as `\u{NNNN}`. Printable UTF-8 is
/// kept as it is.
std::string QuoteField(std::string_view text, size_t max_length = kQuotedFieldLength);

/// "NAME is VALUE; expected a finite number" (with ", too large for a double ..." when the text of a
/// finite-looking decimal overflowed): a NaN or infinite value.
std::string NotFiniteMessage(std::string_view name, std::string_view value, bool too_large = false);

/// "time stamp VALUE in NAME is out of range (int64 nanoseconds, about ±292 years)".
std::string StampOutOfRangeMessage(std::string_view value, std::string_view name);

/// What is wrong with the quaternion (x, y, z, w) as a rotation, or nullopt: a (near) zero norm
/// (below evo's 8.88e-16 for q·q, which it turns into the identity) or a squared norm that overflows a
/// double (its rotation would silently be the identity). `names` names the four values in messages.
std::optional<std::string> QuaternionProblem(double x, double y, double z, double w, std::string_view names);

/// The smallest and largest stamp seen so far, to refuse a trajectory whose stamps span more than
/// int64 nanoseconds (about 292 years): each stamp may be valid alone (±292 years around 1970), but
/// a difference of two of them would overflow, and every duration, rate and fit uses differences.
/// Once a trajectory passes, every difference of two of its stamps fits int64.
class StampSpan {
 public:
  /// Adds the stamp of `row` (a line number or an array row; `unit` is "line" or "row"). Returns the
  /// message when its distance to an earlier stamp does not fit int64 nanoseconds.
  std::optional<std::string> Add(int64_t stamp_ns, int64_t row, std::string_view unit);

 private:
  bool empty_ = true;
  int64_t min_ = 0, max_ = 0;
  int64_t min_row_ = 0, max_row_ = 0;
};

/// A problem of one pose of a trajectory: its index (0-based) and what is wrong, in the readers' words.
struct PoseProblem {
  int64_t row = 0;
  std::string what;
};

/// The first pose of `trajectory` that a reader would refuse in a file, or nullopt: a NaN or infinite
/// position, orientation, velocity or angular velocity, a quaternion that is no rotation
/// (QuaternionProblem), or stamps whose span does not fit int64 nanoseconds (StampSpan). A rotation
/// matrix (KITTI) is checked for finite values. Values are named as the arrays of the Python face
/// (`positions[3, 0] (x)`).
std::optional<PoseProblem> FindPoseProblem(const TrajectoryView& trajectory);

/// Throws InputError(`source`, 0, 0, "row N: ...") for the first problem FindPoseProblem finds (a
/// trajectory built from arrays, which has no lines).
void ValidatePoses(const TrajectoryView& trajectory, const std::string& source);

}  // namespace cheval::traj
