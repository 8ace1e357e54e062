"""The estimator from Python: the same numbers as `cheval estimate quadrotor --json` on the same
data folder, the states as numpy arrays, and the CLI's errors as exceptions."""

import json
import os
import tempfile
import unittest

import numpy as np

import cheval
from support import run_cli


class EstimatorTest(unittest.TestCase):
    def test_same_result_as_the_cli(self):
        with tempfile.TemporaryDirectory() as work:
            folder = os.path.join(work, "flight")
            cheval.simulate_quadrotor("circle", folder, seed=3, duration=3)
            for name in ("vehicle.json", "landmarks.csv", "measurements.csv", "initial.csv", "truth.csv"):
                self.assertTrue(os.path.isfile(os.path.join(folder, name)), name)
            r = cheval.estimate_quadrotor(data=folder)
            code, _, err = run_cli("estimate", "quadrotor", "--data", folder, "--json", os.path.join(work, "r.json"))
            self.assertEqual(code, 0, err)
            with open(os.path.join(work, "r.json")) as f:
                cli = json.load(f)
            for key in ("states", "segments", "degree", "iterations", "converged"):
                self.assertEqual(r[key], cli[key], key)
            for key in ("rotor_error_rpm", "rotor_error_percent", "position_rmse_m", "rotation_rmse_deg",
                        "velocity_rmse_mps"):
                np.testing.assert_allclose(r[key], cli[key], rtol=1e-12, err_msg=key)
            e = r["estimate"]
            n = len(e["times"])
            self.assertEqual(n, 301)  # the 100 Hz truth of 3 s
            for key, width in (("positions", 3), ("quaternions", 4), ("velocities", 3), ("angular_velocities", 3),
                               ("rotor_speeds", 4)):
                self.assertEqual(e[key].shape, (n, width), key)
            np.testing.assert_allclose(np.linalg.norm(e["quaternions"], axis=1), 1.0, atol=1e-12)
            # The mean rotor speed is near the hover speed sqrt(m g / (4 k_F)) of the vehicle (~1133 rad/s).
            self.assertAlmostEqual(float(np.mean(e["rotor_speeds"])) / 1133.0, 1.0, delta=0.1)
            # The per-motor error the dict reports is the one the arrays give against truth.csv.
            truth = np.loadtxt(os.path.join(folder, "truth.csv"), delimiter=",", skiprows=1)
            np.testing.assert_allclose(truth[:, 0], e["times"], atol=1e-12)
            percent = 100 * np.abs(e["rotor_speeds"] - truth[:, 14:18]).sum(axis=0) / truth[:, 14:18].sum(axis=0)
            np.testing.assert_allclose(percent, r["rotor_error_percent"], rtol=1e-9)

    def test_scenario_with_the_default_vehicle(self):
        self.assertTrue(os.path.isfile(cheval.DEFAULT_VEHICLE))
        r = cheval.estimate_quadrotor(scenario="hover", seed=2, duration=2)
        self.assertEqual(r["segments"], 10)  # the defaults: 0.2 s segments
        self.assertEqual(r["degree"], 4)
        self.assertTrue(all(p < 1.5 for p in r["rotor_error_percent"]), r["rotor_error_percent"])

    def test_errors_carry_the_cli_messages(self):
        with self.assertRaises(cheval.UsageError) as e:
            cheval.estimate_quadrotor(scenario="loop")
        self.assertIn("unknown scenario 'loop'", str(e.exception))
        with self.assertRaises(cheval.UsageError):
            cheval.estimate_quadrotor(scenario="hover", data="somewhere")
        with tempfile.TemporaryDirectory() as work:
            with self.assertRaises(cheval.InputError) as e:
                cheval.estimate_quadrotor(data=os.path.join(work, "missing"))
            self.assertTrue(str(e.exception).startswith(os.path.join(work, "missing") + ":0:0: error:"), str(e.exception))


if __name__ == "__main__":
    unittest.main()
