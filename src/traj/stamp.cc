#include "cheval/traj/stamp.h"

#include <cstdlib>

namespace cheval::traj {
namespace {

__extension__ using Int128 = __int128;  // GCC and Clang; exact 128-bit intermediate

// Significant digits kept exactly; later digits only matter as a "sticky" non-zero flag for
// rounding. 36 digits fit an __int128 with room to spare, and any representable int64 result needs
// at most 19 digits plus the rounding digit.
constexpr int kMaxKeptDigits = 36;

Int128 PowerOfTen(int n) {
  Int128 p = 1;
  for (int i = 0; i < n; ++i) p *= 10;
  return p;
}

}  // namespace

StampParseResult ParseDecimalStamp(std::string_view text, int scale_exponent, bool require_integer) {
  StampParseResult result;
  size_t i = 0;
  bool negative = false;
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) {
    negative = text[i] == '-';
    ++i;
  }
  Int128 digits = 0;       // significant digits kept
  int kept = 0;            // how many significant digits are in `digits`
  bool sticky = false;     // a non-zero digit was dropped beyond kMaxKeptDigits
  int64_t exponent = 0;    // value = digits * 10^exponent (before scaling)
  bool any_digit = false;
  bool in_fraction = false;
  for (; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '.') {
      if (in_fraction) break;  // a second dot: reported as trailing garbage below
      in_fraction = true;
      continue;
    }
    if (c < '0' || c > '9') break;
    any_digit = true;
    const int d = c - '0';
    if (kept == 0 && d == 0) {
      if (in_fraction) --exponent;  // leading zeros of a fraction only shift the exponent
      continue;
    }
    if (kept < kMaxKeptDigits) {
      digits = digits * 10 + d;
      ++kept;
      if (in_fraction) --exponent;
    } else {
      sticky = sticky || d != 0;
      if (!in_fraction) ++exponent;  // an integer digit we could not keep still scales the value
    }
  }
  if (!any_digit) {
    result.error = StampParseError::kNotANumber;
    return result;
  }
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    bool exp_negative = false;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) {
      exp_negative = text[i] == '-';
      ++i;
    }
    if (i >= text.size() || text[i] < '0' || text[i] > '9') {
      result.error = StampParseError::kNotANumber;
      return result;
    }
    int64_t e = 0;
    for (; i < text.size() && text[i] >= '0' && text[i] <= '9'; ++i) {
      if (e < 100000) e = e * 10 + (text[i] - '0');  // saturate: anything this large is out of range
    }
    exponent += exp_negative ? -e : e;
  }
  if (i != text.size()) {
    result.error = StampParseError::kNotANumber;
    return result;
  }
  if (digits == 0) {  // zero, whatever the exponent (sticky cannot be set without kept digits)
    result.value = 0;
    return result;
  }

  const int64_t k = exponent + scale_exponent;
  Int128 magnitude = 0;
  if (k >= 0) {
    // The result has kept + k digits; more than 19 cannot fit int64.
    if (kept + k > 19) {
      result.error = StampParseError::kOutOfRange;
      return result;
    }
    magnitude = digits * PowerOfTen(static_cast<int>(k));
    if (sticky) {  // dropped digits sit at positions >= 10^0 only when k >= 0 and kept is full
      result.error = StampParseError::kOutOfRange;
      return result;
    }
  } else {
    Int128 quotient = 0;
    Int128 remainder = digits;
    Int128 divisor = 0;
    if (-k <= 37) {
      divisor = PowerOfTen(static_cast<int>(-k));
      quotient = digits / divisor;
      remainder = digits % divisor;
    }
    const bool inexact = remainder != 0 || sticky;
    if (require_integer && inexact) {
      result.error = StampParseError::kNotAnInteger;
      return result;
    }
    bool round_up = false;
    if (divisor != 0) {
      const Int128 twice = remainder * 2;  // remainder < 10^37, so no overflow
      round_up = twice > divisor || (twice == divisor && (sticky || (quotient % 2) != 0));
    }  // else: digits < 10^36 < divisor/2 for -k > 37, so the value rounds to zero
    magnitude = quotient + (round_up ? 1 : 0);
  }
  constexpr Int128 kMaxMagnitude = static_cast<Int128>(INT64_MAX);
  if (magnitude > kMaxMagnitude + (negative ? 1 : 0)) {
    result.error = StampParseError::kOutOfRange;
    return result;
  }
  result.value = static_cast<int64_t>(negative ? -magnitude : magnitude);
  return result;
}

std::string FormatSeconds(int64_t stamp_ns) {
  const bool negative = stamp_ns < 0;
  // Work with the unsigned magnitude so INT64_MIN does not overflow.
  const uint64_t magnitude = negative ? (~static_cast<uint64_t>(stamp_ns) + 1) : static_cast<uint64_t>(stamp_ns);
  const uint64_t seconds = magnitude / 1'000'000'000ULL;
  const uint64_t fraction = magnitude % 1'000'000'000ULL;
  std::string out = negative ? "-" : "";
  out += std::to_string(seconds);
  out += '.';
  std::string frac = std::to_string(fraction);
  out.append(9 - frac.size(), '0');
  out += frac;
  return out;
}

}  // namespace cheval::traj
