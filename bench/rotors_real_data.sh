#!/bin/sh
# The rotor-speed table of docs/estimator_real_data.md: identification on the three shared Crazyflie
# flights, the estimate of each with it, and the leave-one-out check (identify on two, estimate the
# third); per flight the flatness baseline, the estimate's per-motor error and the estimate's time per
# minute of flight (the issue's target: <= 1 s per minute at 100 Hz).
# Usage: bench/rotors_real_data.sh [CHEVAL_EXE] [DATA_DIR] [OUT_DIR]
set -eu
CHEVAL=${1:-build/cheval}
D=${2:-${CHEVAL_DATA_DIR:-../shared/data}}/crazyflie_brushless_idsia
OUT=${3:-$(mktemp -d)}
mkdir -p "$OUT"
BASE=$(dirname "$0")/../data/vehicles/crazyflie21_brushless.json
FLIGHTS="square_20251017_run1 random1_20251017_run1 melon_20251017_run5"
row() {  # flight vehicle label
  "$CHEVAL" -q estimate rotors --data "$D/$1.csv" --vehicle "$2" --json "$OUT/$1.$3.json" > /dev/null
  python3 - "$OUT/$1.$3.json" "$1" "$3" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
f = lambda v: " ".join("%.2f" % x for x in v)
print("| %s | %s | %s | %s | %.2f s for %.1f s = %.2f s/min |" % (sys.argv[2], sys.argv[3], f(r["flatness_error_percent"]),
      f(r["rotor_error_percent"]), r["seconds"], r["duration_s"], 60 * r["seconds"] / r["duration_s"]))
PY
}
echo "| flight | vehicle | flatness % (m1..m4) | cheval % (m1..m4) | time |"
echo "|---|---|---|---|---|"
for f in $FLIGHTS; do row "$f" "$BASE" published; done
ALL=""
for f in $FLIGHTS; do ALL="$ALL --data $D/$f.csv"; done
"$CHEVAL" -q identify rotors $ALL --vehicle "$BASE" -o "$OUT/all.json" > "$OUT/all.txt"
for f in $FLIGHTS; do row "$f" "$OUT/all.json" "identified on all 3"; done
for f in $FLIGHTS; do
  TRAIN=""
  for g in $FLIGHTS; do [ "$g" = "$f" ] || TRAIN="$TRAIN --data $D/$g.csv"; done
  "$CHEVAL" -q identify rotors $TRAIN --vehicle "$BASE" -o "$OUT/loo_$f.json" > "$OUT/loo_$f.txt"
  row "$f" "$OUT/loo_$f.json" "left out (identified on the other 2)"
done
echo
cat "$OUT/all.txt"
# Stability of θ across training sets: per free parameter, the largest |θ(left out) − θ(all 3)| over
# the three left-out sets, in units of the larger of the two σ.
python3 - "$OUT" $FLIGHTS <<'PY'
import json, sys
out, flights = sys.argv[1], sys.argv[2:]
ident = lambda path: json.load(open(path))["identified"]
every = ident(out + "/all.json")
names = ["k_m1", "k_m2", "k_m3", "k_m4", "J_x", "J_y", "J_z", "k_M", "tau0_x", "tau0_y", "tau0_z",
         "drag_xy", "drag_z", "moment_x", "moment_y", "rotor_inertia"]  # θ's order (rotor_model.h)
worst = {}
for f in flights:
    left = ident("%s/loo_%s.json" % (out, f))
    for i, name in enumerate(names):
        s = max(left["theta_sigma"][i], every["theta_sigma"][i])
        if s > 0:
            worst[name] = max(worst.get(name, 0.0), abs(left["theta"][i] - every["theta"][i]) / s)
print("stability (largest left-out difference / sigma): " + ", ".join("%s %.1f" % kv for kv in worst.items()))
n = len(worst)
print("within 1 sigma: %d of %d, 2 sigma: %d, 3 sigma: %d" % tuple([sum(v <= k for v in worst.values()) for k in (1,)] + [n] +
      [sum(v <= k for v in worst.values()) for k in (2, 3)]))
PY
echo "outputs in $OUT"
