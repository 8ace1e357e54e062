// libFuzzer target for ParseDecimalStamp (src/traj/stamp.cc).
//
// Input: byte 0 holds the options (bit 0: require_integer; bit 1 set: the scale exponent is byte 1 as
// a signed char, else 9, 6, 3 or 0 by bits 2-3, as the readers use it), then the text. The properties
// (FormatSeconds round trip, agreement with strtold) are in fuzz_checks.cc (CheckStampInput), shared
// with tests/traj/fuzz_regression_test.cc, which replays tests/data/fuzz/stamp/. ParseDecimalStamp
// never throws; a violated property is printed and trapped on.
#include <cstddef>
#include <cstdint>

#include "fuzz_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return cheval::fuzz::TrapOnViolation(cheval::fuzz::CheckStampInput(cheval::fuzz::AsText(data, size)));
}
