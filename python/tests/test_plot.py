"""cheval.plot: the figures are written in each format and hold what they should (the paths, the
error colours, one box per estimate and distance, the numbers of cheval.ape / cheval.rpe), and
`python3 -m cheval.plot` writes the same files. Skipped (77) without matplotlib outside CI."""

import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

try:
    import matplotlib  # noqa: F401
except ImportError:
    if os.environ.get("CI", "").lower() not in ("", "0", "false"):
        sys.exit("matplotlib is missing and CI is set (scripts/install-deps.sh installs python3-matplotlib)")
    print("skipped: matplotlib is missing (python3-matplotlib; scripts/install-deps.sh)")
    sys.exit(77)

from matplotlib.collections import LineCollection

import cheval
import cheval.plot as cp


class PlotTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        d = cls.tmp.name
        cls.ref = os.path.join(d, "mocap.tum")
        cls.a = os.path.join(d, "vio_a.txt")
        cls.b = os.path.join(d, "vio_b.txt")
        subprocess.run([os.environ.get("CHEVAL_EXE", "cheval"), "sim", "motion", "--kind", "drone", "--seed", "7",
                        "--noise", "0.0005", "--rotation-noise", "0.003", "--duration", "30", "--rate", "100",
                        "-o", cls.ref, "--estimate", cls.a, "--estimate", cls.b, "--estimate-drift", "0.001", "0.004",
                        "--quiet"], check=True)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def out(self, name):
        return os.path.join(self.tmp.name, name)

    def test_every_format_is_written_with_its_signature(self):
        fig = cp.trajectory(self.ref, [self.a, self.b])
        for suffix, magic in (("pdf", b"%PDF"), ("png", b"\x89PNG"), ("svg", b"<?xml")):
            path = self.out(f"t.{suffix}")
            cp.save(fig, path)
            with open(path, "rb") as f:
                head = f.read(8)
            self.assertTrue(head.startswith(magic), (suffix, head))
            self.assertGreater(os.path.getsize(path), 2000)
            mask = os.umask(0)
            os.umask(mask)
            self.assertEqual(os.stat(path).st_mode & 0o777, 0o666 & ~mask, "the mode of any written file")
        with self.assertRaises(cheval.UsageError):
            cp.save(fig, self.out("t.jpg"))
        self.assertFalse(os.path.exists(self.out("t.jpg")))
        self.assertEqual([f for f in os.listdir(self.tmp.name) if f.startswith(".cheval-plot-")], [])

    def test_trajectory_draws_the_aligned_paths_and_the_errors(self):
        fig = cp.trajectory(self.ref, {"A": self.a, "B": self.b}, color_by_error=True)
        ax = fig.axes[0]
        labels = [line.get_label() for line in ax.get_lines()]
        self.assertIn("reference", labels)
        self.assertNotIn("B", labels, "coloured by error: one estimate, as evo")
        collections = [c for c in ax.collections if isinstance(c, LineCollection)]
        self.assertEqual(len(collections), 1)
        # The colours are A's per-pair APE (after the first pair), the numbers of cheval.ape.
        ape = cheval.ape(self.ref, self.a, align="se3", errors=True)
        np.testing.assert_allclose(collections[0].get_array(), ape["errors"]["error"][1:])
        self.assertEqual(len(fig.axes), 2, "the plot and its colour bar")
        # The aligned estimate lies on the reference (within the drift), not in its own frame.
        reference = cheval.read(self.ref).positions
        both = cp.trajectory(self.ref, {"A": self.a, "B": self.b}).axes[0]
        self.assertEqual([l.get_label() for l in both.get_lines() if not l.get_label().startswith("_")],
                         ["reference", "A", "B"])
        b = [line for line in both.get_lines() if line.get_label() == "B"][0]
        self.assertLess(np.abs(np.asarray(b.get_xdata())[0] - reference[0, 0]), 0.5)
        with self.assertRaises(cheval.UsageError):
            cp.trajectory(self.ref, self.a, plane="xw")

    def test_errors_over_time_and_distributions(self):
        fig = cp.errors_over_time(self.ref, self.a)
        ax = fig.axes[0]
        ape = cheval.ape(self.ref, self.a, align="se3")
        lines = {line.get_label(): line for line in ax.get_lines()}
        self.assertAlmostEqual(lines["rmse"].get_ydata()[0], ape["stats"]["rmse"])
        self.assertEqual(len(lines["vio_a.txt"].get_ydata()), ape["association"]["pairs"])
        box = cp.distribution(self.ref, [self.a, self.b], kind="box")
        self.assertEqual([t.get_text() for t in box.axes[0].get_xticklabels()], ["vio_a.txt", "vio_b.txt"])
        self.assertEqual(box.axes[0].get_ylabel(), "APE (m)")
        degrees = cp.distribution(self.ref, self.a, relation="angle_deg")
        self.assertEqual(degrees.axes[0].get_ylabel(), "APE (deg)")
        # The box's median line is the APE's median.
        median = [line for line in box.axes[0].get_lines() if len(line.get_ydata()) == 2
                  and line.get_ydata()[0] == line.get_ydata()[1]]
        self.assertTrue(any(abs(line.get_ydata()[0] - ape["stats"]["median"]) < 1e-12 for line in median))
        violin = cp.distribution(self.ref, [self.a, self.b], kind="violin")
        self.assertEqual(len(violin.axes[0].collections) >= 2, True)
        with self.assertRaises(cheval.UsageError):
            cp.distribution(self.ref, self.a, kind="pie")

    def test_rpe_per_distance_has_one_box_per_estimate_and_distance(self):
        distances = cp.rpe_distances(self.ref)
        self.assertEqual(len(distances), 5)
        self.assertTrue(all(a < b for a, b in zip(distances, distances[1:])))
        fig = cp.rpe_per_distance(self.ref, [self.a, self.b], distances=distances[:3])
        top, bottom = fig.axes
        # Each box is a patch; two estimates x three distances per axis.
        self.assertEqual(len(top.patches), 6)
        self.assertEqual(len(bottom.patches), 6)
        self.assertEqual([t.get_text() for t in bottom.get_xticklabels()], [f"{d:g}" for d in distances[:3]])

    def test_command_line_writes_the_same_figures(self):
        folder = self.out("figures")
        done = subprocess.run([sys.executable, "-m", "cheval.plot", self.ref, self.a, self.b, "-o", folder,
                               "--format", "svg", "--label", "A", "--label", "B"], capture_output=True, text=True)
        self.assertEqual(done.returncode, 0, done.stderr)
        names = sorted(os.listdir(folder))
        self.assertEqual(names, sorted(f"{n}.svg" for n in ("trajectory", "trajectory_xz", "trajectory_error",
                                                             "ape_over_time", "ape_box", "ape_violin",
                                                             "rpe_per_distance")))
        with open(os.path.join(folder, "trajectory.svg")) as f:
            svg = f.read()
        self.assertIn("<svg", svg)
        bad = subprocess.run([sys.executable, "-m", "cheval.plot", self.ref, self.out("missing.txt"), "-o", folder],
                             capture_output=True, text=True)
        self.assertEqual(bad.returncode, 2, bad.stderr)
        self.assertIn("missing.txt", bad.stderr)


if __name__ == "__main__":
    unittest.main()
