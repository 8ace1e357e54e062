#!/usr/bin/env bash
# The main job on data cheval makes itself: simulate a drone flight with motion-capture noise,
# summarise it, recover its linear and angular velocity from the noisy poses (Chebyshev fits) and
# convert it between formats. Output goes to demo/ (ignored by git).
set -euo pipefail
cd "$(dirname "$0")/.."

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$(nproc 2>/dev/null || echo 2)" --target cheval_cli
cheval=build/cheval
mkdir -p demo

"$cheval" sim motion --kind drone --seed 7 --noise 0.0005 --rotation-noise 0.003 --duration 60 --rate 200 \
  -o demo/drone_mocap.txt --truth demo/drone_truth.txt
"$cheval" info demo/drone_mocap.txt demo/drone_truth.txt --json demo/info.json
"$cheval" velocity demo/drone_mocap.txt --angular -o demo/drone_velocity.txt --json demo/velocity.json
"$cheval" velocity demo/drone_mocap.txt --angular --method central -o demo/drone_velocity_central.txt
"$cheval" convert demo/drone_velocity.txt -o demo/drone_velocity.csv --to euroc
"$cheval" info demo/drone_velocity.csv
# Errors against the simulator's exact truth (same stamps; both files are t x y z qx qy qz qw vx vy vz
# wx wy wz, so after paste the truth's column k is column k + 14).
for f in drone_velocity drone_velocity_central; do
  paste -d' ' "demo/$f.txt" demo/drone_truth.txt | awk -v name="$f" \
    '{ for (k = 9; k <= 11; ++k) { d = $k - $(k + 14); v += d * d }
       for (k = 12; k <= 14; ++k) { d = $k - $(k + 14); w += d * d } n++ }
     END { printf "demo: %-24s velocity RMSE %8.3f mm/s, angular velocity RMSE %8.2f mrad/s\n",
           name, 1000 * sqrt(v / n), 1000 * sqrt(w / n) }'
done
echo "demo: files in demo/; summaries in demo/info.json and demo/velocity.json"
