// libFuzzer target for the trajectory-model reader, cheb::ParseModelJson (src/cheb/model_json.cc):
// what `cheval sample MODEL.json` reads. The properties (clean InputError, write/read round trip,
// the curve evaluates) are in fuzz_checks.cc (CheckModelInput), shared with
// tests/traj/fuzz_regression_test.cc, which replays tests/data/fuzz/model/; then the checksum's
// (CheckModelMutationInput, estim_fuzz_checks.cc): the input re-read as a version 1 model, so its
// structure is fuzzed past the checksum, and a byte mutation of its written form refused or harmless.
#include <cstddef>
#include <cstdint>

#include "estim_fuzz_checks.h"
#include "fuzz_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text = cheval::fuzz::AsText(data, size);
  cheval::fuzz::TrapOnViolation(cheval::fuzz::CheckModelInput(text));
  return cheval::fuzz::TrapOnViolation(cheval::fuzz::CheckModelMutationInput(text));
}
