// Format names and the generic column map.
#include <algorithm>
#include <array>
#include <set>
#include <utility>

#include <fmt/format.h>

#include "cheval/common/error.h"
#include "cheval/common/options.h"
#include "cheval/traj/io.h"
#include "cheval/traj/validate.h"

namespace cheval::traj {
namespace {

constexpr std::array<std::pair<Format, std::string_view>, 7> kFormatNames{{
    {Format::kAuto, "auto"}, {Format::kTum, "tum"}, {Format::kTumV, "tumv"}, {Format::kEuroc, "euroc"},
    {Format::kKitti, "kitti"}, {Format::kVins, "vins"}, {Format::kCsv, "csv"}}};

constexpr std::array<std::pair<ColumnRole, std::string_view>, 23> kRoleNames{{
    {ColumnRole::kSkip, "_"},
    {ColumnRole::kTimeSeconds, "t"}, {ColumnRole::kTimeMilliseconds, "t_ms"},
    {ColumnRole::kTimeMicroseconds, "t_us"}, {ColumnRole::kTimeNanoseconds, "t_ns"},
    {ColumnRole::kPx, "px"}, {ColumnRole::kPy, "py"}, {ColumnRole::kPz, "pz"},
    {ColumnRole::kQx, "qx"}, {ColumnRole::kQy, "qy"}, {ColumnRole::kQz, "qz"}, {ColumnRole::kQw, "qw"},
    {ColumnRole::kRoll, "roll"}, {ColumnRole::kPitch, "pitch"}, {ColumnRole::kYaw, "yaw"},
    {ColumnRole::kVx, "vx"}, {ColumnRole::kVy, "vy"}, {ColumnRole::kVz, "vz"},
    {ColumnRole::kWx, "wx"}, {ColumnRole::kWy, "wy"}, {ColumnRole::kWz, "wz"},
    {ColumnRole::kSkip, "skip"}, {ColumnRole::kSkip, "-"}}};

std::string_view RoleName(ColumnRole role) {
  for (const auto& [r, name] : kRoleNames) {
    if (r == role) return name;
  }
  return "?";
}

}  // namespace

std::string_view ToString(Format format) {
  for (const auto& [f, name] : kFormatNames) {
    if (f == format) return name;
  }
  return "?";
}

std::optional<Format> FormatFromString(std::string_view name) {
  for (const auto& [f, n] : kFormatNames) {
    if (n == name) return f;
  }
  return std::nullopt;
}

ColumnMap ColumnMap::Parse(std::string_view spec) {
  ColumnMap map;
  std::set<ColumnRole> seen;
  size_t start = 0;
  while (start <= spec.size()) {
    const size_t comma = spec.find(',', start);
    const std::string_view token =
        spec.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
    const auto it = std::find_if(kRoleNames.begin(), kRoleNames.end(),
                                 [&](const auto& entry) { return entry.second == token; });
    if (it == kRoleNames.end()) {
      throw UsageError(fmt::format(
          "ReadOptions::columns: unknown column role {} (position {}); expected one of t, t_ms, t_us, t_ns, px, py, pz, "
          "qx, qy, qz, qw, roll, pitch, yaw, vx, vy, vz, wx, wy, wz, or _ to skip a column",
          QuoteField(token), map.roles.size() + 1));
    }
    if (it->first != ColumnRole::kSkip && !seen.insert(it->first).second) {
      throw UsageError(fmt::format("ReadOptions::columns: role {} appears twice", QuoteField(token)));
    }
    map.roles.push_back(it->first);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  auto count = [&](std::initializer_list<ColumnRole> wanted) {
    int n = 0;
    for (ColumnRole r : wanted) n += seen.count(r) ? 1 : 0;
    return n;
  };
  const int times = count({ColumnRole::kTimeSeconds, ColumnRole::kTimeMilliseconds, ColumnRole::kTimeMicroseconds,
                           ColumnRole::kTimeNanoseconds});
  if (times != 1) {
    throw UsageError("ReadOptions::columns: expected exactly one time column (t, t_ms, t_us or t_ns)");
  }
  if (count({ColumnRole::kPx, ColumnRole::kPy, ColumnRole::kPz}) != 3) {
    throw UsageError("ReadOptions::columns: expected all three position columns px, py, pz");
  }
  const int quaternion = count({ColumnRole::kQx, ColumnRole::kQy, ColumnRole::kQz, ColumnRole::kQw});
  const int euler = count({ColumnRole::kRoll, ColumnRole::kPitch, ColumnRole::kYaw});
  if (quaternion != 0 && quaternion != 4) throw UsageError("ReadOptions::columns: give all of qx, qy, qz, qw or none");
  if (euler != 0 && euler != 3) throw UsageError("ReadOptions::columns: give all of roll, pitch, yaw or none");
  if (quaternion != 0 && euler != 0) throw UsageError("ReadOptions::columns: give a quaternion or roll/pitch/yaw, not both");
  if (int v = count({ColumnRole::kVx, ColumnRole::kVy, ColumnRole::kVz}); v != 0 && v != 3) {
    throw UsageError("ReadOptions::columns: give all of vx, vy, vz or none");
  }
  if (int w = count({ColumnRole::kWx, ColumnRole::kWy, ColumnRole::kWz}); w != 0 && w != 3) {
    throw UsageError("ReadOptions::columns: give all of wx, wy, wz or none");
  }
  while (!map.roles.empty() && map.roles.back() == ColumnRole::kSkip) map.roles.pop_back();
  return map;
}

std::string ColumnMap::ToString() const {
  std::string out;
  for (size_t i = 0; i < roles.size(); ++i) {
    if (i > 0) out += ',';
    out += RoleName(roles[i]);
  }
  return out;
}

ReadOptions ReadOptions::FromNames(std::string_view format, std::string_view columns, std::string kitti_times_path) {
  const OptionCheck check("ReadOptions");
  ReadOptions options;
  const std::optional<Format> parsed = FormatFromString(format);
  check(parsed.has_value(), "format", "names an unknown format {} (auto, tum, tumv, euroc, kitti, vins, csv)", QuoteField(format));
  options.format = *parsed;
  if (!columns.empty()) {
    check(options.format == Format::kCsv || options.format == Format::kAuto, "columns",
          "is only for ReadOptions::format csv (got ReadOptions::format {})", format);
    options.format = Format::kCsv;  // a column map implies the generic format
    options.columns = ColumnMap::Parse(columns);
  } else {
    check(options.format != Format::kCsv, "format",
          "csv needs ReadOptions::columns (e.g. ReadOptions::columns t,px,py,pz,qx,qy,qz,qw)");
  }
  check(kitti_times_path.empty() || options.format == Format::kKitti || options.format == Format::kAuto,
        "kitti_times_path", "is only for KITTI files");
  options.kitti_times_path = std::move(kitti_times_path);
  return options;
}

}  // namespace cheval::traj
