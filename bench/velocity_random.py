#!/usr/bin/python3
"""`cheval velocity` on random cases unlike the generators (docs/velocity.md, "Random cases").

usage: /usr/bin/python3 bench/velocity_random.py [--cheval build/cheval] [--first 0] [--count 100]
                                                [--only TEXT] [--jobs 2] [--regions]

Case k draws, from a generator seeded with k alone (so a case is the same whatever --first/--count):
a motion (a few tones; a broad spectrum; stop-and-go legs with smoothstep speed profiles; a chirp; a
circle; a tremor of 0.3-3 mm on slow motion), a rate of 10-400 Hz, a length of 5, 20 or 60 s, white
noise of 0-1 cm, uneven sampling (stamps jittered by 0-2 ms, then sorted), 0-10 dropouts of 0.05-0.5 s,
and on a quarter of the cases an offset to UTM coordinates (450 km east, 5,300 km north). Per case:
cheval's full-range velocity RMSE against the exact velocity, the best Savitzky-Golay window's (local
cubic on the stamps, odd windows 5..201 chosen with the truth: an oracle), central differences', and
the ratios. Flags, as in bench/velocity_sweep.py: cheval/SG > 1 anywhere, cheval/central > 1 on
noise-free data (noise <= 1 um), cheval/central > 0.2 where noise dominates central differences' error
(its noise part >= 10x its bias). At the end: the geometric mean of cheval/SG and the flagged cases.
The baselines run across dropouts as if they were not there, which favours them where the motion is
smooth. With --regions, each case also says where the two differ: cheval's RMSE over the oracle's
at the recording's ends (the first and last 2 % of the samples, at least 3), next to dropouts (2
samples either side of a step over 3 median steps) and elsewhere, and the geometric means of those
ratios per noise level. Runs `cheval velocity` through files. Exit 0 whatever the flags (a report,
not a test).
"""
import argparse
import concurrent.futures
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from velocity_sweep import SG_WINDOWS, broad, central, evaluate, rms, savgol, tones  # noqa: E402

KINDS = ("tones", "broad", "stopgo", "chirp", "circle", "tremor")
UTM = np.array([4.5e5, 5.3e6, 120.0])


# ---------------------------------------------------------------- motion
def stop_and_go(t, rng, legs=12):
    """Rests and straight moves in turn, each move along a random direction with a smoothstep profile."""
    p, v, at = np.zeros((len(t), 3)), np.zeros((len(t), 3)), np.zeros(3)
    edges = np.r_[0.0, np.sort(rng.uniform(0, t[-1], legs)), t[-1]]
    for i in range(len(edges) - 1):
        a, b = edges[i], edges[i + 1]
        inside = (t >= a) & ((t < b) if i < len(edges) - 2 else True)
        if i % 2 == 0:
            p[inside] = at
            continue
        direction = rng.normal(size=3)
        direction /= np.linalg.norm(direction)
        length = 0.5 * (b - a)
        u = (t[inside] - a) / (b - a)
        s = u**3 * (10 - 15 * u + 6 * u * u)
        ds = 30 * u * u * (1 - u) ** 2 / (b - a)
        p[inside] = at + np.outer(s * length, direction)
        v[inside] = np.outer(ds * length, direction)
        at = at + length * direction
    return p, v


def chirp(t, f0, f1):
    """Three phase-shifted sweeps from f0 to f1 Hz."""
    k = (f1 - f0) / t[-1]
    phase = 2 * np.pi * (f0 * t + 0.5 * k * t * t)
    omega = 2 * np.pi * (f0 + k * t)
    scale = omega.mean()
    p = np.stack([a * np.sin(phase + j) / scale for j, a in enumerate((0.3, 0.2, 0.1))], 1)
    v = np.stack([a * np.cos(phase + j) * omega / scale for j, a in enumerate((0.3, 0.2, 0.1))], 1)
    return p, v


def circle(t, radius, omega):
    p = np.stack([radius * np.cos(omega * t), radius * np.sin(omega * t), 0.1 * t], 1)
    v = np.stack([-radius * omega * np.sin(omega * t), radius * omega * np.cos(omega * t), 0.1 + 0 * t], 1)
    return p, v


