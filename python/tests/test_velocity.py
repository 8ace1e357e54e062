"""cheval.simulate, velocity, fit, compress and sample: accuracy on the simulator's exact truth and
the same numbers as the CLI."""

import os
import tempfile
import unittest

import numpy as np

import cheval
from support import run_cli

# The demo's flight (scripts/demo.sh): a drone, motion-capture noise 0.5 mm and 0.003 rad, 60 s at 200 Hz.
DEMO = dict(kind="drone", seed=7, noise=0.0005, rotation_noise=0.003, duration=60, rate=200)


def rmse(a, b):
    """RMS over the samples of the Euclidean norm of the row difference (the demo's definition)."""
    return float(np.sqrt(np.mean(np.sum((a - b) ** 2, axis=1))))


class SimulatorTest(unittest.TestCase):
    def test_simulate_writes_what_the_cli_writes(self):
        measured, truth = cheval.simulate(**DEMO)
        with tempfile.TemporaryDirectory() as tmp:
            code, _, err = run_cli("sim", "motion", "--kind", "drone", "--seed", 7, "--noise", 0.0005,
                                   "--rotation-noise", 0.003, "--duration", 60, "--rate", 200,
                                   "-o", os.path.join(tmp, "m.txt"), "--truth", os.path.join(tmp, "t.txt"))
            self.assertEqual(code, 0, err)
            with open(os.path.join(tmp, "m.txt")) as f:
                self.assertEqual(f.read(), measured.to_text("tum"))
            with open(os.path.join(tmp, "t.txt")) as f:
                self.assertEqual(f.read(), truth.to_text("tumv"))
        self.assertEqual(len(truth), 12001)  # 60 s at 200 Hz, both ends
        self.assertIsNotNone(truth.angular_velocities)
        self.assertIsNone(measured.velocities)

    def test_bad_option_names_the_cli_option(self):
        with self.assertRaises(cheval.UsageError) as raised:
            cheval.simulate(rate=-1)
        self.assertEqual(str(raised.exception), "rate must be a positive number of Hz, got -1")
        with self.assertRaises(cheval.UsageError):
            cheval.simulate(kind="boat")


class VelocityTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.measured, cls.truth = cheval.simulate(**DEMO)

    def test_chebyshev_recovers_the_exact_velocity_far_better_than_central_differences(self):
        np.testing.assert_array_equal(self.measured.stamps, self.truth.stamps)  # no jitter, no dropouts
        cheb = cheval.velocity(self.measured, angular=True)
        central = cheval.velocity(self.measured, angular=True, method="central")
        linear = rmse(cheb["velocities"], self.truth.velocities)
        angular = rmse(cheb["angular_velocities"], self.truth.angular_velocities)
        # README / docs/velocity.md: about 0.24 mm/s and 9 mrad/s, against 122 mm/s and 738 mrad/s for
        # central differences. Bounds at about 2x the measured values: a regression, not noise, breaks them.
        self.assertLess(linear, 0.0005)
        self.assertLess(angular, 0.02)
        self.assertGreater(rmse(central["velocities"], self.truth.velocities), 0.05)
        self.assertGreater(rmse(central["angular_velocities"], self.truth.angular_velocities), 0.3)
        self.assertIsNone(central["curve"])
        self.assertIsNone(central["positions"])
        # The fitted positions are closer to the truth than the 0.5 mm noise.
        self.assertLess(rmse(cheb["positions"], self.truth.positions), 0.0005)
        self.assertEqual(cheb["orientations"].shape, (len(self.truth), 4))
        self.assertLess(cheb["angular_residual_rms"], 0.006)

    def test_outputs_are_not_copied(self):
        v = cheval.velocity(self.measured)
        self.assertTrue(np.shares_memory(v["stamps"], self.measured.stamps))  # the input's own stamps
        self.assertEqual(v["velocities"].shape, (len(self.measured), 3))
        self.assertTrue(v["velocities"].flags.c_contiguous)
        self.assertIsNotNone(v["velocities"].base)  # owned by the library's matrix, not a numpy copy

    def test_same_numbers_as_the_cli(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "m.txt")
            cheval.write(self.measured, path)
            for flags, options in ((["--angular"], dict(angular=True)),
                                   (["--degree", "chop", "--window", "2"], dict(degree="chop", window=2.0)),
                                   (["--degree", "12", "--window", "1"], dict(degree=12, window=1.0)),
                                   (["--method", "central"], dict(method="central"))):
                with self.subTest(flags=flags):
                    out = os.path.join(tmp, "v.txt")
                    code, _, err = run_cli("velocity", path, "-o", out, *flags)
                    self.assertEqual(code, 0, err)
                    cli = cheval.read(out)
                    py = cheval.velocity(path, **options)
                    np.testing.assert_array_equal(py["velocities"], cli.velocities)  # shortest round trip: exact
                    if options.get("angular"):
                        np.testing.assert_array_equal(py["angular_velocities"], cli.angular_velocities)

    def test_at_other_stamps_and_errors(self):
        at = self.truth.stamps[100:200] + 2_500_000  # between the samples
        v = cheval.velocity(self.measured, at=at)
        np.testing.assert_array_equal(v["stamps"], at)
        exact = cheval.simulate(**DEMO)[1]  # same seed: the same motion; velocities at `at` by the truth's curve
        self.assertLess(rmse(v["velocities"], cheval.velocity(exact, at=at)["velocities"]), 0.001)
        with self.assertRaises(cheval.UsageError) as raised:
            cheval.velocity(self.measured, method="savgol", window=0.1)
        self.assertIn("savgol_window", str(raised.exception))
        with self.assertRaises(cheval.UsageError):
            cheval.velocity(self.measured, at=at, method="central")  # only at the trajectory's own stamps
        with self.assertRaises(cheval.UsageError) as raised:
            cheval.velocity(self.measured, window=-1.0)
        self.assertEqual(str(raised.exception), "window must be a positive number of seconds, got -1")
        with self.assertRaises(cheval.UsageError) as raised:
            cheval.velocity(self.measured, threads=-1)
        self.assertEqual(str(raised.exception), "threads must be in 0..256 (0: every core), got -1")

    def test_the_same_numbers_on_any_number_of_threads(self):
        one = cheval.velocity(self.measured, threads=1, angular=True)
        for threads in (2, 3):
            many = cheval.velocity(self.measured, threads=threads, angular=True)
            np.testing.assert_array_equal(many["velocities"], one["velocities"])
            np.testing.assert_array_equal(many["angular_velocities"], one["angular_velocities"])
        curve = cheval.fit(self.measured, threads=2)
        np.testing.assert_array_equal(curve.evaluate(self.truth.stamps, order=1)[1],
                                      cheval.fit(self.measured, threads=1).evaluate(self.truth.stamps, order=1)[1])


    def test_rounded_stamps_are_said(self):
        # 240 Hz written in whole milliseconds (steps of 4 and 5 ms), smooth motion.
        exact = 400_000 + np.round(np.arange(2401) * 1e9 / 240).astype(np.int64)
        stamps = (exact + 500_000) // 1_000_000 * 1_000_000
        t = exact * 1e-9
        positions = np.column_stack([0.2 * np.sin(1.3 * t), 0.1 * np.cos(2.1 * t), 0.05 * np.sin(3.7 * t)])
        out = cheval.velocity({"stamps": stamps, "positions": positions})
        self.assertEqual(out["rounded_stamps"]["resolution_s"], 1e-3)
        self.assertAlmostEqual(out["rounded_stamps"]["rate_hz"], 240.0, places=6)
        truth = np.column_stack([0.26 * np.cos(1.3 * t), -0.21 * np.sin(2.1 * t), 0.185 * np.cos(3.7 * t)])
        central = cheval.velocity({"stamps": stamps, "positions": positions}, method="central")
        self.assertLess(rmse(out["velocities"], truth), 0.1 * rmse(central["velocities"], truth))
        self.assertIsNone(cheval.velocity(self.measured)["rounded_stamps"])

    def test_stamp_noise_is_said(self):
        # Noise-free samples taken at 200 Hz, stamped 0.3 ms (RMS) off the instants they were taken at.
        taken = np.arange(4000) / 200.0
        stamps = np.round((taken + np.random.default_rng(3).normal(0, 3e-4, taken.size)) * 1e9).astype(np.int64)
        w = 2 * np.pi * np.array([[0.7], [2.3], [6.1]])
        positions = (0.3 / w * np.sin(w * taken + [[0.0], [1.0], [2.0]])).T
        out = cheval.velocity({"stamps": stamps, "positions": positions})
        self.assertAlmostEqual(out["curve"].stamp_noise_s, 3e-4, delta=0.6e-4)
        self.assertEqual(cheval.velocity(self.measured)["curve"].stamp_noise_s, 0.0)


    def test_rounded_positions_are_said(self):
        # Slow motion at 500 Hz rounded to the millimetre: a staircase, fitted as motion.
        t = np.arange(5000) / 500.0
        stamps = np.round(t * 1e9).astype(np.int64)
        positions = np.column_stack([0.05 * np.sin(0.5 * t), 0.03 * np.cos(0.4 * t), 0.02 * np.sin(0.3 * t)])
        truth = np.column_stack([0.025 * np.cos(0.5 * t), -0.012 * np.sin(0.4 * t), 0.006 * np.cos(0.3 * t)])
        rounded = {"stamps": stamps, "positions": np.round(positions, 3)}
        out = cheval.velocity(rounded)
        np.testing.assert_allclose(out["curve"].resolution, [1e-3] * 3, rtol=1e-9)
        self.assertEqual(out["curve"].staircase, [True] * 3)  # moving less than a step a sample
        central = cheval.velocity(rounded, method="central")
        self.assertLess(rmse(out["velocities"], truth), 0.1 * rmse(central["velocities"], truth))
        plain = cheval.velocity({"stamps": stamps, "positions": positions})["curve"]
        np.testing.assert_array_equal(plain.resolution, [0.0] * 3)
        self.assertEqual(plain.staircase, [False] * 3)


