#!/usr/bin/env bash
# Builds cheval and runs the whole test suite with CTest.
#   scripts/test.sh             Release build in build/
#   scripts/test.sh --sanitize  AddressSanitizer + UndefinedBehaviorSanitizer build in build-asan/
# The shared real data is taken from $CHEVAL_DATA_DIR, else ../shared/data beside the checkout.
set -euo pipefail
cd "$(dirname "$0")/.."

build_dir=build
cmake_args=(-DCMAKE_BUILD_TYPE=Release -DCHEVAL_BUILD_TESTS=ON -DCHEVAL_BUILD_BENCH=ON -DCHEVAL_BUILD_PYTHON=ON)
if [ "${1:-}" = "--sanitize" ]; then
  build_dir=build-asan
  # -O1 -g1 (line tables for the sanitizers' stack traces): the heaviest file (the estimator, Ceres
  # templates) compiles in 62 s instead of 193 s at -O2 -g, which is most of CI's sanitizer run.
  cmake_args=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG"
              -DCHEVAL_BUILD_TESTS=ON -DCHEVAL_BUILD_BENCH=OFF -DCHEVAL_SANITIZE=ON
              -DCHEVAL_BUILD_PYTHON=OFF)  # Python cannot load an instrumented module without preloading the runtime
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
fi
data_dir="${CHEVAL_DATA_DIR:-$(cd .. && pwd)/shared/data}"
jobs=$(nproc 2>/dev/null || echo 2)

cmake -S . -B "$build_dir" "${cmake_args[@]}" -DCHEVAL_DATA_DIR="$data_dir"
cmake --build "$build_dir" -j "$jobs"
CHEVAL_DATA_DIR="$data_dir" ctest --test-dir "$build_dir" --output-on-failure -j "$jobs"
