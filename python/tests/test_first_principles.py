"""cheval's published numbers on ../shared/data/evo against numpy computations written here from the
definitions, sharing no code with cheval:

- V1_02 APE (docs/evaluation.md: 798 pairs, RMSE 0.091727 m): evo has no result file for this pair, so
  the association (evo's sync.matching_time_indices: each stamp of the shorter trajectory to the nearest
  of the longer, kept within 0.01 s), Umeyama's SE(3) alignment (Umeyama 1991, with the sign correction)
  and the RMSE are computed below.
- KITTI 00 drift (docs/evaluation.md: ORB 0.6997 %, 0.002536 deg/m; S-PTAM 1.4870 %, 0.005578 deg/m;
  3283 segments), from the KITTI odometry devkit's definition (evaluate_odometry.cpp: every 10th first
  frame, lengths 100..800 m of ground-truth path, the first frame whose distance exceeds the length,
  E = (res_f⁻¹ res_l)⁻¹ (gt_f⁻¹ gt_l), |t(E)| / L and acos(clamp((tr R(E) − 1) / 2)) / L, averaged over
  all segments), with P⁻¹ the SE(3) inverse (Rᵀ, −Rᵀt) as docs/evaluation.md writes it.

Needs CHEVAL_DATA_DIR (CTest sets it): exits 77 (skipped) when the folder is missing, unless CI is set.
"""

import os
import unittest

import numpy as np

import cheval
from support import DATA, main_needing

EVO = os.path.join(DATA, "evo")


def read_tum(path):
    """stamps (s), positions (n x 3) of a TUM file (t x y z qx qy qz qw)."""
    a = np.loadtxt(path, comments="#")
    return a[:, 0], a[:, 1:4]


def read_euroc_positions(path):
    """stamps (s, from ns as evo converts them), positions of an EuRoC ground-truth csv."""
    a = np.loadtxt(path, delimiter=",", comments="#")
    return a[:, 0] / 1e9, a[:, 1:4]


def read_kitti(path):
    """n x 4 x 4 homogeneous poses of a KITTI file (3 x 4 row-major per line)."""
    a = np.loadtxt(path).reshape(-1, 3, 4)
    poses = np.zeros((len(a), 4, 4))
    poses[:, :3, :] = a
    poses[:, 3, 3] = 1.0
    return poses


def nearest_pairs(stamps_short, stamps_long, max_diff=0.01):
    """evo's matching_time_indices: every stamp of the shorter trajectory to the nearest stamp of the
    longer (first on ties), kept when the difference is <= max_diff."""
    short_ids, long_ids = [], []
    for i, s in enumerate(stamps_short):
        diffs = np.abs(stamps_long - s)
        j = int(np.argmin(diffs))
        if diffs[j] <= max_diff:
            short_ids.append(i)
            long_ids.append(j)
    return np.array(short_ids), np.array(long_ids)


def umeyama_se3(x, y):
    """R, t minimising sum |y_i - (R x_i + t)|^2 for n x 3 arrays (Umeyama 1991, eq. 39-42)."""
    mx, my = x.mean(axis=0), y.mean(axis=0)
    cov = (y - my).T @ (x - mx) / len(x)
    u, _, vt = np.linalg.svd(cov)
    s = np.eye(3)
    if np.linalg.det(u) * np.linalg.det(vt) < 0:
        s[2, 2] = -1
    r = u @ s @ vt
    return r, my - r @ mx


def se3_inverse(poses):
    """(Rᵀ, −Rᵀ t) of n x 4 x 4 poses."""
    out = np.zeros_like(poses)
    rt = poses[:, :3, :3].transpose(0, 2, 1)
    out[:, :3, :3] = rt
    out[:, :3, 3] = -np.einsum("nij,nj->ni", rt, poses[:, :3, 3])
    out[:, 3, 3] = 1.0
    return out


def kitti_drift(gt, result, inverse=se3_inverse):
    """The devkit's calcSequenceErrors + the means of saveStats: (translation %, rotation deg/m, segments)."""
    steps = np.linalg.norm(np.diff(gt[:, :3, 3], axis=0), axis=1)
    dist = np.concatenate([[0.0], np.cumsum(steps)])
    t_errors, r_errors = [], []
    for length in range(100, 900, 100):
        first = np.arange(0, len(gt), 10)
        last = np.searchsorted(dist, dist[first] + length, side="right")  # first index with dist > dist[first] + L
        keep = last < len(gt)
        first, last = first[keep], last[keep]
        delta_gt = inverse(gt[first]) @ gt[last]
        delta_result = inverse(result[first]) @ result[last]
        error = inverse(delta_result) @ delta_gt
        cosine = np.clip(0.5 * (np.trace(error[:, :3, :3], axis1=1, axis2=2) - 1.0), -1.0, 1.0)
        r_errors.extend(np.arccos(cosine) / length)
        t_errors.extend(np.linalg.norm(error[:, :3, 3], axis=1) / length)
    return 100.0 * np.mean(t_errors), np.degrees(np.mean(r_errors)), len(t_errors)


