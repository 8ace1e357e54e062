// The checks and messages shared by the trajectory readers and the array constructors.
#include "cheval/traj/validate.h"

#include <cmath>
#include <cstdlib>

#include <fmt/format.h>

#include "cheval/common/error.h"
#include "cheval/traj/stamp.h"

namespace cheval::traj {
namespace {

// n = q·q below this is a zero quaternion (evo's threshold for "identity", 4·machine epsilon).
constexpr double kZeroQuaternionNormSquared = 8.881784197001252e-16;

// The code point of the UTF-8 sequence at text[i] and its length, or length 0 when the bytes there
// are not UTF-8 (a stray continuation byte, a truncated, overlong or surrogate sequence).
std::pair<char32_t, size_t> DecodeUtf8(std::string_view text, size_t i) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char lead = byte(i);
  size_t length = 0;
  char32_t code = 0, minimum = 0;
  if (lead >= 0xC2 && lead <= 0xDF) length = 2, code = lead & 0x1F, minimum = 0x80;
  else if (lead >= 0xE0 && lead <= 0xEF) length = 3, code = lead & 0x0F, minimum = 0x800;
  else if (lead >= 0xF0 && lead <= 0xF4) length = 4, code = lead & 0x07, minimum = 0x10000;
  else return {0, 0};
  if (i + length > text.size()) return {0, 0};
  for (size_t k = 1; k < length; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return {0, 0};
    code = (code << 6) | (byte(i + k) & 0x3F);
  }
  if (code < minimum || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return {0, 0};
  return {code, length};
}

// Code points that are invisible or reorder text on a terminal.
bool IsHidden(char32_t code) {
  return (code >= 0x80 && code <= 0x9F) || (code >= 0x200B && code <= 0x200F) ||
         (code >= 0x2028 && code <= 0x202E) || (code >= 0x2066 && code <= 0x2069) || code == 0xFEFF;
}

}  // namespace

std::string QuoteField(std::string_view text, size_t max_length) {
  std::string out = "'";
  size_t shown = 0;
  for (size_t i = 0; i < text.size(); ++shown) {
    if (shown == max_length) {
      out += "'…";
      return out;
    }
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x80) {
      switch (c) {
        case '\0': out += "\\0"; break;
        case '\t': out += "\\t"; break;
        case '\n': out += "\\n"; break;
        case '\r': out += "\\r"; break;
        case '\\': out += "\\\\"; break;
        case '\'': out += "\\'"; break;
        default:
          if (c < 0x20 || c == 0x7F) out += fmt::format("\\x{:02x}", c);
          else out += static_cast<char>(c);
      }
      ++i;
      continue;
    }
    const auto [code, length] = DecodeUtf8(text, i);
    if (length == 0) {
      out += fmt::format("\\x{:02x}", c);
      ++i;
    } else if (IsHidden(code)) {
      out += fmt::format("\\u{{{:04x}}}", static_cast<uint32_t>(code));
      i += length;
    } else {
      out.append(text.substr(i, length));
      i += length;
    }
  }
  return out + "'";
}

std::string NotFiniteMessage(std::string_view name, std::string_view value, bool too_large) {
  return fmt::format("{} is {}{}; expected a finite number", name, value,
                     too_large ? ", too large for a double (at most 1.8e308 in magnitude)" : "");
}

std::string StampOutOfRangeMessage(std::string_view value, std::string_view name) {
  return fmt::format("time stamp {} in {} is out of range (int64 nanoseconds, about ±292 years)", value, name);
}

std::optional<std::string> QuaternionProblem(double x, double y, double z, double w, std::string_view names) {
  const double n = x * x + y * y + z * z + w * w;
  if (n < kZeroQuaternionNormSquared) return fmt::format("quaternion ({}) has zero norm; expected a rotation", names);
  // Each value is finite, but n can still overflow (e.g. qx = 1e175); the rotation would silently
  // become the identity (sqrt(2/n) = 0), so such a quaternion is no rotation either. NaN lands here too.
  if (!std::isfinite(n)) {
    return fmt::format("quaternion ({}) is too large: its squared norm overflows a double; expected a rotation", names);
  }
  return std::nullopt;
}

