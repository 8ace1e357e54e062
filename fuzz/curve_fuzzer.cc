// libFuzzer target for the curve fit, cheb::FitCurve (src/cheb/curve.cc, src/cheb/end_caps.cc): what
// `cheval velocity` and `cheval compress` run on the positions they read. The input decodes into
// samples (stamp steps with repeats and gaps, noise on a smooth motion); the properties (the same
// success or ComputeError with and without end caps, windows that tile, finite values) are in
// fuzz_checks.cc (CheckCurveInput), shared with tests/traj/fuzz_regression_test.cc, which replays
// tests/data/fuzz/curve/.
#include <cstddef>
#include <cstdint>

#include "fuzz_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return cheval::fuzz::TrapOnViolation(cheval::fuzz::CheckCurveInput(cheval::fuzz::AsText(data, size)));
}
