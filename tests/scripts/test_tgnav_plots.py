"""scripts/tgnav_plots.py on synthetic run folders: every KIND writes its figures in png, pdf and
svg and nothing else; optional files may be absent; bad data exits 1 with one line naming the
file and leaves no figure; without matplotlib it exits 3 with one line; what is drawn lands
where the data says (pixels of the flown path, class colours, axes limits, curve values).

Run: TGNAV_SCRIPTS_DIR=scripts /usr/bin/python3 -m unittest -v test_tgnav_plots (in tests/scripts).
"""
import contextlib
import io
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import unittest

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
SCRIPTS_DIR = os.environ.get("TGNAV_SCRIPTS_DIR") or os.path.join(os.path.dirname(__file__), "..", "..", "scripts")
SCRIPT = os.path.join(SCRIPTS_DIR, "tgnav_plots.py")
sys.path.insert(0, SCRIPTS_DIR)

import numpy as np  # noqa: E402
from matplotlib import image  # noqa: E402
from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402

import tgnav_plots  # noqa: E402

PYTHON = sys.executable
ERROR = "tgnav_plots.py: error: "
SKIPPED = "tgnav_plots.py: figures skipped: "
FIGURES = {
    "trial": ["topdown", "ate"],
    "plan": ["plan"],
    "map": ["topdown"],
    "report": ["fig3_synthetic", "fig4_synthetic", "tracking_synthetic", "plan_time"],
    "eval": ["eval"],
}
EXTENT = [-4.0, 4.0, -3.0, 3.0]
EST_OFFSET_M = 0.1  # the VO estimate is the true path shifted in x: error 0.1 everywhere
LOST_AT_S = 4.0


# ---------------------------------------------------------------------------------------------
# Synthetic run folders


def true_xy(t):
    """The flown path: from (-3, 0) to (3, 0) over 10 s through (0, 1.5)."""
    x = -3.0 + 0.6 * t
    return x, 1.5 * np.sin(math.pi * (x + 3.0) / 6.0)


def write(folder, name, text):
    with open(os.path.join(folder, name), "w") as f:
        f.write(text)


def write_json(folder, name, value):
    write(folder, name, json.dumps(value, indent=1))


def write_map_layer(folder, title="synthetic"):
    """A 60 x 80 light grey raster with a dark block at x in [1, 2], y in [-3, -2]."""
    picture = np.full((60, 80, 3), 225, dtype=np.uint8)
    picture[50:60, 50:60] = 60  # rows from the top (y = 3), 0.1 m each
    image.imsave(os.path.join(folder, "map.png"), picture)
    write_json(folder, "map.json", {
        "extent_m": EXTENT, "start_xy": [-3.0, 0.0], "goal_xy": [3.0, 0.0], "title": title,
        "legend": [{"label": "occupied", "rgb": [60, 60, 60]}, {"label": "free", "rgb": [225, 225, 225]}],
    })


def write_trial(folder, lost=True, map_layer=True, plan=True, est=True, metrics=True):
    os.makedirs(folder, exist_ok=True)
    t = np.arange(0.0, 10.0 + 1e-9, 0.01)
    x, y = true_xy(t)
    write(folder, "gt.tum", "# timestamp tx ty tz qx qy qz qw\n"
          + "".join(f"{a:.2f} {b:.6f} {c:.6f} 1.0 -0.5 0.5 -0.5 0.5\n" for a, b, c in zip(t, x, y)))
    frames = t[::5]
    tracked = ~(lost & (frames >= LOST_AT_S))
    rows, est_rows = [], []
    for k, (ft, ok) in enumerate(zip(frames, tracked)):
        fx, fy = true_xy(ft)
        e = f"{fx + EST_OFFSET_M:.6f},{fy:.6f},1.000000" if ok else ",,"
        rows.append(f"{ft:.6f},{'ok' if ok else 'lost'},900,700,600,500,{int(k == 0)},{fx:.6f},{fy:.6f},1.000000,{e},"
                    + ("" if ok else "too few matches") + "\n")
        if ok:
            est_rows.append(f"{ft:.6f} {fx + EST_OFFSET_M:.6f} {fy:.6f} 1.0 -0.5 0.5 -0.5 0.5\n")
    write(folder, "vo.csv", "t,status,features,with_depth,matches,inliers,keyframe,"
          "x_true,y_true,z_true,x_est,y_est,z_est,reason\n" + "".join(rows))
    write(folder, "est.tum", "# timestamp tx ty tz qx qy qz qw\n" + ("".join(est_rows) if est else ""))
    # The reference paths stay away from (0, 1.5), where only the flown path passes.
    write(folder, "trajectory.csv", "t,x,y,z,yaw,vx,vy,vz,ax,ay,az,yaw_rate\n"
          + "".join(f"{a:.2f},{b:.4f},{c + 0.4:.4f},1,0,0,0,0,0,0,0,0\n" for a, b, c in zip(t, x, y)))
    path = [[px, py - 0.5, 1.0, 0.3 * k] for k, (px, py) in enumerate(zip(*true_xy(np.linspace(0, 10, 7))))]
    write_json(folder, "plan.json", {"planner": "proposed", "start": [-3.0, 0.0, 1.0, 0.0],
                                     "goal": [3.0, 0.0, 1.0, 0.0], "path": path if plan else []})
    if metrics:
        lost_xy = true_xy(LOST_AT_S)
        write_json(folder, "metrics.json", {
            "scene": "synthetic", "planner": "proposed", "seed": 3, "status": "vo_lost" if lost else "success",
            "detail": "synthetic", "goal_error_m": None,
            "vo_lost_at_s": LOST_AT_S if lost else None,
            "vo_lost_position": [lost_xy[0], lost_xy[1], 1.0] if lost else None,
            "vo_lost_reason": "too few matches" if lost else None,
            "collision": {"t_s": 9.0, "position": [2.5, -1.0, 1.0], "with": "wall"} if lost else None,
        })
    if map_layer:
        write_map_layer(folder)
    return folder


