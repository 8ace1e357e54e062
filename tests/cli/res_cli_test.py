#!/usr/bin/env python3
"""`cheval res` end to end (docs/cli.md, "cheval res"):
- evo's zips (evo/res_files): the printed table has stats.json's numbers as pandas prints an object
  column (f"{x: .6f}", trailing zeros trimmed), columns in stats.json's order, rows named by the base
  name of est_name; the CSV table has them exactly (repr); --label renames.
- a zip written by `cheval ape --save-results`, as written (stored) and re-packed with deflate, gives
  the numbers of `cheval ape --json`, as the JSON itself does through `cheval res`.
- bad zips (truncated, bad CRC, a missing member, a bad .npy header) are exit 2 naming the member,
  and --save-table writes nothing.

Usage: res_cli_test.py CHEVAL_EXE DATA_DIR. Exit 0 ok, 1 failure, 77 skip (no data).
"""
import csv
import io
import json
import os
import subprocess
import sys
import tempfile
import zipfile

CHEVAL, DATA = sys.argv[1], sys.argv[2]
RES = os.path.join(DATA, "evo", "res_files")
if not os.path.isdir(RES):
    print("shared data missing: skipped")
    sys.exit(77)
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what)


def run(*args):
    p = subprocess.run([CHEVAL, *args], capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def pandas_float(x):
    s = f"{x: .6f}".rstrip("0")
    return s + "0" if s.endswith(".") else s


def csv_table(text):
    rows = list(csv.reader(io.StringIO(text)))
    return rows[0][1:], {r[0]: [float(v) for v in r[1:]] for r in rows[1:]}


# evo's zips: the printed table and the CSV.
for group in (["orb_ape.zip", "sptam_ape.zip"], ["orb_rpe.zip", "sptam_rpe.zip"],
              ["orb_rpe-for-each.zip", "sptam_rpe-for-each.zip"]):
    paths = [os.path.join(RES, g) for g in group]
    code, out, err = run("res", *paths)
    check(code == 0, f"res {group}: exit {code} {err}")
    code, table, err = run("res", *paths, "--table-format", "csv")
    columns, rows = csv_table(table)
    for path in paths:
        with zipfile.ZipFile(path) as z:
            info = json.loads(z.read("info.json"))
            stats = json.loads(z.read("stats.json"))
        label = os.path.basename(info["est_name"])
        check(columns == list(stats), f"{path}: columns {columns} vs {list(stats)}")
        check(rows.get(label) == list(stats.values()), f"{path}: CSV row {rows.get(label)} vs {stats}")
        printed = [line for line in out.splitlines() if line.startswith(label + " ")]
        values = [v for line in printed for v in line[len(label):].split()]
        check(values == [pandas_float(v).strip() for v in stats.values()], f"{path}: printed {values} vs {stats}")
        check(out.startswith("\n" + info["title"] + "\n\n\n"), f"{path}: title missing in {out[:100]!r}")
code, out, _ = run("res", os.path.join(RES, "orb_ape.zip"), "--label", "ORB", "--table-format", "markdown")
check(code == 0 and "| ORB | 1.3034497145650266 |" not in out and "| ORB |" in out, f"--label: {out}")

with tempfile.TemporaryDirectory() as tmp:
    ref, est = os.path.join(DATA, "evo", "fr2_desk_groundtruth.txt"), os.path.join(DATA, "evo", "fr2_desk_ORB.txt")
    zip_path, json_path = os.path.join(tmp, "x.zip"), os.path.join(tmp, "x.json")
    code, _, err = run("ape", ref, est, "-as", "--save-results", zip_path, "--json", json_path)
    check(code == 0, f"ape: {err}")
    with open(json_path) as f:
        stats = json.load(f)["stats"]
    keys = ["rmse", "mean", "median", "std", "min", "max", "sse"]
    deflated = os.path.join(tmp, "deflated.zip")
    with zipfile.ZipFile(zip_path) as z, zipfile.ZipFile(deflated, "w", zipfile.ZIP_DEFLATED) as d:
        for name in z.namelist():
            d.writestr(name, z.read(name))
    for source in (zip_path, deflated, json_path):
        code, table, err = run("res", source, "--table-format", "csv")
        columns, rows = csv_table(table) if code == 0 else ([], {})
        check(code == 0 and columns == keys, f"{source}: {code} {columns} {err}")
        check(rows.get("fr2_desk_ORB.txt") == [stats[k] for k in keys], f"{source}: {rows} vs {stats}")

    # Damaged zips: exit 2, the member named, no table written.
    good = open(zip_path, "rb").read()
    with zipfile.ZipFile(zip_path) as z:
        members = {n: z.read(n) for n in z.namelist()}

    def repack(changed, drop=None):
        path = os.path.join(tmp, "bad.zip")
        with zipfile.ZipFile(path, "w") as d:
            for name, data in members.items():
                if name != drop:
                    d.writestr(name, changed.get(name, data))
        return open(path, "rb").read()

    npy = members["error_array.npz"]
    bad_crc = bytearray(good)
    at = good.find(b"\x93NUMPY") + 100
    bad_crc[at] ^= 0xFF
    cases = {
        "truncated": (good[: len(good) // 2], "no end of central directory"),
        "crc": (bytes(bad_crc), "CRC-32"),
        "missing": (repack({}, drop="stats.json"), "member stats.json is missing"),
        "magic": (repack({"error_array.npz": b"XNUMPY" + npy[6:]}), "member error_array.npz: not a .npy array"),
        "dtype": (repack({"error_array.npz": npy.replace(b"<f8", b"<U8", 1)}), "member error_array.npz: dtype '<U8'"),
        "header": (repack({"timestamps.npz": npy[:40]}), "member timestamps.npz: truncated .npy header"),
    }
    for name, (data, needle) in cases.items():
        path = os.path.join(tmp, name + ".zip")
        with open(path, "wb") as f:
            f.write(data)
        table = os.path.join(tmp, name + ".csv")
        code, out, err = run("res", zip_path, path, "--save-table", table)
        check(code == 2, f"{name}: exit {code}")
        check(err.startswith(path + ":0:0: error:") and needle in err, f"{name}: {err!r}")
        check(not os.path.exists(table) and out == "", f"{name}: something was written")

print(f"{len(failures)} failures" if failures else "ok")
sys.exit(1 if failures else 0)
