"""scripts/flown_views.py on synthetic online trial folders: the plan in force at a VO loss and
what it rated (blind by its own views, blind by the look-ahead's turn, trackable), the windows the
VO came through and those rated blind anyway (a view a later plan replaced not counted), the
per-trial CSV, and bad input: one line naming the file and key, exit 2, nothing written.

Run: TGNAV_SCRIPTS_DIR=scripts /usr/bin/python3 -m unittest -v test_flown_views (in tests/scripts).
"""
import csv
import json
import os
import subprocess
import sys
import tempfile
import unittest

sys.dont_write_bytecode = True
SCRIPTS_DIR = os.environ.get("TGNAV_SCRIPTS_DIR") or os.path.join(os.path.dirname(__file__), "..", "..", "scripts")
SCRIPT = os.path.join(os.path.abspath(SCRIPTS_DIR), "flown_views.py")


def plan(t, flown_p, at_s, own_p=-1.0, flown=True, landmarks=100, prior_landmarks=0):
    return {"t_s": t, "effective_s": t + 0.5, "adopted": False, "views_renewed": flown,
            "flown_min_p": flown_p if flown else -1.0, "flown_min_at_s": at_s if flown else -1.0,
            "own_min_p": own_p, "landmarks": landmarks, "prior_landmarks": prior_landmarks}


def dump(obj, path):
    with open(path, "w") as f:
        json.dump(obj, f)


def write_trial(root, name, plans, lost=None, inliers=600, mode="online", period=2.0):
    d = os.path.join(root, "trials", name)
    os.makedirs(d)
    dump({"mode": mode, "planner": "proposed", "scene": "s", "status": "success" if lost is None else "collision",
          "vo_lost_at_s": lost}, os.path.join(d, "metrics.json"))
    dump({"plans": plans, "guards": []}, os.path.join(d, "online.json"))
    with open(os.path.join(d, "config.yaml"), "w") as f:
        f.write(f"trial:\n  replan_period_s: {period}\n")
    with open(os.path.join(d, "vo.csv"), "w") as f:
        f.write("t,status,inliers\n")
        for i in range(200):
            t = i * 0.05
            f.write(f"{t:.2f},ok,{inliers}\n")
    return d


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


