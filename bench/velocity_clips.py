#!/usr/bin/python3
"""`cheval velocity` on short clips of the simulator's motion (docs/velocity.md, "The ends of a short noisy clip").

usage: /usr/bin/python3 bench/velocity_clips.py [--cheval build/cheval] [--seeds 8] [--only TEXT]

Clips of 0.3, 0.5, 1 and 2 s at 100 Hz (30 to 200 samples) of the simulator's car, drone, hand-held and
legged motion under 0.5 and 2 mm of noise (`cheval sim motion --kind K --duration D --rate 100 --noise N
--seed S`, seeds 1..SEEDS), each through `cheval velocity`. Per case, pooled over the seeds: cheval's
velocity RMSE against the simulator's exact velocity, that of its first and last three samples, the best
Savitzky-Golay window's (local cubic on the stamps, every odd window up to the clip's length, chosen with
the truth: an oracle), central differences', and cheval over the oracle; at the end the geometric mean
of that ratio over the cases printed. Deterministic. Exit 0 whatever the numbers (a report, not a test).
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from velocity_sweep import central, rms, savgol, simulate  # noqa: E402

KINDS = ("car", "drone", "handheld", "legged")
DURATIONS = (0.3, 0.5, 1.0, 2.0)
NOISES = (0.0005, 0.002)


def clip(cheval, folder, kind, duration, noise, seed):
    """One clip's velocity RMSE (m/s): cheval's, at its first and last three samples, the oracle's, central differences'."""
    measured, stamps, positions, v = simulate(cheval, folder, kind, duration, 100, noise, seed)
    out = os.path.join(folder, "o.tum")
    subprocess.run([cheval, "velocity", measured, "-o", out, "--quiet"], check=True, capture_output=True)
    error = np.loadtxt(out)[:, 8:11] - v
    oracle = min(rms(savgol(stamps, positions, w) - v) for w in range(5, len(stamps) + 1, 2))
    return np.array([rms(error), rms(np.r_[error[:3], error[-3:]]), oracle, rms(central(stamps, positions) - v)])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cheval", default="build/cheval")
    parser.add_argument("--seeds", type=int, default=8)
    parser.add_argument("--only", default="", help="only the cases whose name contains this")
    args = parser.parse_args()
    print("velocity RMSE in mm/s, pooled over seeds 1..%d; SG best = the oracle window\n" % args.seeds)
    print("| clip | cheval | ends | SG best | central | /SG |")
    print("|---|---|---|---|---|---|")
    ratios = []
    with tempfile.TemporaryDirectory() as folder:
        for duration in DURATIONS:
            for noise in NOISES:
                for kind in KINDS:
                    name = "%s %g s, %g mm" % (kind, duration, noise * 1e3)
                    if args.only not in name:
                        continue
                    squares = sum(clip(args.cheval, folder, kind, duration, noise, seed) ** 2
                                  for seed in range(1, args.seeds + 1))
                    cheval, ends, oracle, plain = np.sqrt(squares / args.seeds) * 1e3
                    ratios.append(cheval / oracle)
                    print("| %s | %.2f | %.1f | %.2f | %.1f | %.2f |" % (name, cheval, ends, oracle, plain, ratios[-1]),
                          flush=True)
    if ratios:
        print("\ngeometric mean of cheval / SG best over %d cases: %.3f" % (len(ratios), np.exp(np.mean(np.log(ratios)))))


if __name__ == "__main__":
    main()
