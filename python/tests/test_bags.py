"""cheval.read(path, topic=...) on the shared recordings (docs/bags.md): the same poses as the CLI
exports, topics named in errors. Needs CHEVAL_DATA_DIR (exit 77 without it, a failure in CI)."""

import json
import os
import tempfile
import unittest

import cheval
from support import DATA, main_needing, run_cli

EVO = os.path.join(DATA, "evo")


class Bags(unittest.TestCase):
    def test_ros1_topic_equals_the_cli_export(self):
        bag = os.path.join(EVO, "ROS_example.bag")
        t = cheval.read(bag, topic="S-PTAM")
        self.assertEqual(len(t.stamps), 5439)
        self.assertEqual(int(t.stamps[0]), 1502792579887224912)
        with tempfile.TemporaryDirectory() as folder:
            out = os.path.join(folder, "s.tum")
            code, _, err = run_cli("convert", bag, "--topic", "S-PTAM", "-o", out)
            self.assertEqual(code, 0, err)
            exported = cheval.read(out)
        self.assertTrue((exported.positions == t.positions).all())

    def test_tf_chain_of_a_ros2_folder_and_record_time(self):
        folder = os.path.join(EVO, "tf_example")
        t = cheval.read(folder, topic="/tf:odom.base_link")
        # evo's lookups: every 0.1 s from the recording's start, inside the transforms' span.
        self.assertEqual(len(t.stamps), 516)
        self.assertEqual(int(t.stamps[0]), 1714741164211822142)
        self.assertEqual(int(t.stamps[-1]), 1714741215711822142)
        self.assertEqual(len(cheval.read(os.path.join(EVO, "nav2_turtlebot.mcap"), topic="/odom", bag_time=True)
                             .stamps), 2639)

    def test_evaluation_takes_ref_and_est_topics_as_the_cli(self):
        bag = os.path.join(EVO, "ROS_example.bag")
        result = cheval.ape(bag, bag, ref_topic="groundtruth", est_topic="S-PTAM", align="se3")
        with tempfile.TemporaryDirectory() as folder:
            out = os.path.join(folder, "ape.json")
            code, _, err = run_cli("ape", bag, bag, "--ref-topic", "groundtruth", "--est-topic", "S-PTAM",
                                   "--align", "se3", "--json", out)
            self.assertEqual(code, 0, err)
            with open(out) as f:
                cli = json.load(f)
        self.assertEqual(result["stats"], cli["stats"])
        self.assertEqual(result["association"], cli["association"])
        # One topic for both sides, and tf chains of a ROS 2 folder.
        folder = os.path.join(EVO, "tf_example")
        same = cheval.ape(folder, folder, topic="/tf:odom.base_link")
        self.assertEqual(same["stats"]["n"], 516)
        self.assertEqual(same["stats"]["rmse"], 0.0)
        chains = cheval.rpe(folder, folder, ref_topic="/tf:odom.base_footprint", est_topic="/tf:odom.base_link")
        self.assertEqual(chains["stats"]["rmse"], 0.0)

    def test_topic_needs_a_path(self):
        t = cheval.read(os.path.join(EVO, "ROS_example.bag"), topic="S-PTAM")
        with self.assertRaises(TypeError):
            cheval.ape(t, t, topic="S-PTAM")
        with self.assertRaises(cheval.UsageError):  # a recording without a topic
            cheval.ape(os.path.join(EVO, "ROS_example.bag"), t)

    def test_errors_name_the_topic(self):
        with self.assertRaises(cheval.InputError) as e:
            cheval.read(os.path.join(EVO, "ROS_example.bag"), topic="nope")
        self.assertIn("no topic 'nope'", str(e.exception))
        with self.assertRaises(cheval.UsageError) as e:
            cheval.read(os.path.join(EVO, "ROS_example.bag"))
        self.assertIn("choose a topic with topic;", str(e.exception))


if __name__ == "__main__":
    main_needing(EVO)