def motion(kind, t, rng, rate):
    if kind == "tones":
        return evaluate(tones(rng, rng.uniform(0.02, 0.25) * rate, 5), t)
    if kind == "broad":
        return evaluate(broad(rng, rng.uniform(0.01, 0.15) * rate), t)
    if kind == "stopgo":
        return stop_and_go(t, rng)
    if kind == "chirp":
        return chirp(t, 0.05, rng.uniform(0.02, 0.15) * rate)
    if kind == "circle":
        return circle(t, rng.uniform(0.5, 3), rng.uniform(0.3, 3))
    # tremor: 3 tones of 0.3-3 mm on slow motion
    p, v = evaluate(tones(rng, 0.5, 4), t)
    f = rng.uniform(0.1 * rate, 0.2 * rate, 3) if rate < 20 else rng.uniform(3, min(12, 0.2 * rate), 3)
    phase, amplitude = rng.uniform(0, 2 * np.pi, 3), rng.uniform(0.3e-3, 3e-3)
    arg = 2 * np.pi * f * t[:, None] + phase
    return p + amplitude * np.sin(arg), v + amplitude * 2 * np.pi * f * np.cos(arg)


def draw(case):
    """Case `case`: (name, stamps, measured positions, true velocity, noise-free positions, noise)."""
    rng = np.random.default_rng(case)
    kind = str(rng.choice(KINDS))
    rate = float(rng.choice([10, 20, 30, 50, 100, 120, 200, 400]))
    noise = float(rng.choice([0, 1e-6, 1e-5, 1e-4, 5e-4, 2e-3, 1e-2]))
    jitter = float(rng.choice([0, 0, 0.1, 0.5, 2])) * 1e-3
    duration = float(rng.choice([5, 20, 60]))
    dropouts = int(rng.choice([0, 0, 3, 10]))
    offset = UTM if rng.uniform() < 0.25 else np.zeros(3)
    n = int(duration * rate) + 1
    t = np.arange(n) / rate
    if jitter:
        t = np.sort(t + rng.uniform(-0.5, 0.5, n) * jitter)
    keep = np.ones(n, bool)
    for _ in range(dropouts):
        start = rng.integers(0, n)
        keep[start:start + int(rng.uniform(0.05, 0.5) * rate)] = False
    p, v = motion(kind, t, rng, rate)
    t, p, v = t[keep], p[keep], v[keep]
    measured = p + rng.normal(0, noise, p.shape) if noise else p.copy()
    name = (f"{kind} {rate:g}Hz {duration:g}s {noise * 1e3:g}mm jitter {jitter * 1e3:g}ms "
            f"dropouts {dropouts}{' utm' if offset.any() else ''}")
    return name, t, measured + offset, v, p + offset, noise


