#pragma once
/// \file
/// Time stamps: cheval stores every stamp as int64 nanoseconds. Decimal seconds from text files are
/// converted exactly from their digits (never through a double, which resolves only ~2e-7 s at
/// 1.4e9 s), and printed back exactly.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace cheval::traj {

/// Nanoseconds per second.
inline constexpr int64_t kNanosecondsPerSecond = 1'000'000'000;

/// Why a decimal stamp could not be parsed.
enum class StampParseError { kNotANumber, kOutOfRange, kNotAnInteger };

/// Result of ParseDecimalStamp: either `value` or `error` is set.
struct StampParseResult {
  int64_t value = 0;
  std::optional<StampParseError> error;
};

/// Parses a decimal number `text` (optional sign, digits, optional fraction, optional exponent such
/// as `1.403715529112143517e+09`) and returns round(text × 10^`scale_exponent`) as int64, rounding
/// halves to even. Use scale_exponent 9 for seconds -> nanoseconds and 0 for integer nanoseconds.
/// With `require_integer`, a value that is not an integer after scaling is an error (kNotAnInteger).
/// The arithmetic is exact: no floating point is involved. "nan", "inf", hex and empty text are
/// kNotANumber; a result outside int64 is kOutOfRange.
StampParseResult ParseDecimalStamp(std::string_view text, int scale_exponent, bool require_integer = false);

/// Formats nanoseconds as seconds with exactly nine decimals, e.g. 1403715529112143517 ->
/// "1403715529.112143517" and -5 -> "-0.000000005". Exact inverse of ParseDecimalStamp(., 9).
std::string FormatSeconds(int64_t stamp_ns);

/// Converts a difference of stamps to seconds as a double (exact for |dt| < 2^53 ns ≈ 104 days).
inline double ToSeconds(int64_t duration_ns) { return static_cast<double>(duration_ns) * 1e-9; }

}  // namespace cheval::traj
