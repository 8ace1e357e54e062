"""Arrays in and out (#15): quat_order 'wxyz' | 'xyzw' on read, Trajectory and the functions taking
mappings; float-second stamps converted as the readers convert decimal text (the shortest
round-trip decimal of each float, then exact decimal to nanoseconds, halves to even); align()
returning the aligned estimate."""

import decimal
import os
import unittest

import numpy as np

import cheval
from support import DATA, main_needing

EVO = os.path.join(DATA, "evo")
GT, ORB = os.path.join(EVO, "fr2_desk_groundtruth.txt"), os.path.join(EVO, "fr2_desk_ORB.txt")


def nanoseconds(seconds):
    """The definition: repr(x) (shortest round-trip digits) times 1e9, rounded half to even, exactly."""
    value = decimal.Decimal(repr(float(seconds))) * decimal.Decimal(10) ** 9
    return int(value.quantize(decimal.Decimal(1), rounding=decimal.ROUND_HALF_EVEN))


class QuatOrderTest(unittest.TestCase):
    def test_read_gives_w_first_on_request(self):
        xyzw, wxyz = cheval.read(ORB), cheval.read(ORB, quat_order="wxyz")
        self.assertEqual((xyzw.quat_order, wxyz.quat_order), ("xyzw", "wxyz"))
        np.testing.assert_array_equal(wxyz.quaternions, xyzw.quaternions[:, [3, 0, 1, 2]])
        np.testing.assert_array_equal(wxyz.rotations, xyzw.rotations)
        with self.assertRaisesRegex(cheval.UsageError, "quat_order: expected 'xyzw' or 'wxyz', got 'wxzy'"):
            cheval.read(ORB, quat_order="wxzy")

    def test_arrays_in_either_order_are_the_same_trajectory(self):
        t = cheval.read(ORB)
        arrays = t.to_dict()
        w_first = dict(arrays, quaternions=arrays["quaternions"][:, [3, 0, 1, 2]])
        u = cheval.Trajectory(**w_first, quat_order="wxyz")
        np.testing.assert_array_equal(u.rotations, t.rotations)
        np.testing.assert_array_equal(u.quaternions, w_first["quaternions"])
        again = cheval.Trajectory(**u.to_dict())  # to_dict carries quat_order
        np.testing.assert_array_equal(again.rotations, t.rotations)
        # The functions taking mappings: est_quat_order for the estimate's arrays.
        by_file = cheval.ape(GT, ORB, align="se3", relation="angle_deg")
        by_arrays = cheval.ape(GT, w_first, align="se3", relation="angle_deg", est_quat_order="wxyz")
        self.assertEqual(by_arrays["stats"], by_file["stats"])
        wrong = cheval.ape(GT, w_first, align="se3", relation="angle_deg")  # read as x y z w: other numbers
        self.assertNotEqual(wrong["stats"]["rmse"], by_file["stats"]["rmse"])
        v = cheval.velocity(w_first, angular=True, quat_order="wxyz")
        ref = cheval.velocity(t, angular=True)
        np.testing.assert_array_equal(v["angular_velocities"], ref["angular_velocities"])
        np.testing.assert_array_equal(v["orientations"], ref["orientations"][:, [3, 0, 1, 2]])


class FloatStampsTest(unittest.TestCase):
    def test_float_seconds_are_the_decimal_text_of_their_repr(self):
        seconds = np.array([1403715529.1121435, 0.5, 1e-9, 2.5e-9, 3.5e-9, -1.25, 1311868164.363181])
        t = cheval.Trajectory(seconds, np.zeros((len(seconds), 3)))
        self.assertEqual(t.stamps.tolist(), [nanoseconds(s) for s in seconds])
        self.assertEqual(t.stamps[3], 2)  # 2.5 ns: half to even
        self.assertEqual(t.stamps[4], 4)

    def test_a_files_stamps_as_floats_give_the_files_stamps(self):
        with open(ORB) as f:
            texts = [line.split()[0] for line in f if line.strip() and not line.startswith("#")]
        floats = np.array([float(x) for x in texts])
        from_floats = cheval.Trajectory(floats, np.zeros((len(floats), 3))).stamps
        read = cheval.read(ORB).stamps
        same_text = [i for i, x in enumerate(texts) if repr(float(x)) == x]
        self.assertGreater(len(same_text), len(texts) // 2)
        np.testing.assert_array_equal(from_floats[same_text], read[same_text])
        self.assertEqual(from_floats.tolist(), [nanoseconds(x) for x in floats])

    def test_non_finite_seconds_are_refused_with_the_row(self):
        for bad in (np.nan, np.inf, 1e300):
            with self.assertRaisesRegex(cheval.InputError, r"row 1: stamps\[1\]"):
                cheval.Trajectory(np.array([0.0, bad]), np.zeros((2, 3)))


class AlignTest(unittest.TestCase):
    def test_align_returns_the_estimate_as_ape_aligns_it(self):
        for method in ("se3", "sim3"):
            with self.subTest(method=method):
                a = cheval.align(GT, ORB, method=method)
                self.assertEqual(set(a) - {"trajectory"}, {"method", "rotation", "translation", "scale", "pairs_used"})
                est, aligned = cheval.read(ORB), a["trajectory"]
                self.assertEqual(len(aligned), len(est))
                np.testing.assert_array_equal(aligned.stamps, est.stamps)
                expected = (a["rotation"] @ (a["scale"] * est.positions.T)).T + a["translation"]
                np.testing.assert_allclose(aligned.positions, expected, rtol=0, atol=1e-12)
                np.testing.assert_allclose(aligned.rotations, a["rotation"] @ est.rotations, rtol=0, atol=1e-12)
                # APE of the aligned estimate without alignment = APE with the alignment.
                with_alignment = cheval.ape(GT, ORB, align=method)["stats"]
                of_aligned = cheval.ape(GT, aligned)["stats"]
                for key in ("rmse", "mean", "max"):
                    self.assertAlmostEqual(of_aligned[key], with_alignment[key], delta=1e-12)


if __name__ == "__main__":
    main_needing(EVO)