std::optional<std::string> StampSpan::Add(int64_t stamp_ns, int64_t row, std::string_view unit) {
  if (empty_) {
    empty_ = false;
    min_ = max_ = stamp_ns;
    min_row_ = max_row_ = row;
    return std::nullopt;
  }
  int64_t difference = 0;
  int64_t other = 0, other_row = 0;
  bool overflow = false;
  if (stamp_ns > max_) {
    overflow = __builtin_sub_overflow(stamp_ns, min_, &difference);
    other = min_, other_row = min_row_;
    if (!overflow) max_ = stamp_ns, max_row_ = row;
  } else if (stamp_ns < min_) {
    overflow = __builtin_sub_overflow(max_, stamp_ns, &difference);
    other = max_, other_row = max_row_;
    if (!overflow) min_ = stamp_ns, min_row_ = row;
  }
  if (!overflow) return std::nullopt;
  const double span_s = std::abs(static_cast<double>(stamp_ns) - static_cast<double>(other)) * 1e-9;
  return fmt::format("time stamp {} s is {:.4g} s away from the stamp of {} {} ({} s); expected the stamps of one "
                     "trajectory to span at most int64 nanoseconds (about 292 years, 9.2e9 s)",
                     FormatSeconds(stamp_ns), span_s, unit, other_row, FormatSeconds(other));
}

std::optional<PoseProblem> FindPoseProblem(const TrajectoryView& trajectory) {
  static constexpr const char* kAxes[] = {"x", "y", "z", "w"};
  StampSpan span;
  const auto stamps = trajectory.stamps_ns();
  const bool quaternions = trajectory.channels().orientation == OrientationKind::kQuaternion;
  const bool matrices = trajectory.channels().orientation == OrientationKind::kMatrix;
  // The first non-finite value of `count` values at `values`, named as the array `array` shows it.
  auto not_finite = [](const double* values, int count, Eigen::Index row, const char* array) -> std::optional<std::string> {
    for (int j = 0; j < count; ++j) {
      if (std::isfinite(values[j])) continue;
      const std::string name = count == 9 ? fmt::format("{}[{}, {}, {}]", array, row, j / 3, j % 3)
                                          : fmt::format("{}[{}, {}] ({})", array, row, j, kAxes[j]);
      return NotFiniteMessage(name, fmt::format("{}", values[j]));
    }
    return std::nullopt;
  };
  for (Eigen::Index i = 0; i < trajectory.size(); ++i) {
    std::optional<std::string> what;
    if (trajectory.has_stamps()) what = span.Add(stamps[static_cast<size_t>(i)], i, "row");
    if (!what) what = not_finite(trajectory.positions().col(i).data(), 3, i, "positions");
    if (!what && quaternions) {
      const double* q = trajectory.quaternions().col(i).data();
      what = not_finite(q, 4, i, "quaternions");
      if (!what) what = QuaternionProblem(q[0], q[1], q[2], q[3], fmt::format("quaternions[{}]", i));
    }
    if (!what && matrices) {
      const Eigen::Matrix3d R = trajectory.Rotation(i);
      const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> row_major = R;
      what = not_finite(row_major.data(), 9, i, "rotations");
    }
    if (!what && trajectory.has_velocity()) what = not_finite(trajectory.velocities().col(i).data(), 3, i, "velocities");
    if (!what && trajectory.has_angular_velocity()) {
      what = not_finite(trajectory.angular_velocities().col(i).data(), 3, i, "angular_velocities");
    }
    if (what) return PoseProblem{i, std::move(*what)};
  }
  return std::nullopt;
}

void ValidatePoses(const TrajectoryView& trajectory, const std::string& source) {
  if (const auto problem = FindPoseProblem(trajectory)) {
    throw InputError(source, 0, 0, fmt::format("row {}: {}", problem->row, problem->what));
  }
}

}  // namespace cheval::traj
