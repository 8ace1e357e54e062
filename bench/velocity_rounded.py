#!/usr/bin/python3
"""`cheval velocity` on positions rounded to the millimetre (docs/velocity.md, "Rounded positions").

usage: /usr/bin/python3 bench/velocity_rounded.py [--cheval build/cheval] [--baseline OTHER_CHEVAL] [--seeds 3]

20 s of six tones per axis up to 3.3 Hz (the sweep's `tones`, velocity ~0.3 m/s), slowed 1x to 100x (positions and
velocities divided), sampled at 100, 200 and 1000 Hz, rounded to 1 mm, and optionally with white noise of 1/100,
1/20, 1/10, 1/5 and 3/10 of the step added before rounding (at 1000 Hz, slowed 10x). Per case, pooled over seeds 1..SEEDS: cheval's
velocity RMSE against the exact velocity, a baseline build's if given, and the best Savitzky-Golay window's (local
cubic, odd windows 5..59 and 61..2001 by 20, chosen with the truth: an oracle), with both ratios to it. Deterministic.
Exit 0 whatever the numbers (a report, not a test).
"""
import argparse
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from velocity_sweep import evaluate, rms, run_cheval, savgol, tones  # noqa: E402

CASES = [(rate, slowed, 0.0) for rate in (100, 200, 1000) for slowed in (1, 3, 10, 100)] + \
        [(1000, 10, noise) for noise in (1e-5, 5e-5, 1e-4, 2e-4, 3e-4)]
WINDOWS = list(range(5, 60, 2)) + list(range(61, 2002, 20))
STEP = 1e-3


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cheval", default="build/cheval")
    parser.add_argument("--baseline", default="", help="another build's cheval, run on the same files")
    parser.add_argument("--seeds", type=int, default=3)
    args = parser.parse_args()
    binaries = [args.cheval] + ([args.baseline] if args.baseline else [])
    print("velocity RMSE in mm/s, pooled over seeds 1..%d; SG best = the oracle window\n" % args.seeds)
    print("| rate, slowed, noise | cheval |%s SG best | /SG |%s" % (" baseline |" if args.baseline else "",
                                                                   " baseline /SG |" if args.baseline else ""))
    print("|---|---|%s---|---|%s" % ("---|" if args.baseline else "", "---|" if args.baseline else ""))
    with tempfile.TemporaryDirectory() as work:
        for rate, slowed, noise in CASES:
            squares = np.zeros(len(binaries) + 1)
            for seed in range(1, args.seeds + 1):
                rng = np.random.default_rng(seed)
                t = np.arange(0.0, 20.0, 1.0 / rate)
                p, v = evaluate(tones(rng, 3.3, 6), t)
                p, v = p / slowed, v / slowed
                measured = np.round((p + noise * rng.standard_normal(p.shape)) / STEP) * STEP
                for k, binary in enumerate(binaries):
                    squares[k] += rms(run_cheval(binary, work, t, measured) - v) ** 2
                squares[-1] += min(rms(savgol(t, measured, w) - v) for w in WINDOWS if w <= len(t)) ** 2
            errors = np.sqrt(squares / args.seeds) * 1e3
            oracle = errors[-1]
            row = "| %d Hz, %dx, %g mm | %.3f |" % (rate, slowed, noise * 1e3, errors[0])
            if args.baseline:
                row += " %.3f |" % errors[1]
            row += " %.3f | %.2f |" % (oracle, errors[0] / oracle)
            if args.baseline:
                row += " %.2f |" % (errors[1] / oracle)
            print(row, flush=True)


if __name__ == "__main__":
    main()
