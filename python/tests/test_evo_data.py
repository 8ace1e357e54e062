"""cheval.ape / rpe / ase on the real files of ../shared/data/evo: the same dict as the CLI's --json.

Needs CHEVAL_DATA_DIR (CTest sets it): exits 77 (skipped) when the folder is missing, unless CI is
set, where that is a failure.
"""

import json
import os
import tempfile
import unittest

import cheval
from support import DATA, main_needing, run_cli

EVO = os.path.join(DATA, "evo")

# (CLI arguments, the same call in Python). Paths are relative to EVO (both run there).
CASES = [
    (["ape", "KITTI_00_gt.txt", "KITTI_00_ORB.txt", "--align", "se3"],
     lambda: cheval.ape("KITTI_00_gt.txt", "KITTI_00_ORB.txt", align="se3")),
    (["rpe", "KITTI_00_gt.txt", "KITTI_00_SPTAM.txt", "--delta", "100", "--delta-unit", "meters", "--kitti-drift"],
     lambda: cheval.rpe("KITTI_00_gt.txt", "KITTI_00_SPTAM.txt", delta=100, delta_unit="meters", kitti_drift=True)),
    (["ape", "KITTI_00_gt.txt", "KITTI_00_ORB.txt", "--kitti-times", "KITTI_00_gt_times.txt", "-r", "angle_deg"],
     lambda: cheval.ape("KITTI_00_gt.txt", "KITTI_00_ORB.txt", kitti_times="KITTI_00_gt_times.txt",
                        relation="angle_deg")),
    (["rpe", "fr2_desk_groundtruth.txt", "fr2_desk_ORB.txt", "-r", "angle_deg"],
     lambda: cheval.rpe("fr2_desk_groundtruth.txt", "fr2_desk_ORB.txt", relation="angle_deg")),
    (["ape", "fr2_desk_groundtruth.txt", "fr2_desk_ORB_kf_mono.txt", "--align", "sim3", "-r", "full"],
     lambda: cheval.ape("fr2_desk_groundtruth.txt", "fr2_desk_ORB_kf_mono.txt", align="sim3", relation="full")),
    (["ape", "V102_groundtruth.csv", "V102.txt", "--align", "se3"],
     lambda: cheval.ape("V102_groundtruth.csv", "V102.txt", align="se3")),
    (["rpe", "V102_groundtruth.csv", "V102.txt", "--delta", "1", "--delta-unit", "m", "--all-pairs"],
     lambda: cheval.rpe("V102_groundtruth.csv", "V102.txt", delta=1, delta_unit="m", all_pairs=True)),
    (["ase", "V102_groundtruth.csv", "V102.txt", "--align", "full", "--pose-only"],
     lambda: cheval.ase("V102_groundtruth.csv", "V102.txt", align="full", pose_only=True)),
    (["ase", "freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-rgbdslam_drift.txt", "--pose-only", "--align", "se3",
      "--n-align", "100", "--t-max-diff", "0.02"],
     lambda: cheval.ase("freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-rgbdslam_drift.txt", pose_only=True,
                        align="se3", n_align=100, t_max_diff=0.02)),
    (["ape", "freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-ORB_kf_mono.txt", "--align", "sim3",
      "--association", "continuous"],
     lambda: cheval.ape("freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-ORB_kf_mono.txt", align="sim3",
                        association="continuous")),
    (["ape", "V102_groundtruth.csv", "V102.txt", "--ref-columns", "t_ns,px,py,pz", "-r", "point_distance",
      "--align", "posyaw"],
     lambda: cheval.ape("V102_groundtruth.csv", "V102.txt", ref_columns=["t_ns", "px", "py", "pz"],
                        relation="point_distance", align="posyaw")),
]


class EvoDataTest(unittest.TestCase):
    def setUp(self):
        self.cwd = os.getcwd()
        os.chdir(EVO)

    def tearDown(self):
        os.chdir(self.cwd)

    def test_the_dicts_equal_the_cli_json(self):
        for args, call in CASES:
            with self.subTest(command=" ".join(args)), tempfile.TemporaryDirectory() as tmp:
                out = os.path.join(tmp, "r.json")
                code, _, err = run_cli(*args, "--json", out)
                self.assertEqual(code, 0, err)
                with open(out) as f:
                    expected = json.load(f)
                self.assertEqual(call(), expected)

    def test_published_numbers(self):
        # docs/evaluation.md. Independent sources: KITTI 00 in evo's own result files
        # (tests/eval/evo_parity_test.py); V1_02 has none, test_first_principles.py recomputes it in numpy.
        self.assertAlmostEqual(cheval.ape("KITTI_00_gt.txt", "KITTI_00_ORB.txt", align="se3")["stats"]["rmse"],
                               1.303450, places=6)
        v102 = cheval.ape("V102_groundtruth.csv", "V102.txt", align="se3")
        self.assertEqual(v102["association"]["pairs"], 798)
        self.assertAlmostEqual(v102["stats"]["rmse"], 0.091727, places=6)


if __name__ == "__main__":
    main_needing(EVO)
