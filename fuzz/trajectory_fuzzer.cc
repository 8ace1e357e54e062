// libFuzzer target for the trajectory readers. One source, built once per reader: CHEVAL_FUZZ_FORMAT
// names the target (tum, tumv, euroc, kitti, vins, csv, auto, or column_map for ColumnMap::Parse).
//
// What the target runs and the properties it checks are in fuzz_checks.cc (CheckTrajectoryInput),
// shared with tests/traj/fuzz_regression_test.cc, which replays tests/data/fuzz/<target>/. A
// documented failure (cheval::InputError) is fine; a violated property is printed and trapped on;
// a crash, a sanitizer report, a hang or another exception escaping is reported by libFuzzer itself.
#include <cstddef>
#include <cstdint>

#include "fuzz_checks.h"

#ifndef CHEVAL_FUZZ_FORMAT
#error "define CHEVAL_FUZZ_FORMAT (tum, tumv, euroc, kitti, vins, csv, auto or column_map)"
#endif
#define CHEVAL_FUZZ_STRINGIFY2(x) #x
#define CHEVAL_FUZZ_STRINGIFY(x) CHEVAL_FUZZ_STRINGIFY2(x)

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return cheval::fuzz::TrapOnViolation(cheval::fuzz::CheckTrajectoryInput(CHEVAL_FUZZ_STRINGIFY(CHEVAL_FUZZ_FORMAT),
                                                                       cheval::fuzz::AsText(data, size)));
}
