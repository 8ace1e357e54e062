"""cheval.associate, align, ape, rpe, ase on simulated data: the CLI's JSON and per-pair errors,
arrays in, and the CLI's error messages."""

import csv
import json
import os
import tempfile
import unittest

import numpy as np

import cheval
from support import run_cli


def cli_json(*args):
    """The --json of `cheval ARGS` (and its --errors CSV rows)."""
    with tempfile.TemporaryDirectory() as tmp:
        out, errors = os.path.join(tmp, "r.json"), os.path.join(tmp, "e.csv")
        code, _, err = run_cli(*args, "--json", out, "--errors", errors)
        if code != 0:
            raise AssertionError(f"cheval {' '.join(map(str, args))}: exit {code}: {err}")
        with open(out) as f, open(errors) as g:
            return json.load(f), list(csv.DictReader(g))


# The CLI's flags and Python's keywords for the same options (tools/cheval/option_names.cc,
# python/src/option_names.cc), longest first so that --delta-unit is not read as --delta.
_KEYWORDS = sorted({"--t-max-diff": "t_max_diff", "--t-offset": "t_offset", "--n-align": "n_align",
                    "--align": "align", "--pose-only": "pose_only", "--velocity-frame": "velocity_frame",
                    "--delta-unit": "delta_unit", "--delta": "delta", "--all-pairs": "all_pairs",
                    "--gt-velocity": "gt_velocity", "--columns": "columns", "--format": "format",
                    "--kitti-times": "kitti_times"}.items(), key=lambda item: -len(item[0]))


def as_keywords(message):
    """A CLI message with each flag spelled as Python's keyword."""
    for flag, keyword in _KEYWORDS:
        message = message.replace(flag, keyword)
    return message


def cli_error(*args):
    """The exit code and the message (stderr without the CLI's prefix) of a failing command."""
    code, _, err = run_cli(*args)
    return code, err.removeprefix("cheval: error: ").rstrip("\n")


