#!/usr/bin/env bash
# The main job on data cheval makes itself: simulate a drone flight with motion-capture noise,
# summarise it, and convert it between formats. Output goes to demo/ (ignored by git).
set -euo pipefail
cd "$(dirname "$0")/.."

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$(nproc 2>/dev/null || echo 2)" --target cheval_cli
cheval=build/cheval
mkdir -p demo

"$cheval" sim motion --kind drone --seed 7 --noise 0.0005 --duration 60 --rate 200 \
  -o demo/drone_mocap.txt --truth demo/drone_truth.txt
"$cheval" info demo/drone_mocap.txt demo/drone_truth.txt --json demo/info.json
"$cheval" convert demo/drone_truth.txt -o demo/drone_truth.csv --to euroc
"$cheval" info demo/drone_truth.csv
echo "demo: files in demo/; summary in demo/info.json"
