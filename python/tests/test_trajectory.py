"""cheval.Trajectory, read and write: round trips, zero-copy views, and errors with the CLI's messages."""

import os
import resource
import subprocess
import tempfile
import unittest

import numpy as np

import cheval
from support import CLI, TEST_DATA, run_cli


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
        with self.assertRaises(TypeError) as raised:  # float seconds are taken (test_arrays_io.py); text is not
            cheval.Trajectory(arrays["stamps"].astype(str), arrays["positions"])
        self.assertIn("integer nanoseconds (int64) or float seconds", str(raised.exception))
        with self.assertRaises(cheval.UsageError) as raised:
            cheval.Trajectory(arrays["stamps"], arrays["positions"][:, :2])
        self.assertEqual(str(raised.exception), "positions: expected shape (50, 3) (one row per stamp), got (50, 2)")
        with self.assertRaises(cheval.UsageError) as raised:
            cheval.read(os.path.join(TEST_DATA, "bad", "nan.txt"), format="yaml")
        self.assertIn("unknown format 'yaml'", str(raised.exception))
        with self.assertRaises(cheval.UsageError):
            cheval.read(os.path.join(TEST_DATA, "bad", "nan.txt"), columns="t,px,py")  # no pz


class ArrayValidationTest(unittest.TestCase):
    """Trajectory() holds arrays to the readers' rules, with their messages (a row where a file has a line)."""

    def assertRefused(self, message, **changes):
        arrays = example(n=5)
        arrays.update(changes)
        with self.assertRaises(ValueError) as raised:
            cheval.Trajectory(**arrays)
        self.assertIsInstance(raised.exception, cheval.InputError)
        self.assertEqual(str(raised.exception), "<array>:0:0: error: " + message)

    def test_non_finite_values_are_refused_as_the_readers_refuse_them(self):
        arrays = example(n=5, angular=True)
        for name, row, column, value in (("positions", 2, 1, np.nan), ("quaternions", 3, 3, np.inf),
                                         ("velocities", 0, 0, -np.inf), ("angular_velocities", 4, 2, np.nan)):
            with self.subTest(name=name):
                bad = arrays[name].copy()
                bad[row, column] = value
                axis = "xyzw"[column]
                changes = {"angular_velocities": arrays["angular_velocities"], name: bad}
                self.assertRefused(f"row {row}: {name}[{row}, {column}] ({axis}) is {value}; expected a finite number",
                                   **changes)

    def test_a_zero_quaternion_is_refused_not_made_the_identity(self):
        q = example(n=5)["quaternions"].copy()
        q[1] = 0.0
        self.assertRefused("row 1: quaternion (quaternions[1]) has zero norm; expected a rotation", quaternions=q)
        q[1] = [1e-9, 0.0, 0.0, 0.0]  # squared norm 1e-18, below evo's threshold: no rotation
        self.assertRefused("row 1: quaternion (quaternions[1]) has zero norm; expected a rotation", quaternions=q)
        q[1] = [1e200, 0.0, 0.0, 0.0]  # squared norm overflows
        self.assertRefused("row 1: quaternion (quaternions[1]) is too large: its squared norm overflows a double; "
                           "expected a rotation", quaternions=q)

    def test_the_readers_zero_quaternion_message(self):
        # The file reader says the same, naming the line and its columns.
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "z.txt")
            with open(path, "w") as f:
                f.write("0 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 0\n")
            with self.assertRaises(cheval.InputError) as raised:
                cheval.read(path)
            self.assertEqual(raised.exception.detail, "quaternion (qx qy qz qw) has zero norm; expected a rotation")

    def test_unsigned_stamps_beyond_int64_are_refused_not_wrapped(self):
        stamps = np.array([0, 1, 2, 2**63, 4], dtype=np.uint64)
        self.assertRefused("row 3: time stamp 9223372036854775808 in stamps[3] is out of range (int64 nanoseconds, "
                           "about ±292 years)", stamps=stamps)
        ok = cheval.Trajectory(np.array([0, 1, 2, 2**63 - 1, 4], dtype=np.uint64), example(n=5)["positions"])
        self.assertEqual(int(ok.stamps[3]), 2**63 - 1)
        with self.assertRaises(cheval.InputError):  # every face that takes stamps
            cheval.velocity(example(n=50), at=np.array([2**64 - 1], dtype=np.uint64))

    def test_stamps_spanning_more_than_int64_are_refused(self):
        stamps = np.array([-5_000_000_000_000_000_000, 0, 5_000_000_000_000_000_000, 1, 2], dtype=np.int64)
        self.assertRefused("row 2: time stamp 5000000000.000000000 s is 1e+10 s away from the stamp of row 0 "
                           "(-5000000000.000000000 s); expected the stamps of one trajectory to span at most int64 "
                           "nanoseconds (about 292 years, 9.2e9 s)", stamps=stamps)
        with self.assertRaises(cheval.InputError) as raised:  # every face that takes stamps
            cheval.fit(stamps, np.zeros((5, 1)))
        self.assertIn("row 2: time stamp 5000000000.000000000 s is 1e+10 s away", str(raised.exception))

    def test_complex_arrays_are_refused_not_truncated(self):
        arrays = example(n=5)
        self.assertRefused("positions: complex values (dtype complex128) are not accepted; expected real numbers (a "
                           "conversion would drop the imaginary part)", positions=arrays["positions"] + 1j)
        self.assertRefused("quaternions: complex values (dtype complex64) are not accepted; expected real numbers (a "
                           "conversion would drop the imaginary part)",
                           quaternions=arrays["quaternions"].astype(np.complex64))
        self.assertRefused("velocities: expected real numbers, got dtype <U3", velocities=np.full((5, 3), "1.0"))
        stamps = np.arange(50, dtype=np.int64) * 10_000_000
        for function in (cheval.fit, cheval.compress):
            with self.subTest(function=function.__name__):
                with self.assertRaises(cheval.InputError) as raised:
                    function(stamps, np.ones((50, 3)) + 1e-3j)
                self.assertEqual(str(raised.exception), "<array>:0:0: error: values: complex values (dtype complex128) "
                                 "are not accepted; expected real numbers (a conversion would drop the imaginary part)")

    def test_a_path_with_a_nul_byte_is_refused_not_cut_short(self):
        with tempfile.TemporaryDirectory() as folder:
            real = os.path.join(folder, "t.txt")
            t = cheval.Trajectory(**example(n=5))
            cheval.write(t, real)
            with self.assertRaises(ValueError) as raised:
                cheval.read(real + "\0ignored")
            self.assertEqual(str(raised.exception), "path: the file name contains a NUL byte (\\0); expected a path")
            with self.assertRaises(ValueError):
                cheval.write(t, os.path.join(folder, "u.txt\0.bak"))
            self.assertEqual(os.listdir(folder), ["t.txt"])
            with self.assertRaises(ValueError):
                cheval.ape(real + "\0x", real)
            with self.assertRaises(ValueError):
                cheval.read_model(real + "\0")
            with self.assertRaises(ValueError):
                cheval.write_model(cheval.compress(t).model, os.path.join(folder, "m.json\0"))

    def test_write_writes_only_what_read_reads_back(self):
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "t.txt")
            for fmt in ("tum", "tumv", "euroc", "kitti"):
                with self.subTest(format=fmt):
                    t = cheval.Trajectory(**example(n=5))
                    cheval.write(t, path, format=fmt)
                    back = cheval.read(path)
                    self.assertEqual(len(back), 5)
            empty = cheval.Trajectory(np.zeros(0, dtype=np.int64), np.zeros((0, 3)), np.zeros((0, 4)))
            with self.assertRaises(cheval.ComputeError) as raised:
                cheval.write(empty, os.path.join(folder, "e.txt"))
            self.assertEqual(str(raised.exception),
                             "cannot write tum: the trajectory has no poses (a file without poses does not read back)")
            self.assertFalse(os.path.exists(os.path.join(folder, "e.txt")))


