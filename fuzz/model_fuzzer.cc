// libFuzzer target for the trajectory-model reader, cheb::ParseModelJson (src/cheb/model_json.cc):
// what `cheval sample MODEL.json` reads. The properties (clean InputError, write/read round trip,
// the curve evaluates) are in fuzz_checks.cc (CheckModelInput), shared with
// tests/traj/fuzz_regression_test.cc, which replays tests/data/fuzz/model/.
#include <cstddef>
#include <cstdint>

#include "fuzz_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return cheval::fuzz::TrapOnViolation(cheval::fuzz::CheckModelInput(cheval::fuzz::AsText(data, size)));
}
