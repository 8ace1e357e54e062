// libFuzzer target for the recording readers (src/bag): CHEVAL_FUZZ_CONTAINER picks ros1, mcap,
// ros2, ros2_file or ros2_message (fuzz/CMakeLists.txt builds fuzz_bag_<container>). The input is the file (for ros2, the sqlite3
// database of a folder). The properties are in bag_fuzzer_checks.cc (CheckBagInput), shared with
// tests/bag/bag_fuzz_regression_test.cc, which replays tests/data/fuzz/bag_<container>/.
#include <cstddef>
#include <cstdint>

#include "bag_fuzzer_checks.h"
#include "fuzz_checks.h"

#define CHEVAL_STRINGIFY2(x) #x
#define CHEVAL_STRINGIFY(x) CHEVAL_STRINGIFY2(x)

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return cheval::fuzz::TrapOnViolation(
      cheval::fuzz::CheckBagInput(CHEVAL_STRINGIFY(CHEVAL_FUZZ_CONTAINER), cheval::fuzz::AsText(data, size)));
}
