"""Imports the installed Python module cheval from the install prefix and uses it: proves the
module, its package folder and its numpy hand-over were installed and work.
Usage: consumer.py SITE (the folder the package was installed into)."""

import os
import sys

import numpy as np

import cheval

site = os.path.realpath(sys.argv[1])
where = os.path.realpath(os.path.dirname(cheval.__file__))
assert where == os.path.join(site, "cheval"), f"imported {where}, not the installed {site}/cheval"
t = cheval.Trajectory(np.array([1403636579758555651, 1403636579763555651]), [[1.0, 2.0, 3.0], [1.5, 2.0, 3.0]],
                      [[0, 0, 0, 1], [0, 0, 0, 1]])
text = t.to_text("tum")
assert text.startswith("1403636579.758555651 1 2 3 0 0 0 1\n"), text
try:
    cheval.ape(t, t, align="se3")
    raise AssertionError("an alignment from 2 pairs must fail")
except cheval.ComputeError as e:
    assert "at least 3 associated pairs, got 2" in str(e), e
assert os.path.realpath(cheval.DEFAULT_VEHICLE).startswith(where), cheval.DEFAULT_VEHICLE  # inside the package
r = cheval.estimate_quadrotor(scenario="hover", duration=1)
assert r["segments"] == 5 and len(r["estimate"]["times"]) == 101, r  # 0.2 s segments by default
print(f"cheval imported from {where}; {len(t)} poses")
