#!/usr/bin/python3
"""`cheval velocity` on short simulated recordings with dropouts (docs/velocity.md, "Short recordings with dropouts").

usage: /usr/bin/python3 bench/velocity_short_gaps.py [--cheval build/cheval] [--baseline OTHER_BINARY]
                                                    [--durations 2,5] [--rates 10,20,50] [--only TEXT] [--jobs 2]

The simulator's four kinds (`cheval sim motion --kind K --duration D --rate R --gap-count G --gap-seconds S
--noise N --seed K`) for each duration and rate, with 3 dropouts of 0.3 s, 10 of 0.1 s or 6 of 0.5 s, noise
of 0, 0.1 and 2 mm, seeds 1 and 2; a combination the simulator refuses (dropouts longer than the recording)
is left out. Such recordings have a few dozen samples in a few segments, where the noise level rests on few
differences and the segments' ends on fits across the gaps. Per case: cheval's full-range velocity RMSE
against the simulator's exact velocity at the measured samples, central differences' and the best
Savitzky-Golay window's (local cubic on the stamps, odd windows 5..201 chosen with the truth: an oracle;
both run across dropouts as if they were not there), and cheval over the oracle. With --baseline, another
build's RMSE on the same files and cheval over it, and at the end the geometric mean of that ratio and the
cases more than 5 % better or worse: the comparison of two builds in one run. Exit 0 whatever the numbers
(a report, not a test).
"""
import argparse
import concurrent.futures
import itertools
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from velocity_sweep import SG_WINDOWS, central, rms, savgol, simulate  # noqa: E402

KINDS = ("car", "drone", "handheld", "legged")
DROPOUTS = ((3, 0.3), (10, 0.1), (6, 0.5))
NOISES = (0.0, 1e-4, 2e-3)
SEEDS = (1, 2)


def velocity(binary, measured, out):
    """cheval's velocity at the measured samples, or None where it fails."""
    run = subprocess.run([binary, "velocity", measured, "-o", out, "--quiet"], capture_output=True, text=True)
    return np.loadtxt(out, ndmin=2)[:, 8:11] if run.returncode == 0 else None


def name_of(case):
    kind, duration, rate, (gaps, gap_s), noise, seed = case
    return f"{kind} {rate:g}Hz {duration:g}s {gaps}x{gap_s:g}s {noise * 1e3:g}mm seed {seed}"


def score(args):
    cheval, baseline, case = args
    kind, duration, rate, (gaps, gap_s), noise, seed = case
    name = name_of(case)
    with tempfile.TemporaryDirectory() as work:
        made = simulate(cheval, work, kind, duration, rate, noise, seed, (gaps, gap_s))
        if made is None:
            return name, None
        measured, t, p, v = made
        mine = velocity(cheval, measured, os.path.join(work, "out.tum"))
        other = velocity(baseline, measured, os.path.join(work, "base.tum")) if baseline else None
    if mine is None or (baseline and other is None):
        return name, "cheval velocity failed"
    p = p - p[0]
    best = min(rms(savgol(t, p, w) - v) for w in SG_WINDOWS if w <= len(t))
    return name, (len(t), rms(mine - v), rms(central(t, p) - v), best, rms(other - v) if other is not None else None)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cheval", default="build/cheval")
    parser.add_argument("--baseline", default="", help="another build, run on the same files")
    parser.add_argument("--durations", default="2,5", help="seconds, comma-separated")
    parser.add_argument("--rates", default="10,20,50", help="Hz, comma-separated")
    parser.add_argument("--only", default="", help="keep the cases whose name contains this")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    args = parser.parse_args()
    durations = [float(x) for x in args.durations.split(",")]
    rates = [float(x) for x in args.rates.split(",")]
    cases = [case for case in itertools.product(KINDS, durations, rates, DROPOUTS, NOISES, SEEDS)
             if args.only in name_of(case)]

    print("velocity RMSE in mm/s, full range\n")
    extra = " baseline | /baseline |" if args.baseline else ""
    print("| case | samples | cheval | central | SG best | /SG |" + extra)
    print("|---|---|---|---|---|---|" + "---|---|" * bool(args.baseline))
    ratios, against_baseline = [], []
    with concurrent.futures.ProcessPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        for name, result in pool.map(score, [(args.cheval, args.baseline, case) for case in cases]):
            if result is None:  # the simulator refused the combination
                continue
            if isinstance(result, str):
                print(f"| {name} | FAILED: {result} |||||" + "||" * bool(args.baseline), flush=True)
                continue
            samples, e_ch, e_c, best, e_base = result
            ratios.append(e_ch / best if best > 0 else 1.0)
            columns = ""
            if e_base is not None:
                against_baseline.append(e_ch / e_base if e_base > 0 else 1.0)
                columns = f" {1e3 * e_base:.4f} | {against_baseline[-1]:.3f} |"
            print(f"| {name} | {samples} | {1e3 * e_ch:.4f} | {1e3 * e_c:.4f} | {1e3 * best:.4f} | "
                  f"{e_ch / best if best > 0 else 1.0:.3f} |{columns}", flush=True)
    if ratios:
        mean = np.exp(np.mean(np.log(np.maximum(ratios, 1e-12))))
        above = sum(r > 1.0 for r in ratios)
        print(f"\ngeometric mean of cheval/SG over {len(ratios)} case(s): {mean:.3f}x, {above} above 1")
    if against_baseline:
        r = np.array(against_baseline)
        mean = np.exp(np.mean(np.log(np.maximum(r, 1e-12))))
        print(f"cheval/baseline: geometric mean {mean:.4f}x, {int((r > 1.05).sum())} worse by over 5 %, "
              f"{int((r < 0.95).sum())} better by over 5 %")


if __name__ == "__main__":
    main()
