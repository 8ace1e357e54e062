#!/usr/bin/env python3
"""`--save-results` writes evo's result zip: loaded here exactly as evo's file_interface.load_res_file
does (zipfile; each `.npz` member through numpy.load; info.json and stats.json through json), its
statistics and error array must equal cheval's own --json and --errors output, and the members and
their layout must be those of the zips evo wrote (vio_perf's results: info.json, stats.json,
error_array.npz, timestamps.npz, seconds_from_start.npz, stored). Also an RPE, an ASE with its parts,
and the refusal of several estimates.

Usage: evo_res_roundtrip_test.py CHEVAL_EXE DATA_DIR. Exit 0 ok, 1 failure, 77 skip (no data / numpy).
"""
import io
import json
import os
import subprocess
import sys
import tempfile
import zipfile

try:
    import numpy as np
except ImportError:
    print("numpy missing: skipped")
    sys.exit(77)


def load_res_file(path):
    """What evo's load_res_file reads: the arrays by member name, info and stats."""
    arrays = {}
    with zipfile.ZipFile(path) as archive:
        names = archive.namelist()
        assert {"error_array.npz", "info.json", "stats.json"} <= set(names), names
        for name in names:
            if name.endswith(".npz"):
                with io.BytesIO(archive.read(name)) as f:
                    arrays[os.path.splitext(os.path.basename(name))[0]] = np.load(f)
        info = json.loads(archive.read("info.json").decode("utf-8"))
        stats = json.loads(archive.read("stats.json").decode("utf-8"))
        assert archive.testzip() is None, "a CRC does not match"
        kinds = {i.compress_type for i in archive.infolist()}
    return info, stats, arrays, names, kinds


def run(exe, args):
    r = subprocess.run([exe] + args, capture_output=True, text=True)
    return r.returncode, r.stdout, r.stderr


def check(exe, args, tmp, expect_members, failures):
    zip_path, json_path, csv_path = (os.path.join(tmp, n) for n in ("r.zip", "r.json", "e.csv"))
    code, _, err = run(exe, args + ["--save-results", zip_path, "--json", json_path, "--errors", csv_path])
    if code != 0:
        failures.append("%s: exit %d %s" % (args, code, err))
        return
    info, stats, arrays, names, kinds = load_res_file(zip_path)
    with open(json_path) as f:
        ours = json.load(f)["stats"]
    with open(csv_path) as f:
        lines = f.read().splitlines()
    column = lines[0].split(",").index("error")
    rows = [line.split(",") for line in lines[1:]]
    errors = np.array([float(r[column]) for r in rows])
    for key in ("rmse", "mean", "median", "std", "min", "max", "sse"):
        if stats[key] != ours[key]:
            failures.append("%s: stats %s %r != %r" % (args, key, stats[key], ours[key]))
    if arrays["error_array"].dtype != np.float64 or arrays["error_array"].shape != errors.shape:
        failures.append("%s: error_array %s %s" % (args, arrays["error_array"].dtype, arrays["error_array"].shape))
    elif np.max(np.abs(arrays["error_array"] - errors)) > 1e-12 * max(1.0, np.max(np.abs(errors))):
        failures.append("%s: error_array differs from --errors" % args)
    stamps = np.array([float(r[0]) for r in rows])
    if np.max(np.abs(arrays["timestamps"] - stamps)) > 1e-6:
        failures.append("%s: timestamps differ from --errors" % args)
    if arrays["seconds_from_start"][0] != 0.0:
        failures.append("%s: seconds_from_start starts at %r" % (args, arrays["seconds_from_start"][0]))
    for key in ("title", "ref_name", "est_name", "label"):
        if key not in info:
            failures.append("%s: info.json lacks %s" % (args, key))
    if kinds != {zipfile.ZIP_STORED}:
        failures.append("%s: compress types %s, evo stores" % (args, kinds))
    if not set(expect_members) <= set(names):
        failures.append("%s: members %s, expected %s" % (args, names, expect_members))


def main():
    exe, data = sys.argv[1], sys.argv[2]
    evo_zip = os.path.join(data, "vio_perf/commit_b4a7c3f/results/MH_05/vins.zip")
    if not os.path.exists(evo_zip):
        print("shared data missing: skipped")
        return 77
    failures = []
    evo_members = zipfile.ZipFile(evo_zip).namelist()
    gt = os.path.join(data, "ov_data/euroc_mav/MH_05_difficult.csv")
    vins = os.path.join(data, "vio_perf/commit_b4a7c3f/vins/MH_05.tum")
    with tempfile.TemporaryDirectory() as tmp:
        check(exe, ["ape", gt, vins, "-va"], tmp, evo_members, failures)
        check(exe, ["rpe", gt, vins, "-a", "-d", "10", "-u", "m"], tmp, evo_members, failures)
        check(exe, ["ase", gt, vins, "-a", "--pose-only"], tmp, evo_members + ["ase_rotation.npz", "ase_position.npz"],
              failures)
        info = load_res_file(os.path.join(tmp, "r.zip"))[0]
        if info["label"] != "ASE":
            failures.append("ASE label %r" % info["label"])
        code, _, err = run(exe, ["ape", gt, vins, vins, "--save_results", os.path.join(tmp, "two.zip")])
        if code != 1 or "one estimate" not in err or os.path.exists(os.path.join(tmp, "two.zip")):
            failures.append("several estimates: exit %d %s" % (code, err))
    for f in failures:
        print("FAIL", f)
    print("%d failures" % len(failures))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
