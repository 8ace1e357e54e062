#pragma once
/// \file
/// How much memory a run may plan to use (docs/cli.md, "Memory limit"). An option or an input that
/// decides how much a run allocates (stamps to sample, samples to simulate, points to embed in a
/// page) is checked with CheckMemory before the allocation: a value too large is refused with a
/// message naming the option and the cost, instead of exhausting the machine or ending in
/// std::bad_alloc.
///
///     const double stamps = span_s * rate_hz + 1;
///     CheckMemory({"ModelGridStamps", "rate_hz", stamps * kBytesPerStamp,
///                  fmt::format("{:.4g} stamps", stamps), MemoryCost::kOption});

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace cheval {

/// The environment variable that sets the limit (bytes, or a number with a suffix K, M, G or T for
/// powers of 1024: "512M", "2G").
inline constexpr std::string_view kMemoryLimitVariable = "CHEVAL_MEMORY_LIMIT";

/// The physical memory the process may use, bytes: the smallest of the machine's physical memory
/// (sysconf), the address-space and data-segment limits (RLIMIT_AS, RLIMIT_DATA) and the memory limit
/// of the process's control group (cgroup v2 `memory.max`, v1 `memory.limit_in_bytes`), where set.
std::uint64_t AvailableMemory();

/// The memory a run may plan to use, bytes: kMemoryLimitVariable when it is set, else half of
/// AvailableMemory() (the other half is left to what the estimate does not count: the inputs, the
/// library's working copies, the rest of the machine). Throws UsageError naming the variable when
/// its value is not a positive number of bytes.
std::uint64_t MemoryLimit();

/// Who answers for a cost.
enum class MemoryCost {
  kOption,  ///< the option's value alone: OptionError (exit 1 in the CLI)
  kData,    ///< the option's value on these inputs: ComputeError (exit 3 in the CLI)
};

/// A planned allocation, named by the option that decides it.
struct MemoryNeed {
  /// The library's names of the option (`STRUCT`, `FIELD`), spelled by the faces.
  std::string_view options;
  std::string_view field;
  /// The estimated peak, bytes (a double: the estimate may exceed any integer type).
  double bytes = 0;
  /// What is counted, for the message: "2e+09 stamps".
  std::string what;
  MemoryCost cost = MemoryCost::kOption;
};

/// Throws unless need.bytes <= MemoryLimit() (and is a number): OptionError (kOption) or
/// ComputeError (kData) reading "STRUCT::FIELD would need about 18.6 GB of memory (1e+08 stamps);
/// the limit is 11.7 GB (half the available memory; CHEVAL_MEMORY_LIMIT changes it)".
void CheckMemory(const MemoryNeed& need);

/// Bytes as a person reads them: "512 B", "1.5 kB", "18.6 GB" (powers of 1000, 3 significant digits).
std::string FormatBytes(double bytes);

/// Parses a byte count: digits with an optional suffix K, M, G or T (powers of 1024, either case,
/// an optional trailing B or iB); nullopt for anything else, zero or a value beyond 2^64 - 1.
std::optional<std::uint64_t> ParseByteCount(std::string_view text);

}  // namespace cheval