class FirstPrinciplesTest(unittest.TestCase):
    def setUp(self):
        self.cwd = os.getcwd()
        os.chdir(EVO)

    def tearDown(self):
        os.chdir(self.cwd)

    def test_v102_ape_against_numpy(self):
        gt_stamps, gt_positions = read_euroc_positions("V102_groundtruth.csv")
        est_stamps, est_positions = read_tum("V102.txt")
        self.assertLess(len(est_stamps), len(gt_stamps))  # the estimate is the shorter: evo matches it
        est_ids, gt_ids = nearest_pairs(est_stamps, gt_stamps)
        r, t = umeyama_se3(est_positions[est_ids], gt_positions[gt_ids])
        self.assertAlmostEqual(np.linalg.det(r), 1.0, places=12)
        errors = np.linalg.norm(gt_positions[gt_ids] - (est_positions[est_ids] @ r.T + t), axis=1)
        rmse = float(np.sqrt(np.mean(errors ** 2)))
        # The numpy value itself is the published one (docs/evaluation.md) to its 6 decimals.
        self.assertEqual(len(est_ids), 798)
        self.assertAlmostEqual(rmse, 0.091727, places=6)
        result = cheval.ape("V102_groundtruth.csv", "V102.txt", align="se3")
        self.assertEqual(result["association"]["pairs"], len(est_ids))
        # Same pairs and the same least-squares problem: they agree to rounding, measured 2.7e-15 (rmse),
        # 2.4e-15 (max), 5.3e-15 (median) relative; what varies is the summation order of 798 terms and
        # the SVD routine (LAPACK here, Eigen's Jacobi in cheval), hence ~5-10x.
        self.assertAlmostEqual(result["stats"]["rmse"] / rmse, 1.0, delta=3e-14)
        self.assertAlmostEqual(result["stats"]["max"] / errors.max(), 1.0, delta=3e-14)
        self.assertAlmostEqual(result["stats"]["median"] / np.median(errors), 1.0, delta=3e-14)

    def test_kitti_00_drift_against_the_devkit_definition(self):
        gt = read_kitti("KITTI_00_gt.txt")
        published = {"KITTI_00_ORB.txt": (0.6997, 0.002536), "KITTI_00_SPTAM.txt": (1.4870, 0.005578)}
        for name, (translation, rotation) in published.items():
            with self.subTest(estimate=name):
                t_percent, r_deg_per_m, segments = kitti_drift(gt, read_kitti(name))
                self.assertEqual(segments, 3283)
                # The published figures are the devkit definition's, to their printed digits.
                self.assertAlmostEqual(t_percent, translation, delta=0.5e-4)
                self.assertAlmostEqual(r_deg_per_m, rotation, delta=0.5e-6)
                drift = cheval.rpe("KITTI_00_gt.txt", name, delta=100, delta_unit="meters", kitti_drift=True)["drift"]
                self.assertEqual(drift["segments"], segments)
                # Same segments, same products of matrices in another order: measured 9e-16 / 2e-16
                # (translation) and 3.4e-14 / 5.6e-15 (rotation: acos just below 1 amplifies the trace's
                # rounding by 1/angle, angles ~4e-3 rad) relative for ORB / S-PTAM; bounds ~6x.
                self.assertAlmostEqual(drift["translation_percent"] / t_percent, 1.0, delta=1e-14)
                self.assertAlmostEqual(drift["rotation_deg_per_m"] / r_deg_per_m, 1.0, delta=2e-13)

    def test_kitti_00_rotation_drift_depends_on_the_inverse_in_its_fourth_digit(self):
        # The files' rotation matrices are orthonormal to 2e-7 (ground truth) and 8e-7 (ORB) only. The
        # devkit inverts with a general 4 x 4 inverse (Matrix::inv), cheval and evo with the SE(3) inverse
        # (Rᵀ): equal for exact rotations, but acos near 1 (segment angles ~4e-3 rad) turns the 1e-7
        # differences into 0.09 % of the ORB rotation drift: 0.0025333 instead of 0.0025356 deg/m (the
        # general inverse agrees with orthonormalised input to 3e-5 relative). The translation drift is
        # unaffected to 1e-6 relative. Documented here so that the published 4th digit is read with it.
        gt, orb = read_kitti("KITTI_00_gt.txt"), read_kitti("KITTI_00_ORB.txt")
        t_se3, r_se3, _ = kitti_drift(gt, orb)
        t_general, r_general, _ = kitti_drift(gt, orb, inverse=np.linalg.inv)
        self.assertAlmostEqual(t_general / t_se3, 1.0, delta=1e-6)
        self.assertAlmostEqual(r_general, 0.0025333, delta=0.5e-7)
        self.assertAlmostEqual(r_se3, 0.0025356, delta=0.5e-7)


if __name__ == "__main__":
    main_needing(EVO)
