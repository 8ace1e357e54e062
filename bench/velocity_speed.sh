#!/usr/bin/env bash
# End-to-end speed of `cheval velocity` (default) against `cheval velocity --method central` on the
# same file, the read/write floor: the two commands alternate RUNS times and the script prints each
# one's best and median CPU time (user + sys) and their ratio (docs/velocity.md, "Speed").
#   bash bench/velocity_speed.sh [BUILD_DIR] [RUNS] [SAMPLES]
set -euo pipefail
build=${1:-build}
runs=${2:-7}
samples=${3:-100000}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# A drone flight at 200 Hz with 0.5 mm of noise: SAMPLES + 1 samples.
duration=$(awk -v m="$samples" 'BEGIN { printf "%.3f", m / 200 }')
"$build/cheval" sim motion --kind drone --seed 1 --noise 0.0005 --duration "$duration" -o "$work/in.tum" > /dev/null
cpu() {  # CPU seconds of one run of the command
  /usr/bin/time -f "%U %S" -o "$work/time" "$@" > /dev/null 2>&1
  awk '{ printf "%.3f\n", $1 + $2 }' "$work/time"
}
: > "$work/default"
: > "$work/central"
for ((i = 0; i < runs; i++)); do
  cpu "$build/cheval" velocity "$work/in.tum" -o "$work/out.tum" >> "$work/default"
  cpu "$build/cheval" velocity "$work/in.tum" --method central -o "$work/out.tum" >> "$work/central"
done
stats() { sort -n "$1" | awk '{ v[NR] = $1 } END { printf "%.3f %.3f", v[1], v[int((NR + 1) / 2)] }'; }
read -r dbest dmed <<< "$(stats "$work/default")"
read -r cbest cmed <<< "$(stats "$work/central")"
lines=$(wc -l < "$work/in.tum")
echo "samples: $lines, runs: $runs (alternating), CPU seconds best / median"
echo "default:  $dbest / $dmed"
echo "central:  $cbest / $cmed"
awk -v d="$dbest" -v c="$cbest" -v dm="$dmed" -v cm="$cmed" \
  'BEGIN { printf "ratio default / central: best %.2fx, median %.2fx (target <= 2x)\n", d / c, dm / cm }'