def write_online(folder):
    """online.json of `tgnav trial --online`: four plans, two adopted (at 0 s straight along y = 0,
    through unknown space for x > 0; at 5 s along the flown path), one not, one without a route."""
    def path(xy, unknown_from=math.inf):
        return [[x, y, 1.0, int(x > unknown_from)] for x, y in xy]

    straight = [(x, 0.0) for x in np.linspace(-3.0, 3.0, 13)]
    flown = list(zip(*true_xy(np.linspace(5.0, 10.0, 11))))
    plans = [
        {"t_s": 0.0, "effective_s": 0.5, "trigger": "start", "ok": True, "adopted": True, "detail": "",
         "start": [-3.0, 0.0, 1.0, 0.0], "chosen_class": 0, "landmarks": 0, "path": path(straight, 0.0)},
        {"t_s": 2.0, "effective_s": 2.5, "trigger": "period", "ok": True, "adopted": False, "detail": "",
         "start": [-1.8, 0.9, 1.0, 0.0], "chosen_class": 0, "landmarks": 40, "path": path(straight[5:])},
        {"t_s": 4.0, "effective_s": 4.5, "trigger": "blocked", "ok": False, "adopted": False,
         "detail": "no route", "start": [-0.6, 1.4, 1.0, 0.0], "chosen_class": None, "landmarks": 60, "path": []},
        {"t_s": 5.0, "effective_s": 5.5, "trigger": "blocked", "ok": True, "adopted": True, "detail": "",
         "start": [0.0, 1.5, 1.0, 0.0], "chosen_class": 1, "landmarks": 80, "path": path(flown)},
    ]
    write_json(folder, "online.json", {"plans": plans})
    return folder


def write_plan(folder, grid=False, map_layer=True):
    """A scenario plan (classes scored by c_p_min, threshold 6) or a grid plan with a roadmap."""
    os.makedirs(folder, exist_ok=True)
    north = [[-3.0, 0.0], [-1.5, 2.0], [1.5, 2.0], [3.0, 0.0]]
    south = [[-3.0, 0.0], [-1.5, -2.0], [1.5, -2.0], [3.0, 0.0]]
    middle = [[-3.0, 0.0], [0.0, 0.3], [3.0, 0.0]]
    if grid:
        plan = {"planner": "agnostic", "status": "solved", "map": {"file": "/maps/synthetic.map"},
                "start": [-3.0, 0.0], "goal": [3.0, 0.0],
                "classes": [{"h_signature": [1.0], "length_m": 6.1, "waypoints": middle},
                            {"h_signature": [2.0], "length_m": 7.5, "waypoints": north}],
                "chosen_class": 0, "path": middle,
                "roadmap": {"vertices": [[-3.0, 0.5], [3.0, 0.5]], "edges": [[[-3.0, 0.5], [0.0, 1.0], [3.0, 0.5]]]}}
    else:
        def wp(points):
            return [[x, y, 1.0, 0.0] for x, y in points]
        plan = {"planner": "proposed", "status": "solved", "seed": 1, "scene": "/configs/scenes/synthetic.yaml",
                "start": [-3.0, 0.0, 1.0, 0.0], "goal": [3.0, 0.0, 1.0, 0.0], "c_p_threshold": 6.0,
                "classes": [{"feasible": True, "length_m": 7.5, "c_p_min": 30.0, "waypoints": wp(north)},
                            {"feasible": True, "length_m": 7.5, "c_p_min": -20.0, "waypoints": wp(south)},
                            {"feasible": False, "length_m": 6.1, "c_p_min": None, "waypoints": wp(middle)}],
                "chosen_class": 0, "path": wp(north)}
    write_json(folder, "plan.json", plan)
    t = np.linspace(0.0, 1.0, 50)
    rows = [f"{a:.3f},{-3 + 6 * a:.4f},{1.8 * math.sin(math.pi * a):.4f},1,0\n" for a in t]
    write(folder, "trajectory.csv", "t,x,y,z,yaw\n" + "".join(rows))
    if map_layer:
        write_map_layer(folder)
    return folder


def write_map(folder):
    os.makedirs(folder, exist_ok=True)
    write_map_layer(folder)
    write_json(folder, "summary.json", {"scene": "synthetic.yaml", "resolution_m": 0.1, "survey_positions": 12,
                                        "frames": 96, "landmarks": 1234})
    return folder


def write_report(folder, trials):
    """A report of two groups over `trials` (folders), the first successful."""
    os.makedirs(folder, exist_ok=True)
    image.imsave(os.path.join(folder, "map_synthetic.png"), np.full((60, 80, 3), 225, dtype=np.uint8))
    lost = list(true_xy(LOST_AT_S)) + [1.0]

    def trial(i, status):
        return {"id": f"t{i}", "seed": i, "folder": os.path.abspath(trials[i]), "status": status,
                "vo_lost_position": lost if status == "vo_lost" else None}
    groups = [
        {"label": "Proposed", "scene": "synthetic", "successes": 1, "plan_time_s": {"n": 2, "mean": 0.2, "std": 0.05},
         "trials": [trial(0, "success"), trial(1, "vo_lost")]},
        {"label": "AP", "scene": "synthetic", "successes": 0, "plan_time_s": {"n": 1, "mean": 0.02, "std": 0.0},
         "trials": [trial(1, "vo_lost")]},
    ]
    write_json(folder, "report.json", {
        "scenes": [{"name": "synthetic", "map": "map_synthetic.png", "extent_m": EXTENT, "start_xy": [-3.0, 0.0],
                    "goal_xy": [3.0, 0.0]}],
        "groups": groups})
    return folder


