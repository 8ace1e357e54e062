#!/usr/bin/env bash
# The main job on data cheval makes itself (files in demo/, ignored by git):
#  1. simulate a drone flight: motion capture with noise (the reference, poses only) and two simulated
#     visual-inertial odometry outputs with drifting errors (the estimates, with velocity);
#  2. ground-truth velocity from the motion capture by Chebyshev fitting, and its error against the
#     simulator's exact velocity next to central differences;
#  3. evaluate the estimates: APE, and the state error ASE with Chebyshev reference velocity (C-ASE);
#  4. one HTML report of it all (demo/report.html, opens offline);
#  5. the pseudo-spectral estimator: a quadrotor's rotor speeds from a camera and its dynamics.
set -euo pipefail
cd "$(dirname "$0")/.."

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$(nproc 2>/dev/null || echo 2)" --target cheval_cli
cheval=build/cheval
mkdir -p demo

echo "== 1. simulate"
"$cheval" sim motion --kind drone --seed 7 --noise 0.0005 --rotation-noise 0.003 --duration 60 --rate 200 \
  -o demo/mocap.txt --truth demo/truth.txt \
  --estimate demo/vio_a.txt --estimate demo/vio_b.txt --estimate-drift 0.001 0.004
"$cheval" info demo/mocap.txt --json demo/info.json

echo "== 2. ground-truth velocity from the motion capture"
"$cheval" velocity demo/mocap.txt --angular -o demo/mocap_velocity.txt --json demo/velocity.json
"$cheval" velocity demo/mocap.txt --angular --method central -o demo/mocap_velocity_central.txt --quiet
# Errors against the simulator's exact truth (same stamps; both files are t x y z qx qy qz qw vx vy vz
# wx wy wz, so after paste the truth's column k is column k + 14).
for f in mocap_velocity mocap_velocity_central; do
  paste -d' ' "demo/$f.txt" demo/truth.txt | awk -v name="$f" \
    '{ for (k = 9; k <= 11; ++k) { d = $k - $(k + 14); v += d * d }
       for (k = 12; k <= 14; ++k) { d = $k - $(k + 14); w += d * d } n++ }
     END { printf "demo: %-24s velocity RMSE %8.3f mm/s, angular velocity RMSE %8.2f mrad/s\n",
           name, 1000 * sqrt(v / n), 1000 * sqrt(w / n) }'
done

echo "== 3. evaluate the two estimates against the motion capture"
"$cheval" ape demo/mocap.txt demo/vio_a.txt demo/vio_b.txt --align se3 --json demo/ape.json | tail -4
"$cheval" ase demo/mocap.txt demo/vio_a.txt demo/vio_b.txt --align se3 --gt-velocity chebyshev \
  --json demo/ase.json | tail -4

echo "== 4. the report"
"$cheval" report demo/mocap.txt demo/vio_a.txt demo/vio_b.txt -o demo/report.html

echo "== 5. rotor speeds from a camera and the dynamics"
"$cheval" sim quadrotor --scenario figure8 --seed 1 -o demo/quadrotor
"$cheval" estimate quadrotor --data demo/quadrotor --json demo/estimate.json -o demo/estimate.csv
echo "demo: files in demo/; open demo/report.html in a browser"
