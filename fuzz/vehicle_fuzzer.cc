// libFuzzer target for the vehicle JSON reader, estim::ReadVehicle (src/estim/vehicle.cc): what
// `cheval sim quadrotor --vehicle` and `estimate quadrotor` read. The properties are in
// estim_fuzz_checks.cc (CheckVehicleInput), replayed by tests/estim/fuzz_regression_test.cc.
#include <cstddef>
#include <cstdint>

#include "estim_fuzz_checks.h"
#include "fuzz_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return cheval::fuzz::TrapOnViolation(cheval::fuzz::CheckVehicleInput(cheval::fuzz::AsText(data, size)));
}
