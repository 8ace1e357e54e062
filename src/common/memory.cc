#include "cheval/common/memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>

#include <fmt/format.h>

#include "cheval/common/error.h"

namespace cheval {
namespace {

constexpr std::uint64_t kUnlimited = std::numeric_limits<std::uint64_t>::max();

// A control group's limit file: a number of bytes, or "max" (cgroup v2) / a huge number (v1) for none.
std::uint64_t CgroupLimit(const char* path) {
  std::ifstream in(path);
  std::string text;
  if (!(in >> text)) return kUnlimited;
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  return error == std::errc() && end == text.data() + text.size() && value > 0 ? value : kUnlimited;
}

std::uint64_t ResourceLimit(int resource) {
  rlimit limit{};
  if (::getrlimit(resource, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return kUnlimited;
  return static_cast<std::uint64_t>(limit.rlim_cur);
}

}  // namespace

std::optional<std::uint64_t> ParseByteCount(std::string_view text) {
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end == text.data() || value == 0) return std::nullopt;
  std::string suffix(end, text.data() + text.size());
  std::transform(suffix.begin(), suffix.end(), suffix.begin(), [](unsigned char c) { return std::toupper(c); });
  if (suffix.ends_with("IB")) suffix.resize(suffix.size() - 2);
  else if (suffix.size() > 1 && suffix.ends_with("B")) suffix.resize(suffix.size() - 1);
  else if (suffix == "B") suffix.clear();
  int shift = 0;
  if (suffix == "K") shift = 10;
  else if (suffix == "M") shift = 20;
  else if (suffix == "G") shift = 30;
  else if (suffix == "T") shift = 40;
  else if (!suffix.empty()) return std::nullopt;
  if (value > (kUnlimited >> shift)) return std::nullopt;
  return value << shift;
}

std::uint64_t AvailableMemory() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page_size = ::sysconf(_SC_PAGE_SIZE);
  std::uint64_t available = pages > 0 && page_size > 0 ? static_cast<std::uint64_t>(pages) *
                                                            static_cast<std::uint64_t>(page_size)
                                                      : kUnlimited;
  available = std::min({available, ResourceLimit(RLIMIT_AS), ResourceLimit(RLIMIT_DATA),
                        CgroupLimit("/sys/fs/cgroup/memory.max"),
                        CgroupLimit("/sys/fs/cgroup/memory/memory.limit_in_bytes")});
  return available;
}

std::uint64_t MemoryLimit() {
  if (const char* set = std::getenv(std::string(kMemoryLimitVariable).c_str())) {
    const std::optional<std::uint64_t> bytes = ParseByteCount(set);
    if (!bytes) {
      throw UsageError(fmt::format("{} must be a positive number of bytes, optionally with a suffix K, M, G or T "
                                   "(e.g. 4G), got '{}'",
                                   kMemoryLimitVariable, set));
    }
    return *bytes;
  }
  return AvailableMemory() / 2;
}

std::string FormatBytes(double bytes) {
  if (!(bytes < 1e3)) {
    const char* units[] = {"kB", "MB", "GB", "TB", "PB", "EB"};
    double value = bytes / 1e3;
    size_t unit = 0;
    while (value >= 999.5 && unit + 1 < std::size(units)) {
      value /= 1e3;
      ++unit;
    }
    if (std::isfinite(value) && value < 999.5) return fmt::format("{:.3g} {}", value, units[unit]);
    return fmt::format("{:.3g} B", bytes);
  }
  return fmt::format("{:.0f} B", bytes);
}

void CheckMemory(const MemoryNeed& need) {
  const std::uint64_t limit = MemoryLimit();
  if (need.bytes <= static_cast<double>(limit)) return;
  const bool set = std::getenv(std::string(kMemoryLimitVariable).c_str()) != nullptr;
  const std::string rule = fmt::format(
      "would need about {} of memory ({}); the limit is {} ({})", FormatBytes(need.bytes), need.what,
      FormatBytes(static_cast<double>(limit)),
      set ? fmt::format("{}={}", kMemoryLimitVariable, std::getenv(std::string(kMemoryLimitVariable).c_str()))
          : fmt::format("half the available memory; {} changes it", kMemoryLimitVariable));
  if (need.cost == MemoryCost::kOption) {
    throw OptionError(std::string(need.options), std::string(need.field), rule);
  }
  throw ComputeError(fmt::format("{}::{} {}", need.options, need.field, rule));
}

}  // namespace cheval
