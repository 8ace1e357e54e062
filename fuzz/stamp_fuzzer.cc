// libFuzzer target for ParseDecimalStamp (src/traj/stamp.cc).
//
// Input: byte 0 holds the options: bit 0 = require_integer; bit 1 set = the scale exponent is byte 1
// as a signed char (text from byte 2), else it is 9, 6, 3 or 0 by bits 2-3 (text from byte 1), as
// the readers use it. ParseDecimalStamp never throws; a crash, a sanitizer report or a property
// violated (__builtin_trap()) is a bug:
//   - with scale 9, FormatSeconds(value) parses back to the same value;
//   - a parsed value agrees with strtold(text)·10^scale (long double carries 64 bits, so the
//     exact int64 result is within a few units of it); kOutOfRange only when that is beyond int64;
//     kNotAnInteger only when require_integer; kNotANumber never for plain decimal text that strtold
//     reads completely.
//
// tests/traj/fuzz_regression_test.cc replays tests/data/fuzz/stamp/ the same way.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "cheval/traj/stamp.h"

namespace {

#define FUZZ_CHECK(condition)                                                                \
  do {                                                                                       \
    if (!(condition)) {                                                                      \
      std::fprintf(stderr, "property violated: %s (%s:%d)\n", #condition, __FILE__, __LINE__); \
      __builtin_trap();                                                                      \
    }                                                                                        \
  } while (0)

// Plain decimal text: a sign, digits, dots and exponents only (no spaces, hex, inf or nan, all of
// which strtold accepts and ParseDecimalStamp rejects by design).
bool IsPlainDecimal(std::string_view text) {
  if (text.empty()) return false;
  for (char c : text) {
    if (!((c >= '0' && c <= '9') || c == '.' || c == 'e' || c == 'E' || c == '+' || c == '-')) return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace cheval::traj;
  if (size < 2) return 0;
  const bool require_integer = (data[0] & 1) != 0;
  int scale = 0;
  size_t begin = 1;
  if ((data[0] & 2) != 0) {
    scale = static_cast<int8_t>(data[1]);
    begin = 2;
  } else {
    constexpr int kScales[4] = {9, 6, 3, 0};
    scale = kScales[(data[0] >> 2) & 3];
  }
  const std::string text(reinterpret_cast<const char*>(data) + begin, size - begin);
  const StampParseResult r = ParseDecimalStamp(text, scale, require_integer);

  if (!r.error && scale == 9) {
    const std::string printed = FormatSeconds(r.value);
    const StampParseResult again = ParseDecimalStamp(printed, 9);
    FUZZ_CHECK(!again.error && again.value == r.value);
    const StampParseResult again_integer = ParseDecimalStamp(printed, 9, true);
    FUZZ_CHECK(!again_integer.error && again_integer.value == r.value);
  }
  if (r.error && *r.error == StampParseError::kNotAnInteger) FUZZ_CHECK(require_integer);

  // Differential check against long double (only for text strtold must read the same way).
  if (!IsPlainDecimal(text)) {
    FUZZ_CHECK(!r.error ? false : *r.error == StampParseError::kNotANumber);
    return 0;
  }
  char* end = nullptr;
  const long double parsed = std::strtold(text.c_str(), &end);
  const bool complete = end == text.c_str() + text.size();
  if (!r.error) {
    FUZZ_CHECK(complete);
    const long double reference = parsed * std::pow(10.0L, static_cast<long double>(scale));
    FUZZ_CHECK(std::isfinite(reference));
    const long double difference = std::fabs(static_cast<long double>(r.value) - reference);
    FUZZ_CHECK(difference <= 2.0L + std::fabs(reference) * 1e-17L);
    return 0;
  }
  switch (*r.error) {
    case StampParseError::kNotANumber: FUZZ_CHECK(!complete); break;
    case StampParseError::kOutOfRange: {
      FUZZ_CHECK(complete);
      const long double reference = parsed * std::pow(10.0L, static_cast<long double>(scale));
      // INT64_MAX + 0.5 rounds out of range; allow the long double error of the reference.
      FUZZ_CHECK(!(std::fabs(reference) < 9223372036854775807.0L * (1.0L - 1e-17L)));
      break;
    }
    case StampParseError::kNotAnInteger: FUZZ_CHECK(complete); break;
  }
  return 0;
}
