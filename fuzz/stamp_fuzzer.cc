// libFuzzer target for ParseDecimalStamp (src/traj/stamp.cc).
//
// Input: byte 0 holds the options (bit 0: require_integer; bit 1 set: the scale exponent is byte 1 as
// a signed char, else 9, 6, 3 or 0 by bits 2-3, as the readers use it), then the text. The properties
// (FormatSeconds round trip, agreement with strtold) are in fuzz_checks.cc (CheckStampInput), shared
// with tests/traj/fuzz_regression_test.cc, which replays tests/data/fuzz/stamp/. ParseDecimalStamp
// never throws; a violated property is printed and trapped on.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>

#include "fuzz_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::optional<std::string> violation =
      cheval::fuzz::CheckStampInput(std::string_view(reinterpret_cast<const char*>(data), size));
  if (violation) {
    std::fprintf(stderr, "property violated: %s\n", violation->c_str());
    __builtin_trap();
  }
  return 0;
}
