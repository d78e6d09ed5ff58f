"""scripts/fit_track_model.py on synthetic sweeps: it recovers a known rule (the VO tracks where
the promised detections are many), writes a model file planner/track_model.h's reader takes,
scores unseen trials (ROC AUC, reliability bins, class flyable against the oracle), and refuses
bad input with one line naming the file and exit status 2.

Run: TGNAV_SCRIPTS_DIR=scripts /usr/bin/python3 -m unittest -v test_fit_track_model (in tests/scripts).
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

sys.dont_write_bytecode = True
SCRIPTS_DIR = os.environ.get("TGNAV_SCRIPTS_DIR") or os.path.join(os.path.dirname(__file__), "..", "..", "scripts")
SCRIPT = os.path.join(SCRIPTS_DIR, "fit_track_model.py")

import numpy as np  # noqa: E402

HEADER = ("t,status,features,with_depth,matches,inliers,keyframe,x_true,y_true,z_true,x_est,y_est,z_est,"
          "predicted_score,predicted_landmarks,predicted_coverage,predicted_detections,predicted_near_detections,"
          "predicted_mean_range_m,predicted_column_span,predicted_row_span,predicted_inner_detections,"
          "predicted_inner_near_detections,"
          "predicted_track_probability,"
          "ba_correction_m,ba_correction_rad,ba_outliers,keyframe_rule,reason")


def write_trial(folder, rng, oracle=-1, detections_scale=1.0, span_penalty=0.0):
    """A trial whose frames are tracked (>= 30 inliers) exactly where the detections exceed 40
    (40 + span_penalty x the column span, drawn at random when span_penalty is set)."""
    os.makedirs(folder)
    rows = []
    for i in range(200):
        det = detections_scale * rng.uniform(0, 120)
        span = rng.uniform(0, 1) if span_penalty else 0.5
        tracked = det > 40 + span_penalty * span
        inliers = int(30 + det) if tracked else int(det * 0.5)
        status = "ok" if tracked or i == 0 else "lost"  # frame 0: the VO starts (no matches)
        matches = 0 if i == 0 else 50
        rows.append(f"{i * 0.05:.2f},{status},1000,900,{matches},{inliers},0,{i * 0.02:.3f},0,1.0,,,,"
                    f"-10,{det * 5:.1f},{min(1, det / 150):.3f},{det:.3f},{det / 3:.3f},4.0,{span:.3f},0.5,{det * 0.8:.3f},{det / 4:.3f},,,,,,")
    with open(os.path.join(folder, "vo.csv"), "w") as f:
        f.write(HEADER + "\n" + "\n".join(rows) + "\n")
    with open(os.path.join(folder, "config.yaml"), "w") as f:
        f.write(f"vo:\n  min_inliers: 30\nplanner:\n  oracle_class: {oracle}\n  visibility:\n    hfov_rad: 1.3125\n"
                "    vfov_rad: 1.0472\n    min_range_m: 0.3\n    max_range_m: 6\n  information:\n"
                "    max_incidence_rad: 1.5707963267948966\n")


def write_views(folder, max_range_m, rows=None, name="views.csv", face=None):
    """What `tgnav views` writes for the trial in `folder`: its settings line, then its vo.csv's
    predicted_* columns (here: the same values, counted at another range)."""
    with open(os.path.join(folder, "vo.csv")) as f:
        header = f.readline().strip().split(",")
        lines = [line.rstrip("\n").split(",") for line in f if line.strip()]
    cols = ["t"] + [c for c in header if c.startswith("predicted_")]
    idx = [header.index(c) for c in cols]
    body = [",".join(row[i] for i in idx) for row in lines][:rows]
    face = "" if face is None else f" sight_to_face={face}"
    with open(os.path.join(folder, name), "w") as f:
        f.write(f"# view_settings: hfov_rad=1.3125 vfov_rad=1.0472 min_range_m=0.3 max_range_m={max_range_m} "
                f"max_incidence_rad=1.5707963267948966{face}\n" + ",".join(cols) + "\n" + "\n".join(body) + "\n")


def make_sweep(root, scenes, seed):
    rng = np.random.default_rng(seed)
    for s in scenes:
        write_trial(os.path.join(root, "trials", f"{s}__proposed__s01"), rng)
        write_trial(os.path.join(root, "trials", f"{s}__proposed__oracle_class0__s01"), rng, oracle=0)
        write_trial(os.path.join(root, "trials", f"{s}__proposed__oracle_class1__s01"), rng, oracle=1,
                    detections_scale=3.0)


def read_json(path):
    with open(path) as f:
        return json.load(f)


def write_text(path, text):
    with open(path, "w") as f:
        f.write(text)


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


class FitTrackModel(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def test_texture_weights_are_held_non_negative(self):
        # tracking here gets harder as the column span grows: a free fit weighs it down, the
        # default fit holds it at 0 (more texture in view never lowers the probability)
        calib = os.path.join(self.dir, "calib")
        rng = np.random.default_rng(3)
        for s in ["a-1", "a-2", "b-1"]:
            write_trial(os.path.join(calib, "trials", f"{s}__proposed__s01"), rng, span_penalty=60.0)
        model = os.path.join(self.dir, "model.json")
        features = "log_detections,column_span,mean_range_m"
        r = run("fit", calib, "--out", model, "--features", features)
        self.assertEqual(r.returncode, 0, r.stderr)
        doc = read_json(model)
        weights = dict(zip(doc["features"], doc["weights"]))
        self.assertEqual(weights["column_span"], 0.0)
        self.assertGreater(weights["log_detections"], 0.0)
        self.assertEqual(doc["fitted_on"]["weights_held_non_negative"], ["log_detections", "column_span"])
        r = run("fit", calib, "--out", model, "--features", features, "--free-signs")
        self.assertEqual(r.returncode, 0, r.stderr)
        doc = read_json(model)
        self.assertLess(dict(zip(doc["features"], doc["weights"]))["column_span"], -0.5)
        self.assertEqual(doc["fitted_on"]["weights_held_non_negative"], [])
        self.assertIn("--free-signs", doc["fitted_on"]["command"])

    def test_fits_and_evaluates_a_known_rule(self):
        calib = os.path.join(self.dir, "calib")
        held = os.path.join(self.dir, "held")
        make_sweep(calib, ["a-1", "a-2", "b-1"], 1)
        make_sweep(held, ["c-1", "c-2"], 2)
        model = os.path.join(self.dir, "model.json")
        r = run("fit", calib, "--out", model)
        self.assertEqual(r.returncode, 0, r.stderr)
        doc = read_json(model)
        self.assertEqual(doc["format"], "tgnav-track-model")
        self.assertEqual(doc["version"], 1)
        self.assertEqual(len(doc["weights"]), len(doc["features"]))
        self.assertGreater(doc["scores"]["leave_one_scene_out_auc"], 0.95)
        self.assertEqual(doc["fitted_on"]["scenes"], ["a-1", "a-2", "b-1"])
        # the first frame of each trial (no matches: an initialisation) is not a sample
        self.assertEqual(doc["fitted_on"]["frames"], 9 * 199)
        # a subset of the features: the file lists them, evaluate uses them
        small = os.path.join(self.dir, "small.json")
        r = run("fit", calib, "--out", small, "--features", "log_detections,coverage")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(read_json(small)["features"], ["log_detections", "coverage"])
        r = run("evaluate", held, "--model", small, "--out", os.path.join(self.dir, "eval_small"))
        self.assertEqual(r.returncode, 0, r.stderr)
        r = run("fit", calib, "--out", small, "--features", "log_detections,colour")
        self.assertEqual(r.returncode, 2)
        self.assertIn("'colour'", r.stderr)
        out = os.path.join(self.dir, "eval")
        r = run("evaluate", held, "--model", model, "--out", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        ev = read_json(os.path.join(out, "evaluation.json"))
        self.assertGreater(ev["roc_auc"], 0.95)
        self.assertEqual(sum(b["frames"] for b in ev["reliability"]), ev["frames"])
        cf = ev["class_flyable"]
        self.assertEqual(cf["tp"] + cf["fp"] + cf["tn"] + cf["fn"], 4)  # the oracle trials only
        # class 1 trials (detections 3x: a few blind frames remain) and class 0 (often blind)
        # are not flyable, and the model says so
        self.assertEqual(cf["tn"], 4)
        self.assertTrue(os.path.isfile(os.path.join(out, "reliability.png")))

    def test_ramps_fit_a_monotone_step(self):
        # tracked exactly above 40 detections: ramps between knots follow the step, and every
        # ramp's weight is held >= 0, so the probability never falls as detections grow
        calib = os.path.join(self.dir, "calib")
        held = os.path.join(self.dir, "held")
        make_sweep(calib, ["a-1", "a-2", "b-1"], 1)
        make_sweep(held, ["c-1", "c-2"], 2)
        model = os.path.join(self.dir, "ramps.json")
        knots = [10, 20, 30, 40, 50, 60, 80, 120]
        r = run("fit", calib, "--out", model, "--features", "log_detections,mean_range_m",
                "--ramps", "log_detections=" + ",".join(map(str, knots)))
        self.assertEqual(r.returncode, 0, r.stderr)
        doc = read_json(model)
        self.assertEqual(doc["version"], 2)
        self.assertEqual(doc["features"], ["log_detections"] * (len(knots) - 1) + ["mean_range_m"])
        self.assertEqual(len(doc["ramps"]), len(doc["features"]))
        self.assertIsNone(doc["ramps"][-1])
        self.assertAlmostEqual(doc["ramps"][0][0], np.log1p(10))
        self.assertAlmostEqual(doc["ramps"][-2][1], np.log1p(120))
        self.assertTrue(all(w >= 0 for w in doc["weights"][:-1]))
        self.assertIn("--ramps", doc["fitted_on"]["command"])

        def p(detections):
            z = doc["intercept"]
            for name, ramp, m, sc, w in zip(doc["features"], doc["ramps"], doc["mean"], doc["scale"], doc["weights"]):
                f = np.log1p(detections) if name == "log_detections" else 4.0
                if ramp is not None:
                    f = min(max((f - ramp[0]) / (ramp[1] - ramp[0]), 0.0), 1.0)
                z += w * (f - m) / sc
            return 1.0 / (1.0 + np.exp(-z))
        grid = [p(d) for d in range(0, 130, 2)]
        self.assertTrue(all(b >= a - 1e-12 for a, b in zip(grid, grid[1:])))
        self.assertLess(p(30), 0.2)
        self.assertGreater(p(50), 0.8)
        out = os.path.join(self.dir, "eval")
        r = run("evaluate", held, "--model", model, "--out", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertGreater(read_json(os.path.join(out, "evaluation.json"))["roc_auc"], 0.95)
        for bad, says in [("log_detections=10", "two or more increasing knots"),
                          ("log_detections=20,10", "two or more increasing knots"),
                          ("log_detections=a,b", "does not parse"),
                          ("coverage=0.1,0.2", "'coverage' is not one of the model's features")]:
            r = run("fit", calib, "--out", os.path.join(self.dir, "bad.json"), "--features",
                    "log_detections,mean_range_m", "--ramps", bad)
            self.assertEqual(r.returncode, 2, bad)
            self.assertIn(says, r.stderr)
            self.assertEqual(len(r.stderr.strip().splitlines()), 1)
            self.assertFalse(os.path.exists(os.path.join(self.dir, "bad.json")))

    def test_bad_input_is_one_line_and_exit_2(self):
        calib = os.path.join(self.dir, "calib")
        make_sweep(calib, ["a-1"], 1)
        vo = os.path.join(calib, "trials", "a-1__proposed__s01", "vo.csv")
        with open(vo) as f:
            write_text(vo, f.read().replace("predicted_row_span", "row"))
        r = run("fit", calib, "--out", os.path.join(self.dir, "m.json"))
        self.assertEqual(r.returncode, 2)
        self.assertIn(vo, r.stderr)
        self.assertIn("predicted_row_span", r.stderr)
        self.assertEqual(len(r.stderr.strip().splitlines()), 1)
        self.assertFalse(os.path.exists(os.path.join(self.dir, "m.json")))
        r = run("fit", os.path.join(self.dir, "nowhere"), "--out", os.path.join(self.dir, "m.json"))
        self.assertEqual(r.returncode, 2)
        self.assertIn("nowhere: not a folder", r.stderr)
        bad_model = os.path.join(self.dir, "bad.json")
        write_text(bad_model, "{")
        r = run("evaluate", calib, "--model", bad_model, "--out", os.path.join(self.dir, "e"))
        self.assertEqual(r.returncode, 2)
        self.assertIn(bad_model, r.stderr)

    def test_views_replace_the_features_and_their_settings_are_kept(self):
        calib = os.path.join(self.dir, "calib")
        held = os.path.join(self.dir, "held")
        make_sweep(calib, ["a-1", "b-1"], 1)
        make_sweep(held, ["c-1"], 2)
        for root in (calib, held):
            for t in os.listdir(os.path.join(root, "trials")):
                write_views(os.path.join(root, "trials", t), 10)
        six, ten = os.path.join(self.dir, "six.json"), os.path.join(self.dir, "ten.json")
        self.assertEqual(run("fit", calib, "--out", six).returncode, 0)
        r = run("fit", calib, "--out", ten, "--views", "views.csv")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(read_json(six)["view_settings"]["max_range_m"], 6.0)  # from config.yaml
        self.assertEqual(read_json(ten)["view_settings"]["max_range_m"], 10.0)  # from views.csv
        self.assertEqual(read_json(ten)["fitted_on"]["views"], "views.csv")
        self.assertEqual(read_json(six)["view_settings"]["sight_to_face"], 0.0)  # absent: the voxel's centre
        self.assertEqual(read_json(ten)["weights"], read_json(six)["weights"])  # the same numbers here
        r = run("evaluate", held, "--model", ten, "--views", "views.csv", "--out", os.path.join(self.dir, "e10"))
        self.assertEqual(r.returncode, 0, r.stderr)
        # a model evaluated on features counted otherwise: refused, naming both
        r = run("evaluate", held, "--model", six, "--views", "views.csv", "--out", os.path.join(self.dir, "e6"))
        self.assertEqual(r.returncode, 2)
        self.assertIn("its features were counted with", r.stderr)
        self.assertEqual(len(r.stderr.strip().splitlines()), 1)
        # counted to the landmarks' faces: the model says so, and is refused on features counted to centres
        for root in (calib, held):
            for t in os.listdir(os.path.join(root, "trials")):
                write_views(os.path.join(root, "trials", t), 10, name="face.csv", face=1)
        face = os.path.join(self.dir, "face.json")
        self.assertEqual(run("fit", calib, "--out", face, "--views", "face.csv").returncode, 0)
        self.assertEqual(read_json(face)["view_settings"]["sight_to_face"], 1.0)
        self.assertEqual(run("evaluate", held, "--model", face, "--views", "face.csv",
                             "--out", os.path.join(self.dir, "ef")).returncode, 0)
        r = run("evaluate", held, "--model", face, "--views", "views.csv", "--out", os.path.join(self.dir, "ec"))
        self.assertEqual(r.returncode, 2)
        self.assertIn("'sight_to_face': 0.0", r.stderr)
        # views of another trial (too few rows), and a missing views file
        trial = os.path.join(held, "trials", "c-1__proposed__s01")
        write_views(trial, 10, rows=50)
        r = run("evaluate", held, "--model", ten, "--views", "views.csv", "--out", os.path.join(self.dir, "e"))
        self.assertEqual(r.returncode, 2)
        self.assertIn(os.path.join(trial, "views.csv") + ": 50 rows against vo.csv's 200", r.stderr)
        os.remove(os.path.join(trial, "views.csv"))
        r = run("evaluate", held, "--model", ten, "--views", "views.csv", "--out", os.path.join(self.dir, "e"))
        self.assertEqual(r.returncode, 2)
        self.assertIn(os.path.join(trial, "views.csv") + ": not found", r.stderr)
        # views whose settings differ between trials: one model is fitted on one kind
        write_views(os.path.join(calib, "trials", "a-1__proposed__s01"), 8)
        r = run("fit", calib, "--out", os.path.join(self.dir, "mixed.json"), "--views", "views.csv")
        self.assertEqual(r.returncode, 2)
        self.assertIn("differ from", r.stderr)
        self.assertFalse(os.path.exists(os.path.join(self.dir, "mixed.json")))


if __name__ == "__main__":
    unittest.main()