def write_eval(folder):
    """A `tgnav eval` folder: the reference a circle of radius 2 m, the aligned estimate off it
    radially by an error growing from 0 to 0.2 m."""
    os.makedirs(folder, exist_ok=True)
    angle = np.linspace(0.0, 2.0 * math.pi, 41)
    error = np.linspace(0.0, 0.2, 41)
    rows = [f"{0.1 * k:.1f},{2 * math.cos(a):.6f},{2 * math.sin(a):.6f},1,{(2 + e) * math.cos(a):.6f},"
            f"{(2 + e) * math.sin(a):.6f},1,{e:.6f},{2 * a:.6f}\n" for k, (a, e) in enumerate(zip(angle, error))]
    write(folder, "eval_pairs.csv", "t,ref_x,ref_y,ref_z,est_x,est_y,est_z,error_m,distance_m\n" + "".join(rows))
    write_json(folder, "eval.json", {
        "ref": "/data/gt.tum", "est": "/data/est.tum", "format": "tum", "align": "sim3", "pairs": 41,
        "alignment": {"rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "translation": [0, 0, 0], "scale": 1.5},
        "ate": {"rmse_m": float(np.sqrt(np.mean(error ** 2))), "mean_m": 0.1},
        "rpe": {"delta": 1.0, "unit": "m", "pairs": 30, "trans_rmse_m": 0.01}})
    return folder


# ---------------------------------------------------------------------------------------------
# Checks


def run_cli(*args, env=None):
    return subprocess.run([PYTHON, SCRIPT, *args], capture_output=True, text=True, env=env, timeout=120)


def run_main(*args):
    """main() in this process: (exit status, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = tgnav_plots.main(list(args))
    return status, out.getvalue(), err.getvalue()


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    return struct.unpack(">II", head[16:24])


def has_magic(path, fmt):
    with open(path, "rb") as f:
        head = f.read(2048)
    if fmt == "png":
        return head.startswith(b"\x89PNG\r\n\x1a\n")
    if fmt == "pdf":
        return head.startswith(b"%PDF")
    return head.startswith(b"<svg") or (head.startswith(b"<?xml") and b"<svg" in head)


def rendered(fig):
    """The figure as an RGB array (row 0 at the top) and its height in pixels."""
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    rgb = np.asarray(canvas.buffer_rgba())[:, :, :3].astype(int)
    return rgb, rgb.shape[0]


def colour_near(rgb, height, ax, xy, colour, radius=2, tolerance=40):
    """Whether a pixel within `radius` of the data point `xy` is `colour` (0-255 RGB)."""
    px, py = ax.transData.transform(xy)
    row, col = int(round(height - py)), int(round(px))
    patch = rgb[row - radius:row + radius + 1, col - radius:col + radius + 1]
    return bool((np.abs(patch - np.array(colour)).max(axis=2) <= tolerance).any())


def hex_rgb(colour):
    return [int(colour[i:i + 2], 16) for i in (1, 3, 5)]


def line(ax, label):
    lines = [li for li in ax.get_lines() if li.get_label() == label]
    assert len(lines) == 1, f"{label}: {[li.get_label() for li in ax.get_lines()]}"
    return lines[0]


class PlotsTest(unittest.TestCase):
    def setUp(self):
        self._tmp = tempfile.TemporaryDirectory()
        self.tmp = self._tmp.name

    def tearDown(self):
        self._tmp.cleanup()

    def folder(self, name):
        return os.path.join(self.tmp, name)

    def make(self, kind, name="run"):
        folder = self.folder(name)
        if kind == "trial":
            return write_trial(folder)
        if kind == "plan":
            return write_plan(folder)
        if kind == "map":
            return write_map(folder)
        if kind == "eval":
            return write_eval(folder)
        return write_report(folder, [write_trial(self.folder("a"), lost=False), write_trial(self.folder("b"))])

    def assert_figures(self, folder, names, fmt, inputs):
        """Exactly the input files and the figures <names>.<fmt>, each a real file of its format."""
        self.assertEqual(sorted(os.listdir(folder)), sorted(inputs | {f"{n}.{fmt}" for n in names}))
        for name in names:
            path = os.path.join(folder, f"{name}.{fmt}")
            self.assertTrue(has_magic(path, fmt), path)
            if fmt == "png":
                width, height = png_size(path)
                self.assertTrue(500 <= width <= 4000 and 300 <= height <= 4000, (path, width, height))

    def assert_error(self, status, out, err, file):
        self.assertEqual(status, 1, err)
        self.assertEqual(out, "")
        lines = err.splitlines()
        self.assertEqual(len(lines), 1, err)
        self.assertTrue(lines[0].startswith(ERROR + file), err)

    # --- every kind, every format, nothing else left behind

    def test_every_kind_writes_its_figures_in_every_format(self):
        for kind, names in FIGURES.items():
            with self.subTest(kind=kind):
                folder = self.make(kind, kind)
                inputs = set(os.listdir(folder))
                result = run_cli(kind, folder)
                self.assertEqual((result.returncode, result.stdout, result.stderr), (0, "", ""))
                self.assert_figures(folder, names, "png", inputs)
                written = set(os.listdir(folder))
                for fmt in ("pdf", "svg"):
                    paths = tgnav_plots.PLOTTERS[kind](folder, None, fmt)
                    self.assertEqual(sorted(paths), sorted(os.path.join(folder, f"{n}.{fmt}") for n in names))
                    self.assert_figures(folder, names, fmt, written)
                    written = set(os.listdir(folder))

    def test_out_folder_and_format_option(self):
        folder = write_trial(self.folder("trial"))
        inputs = set(os.listdir(folder))
        out = self.folder("figures")
        result = run_cli("trial", folder, "--format", "svg", "--out", out)
        self.assertEqual((result.returncode, result.stdout, result.stderr), (0, "", ""))
        self.assert_figures(out, FIGURES["trial"], "svg", set())
        self.assertEqual(set(os.listdir(folder)), inputs)

    def test_optional_files_may_be_absent(self):
        folder = write_trial(self.folder("bare"), map_layer=False, plan=False, est=False, metrics=False)
        os.remove(os.path.join(folder, "trajectory.csv"))
        os.remove(os.path.join(folder, "plan.json"))
        inputs = set(os.listdir(folder))
        self.assertEqual(run_main("trial", folder), (0, "", ""))
        self.assert_figures(folder, FIGURES["trial"], "png", inputs)
        empty_path = write_trial(self.folder("no_path"), plan=False, est=False)  # plan.json with "path": []
        self.assertEqual(run_main("trial", empty_path)[0], 0)
        for grid in (False, True):
            plan = write_plan(self.folder(f"plan_{grid}"), grid=grid, map_layer=False)
            os.remove(os.path.join(plan, "trajectory.csv"))
            self.assertEqual(run_main("plan", plan), (0, "", ""))
        map_folder = write_map(self.folder("map"))
        os.remove(os.path.join(map_folder, "summary.json"))
        self.assertEqual(run_main("map", map_folder), (0, "", ""))

    # --- bad data: exit 1, one line naming the file, no figure

    def test_bad_data_exits_1_naming_the_file_and_leaves_no_figure(self):
        trial_b = self.folder("b")  # the report's second trial
        cases = [  # kind, file named in the error (in the run folder, or a path), damage done to the folder
            ("trial", "metrics.json", lambda f: write(f, "metrics.json", '{"scene": "synthetic", "planner"')),
            ("trial", "vo.csv", lambda f: self.corrupt_cell(os.path.join(f, "vo.csv"), 5, 8, "abc")),
            ("trial", "gt.tum", lambda f: os.remove(os.path.join(f, "gt.tum"))),
            ("trial", "map.png", lambda f: write(f, "map.png", "not a picture")),
            ("trial", "map.json", lambda f: write_json(f, "map.json", {"extent_m": [1, 0, 0, 1], "title": "x"})),
            ("plan", "plan.json", lambda f: os.remove(os.path.join(f, "plan.json"))),
            ("plan", "trajectory.csv", lambda f: self.corrupt_cell(os.path.join(f, "trajectory.csv"), 3, 1, "1.2.3")),
            ("map", "map.json", lambda f: os.remove(os.path.join(f, "map.json"))),
            ("report", "report.json", lambda f: write(f, "report.json", '{"scenes": [')),
            ("report", os.path.join(trial_b, "gt.tum"), lambda f: write(trial_b, "gt.tum", "0 1 2\n")),
            ("eval", "eval_pairs.csv", lambda f: self.corrupt_cell(os.path.join(f, "eval_pairs.csv"), 2, 7, "x")),
            ("eval", "eval.json", lambda f: write_json(f, "eval.json", {"align": "se3"})),
        ]
        for k, (kind, file, damage) in enumerate(cases):
            with self.subTest(kind=kind, file=file):
                folder = self.make(kind, f"bad{k}")
                damage(folder)
                inputs = set(os.listdir(folder))
                status, out, err = run_main(kind, folder)
                self.assert_error(status, out, err, os.path.join(folder, file))
                self.assertEqual(set(os.listdir(folder)), inputs)

    @staticmethod
    def corrupt_cell(path, row, column, value):
        with open(path) as f:
            lines = f.read().splitlines()
        cells = lines[row].split(",")
        cells[column] = value
        lines[row] = ",".join(cells)
        with open(path, "w") as f:
            f.write("\n".join(lines) + "\n")

    def test_command_line_failures(self):
        folder = write_trial(self.folder("trial"))
        os.remove(os.path.join(folder, "vo.csv"))
        result = run_cli("trial", folder)
        self.assert_error(result.returncode, result.stdout, result.stderr, os.path.join(folder, "vo.csv"))
        result = run_cli("trial", self.folder("nowhere"))
        self.assert_error(result.returncode, result.stdout, result.stderr, self.folder("nowhere"))
        self.assertEqual(run_cli("movie", folder).returncode, 2)
        self.assertEqual(run_cli("trial", folder, "--format", "gif").returncode, 2)

    def test_without_matplotlib_exits_3_with_one_line(self):
        fake = self.folder("fake")
        os.makedirs(os.path.join(fake, "matplotlib"))
        write(os.path.join(fake, "matplotlib"), "__init__.py", 'raise ImportError("no matplotlib here")\n')
        folder = write_trial(self.folder("trial"))
        inputs = set(os.listdir(folder))
        result = run_cli("trial", folder, env=dict(os.environ, PYTHONPATH=fake, PYTHONDONTWRITEBYTECODE="1"))
        self.assertEqual(result.returncode, 3, result.stderr)
        self.assertEqual(result.stdout, "")
        lines = result.stderr.splitlines()
        self.assertEqual(len(lines), 1, result.stderr)
        self.assertTrue(lines[0].startswith(SKIPPED), lines[0])
        self.assertIn("python3-matplotlib", lines[0])
        self.assertEqual(set(os.listdir(folder)), inputs)

    # --- content: what is drawn is where the data says

    def test_trial_topdown_draws_the_flown_path_where_it_went(self):
        figures = tgnav_plots.trial_figures(write_trial(self.folder("trial")))
        ax = figures["topdown"].axes[0]
        self.assertEqual(ax.get_title(), "synthetic proposed seed 3: vo_lost")
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        self.assertEqual((x0, x1, y0, y1), tuple(EXTENT))  # the map's; every path lies inside it
        flown = line(ax, "flown (true)")
        self.assertAlmostEqual(float(np.max(flown.get_ydata())), 1.5, places=3)
        labels = [text.get_text() for text in ax.get_legend().get_texts()]
        for label in ("planned path", "trajectory", "VO estimate", "start", "goal", "VO lost at 4.0 s",
                      "collision at 9.0 s", "occupied"):
            self.assertIn(label, labels)
        rgb, height = rendered(figures["topdown"])
        green = hex_rgb(tgnav_plots.FLOWN)
        self.assertTrue(colour_near(rgb, height, ax, (0.0, 1.5), green))  # after the loss: only the flown path
        self.assertFalse(colour_near(rgb, height, ax, (0.0, -1.5), green, radius=6))
        self.assertTrue(colour_near(rgb, height, ax, (1.5, -2.5), [60, 60, 60]))  # the map's dark block
        self.assertTrue(colour_near(rgb, height, ax, (2.5, -1.0), hex_rgb(tgnav_plots.COLLISION)))

    def test_trial_limits_hold_paths_without_a_map(self):
        folder = write_trial(self.folder("trial"), map_layer=False, metrics=False)
        ax = tgnav_plots.trial_figures(folder)["topdown"].axes[0]
        self.assertEqual(ax.get_title(), "trial: no metrics.json (incomplete trial)")
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        self.assertTrue(x0 < -3.0 and x1 > 3.1 and y0 < -0.5 and y1 > 1.9, (x0, x1, y0, y1))

    def test_trial_ate_is_the_error_against_distance_with_the_loss(self):
        ax = tgnav_plots.trial_figures(write_trial(self.folder("trial")))["ate"].axes[0]
        curve = ax.get_lines()[0]
        error = np.asarray(curve.get_ydata(), dtype=float)
        tracked = error[np.isfinite(error)]
        self.assertEqual(tracked.size, int(LOST_AT_S / 0.05))
        np.testing.assert_allclose(tracked, EST_OFFSET_M, atol=1e-5)
        distance = np.asarray(curve.get_xdata(), dtype=float)
        self.assertEqual(distance[0], 0.0)
        self.assertTrue(np.all(np.diff(distance) > 0))
        lost = line(ax, next(t.get_text() for t in ax.get_legend().get_texts() if t.get_text().startswith("VO lost")))
        self.assertAlmostEqual(float(lost.get_xdata()[0]), distance[tracked.size - 1])
        self.assertLess(ax.get_xlim()[0], 1e-9)
        self.assertGreater(ax.get_xlim()[1], distance[-1])

    def test_plan_classes_are_coloured_by_perception_quality(self):
        figures = tgnav_plots.plan_figures(write_plan(self.folder("plan")))
        ax = figures["plan"].axes[0]
        self.assertEqual(ax.get_title(), "synthetic proposed seed 1: solved, 3 homology classes")
        weak = line(ax, r"class 1, $c_{p,\min}$ -20, 7.5 m")
        unknown = line(ax, "class 2, 6.1 m, infeasible")
        red, green, _ = weak.get_color()[:3]
        self.assertGreater(red, green + 0.3)  # far below c_p,thr
        self.assertEqual(unknown.get_color(), tgnav_plots.NO_SCORE)
        self.assertNotEqual(unknown.get_linestyle(), "-")
        chosen = line(ax, r"chosen path (class 0, $c_{p,\min}$ 30, 7.5 m)")
        self.assertEqual(chosen.get_color(), tgnav_plots.PLANNED)
        self.assertEqual(len(ax.collections[0].get_offsets()), 4)  # yaw arrows, one each 0.8 m and more
        self.assertEqual(len(figures["plan"].axes), 2)  # and the colour bar
        rgb, height = rendered(figures["plan"])
        self.assertTrue(colour_near(rgb, height, ax, (0.0, 2.0), hex_rgb(tgnav_plots.PLANNED)))

    def test_grid_plan_draws_every_class_and_the_roadmap(self):
        ax = tgnav_plots.plan_figures(write_plan(self.folder("grid"), grid=True))["plan"].axes[0]
        self.assertEqual(ax.get_title(), "synthetic agnostic: solved, 2 homology classes")
        line(ax, "class 1, 7.5 m")
        line(ax, "chosen path (class 0, 6.1 m)")
        line(ax, "roadmap (Voronoi)")

    def test_map_figure_draws_the_raster_in_metres(self):
        ax = tgnav_plots.map_figures(write_map(self.folder("map")))["topdown"].axes[0]
        self.assertEqual(list(ax.images[0].get_extent()), EXTENT)
        self.assertIn("1234 landmarks from 96 frames", ax.get_title())
        self.assertEqual((ax.get_xlim(), ax.get_ylim()), (tuple(EXTENT[:2]), tuple(EXTENT[2:])))

    def test_report_figures_draw_every_trial(self):
        folder = self.make("report")
        figures = tgnav_plots.report_figures(folder)
        self.assertEqual(sorted(figures), sorted(FIGURES["report"]))
        proposed, ap = figures["fig3_synthetic"].axes[:2]
        self.assertEqual(proposed.get_title(), "Proposed: 1/2 VO success")
        colours = [li.get_color() for li in proposed.get_lines() if li.get_linestyle() == "-"]
        self.assertEqual(colours, [tgnav_plots.SUCCESS, tgnav_plots.FAILED])
        fig4 = figures["fig4_synthetic"].axes[0]
        mean = line(fig4, "Proposed (1/2)")
        values = np.asarray(mean.get_ydata(), dtype=float)
        np.testing.assert_allclose(values[np.isfinite(values)], EST_OFFSET_M, atol=1e-5)

    # --- online trials: online.json's plans

    def test_online_trial_draws_every_adopted_plan(self):
        folder = write_online(write_trial(self.folder("online")))
        figures = tgnav_plots.trial_figures(folder)
        self.assertEqual(sorted(figures), ["ate", "online_plans", "topdown"])
        top = figures["topdown"].axes[0]
        labels = [text.get_text() for text in top.get_legend().get_texts()]
        self.assertIn("first plan", labels)
        self.assertIn("plans (colour: time)", labels)
        self.assertNotIn("planned path", labels)
        self.assertAlmostEqual(float(np.max(line(top, "flown (true)").get_ydata())), 1.5, places=3)
        plans = top.collections[0]  # the adopted plans, coloured by their times
        self.assertEqual(len(plans.get_segments()), 2)
        np.testing.assert_array_equal(plans.get_array(), [0.0, 5.0])
        self.assertEqual(len(figures["topdown"].axes), 2)  # and the colour bar
        rgb, height = rendered(figures["topdown"])
        self.assertTrue(colour_near(rgb, height, top, (0.0, 1.5), hex_rgb(tgnav_plots.FLOWN)))
        panels = [ax for ax in figures["online_plans"].axes if ax.axison]
        self.assertEqual([ax.get_title() for ax in panels], ["t = 0.00 s (start)", "t = 5.00 s (blocked)"])
        first, second = panels
        self.assertEqual(len(first.images), 1)  # the map
        # The flown path up to each plan's time: none at 0 s, to (0, 1.5) at 5 s.
        flown = [li for li in second.get_lines() if li.get_color() == tgnav_plots.FLOWN]
        self.assertEqual(len(flown), 1)
        self.assertAlmostEqual(float(np.nanmax(flown[0].get_xdata())), 0.0, places=6)
        at_start = [li for li in first.get_lines() if li.get_color() == tgnav_plots.FLOWN]
        self.assertTrue(all(len(li.get_xdata()) <= 1 for li in at_start))  # gt.tum's first row at most
        rgb, height = rendered(figures["online_plans"])
        self.assertTrue(colour_near(rgb, height, first, (-1.5, 0.0), hex_rgb(tgnav_plots.PLANNED)))
        self.assertTrue(colour_near(rgb, height, first, (1.75, 0.0), hex_rgb(tgnav_plots.UNKNOWN_PATH)))
        self.assertFalse(colour_near(rgb, height, first, (-1.5, 0.0), hex_rgb(tgnav_plots.UNKNOWN_PATH)))
        inputs = set(os.listdir(folder))
        self.assertEqual(run_main("trial", folder), (0, "", ""))
        self.assert_figures(folder, FIGURES["trial"] + ["online_plans"], "png", inputs)

    def test_trial_without_online_json_has_no_online_plans(self):
        figures = tgnav_plots.trial_figures(write_trial(self.folder("trial")))
        self.assertEqual(sorted(figures), ["ate", "topdown"])
        labels = [text.get_text() for text in figures["topdown"].axes[0].get_legend().get_texts()]
        self.assertIn("planned path", labels)
        self.assertNotIn("first plan", labels)
        self.assertEqual(len(figures["topdown"].axes), 1)  # no colour bar

    def test_bad_online_json_exits_1_naming_the_file(self):
        def bad_row(doc):
            doc["plans"][0]["path"][1] = doc["plans"][0]["path"][1][:3]
            return doc

        def no_adopted(doc):
            del doc["plans"][1]["adopted"]
            return doc

        cases = [("plans: expected a list", lambda doc: {"plans": {"t_s": 0.0}}),
                 ("plans[0].path[1]: expected 4 or more numbers, got 3", bad_row),
                 ("plans[1]: missing field 'adopted'", no_adopted)]
        for k, (what, damage) in enumerate(cases):
            with self.subTest(what=what):
                folder = write_online(write_trial(self.folder(f"bad{k}")))
                with open(os.path.join(folder, "online.json")) as f:
                    write_json(folder, "online.json", damage(json.load(f)))
                inputs = set(os.listdir(folder))
                status, out, err = run_main("trial", folder)
                self.assert_error(status, out, err, os.path.join(folder, "online.json"))
                self.assertIn(what, err)
                self.assertEqual(set(os.listdir(folder)), inputs)

    def test_online_plans_shows_at_most_twelve_the_first_and_the_last(self):
        self.assertEqual(tgnav_plots.pick_evenly(list(range(5)), 12), [0, 1, 2, 3, 4])
        picked = tgnav_plots.pick_evenly(list(range(40)), 12)
        self.assertEqual((len(picked), picked[0], picked[-1]), (12, 0, 39))
        self.assertEqual(picked, sorted(set(picked)))
        self.assertEqual(len(tgnav_plots.pick_evenly(list(range(13)), 12)), 12)

    def test_eval_colours_the_estimate_by_its_error(self):
        fig = tgnav_plots.eval_figures(write_eval(self.folder("eval")))["eval"]
        top, along = fig.axes[:2]
        self.assertIn("est.tum against gt.tum: ATE (sim3, scale 1.5) rmse", fig._suptitle.get_text())
        # The scatter holds the aligned estimate, coloured by error_m on a scale from 0 to the largest.
        points = top.collections[0]
        np.testing.assert_allclose(points.get_offsets()[-1], [2.2, 0.0], atol=1e-6)
        np.testing.assert_allclose(points.get_array()[[0, 20, 40]], [0.0, 0.1, 0.2], atol=1e-6)
        self.assertEqual((points.norm.vmin, points.norm.vmax), (0.0, 0.2))
        self.assertEqual(line(top, "reference").get_color(), tgnav_plots.REFERENCE)
        # Beside it: the error along the reference, and the RMSE as a horizontal line.
        curve = line(along, "position error")
        np.testing.assert_allclose(curve.get_xdata()[-1], 4 * math.pi, atol=1e-5)
        np.testing.assert_allclose(curve.get_ydata()[-1], 0.2, atol=1e-6)
        rmse = math.sqrt(float(np.mean(np.linspace(0.0, 0.2, 41) ** 2)))
        self.assertEqual(list(line(along, f"RMSE {rmse:.3g} m").get_ydata()), [rmse, rmse])
        self.assertIn("RPE (1 m): rmse 0.01 m over 30 pairs", along.get_legend().get_title().get_text())


# ---------------------------------------------------------------------------------------------
# The report's tracking and calibration figures (vo.csv with the perception model's prediction)

VO_HEADER = ["t", "status", "features", "with_depth", "matches", "inliers", "keyframe", "x_true", "y_true", "z_true",
             "x_est", "y_est", "z_est", "predicted_score", "predicted_landmarks", "reason"]


def write_vo(folder, inliers, lost_from=None, predicted=True, order=None):
    """vo.csv of frames 0.1 m apart along x: `inliers` per frame, lost from frame `lost_from` on,
    predicted_score = inliers / 10 and predicted_landmarks = 2 * inliers (when `predicted`),
    columns in `order` (default VO_HEADER)."""
    os.makedirs(folder, exist_ok=True)
    header = [c for c in (order or VO_HEADER) if predicted or not c.startswith("predicted_")]
    rows = []
    for k, n in enumerate(inliers):
        lost = lost_from is not None and k >= lost_from
        cell = {"t": f"{0.1 * k:.3f}", "status": "lost" if lost else ("weak" if n < 60 else "ok"),
                "features": str(n + 100), "with_depth": "0", "matches": "0", "inliers": str(n), "keyframe": "0",
                "x_true": f"{0.1 * k:.3f}", "y_true": "0", "z_true": "1",
                "x_est": "" if lost else f"{0.1 * k:.3f}", "y_est": "" if lost else "0", "z_est": "" if lost else "1",
                "predicted_score": f"{n / 10:.2f}", "predicted_landmarks": str(2 * n),
                "reason": f"{n} inliers < 30" if lost else ""}
        rows.append(",".join(cell[c] for c in header))
    write(folder, "vo.csv", ",".join(header) + "\n" + "\n".join(rows) + "\n")
    return folder


def write_generalisation_report(folder, trials, threshold=4.0, min_inliers=30):
    """report.json of one scene, two groups: Proposed over trials[:-1], an oracle group over the last."""
    os.makedirs(folder, exist_ok=True)

    def trial(i, oracle=None):
        status = "success" if i % 2 == 0 else "vo_lost"
        return {"id": f"t{i}", "seed": i + 1, "folder": os.path.abspath(trials[i]), "status": status,
                "vo_lost_position": None, "oracle_class": oracle, "c_p_threshold": threshold,
                "min_inliers": min_inliers}
    groups = [{"label": "Proposed", "scene": "synthetic", "successes": 1, "plan_time_s": None,
               "trials": [trial(i) for i in range(len(trials) - 1)]},
              {"label": "Proposed [planner.oracle_class=1]", "scene": "synthetic", "successes": 1,
               "plan_time_s": None, "trials": [trial(len(trials) - 1, oracle=1)]}]
    write_json(folder, "report.json", {"scenes": [{"name": "synthetic", "map": None}], "groups": groups})
    return folder


class ReportTrackingTest(unittest.TestCase):
    def setUp(self):
        self._tmp = tempfile.TemporaryDirectory()
        self.tmp = self._tmp.name

    def tearDown(self):
        self._tmp.cleanup()

    def folder(self, name):
        return os.path.join(self.tmp, name)

    def test_vo_csv_is_read_by_header_names_in_any_order(self):
        shuffled = ["reason", "z_est", "inliers", "predicted_landmarks", "x_true", "status", "y_true", "z_true",
                    "features", "x_est", "predicted_score", "y_est", "t", "keyframe"]
        for order in (None, shuffled):
            with self.subTest(order=order):
                folder = write_vo(self.folder("v"), [200, 100, 50, 20, 10], lost_from=3, order=order)
                f = tgnav_plots.read_vo_frames(os.path.join(folder, "vo.csv"))
                np.testing.assert_allclose(f.distance, [0.0, 0.1, 0.2, 0.3, 0.4], atol=1e-9)
                np.testing.assert_array_equal(f.inliers, [200, 100, 50, 20, 10])
                np.testing.assert_array_equal(f.features, [300, 200, 150, 120, 110])
                np.testing.assert_array_equal(f.tracking, [True, True, True, False, False])  # weak is tracking
                np.testing.assert_allclose(f.predicted_score, [20.0, 10.0, 5.0, 2.0, 1.0])
                np.testing.assert_array_equal(f.predicted_landmarks, [400, 200, 100, 40, 20])
                self.assertTrue(np.isnan(f.error[3:]).all() and np.allclose(f.error[:3], 0.0))

    def test_vo_csv_without_the_prediction_columns(self):
        folder = write_vo(self.folder("v"), [200, 100], predicted=False)
        f = tgnav_plots.read_vo_frames(os.path.join(folder, "vo.csv"))
        self.assertIsNone(f.predicted_score)
        self.assertIsNone(f.predicted_landmarks)
        write(folder, "vo.csv", "t,status,features\n0,ok,3\n")
        with self.assertRaisesRegex(tgnav_plots.DataError, "no column inliers, x_true"):
            tgnav_plots.read_vo_frames(os.path.join(folder, "vo.csv"))
        write(folder, "vo.csv", ",".join(VO_HEADER) + "\n" + ",".join(["0", "ok", "x"] + ["1"] * 13) + "\n")
        with self.assertRaisesRegex(tgnav_plots.DataError, "line 2, column features: 'x' is not a number"):
            tgnav_plots.read_vo_frames(os.path.join(folder, "vo.csv"))

    def test_lost_stretches(self):
        d = np.arange(6, dtype=float)
        spans = tgnav_plots.lost_spans(d, np.array([True, False, False, True, True, False]))
        self.assertEqual(spans, [(0.0, 3.0), (4.0, 5.0)])  # from the last tracked frame on

    def make(self, predicted=True):
        inliers = [[200, 150, 80, 45, 40, 90, 120], [200, 100, 40, 20, 10, 5, 5], [300, 250, 200, 150, 100, 80, 60]]
        lost = [None, 3, None]
        trials = [write_vo(self.folder(f"t{i}"), n, lost_from=lost[i], predicted=predicted)
                  for i, n in enumerate(inliers)]
        return write_generalisation_report(self.folder("report"), trials)

    def test_tracking_panels_per_trial_mark_the_lost_frames(self):
        figures = tgnav_plots.report_figures(self.make())
        self.assertIn("tracking_synthetic", figures)
        axes = [ax for ax in figures["tracking_synthetic"].axes if ax.axison]
        self.assertEqual(len(axes), 3)  # 2 proposed, 1 oracle; the fourth panel is off
        held, lost, oracle = axes
        self.assertEqual([t.get_text() for t in held.texts], ["seed 1: success"])
        self.assertEqual([t.get_text() for t in lost.texts], ["seed 2: vo_lost"])
        self.assertEqual(held.get_xlim(), lost.get_xlim())  # the same scale in every panel
        self.assertEqual(held.get_ylim(), oracle.get_ylim())
        np.testing.assert_array_equal(line(held, "inliers").get_ydata(), [200, 150, 80, 45, 40, 90, 120])
        np.testing.assert_allclose(line(held, "inliers").get_xdata(), np.arange(7) * 0.1, atol=1e-9)
        # The faint stretch of the first trial held: no lost marker, no band; the second's is marked.
        self.assertEqual([li.get_label() for li in held.get_lines() if li.get_label() == "lost frame"], [])
        self.assertEqual(len(held.patches), 0)
        np.testing.assert_allclose(line(lost, "lost frame").get_xdata(), [0.3, 0.4, 0.5, 0.6], atol=1e-9)
        self.assertEqual(len(lost.patches), 1)
        self.assertEqual(line(lost, "min. inliers").get_ydata()[0], 30)
        self.assertIn("oracle_class=1", oracle.get_ylabel())

    def test_calibration_plots_every_frame_against_the_threshold(self):
        figures = tgnav_plots.report_figures(self.make())
        score, landmarks = figures["calibration"].axes
        tracking = [li for li in score.get_lines() if li.get_label().startswith("tracking")][0]
        lost = [li for li in score.get_lines() if li.get_label().startswith("lost")][0]
        self.assertEqual(len(tracking.get_xdata()) + len(lost.get_xdata()), 21)
        np.testing.assert_allclose(sorted(lost.get_xdata()), [0.5, 0.5, 1.0, 2.0])  # inliers / 10
        self.assertEqual(line(score, "$c_{p,thr}$").get_xdata()[0], 4.0)
        self.assertEqual(line(score, "VO min. inliers").get_ydata()[0], 30)
        self.assertEqual(sorted(landmarks.get_lines()[1].get_xdata())[:2], [10, 10])  # 2 * inliers of lost frames
        self.assertIn("21 frames of 3 trials", figures["calibration"]._suptitle.get_text())

    def test_no_calibration_without_predicted_score(self):
        figures = tgnav_plots.report_figures(self.make(predicted=False))
        self.assertNotIn("calibration", figures)
        self.assertIn("tracking_synthetic", figures)
        status, out, err = run_main("report", self.folder("report"))
        self.assertEqual((status, out, err), (0, "", ""))
        self.assertTrue(os.path.exists(os.path.join(self.folder("report"), "tracking_synthetic.png")))
        self.assertFalse(os.path.exists(os.path.join(self.folder("report"), "calibration.png")))

    def test_many_trials_wrap_into_rows(self):
        trials = [tgnav_plots.ReportTrial("success", None, None, None, seed=k + 1) for k in range(23)]
        group = tgnav_plots.ReportGroup("Proposed", "synthetic", 23, None, trials)
        fig = tgnav_plots.tracking_figure(tgnav_plots.ReportScene("synthetic", None), [group])
        shown = [ax for ax in fig.axes if ax.axison]
        self.assertEqual(len(shown), 23)
        self.assertEqual(len(fig.axes), 24)  # 3 rows of 8 (as even as 10 a row allows)

    def test_reading_many_trials_is_fast(self):
        import time
        folder = write_vo(self.folder("big"), list(np.arange(1500) % 300))
        path = os.path.join(folder, "vo.csv")
        start = time.perf_counter()
        for _ in range(100):
            tgnav_plots.read_vo_frames(path)
        # 100 trials of 1500 frames; 600 trials must stay well within a report's minute.
        self.assertLess(time.perf_counter() - start, 10.0)


if __name__ == "__main__":
    unittest.main()
