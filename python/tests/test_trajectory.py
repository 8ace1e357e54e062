"""cheval.Trajectory, read and write: round trips, zero-copy views, and errors with the CLI's messages."""

import os
import tempfile
import unittest

import numpy as np

import cheval
from support import TEST_DATA, run_cli


def example(n=50, velocity=True, angular=False):
    """A small trajectory from arrays: stamps near the EuRoC epoch (1.4e18 ns, beyond float precision)."""
    rng = np.random.default_rng(3)
    stamps = 1_403_636_579_758_555_651 + np.arange(n, dtype=np.int64) * 5_000_001
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return dict(stamps=stamps, positions=rng.normal(size=(n, 3)), quaternions=q,
                velocities=rng.normal(size=(n, 3)) if velocity else None,
                angular_velocities=rng.normal(size=(n, 3)) if angular else None)


class RoundTripTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.tmp.cleanup()

    def path(self, name):
        return os.path.join(self.tmp.name, name)

    def test_arrays_survive_every_writable_format_exactly(self):
        arrays = example()
        t = cheval.Trajectory(**arrays)
        for fmt, has_velocity in (("tum", False), ("tumv", True), ("euroc", True)):
            with self.subTest(format=fmt):
                cheval.write(t, self.path("t." + fmt), format=fmt)
                back = cheval.read(self.path("t." + fmt))
                self.assertEqual(back.format, "tumv" if fmt == "tumv" else fmt)
                # Stamps are exact int64 ns (TUM writes 9 decimals); doubles are written shortest round-trip.
                np.testing.assert_array_equal(back.stamps, arrays["stamps"])
                np.testing.assert_array_equal(back.positions, arrays["positions"])
                np.testing.assert_array_equal(back.quaternions, arrays["quaternions"])
                if has_velocity:
                    np.testing.assert_array_equal(back.velocities, arrays["velocities"])
                else:
                    self.assertIsNone(back.velocities)

    def test_to_text_is_what_write_writes_and_the_cli_converts_the_same(self):
        t = cheval.Trajectory(**example(velocity=True))
        cheval.write(t, self.path("a.txt"), format="tumv")
        with open(self.path("a.txt")) as f:
            self.assertEqual(f.read(), t.to_text("tumv"))
        code, _, err = run_cli("convert", self.path("a.txt"), "-o", self.path("b.csv"), "--to", "euroc")
        self.assertEqual(code, 0, err)
        with open(self.path("b.csv")) as f:
            self.assertEqual(f.read(), cheval.read(self.path("a.txt")).to_text("euroc"))

    def test_columns_select_a_position_only_trajectory(self):
        t = cheval.Trajectory(**example())
        cheval.write(t, self.path("t.csv"), format="euroc")
        p = cheval.read(self.path("t.csv"), columns=["t_ns", "px", "py", "pz"])
        self.assertEqual(p.orientation, "none")
        self.assertIsNone(p.quaternions)
        self.assertIsNone(p.rotations)
        np.testing.assert_array_equal(p.positions, t.positions)
        self.assertEqual(p.format, "csv")

    def test_path_like_and_mapping_sources(self):
        t = cheval.Trajectory(**example())
        cheval.write(t, self.path("t.txt"))
        import pathlib
        back = cheval.read(pathlib.Path(self.path("t.txt")))
        np.testing.assert_array_equal(back.positions, t.positions)
        self.assertEqual(back.path, self.path("t.txt"))
        self.assertEqual(cheval.Trajectory(**back.to_dict()).path, "<array>")


