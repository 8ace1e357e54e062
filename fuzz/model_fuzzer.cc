// libFuzzer target for the trajectory-model reader, cheb::ParseModelJson (src/cheb/model_json.cc):
// what `cheval sample MODEL.json` reads. The properties (clean InputError, write/read round trip,
// the curve evaluates) are in fuzz_checks.cc (CheckModelInput), shared with
// tests/traj/fuzz_regression_test.cc, which replays tests/data/fuzz/model/.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>

#include "fuzz_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::optional<std::string> violation =
      cheval::fuzz::CheckModelInput(std::string_view(reinterpret_cast<const char*>(data), size));
  if (violation) {
    std::fprintf(stderr, "property violated: %s\n", violation->c_str());
    __builtin_trap();
  }
  return 0;
}