class FitTest(unittest.TestCase):
    def test_a_polynomial_is_fitted_and_differentiated_exactly(self):
        stamps = np.arange(0, 2001, dtype=np.int64) * 1_000_000  # 2 s at 1 kHz
        t = stamps * 1e-9
        values = np.column_stack([1 + 2 * t - t ** 3, np.cos(0 * t), t ** 2])
        curve = cheval.fit(stamps, values, degree=3)
        self.assertEqual(curve.dimension, 3)
        self.assertEqual(len(curve.windows), 1)  # a fixed degree alone: one global fit
        at = stamps[::7] + 123_456
        v, d, dd = curve.evaluate(at, order=2)
        ta = at * 1e-9
        # Degree 3 reproduces a cubic up to rounding of the least squares on O(1) values.
        np.testing.assert_allclose(v[:, 0], 1 + 2 * ta - ta ** 3, atol=1e-12)
        np.testing.assert_allclose(d[:, 0], 2 - 3 * ta ** 2, atol=1e-10)
        np.testing.assert_allclose(dd[:, 2], 2.0, atol=1e-8)
        self.assertTrue(v.flags.f_contiguous)  # the library's column-major matrix, not copied
        with self.assertRaises(cheval.ComputeError):
            curve.evaluate(np.array([stamps[-1] + 10**9]))  # 1 s after the data
        with self.assertRaises(cheval.UsageError):
            curve.evaluate(at, order=3)

    def test_trajectory_positions_and_diagnostics(self):
        measured, truth = cheval.simulate(kind="car", seed=2, noise=0.001, duration=20)
        curve = cheval.fit(measured)
        self.assertLess(rmse(curve.evaluate(truth.stamps), truth.positions), 0.001)
        self.assertAlmostEqual(float(np.mean(curve.noise_sigma)), 0.001, delta=0.0002)
        self.assertTrue(np.all(np.asarray(curve.noise_sigma_max) >= np.asarray(curve.noise_sigma)))
        # Given, the noise is taken everywhere: nothing is raised.
        given = cheval.fit(measured, noise=0.001)
        self.assertEqual(given.noisier_samples, 0)
        np.testing.assert_array_equal(given.noise_sigma_max, given.noise_sigma)
        self.assertGreater(len(curve.windows), 1)
        self.assertEqual(sum(len(w["degrees"]) for w in curve.windows), 3 * len(curve.windows))


class CompressTest(unittest.TestCase):
    def test_tolerance_model_round_trip_and_cli_parity(self):
        measured, _ = cheval.simulate(kind="handheld", seed=3, noise=0.0002, duration=10)
        c = cheval.compress(measured, tolerance=0.001)
        self.assertLessEqual(c.max_error, 0.001)
        self.assertGreater(c.ratio, 1.0)
        self.assertEqual(c.input_numbers, 3 * len(measured))
        self.assertEqual(c.model_numbers, c.model.number_count)
        back = cheval.sample(c.model, at=measured.stamps)["values"]
        self.assertLessEqual(float(np.max(np.linalg.norm(back - measured.positions, axis=1))), 0.001)
        with tempfile.TemporaryDirectory() as tmp:
            traj, model = os.path.join(tmp, "m.txt"), os.path.join(tmp, "m.json")
            cheval.write(measured, traj)
            code, _, err = run_cli("compress", traj, "-o", model, "--tolerance", 0.001)
            self.assertEqual(code, 0, err)
            with open(model) as f:
                self.assertEqual(f.read(), c.model.to_json())
            grid = cheval.sample(model, rate=50.0)
            code, _, err = run_cli("sample", model, "--rate", 50, "-o", os.path.join(tmp, "s.txt"))
            self.assertEqual(code, 0, err)
            sampled = cheval.read(os.path.join(tmp, "s.txt"))
            np.testing.assert_array_equal(grid["stamps"], sampled.stamps)
            np.testing.assert_array_equal(grid["values"], sampled.positions)
        self.assertEqual(cheval.Model.from_json(c.model.to_json()).to_json(), c.model.to_json())

    def test_errors(self):
        measured, _ = cheval.simulate(kind="legged", seed=1, noise=0.001, duration=5)
        with self.assertRaises(cheval.UsageError) as raised:
            cheval.compress(measured, tolerance=-1.0)
        self.assertEqual(str(raised.exception), "tolerance must be a positive number of metres, got -1")
        with self.assertRaises(cheval.ComputeError):
            cheval.compress(measured, tolerance=1e-9)  # far below the noise
        with self.assertRaises(cheval.InputError) as raised:
            cheval.Model.from_json('{"format": "x"}', "m.json")
        self.assertTrue(str(raised.exception).startswith("m.json:0:0: error: "), raised.exception)
        model = cheval.compress(measured).model
        with self.assertRaises(cheval.ComputeError):
            cheval.sample(model, at=measured.stamps[-1:] + 10**9)
        with self.assertRaises(cheval.UsageError):
            cheval.sample(model)


if __name__ == "__main__":
    unittest.main()
