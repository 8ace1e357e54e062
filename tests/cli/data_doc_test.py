#!/usr/bin/env python3
"""Runs every `cheval info` command documented in docs/data.md with the real executable and checks
the poses and duration it reports against the table. Usage: data_doc_test.py CHEVAL DOCS_MD DATA_DIR.
With CI=true a missing data folder is a failure; otherwise the test is skipped (exit 77)."""
import json
import os
import re
import shlex
import subprocess
import sys
import tempfile

cheval, doc, data_dir = sys.argv[1:4]
if not os.path.isdir(data_dir):
    print(f"shared data not found at {data_dir}")
    sys.exit(1 if os.environ.get("CI") == "true" else 77)

rows = re.findall(r"^\| `[^`]+` \| `cheval info ([^`]+)` \| (\d+) \| ([0-9.]+) \| (\d+) \|$", open(doc).read(), re.M)
if len(rows) < 90:
    print(f"expected the whole table in {doc}, found {len(rows)} rows")
    sys.exit(1)
failures = 0
with tempfile.TemporaryDirectory() as tmp:
    out = os.path.join(tmp, "info.json")
    for args, poses, duration, non_increasing in rows:
        args = args.replace("../shared/data", data_dir)
        result = subprocess.run([cheval, "info", *shlex.split(args), "--json", out], capture_output=True, text=True)
        if result.returncode != 0:
            print(f"FAIL (exit {result.returncode}): cheval info {args}\n{result.stderr}")
            failures += 1
            continue
        info = json.load(open(out))
        ok = (info["poses"] == int(poses) and abs(info["duration_s"] - float(duration)) <= 1e-9 * max(1.0, float(duration))
              and info["non_increasing_stamps"] == int(non_increasing))
        if not ok:
            print(f"FAIL: cheval info {args}: poses {info['poses']} duration {info['duration_s']} "
                  f"non-increasing {info['non_increasing_stamps']}; documented {poses} {duration} {non_increasing}")
            failures += 1
print(f"{len(rows) - failures} passed, {failures} failed")
sys.exit(1 if failures else 0)