# ---------------------------------------------------------------- scoring
def score(args):
    binary, case = args
    name, t, p, truth, clean, noise = draw(case)
    with tempfile.TemporaryDirectory() as work:
        src, out = os.path.join(work, "in.tum"), os.path.join(work, "out.tum")
        np.savetxt(src, np.column_stack([t, p, np.zeros((len(t), 3)), np.ones(len(t))]), fmt="%.9f")
        result = subprocess.run([binary, "velocity", src, "-o", out, "--quiet"], capture_output=True, text=True)
        if result.returncode != 0:
            return case, name, None, f"cheval velocity failed ({result.returncode}): {result.stderr.strip()[:200]}"
        mine = np.loadtxt(out)[:, 8:11]
    # Positions about their first sample: the baselines' differences keep their precision in UTM.
    p, clean = p - p[0], clean - p[0]
    e_ch, vc = rms(mine - truth), central(t, p)
    e_c = rms(vc - truth)
    best, best_w = min((rms(savgol(t, p, w) - truth), w) for w in SG_WINDOWS if w <= len(t))
    sg = savgol(t, p, best_w)
    mine_sq, sg_sq = ((mine - truth) ** 2).sum(1), ((sg - truth) ** 2).sum(1)
    steps = np.diff(t)
    near_gap, ends = np.zeros(len(t), bool), np.zeros(len(t), bool)
    for i in np.nonzero(steps > 3 * np.median(steps))[0]:
        near_gap[max(0, i - 1):i + 3] = True
    k = max(3, len(t) // 50)
    ends[:k], ends[-k:] = True, True
    regions = {}
    for region, mask in (("ends", ends), ("gaps", near_gap & ~ends), ("rest", ~near_gap & ~ends)):
        if mask.any() and sg_sq[mask].sum() > 0:
            regions[region] = np.sqrt(mine_sq[mask].mean() / sg_sq[mask].mean())
    flags = []
    if e_ch > best:
        flags.append("SG")
    if noise <= 1e-6 and e_ch > e_c:
        flags.append("central(noise-free)")
    if rms(vc - central(t, clean)) >= 10 * rms(central(t, clean) - truth) and e_ch > 0.2 * e_c:
        flags.append("0.2x central")
    return case, name, (e_ch, e_c, best, best_w, regions, noise), flags


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cheval", default="build/cheval")
    parser.add_argument("--first", type=int, default=0, help="first case (its seed)")
    parser.add_argument("--count", type=int, default=100, help="number of cases")
    parser.add_argument("--only", default="", help="keep the cases whose name contains this")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--regions", action="store_true", help="where cheval and the oracle differ (ends, dropouts)")
    args = parser.parse_args()
    cases = range(args.first, args.first + args.count)
    if args.only:  # drawn here for the name only; the case is drawn again where it is scored
        cases = [k for k in cases if args.only in draw(k)[0]]

    print("velocity RMSE in mm/s, full range\n")
    extra = " /SG ends | /SG gaps | /SG rest |" if args.regions else ""
    print("| case | motion | cheval | central | SG best (win) | /central | /SG | flags |" + extra)
    print("|---|---|---|---|---|---|---|---|" + "---|" * (3 if args.regions else 0))
    ratios, flagged, failed, by_noise = [], [], 0, {}
    with concurrent.futures.ProcessPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        for case, name, errors, flags in pool.map(score, [(args.cheval, k) for k in cases]):
            if errors is None:
                failed += 1
                print(f"| {case} | {name} | FAILED: {flags} |||||||", flush=True)
                continue
            e_ch, e_c, best, best_w, regions, noise = errors
            ratios.append(e_ch / best if best > 0 else 1.0)
            if flags:
                flagged.append(case)
            columns = ""
            if args.regions:
                columns = "".join(f" {regions[r]:.3f} |" if r in regions else " |" for r in ("ends", "gaps", "rest"))
                for region, ratio in regions.items():
                    by_noise.setdefault((noise, region), []).append(ratio)
            print(f"| {case} | {name} | {1e3 * e_ch:.4f} | {1e3 * e_c:.4f} | {1e3 * best:.4f} ({best_w}) | "
                  f"{e_ch / e_c:.3f} | {e_ch / best:.3f} | {'FAIL ' + ', '.join(flags) if flags else ''} |{columns}",
                  flush=True)
    if ratios:
        print(f"\ngeometric mean of cheval/SG over {len(ratios)} case(s): {np.exp(np.mean(np.log(ratios))):.3f}x")
    print(f"{len(flagged)} case(s) failing a criterion: {' '.join(map(str, flagged))}")
    if by_noise:
        print("\ncheval/SG by region, geometric mean over the cases (count), per noise level:")
        for noise in sorted({n for n, _ in by_noise}):
            parts = [f"{region} {np.exp(np.mean(np.log(by_noise[noise, region]))):.3f} ({len(by_noise[noise, region])})"
                     for region in ("ends", "gaps", "rest") if (noise, region) in by_noise]
            print(f"  {noise * 1e3:g} mm: " + ", ".join(parts))
    if failed:
        print(f"{failed} case(s) where cheval velocity failed")


if __name__ == "__main__":
    main()