class ZeroCopyTest(unittest.TestCase):
    def test_channels_are_read_only_views_of_the_stored_data(self):
        t = cheval.Trajectory(**example(angular=True))
        for name in ("stamps", "positions", "quaternions", "velocities", "angular_velocities"):
            with self.subTest(channel=name):
                a, b = getattr(t, name), getattr(t, name)
                self.assertFalse(a.flags.owndata)      # a view ...
                self.assertTrue(np.shares_memory(a, b))  # ... of the same memory every time
                self.assertFalse(a.flags.writeable)
                self.assertTrue(a.flags.c_contiguous)
        self.assertEqual(t.positions.shape, (50, 3))
        self.assertEqual(t.quaternions.shape, (50, 4))
        self.assertEqual(t.stamps.dtype, np.int64)

    def test_a_view_keeps_its_trajectory_alive(self):
        positions = cheval.Trajectory(**example()).positions  # the trajectory object is dropped at once
        np.testing.assert_array_equal(positions, example()["positions"])

    def test_rotations_of_quaternions_follow_evo_normalisation(self):
        arrays = example()
        arrays["quaternions"] = arrays["quaternions"] * 3.0  # not unit: normalised on use, as evo
        t = cheval.Trajectory(**arrays)
        np.testing.assert_array_equal(t.quaternions, arrays["quaternions"])  # kept as given
        for R, (x, y, z, w) in zip(t.rotations, arrays["quaternions"] / 3.0):
            expected = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
            np.testing.assert_allclose(R, expected, atol=1e-14)  # rounding of the normalisation only


class ErrorTest(unittest.TestCase):
    def test_every_broken_file_raises_input_error_with_the_cli_message(self):
        folder = os.path.join(TEST_DATA, "bad")
        checked = 0
        for name in sorted(os.listdir(folder)):
            path = os.path.join(folder, name)
            code, _, err = run_cli("info", path)
            with self.subTest(file=name):
                if code == 0:  # readable with format auto (a test of another option's error)
                    self.assertGreater(len(cheval.read(path)), 0)
                    continue
                self.assertEqual(code, 2, err)
                with self.assertRaises(cheval.InputError) as raised:
                    cheval.read(path)
                # The CLI's message, the options spelled as Python's keywords.
                self.assertEqual(str(raised.exception) + "\n",
                                 err.replace("--format", "format").replace("--columns", "columns"))
                self.assertEqual(raised.exception.path, path)
                self.assertTrue(str(raised.exception).endswith(raised.exception.detail))
                checked += 1
        self.assertGreaterEqual(checked, 20)

    def test_the_exception_classes(self):
        self.assertTrue(issubclass(cheval.InputError, ValueError))
        self.assertTrue(issubclass(cheval.UsageError, ValueError))
        self.assertTrue(issubclass(cheval.ComputeError, RuntimeError))
        self.assertTrue(issubclass(cheval.OutputError, OSError))
        for cls in (cheval.InputError, cheval.UsageError, cheval.ComputeError, cheval.OutputError):
            self.assertTrue(issubclass(cls, cheval.Error))

    def test_missing_file(self):
        with self.assertRaises(cheval.InputError) as raised:
            cheval.read("/no/such/file.txt")
        self.assertEqual(str(raised.exception), "/no/such/file.txt:0:0: error: cannot open file: No such file or directory")
        self.assertEqual((raised.exception.line, raised.exception.column), (0, 0))

    def test_unwritable_output_and_missing_channels(self):
        t = cheval.Trajectory(**example(velocity=False))
        with self.assertRaises(cheval.OutputError) as raised:
            cheval.write(t, "/no/such/folder/t.txt")
        self.assertTrue(str(raised.exception).startswith("/no/such/folder/t.txt: error: cannot write"), raised.exception)
        with self.assertRaises(cheval.ComputeError):
            t.to_text("tumv")  # no velocity

    def test_bad_arrays_and_arguments(self):
        arrays = example()
        with self.assertRaises(TypeError) as raised:
            cheval.Trajectory(arrays["stamps"] * 1e-9, arrays["positions"])  # float seconds
        self.assertIn("integer nanoseconds", str(raised.exception))
        with self.assertRaises(cheval.UsageError) as raised:
            cheval.Trajectory(arrays["stamps"], arrays["positions"][:, :2])
        self.assertEqual(str(raised.exception), "positions: expected shape (50, 3) (one row per stamp), got (50, 2)")
        with self.assertRaises(cheval.UsageError) as raised:
            cheval.read(os.path.join(TEST_DATA, "bad", "nan.txt"), format="yaml")
        self.assertIn("unknown format 'yaml'", str(raised.exception))
        with self.assertRaises(cheval.UsageError):
            cheval.read(os.path.join(TEST_DATA, "bad", "nan.txt"), columns="t,px,py")  # no pz


if __name__ == "__main__":
    unittest.main()
