#!/usr/bin/env bash
# End-to-end speed of `cheval velocity` (default) against `cheval velocity --method central` on the
# same file, the read/write floor: the commands alternate RUNS times and the script prints each
# one's best and median wall-clock time and CPU time (user + sys, all threads), and their ratios
# (docs/velocity.md, "Speed"). With BASELINE_BUILD_DIR (another build, e.g. of an earlier commit)
# its default command alternates with them too, and the script prints this build's time over it.
#   bash bench/velocity_speed.sh [BUILD_DIR] [RUNS] [SAMPLES] [BASELINE_BUILD_DIR]
set -euo pipefail
build=${1:-build}
runs=${2:-7}
samples=${3:-100000}
baseline=${4:-}
if [[ -n "$baseline" && ! -x "$baseline/cheval" ]]; then
  echo "velocity_speed.sh: no cheval executable in the baseline build $baseline" >&2
  exit 2
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# A drone flight at 200 Hz with 0.5 mm of noise: SAMPLES + 1 samples.
duration=$(awk -v m="$samples" 'BEGIN { printf "%.3f", m / 200 }')
"$build/cheval" sim motion --kind drone --seed 1 --noise 0.0005 --duration "$duration" -o "$work/in.tum" > /dev/null
timed() {  # appends the wall-clock and CPU seconds of one run of the command to files $1.wall, $1.cpu
  local name=$1 start end
  shift
  start=$EPOCHREALTIME  # microseconds; /usr/bin/time's %e has 10 ms steps
  /usr/bin/time -f "%U %S" -o "$work/time" "$@" > /dev/null 2>&1
  end=$EPOCHREALTIME
  awk -v a="$start" -v b="$end" 'BEGIN { printf "%.4f\n", b - a }' >> "$name.wall"
  awk '{ printf "%.3f\n", $1 + $2 }' "$work/time" >> "$name.cpu"
}
for ((i = 0; i < runs; i++)); do
  timed "$work/default" "$build/cheval" velocity "$work/in.tum" -o "$work/out.tum"
  timed "$work/central" "$build/cheval" velocity "$work/in.tum" --method central -o "$work/central.tum"
  if [[ -n "$baseline" ]]; then
    timed "$work/baseline" "$baseline/cheval" velocity "$work/in.tum" -o "$work/baseline.tum"
  fi
done
if [[ -n "$baseline" ]] && ! cmp -s "$work/out.tum" "$work/baseline.tum"; then
  echo "note: this build's output differs from the baseline's"
fi
stats() { sort -n "$1" | awk '{ v[NR] = $1 } END { printf "%.4f %.4f", v[1], v[int((NR + 1) / 2)] }'; }
lines=$(wc -l < "$work/in.tum")
# The fit's kernels take 8-wide vectors where the CPU has AVX-512 and 4-wide ones elsewhere
# (docs/velocity.md, "Kernels"): figures from machines of the two kinds are not comparable.
vectors=$(grep -q -m1 -w avx512f /proc/cpuinfo 2> /dev/null && echo "AVX-512" || echo "no AVX-512")
cpu=$(grep -m1 "model name" /proc/cpuinfo 2> /dev/null | sed 's/.*: //' || true)
echo "samples: $lines, runs: $runs (alternating), seconds best / median; $(nproc) cores, ${cpu:-unknown CPU}, $vectors"
for kind in wall cpu; do
  read -r dbest dmed <<< "$(stats "$work/default.$kind")"
  read -r cbest cmed <<< "$(stats "$work/central.$kind")"
  echo "$kind default:  $dbest / $dmed"
  echo "$kind central:  $cbest / $cmed"
  awk -v k="$kind" -v d="$dbest" -v c="$cbest" -v dm="$dmed" -v cm="$cmed" \
    'BEGIN { printf "%s ratio default / central: best %.2fx, median %.2fx (target <= 2x)\n", k, d / c, dm / cm }'
  if [[ -n "$baseline" ]]; then
    read -r bbest bmed <<< "$(stats "$work/baseline.$kind")"
    echo "$kind baseline default:  $bbest / $bmed"
    awk -v k="$kind" -v d="$dbest" -v b="$bbest" -v dm="$dmed" -v bm="$bmed" -v c="$cbest" -v cm="$cmed" \
      'BEGIN { printf "%s ratio default / baseline default: best %.2fx, median %.2fx (baseline / central: %.2fx, %.2fx)\n", k, d / b, dm / bm, b / c, bm / cm }'
  fi
done
