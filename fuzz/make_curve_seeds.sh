#!/usr/bin/env bash
# Writes the seed inputs of the curve target (fuzz/curve_fuzzer.cc, docs/fuzzing.md) into
# tests/data/fuzz/curve/ (or DIR): byte 0 picks the dimension (1 + byte % 3), then one record of
# 1 + d bytes per sample, a stamp step code and d noise bytes (fuzz_checks.h, CheckCurveInput).
# Deterministic: the noise bytes come from a fixed linear congruential sequence.
#
#   fuzz/make_curve_seeds.sh [DIR]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
dir="${1:-$here/../tests/data/fuzz/curve}"
mkdir -p "$dir"

# seed NAME DIM SAMPLES STEP_PROGRAM: STEP_PROGRAM is an awk expression of i (sample index) and n
# giving the step code of sample i.
seed() {
  LC_ALL=C awk -v d="$2" -v n="$3" "
    BEGIN {
      x = 12345; printf \"%c\", d - 1
      for (i = 0; i < n; ++i) {
        code = $4; printf \"%c\", code
        for (c = 0; c < d; ++c) { x = (1103515245 * x + 12345) % 2147483648; printf \"%c\", int(x / 65536) % 256 }
      }
    }" > "$dir/$1"
}

seed regular_200hz_3d 3 2000 '100'                          # 5 ms steps: the gait at 200 Hz
seed repeated_stamps_at_start 3 1500 '(i < 40 ? 0 : 100)'   # 40 samples on the first stamp
seed repeated_stamps_at_end 3 1500 '(i > n - 40 ? 0 : 100)' # and on the last
seed doubled_stamps 2 2000 '(i % 2 ? 0 : 200)'              # every stamp twice
seed gap_in_the_middle 3 1800 '(i == 900 ? 255 : 100)'      # a 0.5 s gap: two segments
seed irregular_1d 1 2500 '(1 + (i * 37) % 200)'             # steps of 0.05..10 ms
seed few_samples 3 3 '100'                                  # too few for any window
echo "curve seeds: $(ls "$dir" | wc -l) in $dir"
