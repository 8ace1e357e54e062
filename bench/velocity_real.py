#!/usr/bin/python3
"""`cheval velocity` on real ground truth of ../shared/data (docs/velocity.md, "Real ground truth").

usage: /usr/bin/python3 bench/velocity_real.py [--cheval build/cheval] [--data /work/shared/data] [--only TEXT]

Files that carry their own velocity (DIDO, the RPNG AR table, Blackbird) are scored against it. Files
that do not (TUM fr1/xyz and fr2/desk, TUM-VI room1, the iCub's Vicon base) are scored against a
secant over +-max(30 ms, 8 median steps) (p(t+H) - p(t-H)) / 2H: a reference of its own error (its
bias grows with the acceleration, its noise is ~sigma/H), which cannot rank methods within a few per
cent but does show velocities that are wrong by far more than the motion allows; hence the count of
samples more than 0.3 m/s off it. Baselines, computed here: central differences on the stamps and the
running median of five of them. Per row: RMS, median, 99th percentile and largest error in mm/s, and
that count. Exit 0 whatever the numbers (a report, not a test).
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

# name, path under the data folder, cheval's reading options, columns of t and p in the file as numpy
# reads it (delimiter, header rows, time scale to seconds), velocity columns or None.
FILES = [
    ("TUM fr1/xyz", "evo/freiburg1_xyz-groundtruth.txt", ["--format", "tum"], (None, "#", 1.0, 0, [1, 2, 3]), None),
    ("TUM fr2/desk", "evo/fr2_desk_groundtruth.txt", ["--format", "tum"], (None, "#", 1.0, 0, [1, 2, 3]), None),
    ("TUM-VI room1", "ov_data/tum_vi/dataset-room1_512_16.csv", ["--format", "euroc"],
     (",", "#", 1e-9, 0, [1, 2, 3]), None),
    ("iCub walking", "icub_diligent_kio/walking.csv",
     ["--format", "csv", "--columns", "t,px,py,pz"], (",", "t", 1.0, 0, [1, 2, 3]), None),
    ("RPNG table_01", "ov_data/rpng_plane/table_01.csv", ["--format", "csv", "--columns",
                                                          "t_ns,px,py,pz,qw,qx,qy,qz,vx,vy,vz"],
     (",", "#", 1e-9, 0, [1, 2, 3]), [8, 9, 10]),
    ("Blackbird clover", "blackbird_imo/clover_yawForward_maxSpeed5p0/test/stamped_groundtruth_imu.txt",
     ["--format", "tumv"], (None, "#", 1.0, 0, [1, 2, 3]), [8, 9, 10]),
    ("DIDO circle", "dido/csv/circle_a_1.5_v_2.5_r_1.5_2022-02-21-23-46-22.csv",
     ["--format", "csv", "--columns", "t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz"], (",", "t", 1.0, 0, [1, 2, 3]),
     [8, 9, 10]),
    ("DIDO eight", "dido/csv/eight_a_2.2_v_3.5_rx_1.8_2022-02-22-11-50-24.csv",
     ["--format", "csv", "--columns", "t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz"], (",", "t", 1.0, 0, [1, 2, 3]),
     [8, 9, 10]),
]


def load(path, delimiter, comment, scale):
    if comment == "#":
        data = np.loadtxt(path, delimiter=delimiter, comments="#")
    else:  # a header row that starts with a name
        data = np.loadtxt(path, delimiter=delimiter, skiprows=1)
    return data[:, 0] * scale, data


def central(t, p):
    """Central differences on the stamps, across samples with equal stamps."""
    v = np.zeros_like(p)
    n = len(t)
    for i in range(n):
        a, b = i - 1, i + 1
        while a > 0 and t[a] >= t[i]:
            a -= 1
        while b < n - 1 and t[b] <= t[i]:
            b += 1
        a, b = max(a, 0), min(b, n - 1)
        if t[b] > t[a]:
            v[i] = (p[b] - p[a]) / (t[b] - t[a])
    return v


def median5(v):
    padded = np.concatenate([v[:1].repeat(2, 0), v, v[-1:].repeat(2, 0)])
    return np.median(np.stack([padded[k:k + len(v)] for k in range(5)]), axis=0)


def secant(t, p):
    h = max(0.03, 8 * np.median(np.diff(t)))
    a = np.searchsorted(t, t - h)
    b = np.clip(np.searchsorted(t, t + h, side="right") - 1, 0, len(t) - 1)
    return (p[b] - p[a]) / np.maximum(t[b] - t[a], 1e-9)[:, None], h


def row(label, v, reference):
    e = np.linalg.norm(v - reference, axis=1)
    return (f"| {label} | {np.sqrt(np.mean(e ** 2)) * 1e3:.3f} | {np.median(e) * 1e3:.3f} | "
            f"{np.percentile(e, 99) * 1e3:.2f} | {e.max() * 1e3:.1f} | {int((e > 0.3).sum())} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cheval", default="build/cheval")
    parser.add_argument("--data", default="../shared/data")
    parser.add_argument("--only", default="")
    args = parser.parse_args()
    print("velocity error in mm/s (and samples more than 0.3 m/s off) against each file's own velocity or a secant\n")
    print("| file, method | RMS | median | p99 | max | > 0.3 m/s |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as work:
        for name, relative, options, (delimiter, comment, scale, _, position_columns), velocity_columns in FILES:
            if args.only not in name:
                continue
            path = os.path.join(args.data, relative)
            if not os.path.exists(path):
                print(f"| {name}: missing {path} | | | | | |")
                continue
            t, data = load(path, delimiter, comment, scale)
            order = np.argsort(t, kind="stable")
            t, data = t[order], data[order]
            p = data[:, position_columns]
            out = os.path.join(work, "out.txt")
            run = subprocess.run([args.cheval, "velocity", path, *options, "-o", out], capture_output=True, text=True)
            if run.returncode != 0:
                print(f"| {name}: cheval failed: {run.stderr.strip()} | | | | | |")
                continue
            written = np.loadtxt(out)
            written = written[np.argsort(written[:, 0], kind="stable")]
            chebyshev = written[:, 8:11]
            if velocity_columns is not None:
                reference, what = data[:, velocity_columns], "own velocity"
            else:
                reference, h = secant(t, p)
                what = f"secant +-{h * 1e3:.0f} ms"
            c = central(t, p)
            print(f"| **{name}** ({len(t)} samples, {1 / np.median(np.diff(t)):.0f} Hz; {what}) | | | | | |")
            print(row("cheval", chebyshev, reference))
            print(row("central differences", c, reference))
            print(row("median of 5 central", median5(c), reference))
    return 0


if __name__ == "__main__":
    sys.exit(main())
