#!/usr/bin/python3
"""`cheval velocity` on bursts of displaced samples (docs/velocity.md, "Jumps and glitches").

usage: /usr/bin/python3 bench/velocity_bursts.py [--cheval build/cheval] [--baseline OTHER_CHEVAL]

Smooth random motion (6 tones per axis up to 3.3 Hz, ~0.3 m/s) at 100 Hz for 20 s under 0.1 mm of
noise, with 8 bursts of 1-5 consecutive samples displaced by 5 mm, 5 cm or 0.5 m: each sample in a
random direction ("xyz") or along x with a random sign ("x"), as a marker swap or a lost track
gives. Per case: velocity RMSE over all samples and over the samples more than two away from any
burst ("clean"), in mm/s, and what `--json` says (outliers, jumps, steps); the running median of
five central differences for comparison. With --baseline, the same for another build side by side.
Deterministic (fixed seeds); exit 0 whatever the numbers (a report, not a test).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import velocity_sweep as sweep  # noqa: E402  (the motion and the baselines)


def run(binary, work, t, p, truth, mask):
    src, out, report = (os.path.join(work, name) for name in ("in.tum", "out.tum", "out.json"))
    np.savetxt(src, np.column_stack([t, p, np.zeros((len(t), 3)), np.ones(len(t))]), fmt="%.9f")
    result = subprocess.run([binary, "velocity", src, "-o", out, "--json", report], capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(f"cheval velocity failed ({result.returncode}): {result.stderr.strip()}")
    error = np.linalg.norm(np.loadtxt(out)[:, 8:11] - truth, axis=1)
    summary = json.load(open(report))
    return (f"{1e3 * np.sqrt(np.mean(error ** 2)):9.1f} | {1e3 * np.sqrt(np.mean(error[mask] ** 2)):6.2f} | "
            f"{summary['outliers']} / {summary['jumps']} / {summary['steps']}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cheval", default="build/cheval")
    parser.add_argument("--baseline", default=None, help="another cheval binary, side by side")
    args = parser.parse_args()

    t = np.arange(2001) / 100.0
    p, v = sweep.evaluate(sweep.tones(np.random.default_rng(55), 100 / 30, 6), t)
    noisy = p + 1e-4 * np.random.default_rng(120).normal(0, 1, p.shape)
    binaries = [args.cheval] + ([args.baseline] if args.baseline else [])
    columns = " | ".join(f"{name}: RMSE | clean | outliers / jumps / steps" for name in binaries)
    print(f"velocity RMSE in mm/s\n\n| burst | {columns} | median-5 |")
    print("|---|" + "---|---|---|" * len(binaries) + "---|")
    with tempfile.TemporaryDirectory() as work:
        for size in (5e-3, 5e-2, 0.5):
            for length in range(1, 6):
                for mode in ("xyz", "x"):
                    rng = np.random.default_rng([121, length, int(size * 1e4)])
                    q = noisy.copy()
                    starts = np.sort(rng.choice(np.arange(50, len(t) - 50), 8, replace=False))
                    mask = np.ones(len(t), bool)
                    for start in starts:
                        d = rng.normal(0, 1, (length, 3))
                        d /= np.linalg.norm(d, axis=1, keepdims=True)
                        if mode == "x":
                            d = np.column_stack([np.sign(d[:, 0]), 0 * d[:, 0], 0 * d[:, 0]])
                        q[start:start + length] += size * d
                        mask[max(0, start - 2):start + length + 2] = False
                    cells = " | ".join(run(b, work, t, q, v, mask) for b in binaries)
                    median5 = sweep.rms(sweep.median5(sweep.central(t, q)) - v)
                    print(f"| {1e3 * size:g} mm x{length} {mode} | {cells} | {1e3 * median5:.1f} |", flush=True)


if __name__ == "__main__":
    main()
