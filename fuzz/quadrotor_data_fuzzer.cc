// libFuzzer target for the quadrotor data-folder reader, estim::ReadQuadrotorData
// (src/estim/quadrotor_data.cc): what `cheval estimate quadrotor --data DIR` reads. Byte 0 picks the
// file the other bytes replace in a small valid folder; the properties are in estim_fuzz_checks.cc
// (CheckQuadrotorDataInput), replayed by tests/estim/fuzz_regression_test.cc.
#include <cstddef>
#include <cstdint>

#include "estim_fuzz_checks.h"
#include "fuzz_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return cheval::fuzz::TrapOnViolation(cheval::fuzz::CheckQuadrotorDataInput(cheval::fuzz::AsText(data, size)));
}