class SimulatedEvaluationTest(unittest.TestCase):
    """A reference with exact velocity and an estimate with velocity, drift and noise, as files."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        measured, truth = cheval.simulate(kind="handheld", seed=5, noise=0.002, rotation_noise=0.004,
                                          jitter=0.0005, dropout=0.2, duration=20)
        # The estimate: noisy poses with the Chebyshev velocity of their positions, moved rigidly.
        v = cheval.velocity(measured)
        c, s = np.cos(0.3), np.sin(0.3)
        R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
        q = measured.quaternions  # rotated by R about z: q_R * q
        qz = np.array([0, 0, np.sin(0.15), np.cos(0.15)])
        x1, y1, z1, w1 = qz
        x2, y2, z2, w2 = q.T
        moved = np.column_stack([w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2, w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                                 w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2, w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2])
        cls.estimate = cheval.Trajectory(measured.stamps, measured.positions @ R.T + [1.0, -2.0, 0.5], moved,
                                         velocities=v["velocities"] @ R.T)
        cls.truth = truth
        cls.ref_path = os.path.join(cls.tmp.name, "truth.txt")
        cls.est_path = os.path.join(cls.tmp.name, "est.txt")
        cheval.write(truth, cls.ref_path, format="tumv")
        cheval.write(cls.estimate, cls.est_path, format="tumv")

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def check_same_as_cli(self, metric, cli_flags, **options):
        expected, rows = cli_json(metric, self.ref_path, self.est_path, *cli_flags)
        got = getattr(cheval, metric)(self.ref_path, self.est_path, errors=True, **options)
        per_pair = got.pop("errors")
        self.assertEqual(got, expected)  # same keys, same numbers (the same JSON text, parsed)
        # --errors CSV: shortest round-trip numbers, so equal as doubles; stamps in seconds (9 decimals).
        self.assertEqual(len(rows), len(per_pair["error"]))
        np.testing.assert_array_equal(per_pair["error"], [float(r["error"]) for r in rows])
        stamps = [int(r["stamp"].replace(".", "")) for r in rows]
        np.testing.assert_array_equal(per_pair["stamps"], stamps)
        for part in ("rotation", "position", "velocity"):
            if part in rows[0]:
                np.testing.assert_array_equal(per_pair[part], [float(r[part]) for r in rows])
        return got

    def test_ase_with_velocity_and_every_reference_velocity(self):
        for source in ("given", "chebyshev", "central"):
            with self.subTest(gt_velocity=source):
                got = self.check_same_as_cli("ase", ["--align", "se3", "--gt-velocity", source],
                                             align="se3", gt_velocity=source)
                self.assertEqual(got["velocity_source"], source)
                self.assertEqual(set(got["parts"]), {"rotation", "position", "velocity"})
                # The rigid motion is undone: the errors are those of the noise (2 mm, 4 mrad).
                self.assertLess(got["parts"]["position"]["rmse"], 0.004)
        full = self.check_same_as_cli("ase", ["--align", "full", "--association", "continuous"], align="full",
                                      association="continuous")
        self.assertEqual(full["association"]["method"], "continuous")

    def test_ape_and_rpe(self):
        ape = self.check_same_as_cli("ape", ["--align", "posyaw", "-r", "full", "--n-align", "500"],
                                     align="posyaw", relation="full", n_align=500)
        self.assertEqual(ape["alignment"]["pairs_used"], 500)
        self.check_same_as_cli("rpe", ["--delta", "2", "-u", "m", "--all-pairs", "-r", "angle_deg"],
                               delta=2, delta_unit="m", all_pairs=True, relation="angle_deg")
        self.check_same_as_cli("ape", ["--t-offset", "0.001", "--t-max-diff", "0.02"], t_offset=0.001,
                               t_max_diff=0.02)

    def test_arrays_in_give_the_numbers_of_files(self):
        from_files = cheval.ase(self.ref_path, self.est_path, align="se3")
        from_arrays = cheval.ase(self.truth, self.estimate.to_dict(), align="se3")
        self.assertEqual(from_arrays["estimate"]["path"], "<array>")
        self.assertEqual(from_arrays["stats"], from_files["stats"])  # tumv files round-trip exactly
        self.assertEqual(from_arrays["alignment"], from_files["alignment"])

    def test_associate_and_align(self):
        pairs = cheval.associate(self.truth, self.estimate)
        self.assertFalse(pairs["by_index"])
        # Every estimate pose (the shorter file) finds its truth pose within the 0.5 ms jitter.
        np.testing.assert_array_equal(pairs["est"], np.arange(len(self.estimate)))
        dt = self.truth.stamps[pairs["ref"]] - self.estimate.stamps[pairs["est"]]
        self.assertLessEqual(int(np.max(np.abs(dt))), 10_000_000)
        a = cheval.align(self.truth, self.estimate, method="se3")
        ape = cheval.ape(self.truth, self.estimate, align="se3")
        np.testing.assert_array_equal(a["rotation"], ape["alignment"]["rotation"])
        np.testing.assert_array_equal(a["translation"], ape["alignment"]["translation"])
        self.assertEqual(a["pairs_used"], ape["association"]["pairs"])
        # The inverse of the rigid motion applied in setUpClass, to the noise level.
        c, s = np.cos(0.3), np.sin(0.3)
        np.testing.assert_allclose(a["rotation"], [[c, s, 0], [-s, c, 0], [0, 0, 1]], atol=1e-3)

    def test_errors_carry_the_cli_messages(self):
        ref, est = self.ref_path, self.est_path
        cases = [
            (["ape", ref, est, "--t-offset", "1000"], lambda: cheval.ape(ref, est, t_offset=1000.0), cheval.ComputeError, 3),
            (["ape", ref, est, "--n-align", "5"], lambda: cheval.ape(ref, est, n_align=5), cheval.UsageError, 1),
            (["ase", ref, est, "--pose-only", "--velocity-frame", "body"],
             lambda: cheval.ase(ref, est, pose_only=True, velocity_frame="body"), cheval.UsageError, 1),
            (["rpe", ref, est, "--delta", "0"], lambda: cheval.rpe(ref, est, delta=0), cheval.UsageError, 1),
            (["ape", ref, est, "--align", "se3", "--n-align", "2"], lambda: cheval.ape(ref, est, align="se3", n_align=2),
             cheval.ComputeError, 3),
            (["ape", ref, est, "-r", "rot_part", "--est-columns", "t,px,py,pz"],
             lambda: cheval.ape(ref, est, relation="rot_part", est_columns="t,px,py,pz"), cheval.ComputeError, 3),
            (["ase", ref, ref + ".missing"], lambda: cheval.ase(ref, ref + ".missing"), cheval.InputError, 2),
        ]
        for args, call, error, code in cases:
            with self.subTest(args=args[0:1] + args[3:]):
                expected_code, message = cli_error(*args)
                self.assertEqual(expected_code, code)
                with self.assertRaises(error) as raised:
                    call()
                # The same message, each face spelling the options its way.
                self.assertEqual(str(raised.exception), as_keywords(message))

    def test_option_errors_name_the_keyword(self):
        ref, est = self.ref_path, self.est_path
        cases = [
            (lambda: cheval.ape(ref, est, n_align=5), "n_align needs align (se3, sim3, scale, posyaw or full)"),
            (lambda: cheval.ape(ref, est, t_max_diff=-1), "t_max_diff must be >= 0, got -1.000000000 s"),
            (lambda: cheval.rpe(ref, est, delta=1.5), "delta must be an integer for delta_unit frames, got 1.5"),
            (lambda: cheval.ase(ref, est, pose_only=True, velocity_frame="body"),
             "pose_only ignores velocity: drop velocity_frame"),
            (lambda: cheval.velocity(ref, degree="foo"),
             "degree must be auto, cv, chop or a non-negative integer, got 'foo'"),
        ]
        for call, message in cases:
            with self.subTest(message=message):
                with self.assertRaises(ValueError) as raised:
                    call()
                self.assertIsInstance(raised.exception, cheval.UsageError)
                self.assertEqual(str(raised.exception), message)

    def test_python_only_argument_errors(self):
        with self.assertRaises(cheval.UsageError) as raised:
            cheval.ape(self.truth, self.estimate, align="se4")
        self.assertEqual(str(raised.exception),
                         "align: expected one of none, origin, se3, sim3, scale, posyaw, full, got 'se4'")
        with self.assertRaises(TypeError):
            cheval.ape(self.truth, self.estimate, delta=3)  # an rpe option
        with self.assertRaises(TypeError):
            cheval.ape(self.truth, 42)


if __name__ == "__main__":
    unittest.main()
