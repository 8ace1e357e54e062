#!/usr/bin/env bash
# Wall time of the `cheval` executable end to end (process start, reading both files, association,
# SE(3) alignment, errors, statistics, printing) on an N-pose TUM pair written by eval_bench, the
# issue 4 targets: APE <= 0.25 s and RPE <= 0.3 s at N = 200,000. Prints the median of RUNS runs.
#   bash bench/eval_cli_timing.sh BUILD_DIR [N [RUNS]]
set -euo pipefail
build=${1:?usage: eval_cli_timing.sh BUILD_DIR [N [RUNS]]}
n=${2:-200000}
runs=${3:-7}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$build/bench/eval_bench" --write-pair "$n" "$dir"
echo "pair: $n poses, $(du -h "$dir/ref.txt" | cut -f1) + $(du -h "$dir/est.txt" | cut -f1) TUM"
for command in "ape --align se3" "rpe --align se3" "rpe --align se3 --delta 10 --delta-unit meters" "ape --align none"; do
  times=()
  for _ in $(seq "$runs"); do
    start=$(date +%s.%N)
    "$build/cheval" ${command%% *} "$dir/ref.txt" "$dir/est.txt" ${command#* } >/dev/null
    end=$(date +%s.%N)
    times+=("$(echo "$end - $start" | bc)")
  done
  median=$(printf '%s\n' "${times[@]}" | sort -g | sed -n "$(((runs + 1) / 2))p")
  printf 'cheval %-48s median %.3f s over %d runs (min %.3f)\n' "$command" "$median" "$runs" \
    "$(printf '%s\n' "${times[@]}" | sort -g | head -1)"
done
