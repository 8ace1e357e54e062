// libFuzzer target for the curve fit, cheb::FitCurve (src/cheb/curve.cc, src/cheb/end_caps.cc): what
// `cheval velocity` and `cheval compress` run on the positions they read. The input decodes into
// samples (stamp steps with repeats and gaps, noise on a smooth motion); the properties (the same
// success or ComputeError with and without end caps, windows that tile, finite values) are in
// fuzz_checks.cc (CheckCurveInput), shared with tests/traj/fuzz_regression_test.cc, which replays
// tests/data/fuzz/curve/.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>

#include "fuzz_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::optional<std::string> violation =
      cheval::fuzz::CheckCurveInput(std::string_view(reinterpret_cast<const char*>(data), size));
  if (violation) {
    std::fprintf(stderr, "property violated: %s\n", violation->c_str());
    __builtin_trap();
  }
  return 0;
}