class InputLimitsTest(unittest.TestCase):
    """The CLI's readers: stamp spans, unbounded inputs and memory, end to end (exit 2, the file named)."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.tmp.cleanup()

    def path(self, name, text=None):
        path = os.path.join(self.tmp.name, name)
        if text is not None:
            with open(path, "w") as f:
                f.write(text)
        return path

    def test_a_stamp_span_beyond_int64_is_exit_2_for_every_command(self):
        path = self.path("span.txt", "".join(f"{t} {i} 0 0 0 0 0 1\n" for i, t in
                                             enumerate([-5e9, -4e9, 0, 4e9, 5e9])))
        message = (path + ":5:1: error: time stamp 5000000000.000000000 s is 1e+10 s away from the stamp of line 1 "
                   "(-5000000000.000000000 s); expected the stamps of one trajectory to span at most int64 "
                   "nanoseconds (about 292 years, 9.2e9 s)\n")
        for args in (["info", path], ["velocity", path, "-o", self.path("v.txt")],
                     ["compress", path, "-o", self.path("m.json")], ["ape", path, path]):
            with self.subTest(command=args[0]):
                code, out, err = run_cli(*args)
                self.assertEqual((code, err), (2, message))
        self.assertEqual(sorted(os.listdir(self.tmp.name)), ["span.txt"])
        with self.assertRaises(cheval.InputError) as raised:
            cheval.read(path)
        self.assertEqual(str(raised.exception) + "\n", message)

    def test_devices_and_fifos_are_read_with_a_bound(self):
        code, _, err = run_cli("info", "/dev/zero")
        self.assertEqual((code, err), (2, "/dev/zero:1:1: error: contains a NUL byte (\\0); expected a text file\n"))
        fifo = self.path("fifo")
        os.mkfifo(fifo)
        writer = subprocess.Popen(["sh", "-c", f"yes 1 | tr -d '\\n' > {fifo}"])
        try:
            code, _, err = run_cli("info", fifo)
        finally:
            writer.kill()
            writer.wait()
        self.assertEqual(code, 2, err)
        self.assertTrue(err.startswith(fifo + ":1:1: error: no newline in the first "), err)

    def test_an_input_larger_than_the_memory_left_is_exit_2_not_an_internal_error(self):
        path = self.path("big.txt", "1.000000000 0.5 0.25 0.125 0 0 0 1\n" * 3_000_000)  # 105 MB
        limit = 100 * 2**20  # address space for the whole process: the poses (192 MB) do not fit

        def limited():
            resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

        done = subprocess.run([CLI, "info", path], capture_output=True, text=True, preexec_fn=limited, check=False)
        self.assertEqual(done.returncode, 2, done.stderr)
        self.assertEqual(done.stderr, path + ":0:0: error: not enough memory to read the file of 105000000 bytes "
                         "(100 MiB): its poses need up to about twice its size; expected a smaller file or more free "
                         "memory\n")


if __name__ == "__main__":
    unittest.main()
