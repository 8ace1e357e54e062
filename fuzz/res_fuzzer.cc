// libFuzzer target for the result-file readers of `cheval res` (common/zip.h, common/npy.h,
// eval/res_read.h): the bytes as a result zip and as a lone .npy array. The properties are in
// res_fuzz_checks.cc (CheckResultFileInput), replayed by tests/eval/res_read_test.cc.
#include <cstddef>
#include <cstdint>

#include "fuzz_checks.h"
#include "res_fuzz_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return cheval::fuzz::TrapOnViolation(cheval::fuzz::CheckResultFileInput(cheval::fuzz::AsText(data, size)));
}
