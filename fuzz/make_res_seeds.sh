#!/usr/bin/env bash
# Builds the seed corpus of fuzz_res (docs/fuzzing.md) with cheval's own code: a simulated flight
# evaluated with `cheval ape|rpe --save-results`, the zips re-packed (deflate; evo >= 1.13's .npy
# member names), a lone error array, and numpy layouts the reader accepts (big-endian, int64, a 2-D
# Fortran array) or refuses (a unicode dtype). Small files only (< 4 KiB each).
#
#   fuzz/make_res_seeds.sh CHEVAL_EXE [CORPUS_DIR]      (default: tests/data/fuzz/res)
set -euo pipefail

here="$(cd "$(dirname "$0")" && pwd)"
cheval="$(realpath "$1")"
corpus="${2:-$here/../tests/data/fuzz/res}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
mkdir -p "$corpus"

corpus="$(realpath "$corpus")"
cd "$work"  # relative names in the zips' info.json
"$cheval" sim motion --kind drone --duration 2 --rate 20 --noise 0.01 -o measured.tum --truth truth.tum >/dev/null 2>&1
"$cheval" ape truth.tum measured.tum --align se3 --save-results "$corpus/ape_stored.zip" >/dev/null 2>&1
"$cheval" rpe truth.tum measured.tum --delta 5 --save-results "$corpus/rpe_stored.zip" >/dev/null 2>&1

python3 - "$corpus" <<'PY'
import struct, sys, zipfile, os
corpus = sys.argv[1]
with zipfile.ZipFile(os.path.join(corpus, "ape_stored.zip")) as z:
    members = {n: z.read(n) for n in z.namelist()}
with zipfile.ZipFile(os.path.join(corpus, "ape_deflated_npy_names.zip"), "w", zipfile.ZIP_DEFLATED) as d:
    for name, data in members.items():
        d.writestr(name.replace(".npz", ".npy"), data)
with open(os.path.join(corpus, "error_array.npy"), "wb") as f:
    f.write(members["error_array.npz"])

def npy(descr, shape, fortran, data):
    header = "{'descr': '%s', 'fortran_order': %s, 'shape': %s, }" % (descr, fortran, shape)
    header += " " * ((64 - (10 + len(header) + 1) % 64) % 64) + "\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode() + data

layouts = {
    "big_endian.npy": npy(">f8", "(3,)", False, struct.pack(">3d", 1.5, -2.0, 1e-300)),
    "int64.npy": npy("<i8", "(2,)", False, struct.pack("<2q", -7, 2**62)),
    "fortran_2d.npy": npy("<f4", "(2, 3)", True, struct.pack("<6f", 1, 4, 2, 5, 3, 6)),
    "unicode_refused.npy": npy("<U8", "(1,)", False, b"\0" * 32),
}
for name, data in layouts.items():
    with open(os.path.join(corpus, name), "wb") as f:
        f.write(data)
# A result whose error array is int64 and whose timestamps are big-endian (both read as numbers).
with zipfile.ZipFile(os.path.join(corpus, "mixed_dtypes.zip"), "w") as d:
    d.writestr("info.json", '{"title": "t", "est_name": "e"}')
    d.writestr("stats.json", '{"rmse": 1.0, "max": 2}')
    d.writestr("error_array.npy", layouts["int64.npy"])
    d.writestr("timestamps.npy", npy(">f8", "(2,)", False, struct.pack(">2d", 0.5, 1.5)))
PY
