#!/usr/bin/env bash
# `cheval table -j 2` against `-j 1` measured side by side in one run (issue 19's target: >= 1.7x the
# throughput): 40 runs of 20,000 poses (4 simulated sequences x 10 estimates with velocity, APE + RPE
# + C-ASE), no cache. The two settings alternate ROUNDS times; the best wall time of each is kept and
# the ratio printed. Needs two free cores to show the target.
#   bash bench/table_parallel.sh BUILD_DIR [ROUNDS]
set -euo pipefail
build=${1:?usage: table_parallel.sh BUILD_DIR [ROUNDS]}
rounds=${2:-3}
cheval="$build/cheval"
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT

config="$dir/exp.yaml"
{
  echo "metrics: [ape_trans, rpe_trans_10m, ase]"
  echo "datasets:"
  for s in 1 2 3 4; do echo "  s$s: {reference: s${s}_ref.txt}"; done
  echo "algorithms:"
} >"$config"
for s in 1 2 3 4; do
  estimates=()
  for k in $(seq 0 9); do estimates+=(--estimate "$dir/s${s}_e$k.txt"); done
  # 100 s at 200 Hz: 20,001 reference and estimate poses.
  "$cheval" -q sim motion --kind car --duration 100 --rate 200 --estimate-rate 200 --seed "$s" \
    -o "$dir/s${s}_ref.txt" "${estimates[@]}" >/dev/null
done
for k in $(seq 0 9); do
  echo "  - name: alg$k"
  echo "    estimates:"
  for s in 1 2 3 4; do echo "      s$s: [s${s}_e$k.txt]"; done
done >>"$config"
echo "experiment: 40 runs, $(wc -l <"$dir/s1_e0.txt") poses per estimate, $(nproc) cores"

best1=999999
best2=999999
for _ in $(seq "$rounds"); do
  for j in 1 2; do
    start=$(date +%s.%N)
    "$cheval" -q table "$config" -o "$dir/t$j.json" --no-cache -j "$j"
    end=$(date +%s.%N)
    t=$(echo "$end - $start" | bc)
    if [ "$j" = 1 ]; then best1=$(echo "if ($t < $best1) $t else $best1" | bc); else best2=$(echo "if ($t < $best2) $t else $best2" | bc); fi
    printf 'j=%d  %.2f s\n' "$j" "$t"
  done
done
cmp -s "$dir/t1.json" "$dir/t2.json" || { echo "error: -j 1 and -j 2 tables differ" >&2; exit 1; }
printf 'best -j 1: %.2f s (%.1f runs/s)   best -j 2: %.2f s (%.1f runs/s)   throughput ratio %.2fx\n' \
  "$best1" "$(echo "40 / $best1" | bc -l)" "$best2" "$(echo "40 / $best2" | bc -l)" "$(echo "$best1 / $best2" | bc -l)"