class FlownViews(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.root = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def analyse_all(self):
        """Runs the script on every trial written, with --out; its result and the CSV's rows by trial."""
        out = os.path.join(self.root, "fv.csv")
        r = run(self.root, "--out", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(out) as f:
            return r, {row["trial"]: row for row in csv.DictReader(f)}

    def test_attributes_each_loss_to_the_plan_in_force_and_counts_false_alarms(self):
        # a: lost at 5.0 in the window of the plan at 4.0 (effective 4.5), which rated a view blind
        # at 4.9 that its own views were not: the look-ahead's turn.
        write_trial(self.root, "a", [plan(0.0, 0.9, 1.0), plan(2.0, 0.1, 3.0, own_p=0.2), plan(4.0, 0.05, 4.9, own_p=0.9)],
                    lost=5.0)
        # b: lost at 3.0, the plan in force rated its views blind, its own too.
        write_trial(self.root, "b", [plan(0.0, 0.9, 1.0), plan(2.0, 0.1, 2.8, own_p=0.1)], lost=3.0)
        # c: lost at 3.0 where the plan in force rated every view trackable.
        write_trial(self.root, "c", [plan(2.0, 0.8, 2.6)], lost=3.0)
        # e: lost at 3.0, the window's worst view (blind) at 4.0, after the loss.
        write_trial(self.root, "e", [plan(2.0, 0.1, 4.0, own_p=0.1)], lost=3.0)
        # d: no loss; two windows rated blind, one of whose worst view a later plan replaced first.
        write_trial(self.root, "d", [plan(0.0, 0.2, 1.0, own_p=0.9), plan(2.0, 0.1, 6.0, own_p=0.9), plan(4.0, 0.9, 5.0),
                                     plan(6.0, 0.5, 6.6, flown=False)], inliers=444)
        r, rows = self.analyse_all()
        self.assertEqual(rows["a"]["attribution"], "rated blind: turned by the look-ahead or splice")
        self.assertEqual(float(rows["a"]["loss_plan_s"]), 4.0)
        self.assertEqual(rows["b"]["attribution"], "rated blind: the plan's own views")
        self.assertEqual(rows["c"]["attribution"], "rated trackable")
        self.assertEqual(rows["d"]["attribution"], "")
        self.assertEqual(rows["e"]["attribution"], "its worst view after the loss")
        # a: the windows before the loss's (0.5-2.5, 2.5-4.5), one rated blind.
        self.assertEqual(int(rows["a"]["windows_passed"]), 2)
        self.assertEqual(int(rows["a"]["windows_passed_rated_blind"]), 1)
        # d: windows 0.5-2.5 (blind), 2.5-4.5 (its worst view at 6.0 was never flown), 4.5-6.5.
        self.assertEqual(int(rows["d"]["windows_passed"]), 2)
        self.assertEqual(int(rows["d"]["windows_passed_rated_blind"]), 1)
        self.assertIn("at the loss, the plan in force had rated trackable: 1", r.stdout)
        self.assertIn("windows the VO came through: 5; rated blind anyway: 2", r.stdout)

    def test_a_plan_on_an_empty_map_neither_foresees_nor_false_alarms(self):
        # f: the plan before take-off, on no map, rates everything blind; the VO came through its
        # window and was lost in the next plan's. g: lost in the empty map's own window.
        write_trial(self.root, "f", [plan(0.0, 0.07, 1.0, own_p=0.07, landmarks=0), plan(2.0, 0.9, 3.0)], lost=4.0)
        write_trial(self.root, "g", [plan(0.0, 0.07, 1.0, own_p=0.07, landmarks=0)], lost=2.0)
        # k: none mapped, but trial.unseen_prior's landmarks rated it: a rating like any other.
        write_trial(self.root, "k", [plan(0.0, 0.07, 1.0, own_p=0.07, landmarks=0, prior_landmarks=50)], lost=2.0)
        r, rows = self.analyse_all()
        self.assertEqual(rows["f"]["attribution"], "rated trackable")
        self.assertEqual(int(rows["f"]["windows_passed"]), 0)
        self.assertEqual(rows["g"]["attribution"], "rated blind: nothing mapped yet")
        self.assertEqual(int(rows["g"]["windows_passed_rated_blind"]), 0)
        self.assertEqual(rows["k"]["attribution"], "rated blind: the plan's own views")
        bad = write_trial(self.root, "h", [{k: v for k, v in plan(0.0, 0.5, 1.0).items() if k != "landmarks"}])
        r = run(bad)
        self.assertEqual(r.returncode, 2)
        self.assertIn("online.json: key 'landmarks' missing", r.stderr)

    def test_bad_input_is_one_line_exit_2_and_writes_nothing(self):
        out = os.path.join(self.root, "fv.csv")
        d = write_trial(self.root, "old", [{"t_s": 1.0, "effective_s": 1.5}])
        r = run(self.root, "--out", out)
        self.assertEqual(r.returncode, 2)
        self.assertIn("online.json: key 'flown_min_p' missing", r.stderr)
        self.assertEqual(len(r.stderr.strip().splitlines()), 1)
        self.assertFalse(os.path.exists(out))
        os.remove(os.path.join(d, "config.yaml"))
        dump({"plans": [plan(0.0, 0.9, 1.0)]}, os.path.join(d, "online.json"))
        r = run(d)
        self.assertEqual(r.returncode, 2)
        self.assertIn("config.yaml: cannot read", r.stderr)
        r = run(os.path.join(self.root, "nothing"))
        self.assertEqual(r.returncode, 2)
        self.assertIn("neither a trial folder", r.stderr)
        prior = write_trial(self.root, "prior", [], mode="prior")
        r = run(prior)
        self.assertEqual(r.returncode, 2)
        self.assertIn("key 'mode' has value 'prior'", r.stderr)
        r = run(prior, "--threshold", "1.5")
        self.assertEqual(r.returncode, 2)
        self.assertIn("--threshold", r.stderr)


if __name__ == "__main__":
    unittest.main()
