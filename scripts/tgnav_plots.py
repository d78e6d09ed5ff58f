#!/usr/bin/env python3
"""Every figure of tgnav, drawn with matplotlib from the data files of a run folder.

Usage: tgnav_plots.py KIND DIR [--format png|pdf|svg] [--out OUTDIR]

KIND is trial, plan, map, report or eval; DIR is the run folder the data files are read from;
figures go to OUTDIR (default DIR) as <name>.<format> (default png), each written under a
temporary name in that folder and renamed into place. Exit status: 0 on success, printing
nothing; 1 on any other failure (bad or missing data, an unwritable OUTDIR; nothing
half-written is left behind), printing one line "tgnav_plots.py: error: <file>: <what>";
2 on bad usage; 3 when matplotlib or numpy cannot be
imported, printing one line "tgnav_plots.py: figures skipped: ..." (install python3-matplotlib).
As a module: plot_trial, plot_plan, plot_map, plot_report and plot_eval(dir, out=None, fmt="png")
write the figures and return their paths; trial_figures, plan_figures, map_figures,
report_figures and eval_figures(dir) return them as {name: matplotlib Figure} without writing
anything.

Map layer (optional in trial and plan folders, required in map folders):
  map.png   top-down RGB raster of the map; row 0 is the largest y, column 0 the smallest x
  map.json  {"extent_m": [x_min, x_max, y_min, y_max] of the raster's outer pixel edges,
             "start_xy": [x, y] or null, "goal_xy": [x, y] or null,
             "title": short name of the map, e.g. "storage",
             "legend": optional [{"label": "occupied", "rgb": [60, 60, 60]}, ...] naming the
                       raster's colours (0-255), drawn as legend entries}
  Both files or neither: without them a figure has no background.

trial  (a `tgnav trial` folder) -> topdown, ate, and online_plans with online.json
  gt.tum           required; the true camera path (TUM: t tx ty tz qx qy qz qw, '#' comments)
  vo.csv           required; one row per frame with columns x_true,y_true,z_true and
                   x_est,y_est,z_est (world frame: the VO starts at the true pose; empty when
                   the frame was not tracked), other columns ignored
  est.tum          optional, may be empty; the VO's camera path (tracked frames)
  trajectory.csv   optional; the flown trajectory, columns x and y used
  plan.json        optional; `path` ([[x, y, ...], ...], may be empty) is the planned path (of an
                   online trial: the first plan), and `start`/`goal` ([x, y, ...]) the start and
                   goal (else the map layer's)
  online.json      optional (`tgnav trial --online`); `plans`, each (re)plan in time order:
                   {"t_s" (sim time, gt.tum's clock), "trigger" (text), "ok", "adopted" (true when
                   it was flown), "start" ([x, y, ...]), "path" ([[x, y, z, unknown01], ...], may be
                   empty; unknown01 1 where the point lay in space never observed), ...}
  metrics.json     optional (an interrupted trial has none); `scene`, `planner`, `seed`,
                   `status` make the titles, `vo_lost_position` ([x, y, z] or null) with
                   `vo_lost_at_s` and `collision` ({"t_s", "position", ...} or null) the
                   VO-lost and collision markers
  topdown: map, planned path, trajectory, flown (true) and VO-estimated paths, start, goal,
  VO-lost and collision markers, legend, title "<scene> <planner> seed <seed>: <status>"; with
  online.json also every adopted plan as a thin line coloured by its time (colour bar), and
  plan.json's path is the "first plan".
  online_plans (only with online.json): one small top-down panel per adopted plan (at most 12,
  evenly chosen, the first and the last always), titled "t = <t_s> s (<trigger>)": the map, the
  plan (dashed in another colour where it runs through unknown space), its start, the goal and
  the flown (true) path up to t_s.
  ate: VO position error |p_est - p_true| (no alignment: the VO frame is the true frame at
  take-off) against distance travelled along the true path, its RMSE in the legend, a marker
  at the last tracked frame before the VO was first lost (the paper's Fig. 4).

plan  (a `tgnav plan` folder, scenario or --grid) -> plan
  plan.json        required; `classes` (each with `waypoints` [[x, y, ...], ...], optional
                   `length_m`, and for scenario plans `c_p_min` (number or null) and
                   `feasible`), `chosen_class` (index into classes, or null), `path`
                   ([[x, y, z, yaw], ...], or [[x, y], ...] for grid plans), `start`, `goal`,
                   and for the title `planner`, `status`, optional `seed`, and `scene`
                   (scenario plans) or `map.file` (grid plans);
                   optional `c_p_threshold` (c_p,thr: the colour scale's midpoint) and
                   `roadmap` {"vertices": [[x, y], ...], "edges": [[[x, y], ...], ...]} (the
                   grid planner's Voronoi graph)
  trajectory.csv   optional; columns x and y used
  plan: map, the roadmap, every class (scenario plans: coloured by c_p_min, red below
  c_p_threshold to green above, with a colour bar, dashed when infeasible; grid plans: one
  colour per class), the chosen path with yaw arrows (4-DoF paths), the trajectory, start, goal.

map  (a `tgnav map` folder) -> topdown
  map.png, map.json   required (the map layer)
  summary.json        optional; `landmarks`, `frames`, `survey_positions`, `resolution_m`
                      make the second title line
  topdown: the raster in metres with start, goal and the map.json legend.

eval  (a `tgnav eval --out` folder) -> eval
  eval.json        required; `ref`, `est` (file paths), `align`, `pairs`, `alignment.scale`,
                   `ate.rmse_m` and `rpe` ({"delta", "unit", "pairs", "trans_rmse_m"}) make the titles
  eval_pairs.csv   required; one row per associated pair: t, ref_x, ref_y, ref_z (the reference),
                   est_x, est_y, est_z (the aligned estimate), error_m, distance_m (along the
                   reference)
  eval: top-down, the reference and the aligned estimate coloured by its error (colour bar from
  the least error to the largest);
  beside it the error against the distance along the reference with the RMSE as a line.

report  (a `tgnav report` folder) -> fig3_<scene>, fig4_<scene>, tracking_<scene> per scene,
        plan_time, calibration
  report.json      required, as `tgnav report` writes it: `scenes` [{"name", "map" (image file
                   in DIR, or null), "extent_m", "start_xy", "goal_xy"}], `groups`
                   [{"label", "scene", "successes", "plan_time_s" ({"n", "mean", "std"} or
                   null), "trials": [{"folder" (absolute), "status", "vo_lost_position",
                   optional "seed", "oracle_class", "c_p_threshold", "min_inliers" (the VO's
                   lost threshold)}]}];
                   each trial folder's gt.tum and vo.csv are read
                   (a missing one leaves the trial out, and the figure says how many)
  vo.csv           read by header names: status (ok, weak, lost), features, inliers,
                   x_true.., x_est..; optional predicted_score (the planner's perception model
                   at the frame's true pose: log det of the Fisher information) and
                   predicted_landmarks (map landmarks in the camera's field of view)
  fig3_<scene>: every trial's true xy path over the scene's map, one panel per group
  (green: VO success, red: failed, x: VO lost; the paper's Fig. 3).
  fig4_<scene>: VO position error against distance travelled, per group the mean over the
  trials still tracking with the min-max band, and an X where each lost trial ended.
  plan_time: mean planning time per group with std error bars, log scale.
  tracking_<scene>: one small panel per trial (rows: groups, columns: their trials): tracked
  features and inliers against distance travelled, lost frames as red x over a red band, the
  VO's min_inliers dashed (only when some trial of the scene has vo.csv frames).
  calibration: predicted_score against inliers for every frame of every trial (oracle ones
  too), green while the VO was tracking, red when lost, the median per bin, c_p_threshold as a
  vertical line and min_inliers as a horizontal one; a second panel against
  predicted_landmarks when vo.csv has it. Not drawn when no vo.csv has predicted_score.
"""
import argparse
import csv
import functools
import json
import logging
import math
import os
import re
import sys
import warnings
from dataclasses import dataclass

PROG = "tgnav_plots.py"
FORMATS = ("png", "pdf", "svg")
# Without this, a first import on a fresh machine announces that it builds the font cache.
logging.getLogger("matplotlib").setLevel(logging.ERROR)
try:
    import numpy as np
    import matplotlib
    from matplotlib import colormaps, colors, image, patheffects
    from matplotlib.cm import ScalarMappable
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    from matplotlib.ticker import MaxNLocator
except ImportError as error:
    MISSING = error
else:
    MISSING = None

PACKAGES = {"numpy": "python3-numpy"}  # the Debian package of each import, default matplotlib's

STYLE = {
    "font.size": 9,
    "axes.titlesize": 10,
    "axes.labelsize": 9,
    "legend.fontsize": 8,
    "xtick.labelsize": 8,
    "ytick.labelsize": 8,
    "pdf.fonttype": 42,  # TrueType in PDFs, as journals ask
    "svg.hashsalt": "tgnav",  # the same SVG for the same data
}
SAVE_OPTIONS = {
    "png": {"dpi": 200},
    "pdf": {"metadata": {"CreationDate": None}},
    "svg": {"metadata": {"Date": None}},
}

# Colours by meaning, the same in every figure.
PLANNED = "#003cc8"
TRAJECTORY = "#404040"
FLOWN = "#00af28"
ESTIMATED = "#d200d2"
COLLISION = "#e60000"
YAW = "#780078"
ROADMAP = "#2878c8"
NO_SCORE = "#999999"
SUCCESS = "#2ca02c"
FAILED = "#d62728"
START_STYLE = {"ls": "", "marker": "o", "ms": 9, "mfc": "white", "mec": "black", "mew": 1.5}
GOAL_STYLE = {"ls": "", "marker": "*", "ms": 15, "mfc": "gold", "mec": "black", "mew": 1.0}
LOST_STYLE = {"ls": "", "marker": "X", "ms": 11, "mfc": "black", "mec": "white", "mew": 1.0}
COLLISION_STYLE = {"ls": "", "marker": "X", "ms": 11, "mfc": COLLISION, "mec": "white", "mew": 1.0}
# c_p of a class: red (weakest segment far below c_p,thr) to green (far above).
QUALITY_CMAP = "RdYlGn"
MAP_WIDTH_IN = 7.2  # topdown figures; the legend takes about a third
UNKNOWN_PATH = "#e67300"  # a plan's stretch through space never observed
PLAN_TIME_CMAP = "viridis"  # online plans coloured by their time
ONLINE_PANELS = 12  # the most plans online_plans shows
ONLINE_COLUMNS = 4
ONLINE_PANEL_IN = 2.9


class DataError(Exception):
    """Bad or missing input: `file` names it, `what` says what is wrong."""

    def __init__(self, file, what):
        super().__init__(f"{file}: {what}")


class Json:
    """A value of a JSON file that knows where it is, for errors naming the file and the field."""

    def __init__(self, value, file, where=""):
        self.value = value
        self.file = file
        self.where = where

    def fail(self, what):
        raise DataError(self.file, f"{self.where}: {what}" if self.where else what)

    def _child(self, key):
        if isinstance(key, int):
            return Json(self.value[key], self.file, f"{self.where}[{key}]")
        return Json(self.value[key], self.file, f"{self.where}.{key}" if self.where else key)

    def __getitem__(self, key):
        """The required field `key` (or element, for an int)."""
        if isinstance(key, int):
            if not isinstance(self.value, list) or not -len(self.value) <= key < len(self.value):
                self.fail(f"expected a list with an element {key}")
        elif not isinstance(self.value, dict) or key not in self.value:
            self.fail(f"missing field '{key}'")
        return self._child(key)

    def get(self, key):
        """The optional field `key`: None when it is missing or null."""
        if not isinstance(self.value, dict):
            self.fail("expected an object")
        return self._child(key) if self.value.get(key) is not None else None

    def items(self):
        if not isinstance(self.value, list):
            self.fail("expected a list")
        return [self._child(i) for i in range(len(self.value))]

    def number(self):
        if isinstance(self.value, bool) or not isinstance(self.value, (int, float)):
            self.fail(f"expected a number, got {json.dumps(self.value)}")
        return float(self.value)

    def integer(self):
        if isinstance(self.value, bool) or not isinstance(self.value, int):
            self.fail(f"expected an integer, got {json.dumps(self.value)}")
        return self.value

    def text(self):
        if not isinstance(self.value, str):
            self.fail(f"expected a string, got {json.dumps(self.value)}")
        return self.value

    def flag(self):
        if not isinstance(self.value, bool):
            self.fail(f"expected true or false, got {json.dumps(self.value)}")
        return self.value

    def numbers(self, count):
        """Exactly `count` numbers (at least `count` when it is negative: -2 takes x, y, ...)."""
        items = self.items()
        if len(items) != count and not (count < 0 and len(items) >= -count):
            self.fail(f"expected {abs(count)}{'' if count > 0 else ' or more'} numbers, got {len(items)}")
        return [item.number() for item in items]

    def xy(self):
        """x, y of a point written as [x, y, ...]."""
        return tuple(self.numbers(-2)[:2])

    def rows(self, min_columns=2):
        """A list of rows of numbers, all as long and at least `min_columns` long, as an array."""
        rows = [row.numbers(-min_columns) for row in self.items()]
        if not rows:
            return np.empty((0, min_columns))
        if len({len(row) for row in rows}) > 1:
            self.fail("rows of different lengths")
        return np.array(rows, dtype=float)


def read_json(path):
    try:
        with open(path, encoding="utf-8") as f:
            return Json(json.load(f), path)
    except FileNotFoundError:
        raise DataError(path, "missing") from None
    except OSError as e:
        raise DataError(path, f"cannot read: {e.strerror}") from None
    except ValueError as e:
        raise DataError(path, f"not valid JSON: {e}") from None


def read_json_optional(path):
    return read_json(path) if os.path.exists(path) else None


def parse_number(cell, path, line, column, may_be_empty=False):
    cell = cell.strip()
    if cell == "" and may_be_empty:
        return math.nan
    try:
        return float(cell)
    except ValueError:
        raise DataError(path, f"line {line}, column {column}: '{cell}' is not a number") from None


def read_csv_columns(path, columns, may_be_empty=()):
    """The named columns of a CSV file with a header row, as float arrays (NaN for the empty cells
    allowed in the columns `may_be_empty`). Blank lines and lines starting with '#' are skipped."""
    values = {column: [] for column in columns}
    header = None
    try:
        with open(path, newline="", encoding="utf-8") as f:
            reader = csv.reader(f)
            for row in reader:
                if not row or row[0].lstrip().startswith("#"):
                    continue
                if header is None:
                    header = [name.strip() for name in row]
                    missing = [column for column in columns if column not in header]
                    if missing:
                        raise DataError(path, f"no column {', '.join(missing)} in the header row")
                    continue
                if len(row) != len(header):
                    raise DataError(path, f"line {reader.line_num}: {len(row)} fields, the header has {len(header)}")
                for column, column_values in values.items():
                    cell = row[header.index(column)]
                    column_values.append(parse_number(cell, path, reader.line_num, column, column in may_be_empty))
    except FileNotFoundError:
        raise DataError(path, "missing") from None
    except OSError as e:
        raise DataError(path, f"cannot read: {e.strerror}") from None
    except (UnicodeDecodeError, csv.Error) as e:
        raise DataError(path, f"not CSV text: {e}") from None
    if header is None:
        raise DataError(path, "empty: no header row")
    return {column: np.array(v, dtype=float) for column, v in values.items()}


def read_tum(path):
    """The rows (t, tx, ty, tz, qx, qy, qz, qw) of a TUM trajectory file, as an n x 8 array."""
    rows = []
    try:
        with open(path, encoding="utf-8") as f:
            for line_number, line in enumerate(f, start=1):
                fields = line.split()
                if not fields or fields[0].startswith("#"):
                    continue
                if len(fields) != 8:
                    raise DataError(path, f"line {line_number}: {len(fields)} fields, expected 8 "
                                          "(t tx ty tz qx qy qz qw)")
                rows.append([parse_number(field, path, line_number, k + 1) for k, field in enumerate(fields)])
    except FileNotFoundError:
        raise DataError(path, "missing") from None
    except OSError as e:
        raise DataError(path, f"cannot read: {e.strerror}") from None
    except UnicodeDecodeError as e:
        raise DataError(path, f"not TUM text: {e}") from None
    return np.array(rows, dtype=float).reshape(-1, 8)


def read_png(path):
    try:
        picture = image.imread(path, format="png")
    except FileNotFoundError:
        raise DataError(path, "missing") from None
    except (OSError, ValueError, SyntaxError) as e:
        raise DataError(path, f"not a readable PNG image: {e}") from None
    if picture.ndim not in (2, 3) or min(picture.shape[:2]) == 0:
        raise DataError(path, f"not an image raster (shape {picture.shape})")
    return picture


def xy_of(array, x=0, y=1):
    """Columns x, y of an n x k array as an n x 2 array; non-finite values become NaN (a gap)."""
    points = array[:, [x, y]] if len(array) else np.empty((0, 2))
    return np.where(np.isfinite(points), points, np.nan)


def vo_error(vo):
    """Distance travelled along the true camera path at every frame of vo.csv (as read by
    read_vo_csv) and the VO's position error |p_est - p_true| there (NaN where not tracked)."""
    true = np.column_stack([vo["x_true"], vo["y_true"], vo["z_true"]])
    est = np.column_stack([vo["x_est"], vo["y_est"], vo["z_est"]])
    steps = np.linalg.norm(np.diff(true, axis=0), axis=1)
    distance = np.cumsum(np.concatenate([[0.0], np.where(np.isfinite(steps), steps, 0.0)]))
    return distance[: len(true)], np.linalg.norm(est - true, axis=1)  # no frames: no distance either


def read_trajectory_xy(path):
    """x, y of an optional trajectory.csv as an n x 2 array (no rows when there is none)."""
    if not os.path.exists(path):
        return np.empty((0, 2))
    columns = read_csv_columns(path, ("x", "y"))
    return xy_of(np.column_stack([columns["x"], columns["y"]]))


def read_vo_csv(path):
    true = ("x_true", "y_true", "z_true")
    est = ("x_est", "y_est", "z_est")
    return read_csv_columns(path, true + est, may_be_empty=est)


def first_loss(distance, error):
    """(distance, error) at the last tracked frame before the first untracked one, or None when
    every frame was tracked or none before the loss."""
    untracked = np.flatnonzero(~np.isfinite(error))
    if untracked.size == 0 or untracked[0] == 0:
        return None
    last = untracked[0] - 1
    return distance[last], error[last]


# ---------------------------------------------------------------------------------------------
# The map layer and what every top-down figure draws


@dataclass
class MapLayer:
    picture: "np.ndarray"
    extent: tuple  # x_min, x_max, y_min, y_max of the raster's outer edges
    start: tuple  # (x, y) or None
    goal: tuple
    title: str
    legend: list  # (label, (r, g, b) in 0..1)


def load_map_layer(folder):
    """The map layer of `folder`, or None when it has neither map.png nor map.json."""
    json_path = os.path.join(folder, "map.json")
    png_path = os.path.join(folder, "map.png")
    if not os.path.exists(json_path) and not os.path.exists(png_path):
        return None
    doc = read_json(json_path)
    extent = doc["extent_m"].numbers(4)
    if not (all(map(math.isfinite, extent)) and extent[0] < extent[1] and extent[2] < extent[3]):
        doc["extent_m"].fail(f"{extent}: expected finite [x_min, x_max, y_min, y_max] with min < max")
    legend = []
    for entry in doc.get("legend").items() if doc.get("legend") else []:
        rgb = entry["rgb"].numbers(3)
        if not all(0 <= c <= 255 for c in rgb):
            entry["rgb"].fail(f"{rgb}: expected 0..255")
        legend.append((entry["label"].text(), tuple(c / 255 for c in rgb)))
    return MapLayer(
        picture=read_png(png_path),
        extent=tuple(extent),
        start=doc.get("start_xy").xy() if doc.get("start_xy") else None,
        goal=doc.get("goal_xy").xy() if doc.get("goal_xy") else None,
        title=doc["title"].text(),
        legend=legend,
    )


def draw_map(ax, layer, **style):
    ax.imshow(layer.picture, origin="upper", extent=layer.extent, cmap="gray", vmin=0.0, vmax=1.0, zorder=0, **style)


def draw_path(ax, xy, colour, width, label, dashes=None, outline=False, zorder=3):
    """A path (n x 2, NaN rows are gaps) as a line; nothing, and no legend entry, when empty."""
    if not np.isfinite(xy).any():
        return
    effects = [patheffects.withStroke(linewidth=width + 1.2, foreground="white")] if outline else None
    ax.plot(xy[:, 0], xy[:, 1], color=colour, lw=width, label=label, dashes=dashes or (None, None),
            path_effects=effects, solid_capstyle="round", zorder=zorder)


def draw_start_goal(ax, start, goal):
    if start is not None:
        ax.plot(*start, **START_STYLE, label="start", zorder=8)
    if goal is not None:
        ax.plot(*goal, **GOAL_STYLE, label="goal", zorder=8)


def topdown_bounds(extent, paths, margin=0.5):
    """x_min, x_max, y_min, y_max over the map's extent (or None) and every finite point of
    `paths` (n x 2 arrays), with `margin` around the points outside the map."""
    points = np.concatenate([np.empty((0, 2))] + [p for p in paths if len(p)])
    points = points[np.isfinite(points).all(axis=1)]
    if extent is None and not len(points):
        extent = (-1.0, 1.0, -1.0, 1.0)
    x0, x1, y0, y1 = extent if extent is not None else (math.inf, -math.inf, math.inf, -math.inf)
    if len(points):
        (lo_x, lo_y), (hi_x, hi_y) = points.min(axis=0), points.max(axis=0)
        x0, y0 = (lo_x - margin if lo_x < x0 else x0), (lo_y - margin if lo_y < y0 else y0)
        x1, y1 = (hi_x + margin if hi_x > x1 else x1), (hi_y + margin if hi_y > y1 else y1)
    return x0, x1, y0, y1


def set_topdown_limits(ax, extent, paths, margin=0.5):
    """Equal-aspect limits over the map's extent (or None) and every finite point of `paths`
    (n x 2 arrays), with `margin` around the points outside the map; then the figure's height
    to fit."""
    x0, x1, y0, y1 = topdown_bounds(extent, paths, margin)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    aspect = min(max((y1 - y0) / (x1 - x0), 0.3), 2.5)
    ax.figure.set_size_inches(MAP_WIDTH_IN, 0.62 * MAP_WIDTH_IN * aspect + 1.0)


def legend_outside(ax):
    """The axes' legend to the right of it."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, frameon=False)


def map_legend(ax, layer):
    """The raster's own colours, as map.json names them."""
    for label, rgb in layer.legend if layer is not None else []:
        ax.fill([], [], color=rgb, ec="#808080", lw=0.5, label=label)


def styled(function):
    """Runs `function` with the figures' style (fonts, PDF font type)."""

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with matplotlib.rc_context(STYLE):
            return function(*args, **kwargs)

    return wrapper


def new_figure(**kwargs):
    return Figure(layout="constrained", **kwargs)


# ---------------------------------------------------------------------------------------------
# trial


@dataclass
class OnlinePlan:
    """One (re)plan of online.json."""
    t: float  # sim time, as gt.tum's
    trigger: str
    ok: bool
    adopted: bool  # flown
    start: tuple  # (x, y)
    path: "np.ndarray"  # n x 2
    unknown: "np.ndarray"  # n bools: the point lay in space never observed when planned


@dataclass
class Trial:
    name: str  # what the title calls it without metrics.json
    metrics: "Json"  # or None
    planned: "np.ndarray"  # n x 2
    trajectory: "np.ndarray"
    flown: "np.ndarray"
    flown_t: "np.ndarray"  # the time of each row of flown
    estimated: "np.ndarray"
    start: tuple
    goal: tuple
    distance: "np.ndarray"  # per frame of vo.csv
    error: "np.ndarray"
    layer: MapLayer
    online: list  # the OnlinePlans of online.json, or None without one


def plan_start_goal(plan, layer):
    """Start and goal from plan.json, else from the map layer; None where neither has one."""
    start = plan.get("start").xy() if plan is not None and plan.get("start") else None
    goal = plan.get("goal").xy() if plan is not None and plan.get("goal") else None
    if layer is not None:
        start = start if start is not None else layer.start
        goal = goal if goal is not None else layer.goal
    return start, goal


def load_online(path):
    """The plans of an optional online.json, or None without one."""
    doc = read_json_optional(path)
    if doc is None:
        return None
    plans = []
    for plan in doc["plans"].items():
        rows = plan["path"].rows(4)
        plans.append(OnlinePlan(t=plan["t_s"].number(), trigger=plan["trigger"].text(), ok=plan["ok"].flag(),
                                adopted=plan["adopted"].flag(), start=plan["start"].xy(), path=xy_of(rows),
                                unknown=rows[:, 3] > 0.5))
    return plans


def load_trial(folder):
    path = functools.partial(os.path.join, folder)
    plan = read_json_optional(path("plan.json"))
    layer = load_map_layer(folder)
    gt = read_tum(path("gt.tum"))
    est = read_tum(path("est.tum")) if os.path.exists(path("est.tum")) else np.empty((0, 8))
    distance, error = vo_error(read_vo_csv(path("vo.csv")))
    start, goal = plan_start_goal(plan, layer)
    return Trial(
        name=layer.title if layer is not None else os.path.basename(os.path.abspath(folder)),
        metrics=read_json_optional(path("metrics.json")),
        planned=xy_of(plan["path"].rows(2)) if plan is not None and plan.get("path") else np.empty((0, 2)),
        trajectory=read_trajectory_xy(path("trajectory.csv")),
        flown=xy_of(gt, 1, 2),
        flown_t=gt[:, 0],
        estimated=xy_of(est, 1, 2),
        start=start,
        goal=goal,
        distance=distance,
        error=error,
        layer=layer,
        online=load_online(path("online.json")),
    )


def trial_title(trial):
    m = trial.metrics
    if m is None:
        return f"{trial.name}: no metrics.json (incomplete trial)"
    return f"{m['scene'].text()} {m['planner'].text()} seed {m['seed'].integer()}: {m['status'].text()}"


def trial_events(trial):
    """[(x, y), style, label] of the VO-lost and collision markers in metrics.json."""
    m = trial.metrics
    if m is None:
        return []
    events = []
    if m.get("vo_lost_position"):
        when = f" at {m['vo_lost_at_s'].number():.1f} s" if m.get("vo_lost_at_s") else ""
        events.append((m["vo_lost_position"].xy(), LOST_STYLE, "VO lost" + when))
    if m.get("collision"):
        c = m["collision"]
        events.append((c["position"].xy(), COLLISION_STYLE, f"collision at {c['t_s'].number():.1f} s"))
    return events


def plan_time_colours(plans):
    """Colour map and norm of the plans' times: viridis without its palest yellow."""
    times = [p.t for p in plans] or [0.0]
    lo, hi = min(times), max(times)
    cmap = colors.ListedColormap(colormaps[PLAN_TIME_CMAP](np.linspace(0.0, 0.88, 256)))
    return cmap, colors.Normalize(lo - 0.5, hi + 0.5) if lo == hi else colors.Normalize(lo, hi)


def draw_online_plans(fig, ax, plans):
    """Every adopted plan's path as a thin line coloured by its time, with a colour bar; returns
    the paths."""
    adopted = [p for p in plans if p.adopted and len(p.path)]
    cmap, norm = plan_time_colours(adopted)
    lines = LineCollection([p.path for p in adopted], cmap=cmap, norm=norm, linewidths=1.0, alpha=0.9, zorder=2)
    lines.set_array(np.array([p.t for p in adopted]))
    ax.add_collection(lines)
    ax.plot([], [], color=cmap(0.5), lw=1.0, label="plans (colour: time)")  # the legend's entry
    bar = fig.colorbar(ScalarMappable(norm, cmap), ax=ax, location="bottom", shrink=0.45, aspect=30, pad=0.02)
    bar.set_label("time of the (adopted) plan [s]")
    bar.ax.xaxis.set_major_locator(MaxNLocator(nbins=6))
    return [p.path for p in adopted]


@styled
def trial_topdown_figure(trial):
    fig = new_figure()
    ax = fig.add_subplot()
    if trial.layer is not None:
        draw_map(ax, trial.layer)
    online = trial.online is not None
    plans = draw_online_plans(fig, ax, trial.online) if online else []
    # The trajectory goes over the flown path, so the reference shows as dashes where they coincide.
    draw_path(ax, trial.planned, PLANNED, 1.2, "first plan" if online else "planned path",
              dashes=(4, 2) if online else None, zorder=2.5)
    draw_path(ax, trial.flown, FLOWN, 3.6, "flown (true)", outline=True, zorder=3)
    draw_path(ax, trial.trajectory, TRAJECTORY, 1.0, "trajectory", dashes=(5, 3), zorder=4)
    draw_path(ax, trial.estimated, ESTIMATED, 1.3, "VO estimate", outline=True, zorder=5)
    draw_start_goal(ax, trial.start, trial.goal)
    events = trial_events(trial)
    for xy, style, label in events:
        ax.plot(*xy, **style, label=label, zorder=9)
    map_legend(ax, trial.layer)
    points = [trial.planned, trial.flown, trial.trajectory, trial.estimated] + plans
    points += [np.array([xy]) for xy in (trial.start, trial.goal) if xy is not None]
    points += [np.array([xy]) for xy, _, _ in events]
    set_topdown_limits(ax, trial.layer.extent if trial.layer is not None else None, points)
    if online:  # room for the colour bar
        fig.set_size_inches(fig.get_figwidth(), fig.get_figheight() + 0.7)
    ax.set_title(trial_title(trial))
    legend_outside(ax)
    return fig


@styled
def trial_ate_figure(trial):
    fig = new_figure(figsize=(7.0, 3.8))
    ax = fig.add_subplot()
    m = trial.metrics
    label = f"{m['planner'].text()} seed {m['seed'].integer()}" if m is not None else "VO"
    tracked = np.isfinite(trial.error)
    if tracked.any():
        rmse = math.sqrt(float(np.mean(trial.error[tracked] ** 2)))
        ax.plot(trial.distance, trial.error, color="C0", lw=1.3, label=f"{label} (RMSE {rmse:.3g} m)")
    else:
        ax.plot([], [], color="C0", lw=1.3, label=f"{label} (no tracked frames)")
        ax.text(0.5, 0.5, "no tracked frames", transform=ax.transAxes, ha="center", va="center", color="0.5")
    loss = first_loss(trial.distance, trial.error)
    if loss is not None:
        ax.plot(*loss, **LOST_STYLE, label=f"VO lost after {loss[0]:.2f} m", zorder=5)
    longest = trial.distance.max(initial=0.0)
    ax.set_xlim(0.0, 1.02 * longest if longest > 0 else 1.0)  # room for a lost marker at the end
    ax.set_ylim(0.0, None if tracked.any() else 1.0)
    ax.set_xlabel("distance travelled (true path) [m]")
    ax.set_ylabel("VO position error [m]")
    ax.set_title("VO position error (VO frame = true frame at take-off)")
    ax.grid(True, color="#e0e0e0")
    ax.set_axisbelow(True)
    ax.legend(loc="best")
    return fig


def pick_evenly(items, most):
    """At most `most` of `items`, evenly spread, the first and the last always."""
    if len(items) <= most:
        return list(items)
    return [items[k] for k in sorted({round(i * (len(items) - 1) / (most - 1)) for i in range(most)})]


def segments_where(xy, mask):
    """The segments k -> k + 1 of a path (n x 2) where mask[k], as one array with NaN gaps."""
    parts = [[xy[k], xy[k + 1], [math.nan, math.nan]] for k in np.flatnonzero(mask)]
    return np.array(parts, dtype=float).reshape(-1, 2)


def draw_online_panel(ax, trial, plan, limits):
    if trial.layer is not None:
        draw_map(ax, trial.layer, interpolation="bilinear", alpha=0.85)
    through = plan.unknown[:-1] | plan.unknown[1:]  # a segment with an end in unknown space
    draw_path(ax, segments_where(plan.path, ~through), PLANNED, 1.4, None, zorder=3)
    draw_path(ax, segments_where(plan.path, through), UNKNOWN_PATH, 1.4, None, dashes=(3, 1.5), zorder=3)
    draw_path(ax, trial.flown[trial.flown_t <= plan.t], FLOWN, 2.2, None, outline=True, zorder=4)
    ax.plot(*plan.start, **dict(START_STYLE, ms=6, mew=1.2), zorder=8)
    if trial.goal is not None:
        ax.plot(*trial.goal, **dict(GOAL_STYLE, ms=10), zorder=8)
    ax.set_xlim(*limits[:2])
    ax.set_ylim(*limits[2:])
    ax.set_aspect("equal")
    ax.set_title(f"t = {plan.t:.2f} s ({plan.trigger})", fontsize=9)
    ax.tick_params(labelsize=7)


def online_plans_legend(fig, trial):
    legend = [Line2D([], [], color=PLANNED, lw=1.4, label="plan"),
              Line2D([], [], color=UNKNOWN_PATH, lw=1.4, dashes=(3, 1.5), label="through unknown"),
              Line2D([], [], color=FLOWN, lw=2.2, label="flown (true) so far"),
              Line2D([], [], **dict(START_STYLE, ms=6, mew=1.2), label="plan start")]
    if trial.goal is not None:
        legend.append(Line2D([], [], **dict(GOAL_STYLE, ms=10), label="goal"))
    legend += [Patch(color=rgb, ec="#808080", lw=0.5, label=label) for label, rgb in
               (trial.layer.legend if trial.layer is not None else [])]
    fig.legend(handles=legend, loc="lower center", ncol=min(len(legend), 5), frameon=False,
               bbox_to_anchor=(0.5, 0.02 / fig.get_figheight()))


def online_axes(panels, limits):
    """A figure of `panels` equal-aspect panels of the same `limits`, ONLINE_COLUMNS a row, with
    room for the title above and the legend below (margins set in inches: constrained layout
    leaves no room for a figure legend)."""
    columns = max(1, min(panels, ONLINE_COLUMNS))
    rows = max(1, math.ceil(panels / columns))
    axes_w = ONLINE_PANEL_IN
    axes_h = axes_w * min(max((limits[3] - limits[2]) / (limits[1] - limits[0]), 0.3), 2.5)
    gap_w, gap_h = 0.15, 0.4  # between panels: no inner tick labels, a title above each
    panels_w = columns * axes_w + (columns - 1) * gap_w
    width = max(panels_w + 0.8, 6.5)  # the legend's width at least
    height = rows * axes_h + (rows - 1) * gap_h + 0.8 + 1.1  # the title's lines, x labels and the legend
    left = max(0.6, (width - panels_w) / 2)
    fig = Figure(figsize=(width, height))
    axes = fig.subplots(rows, columns, squeeze=False, sharex=True, sharey=True, gridspec_kw={
        "left": left / width, "right": (left + panels_w) / width, "top": 1 - 0.8 / height, "bottom": 1.1 / height,
        "wspace": gap_w / axes_w, "hspace": gap_h / axes_h})
    return fig, axes


@styled
def online_plans_figure(trial):
    """One small top-down panel per adopted plan (at most ONLINE_PANELS, evenly chosen)."""
    adopted = [p for p in trial.online if p.adopted]
    shown = pick_evenly(adopted, ONLINE_PANELS)
    extent = trial.layer.extent if trial.layer is not None else None
    limits = topdown_bounds(extent, [trial.flown] + [p.path for p in shown], margin=0.3)
    fig, axes = online_axes(len(shown), limits)
    for ax, plan in zip(axes.flat, shown):
        draw_online_panel(ax, trial, plan, limits)
    for ax in list(axes.flat)[len(shown):]:
        ax.axis("off")
    if not shown:
        axes[0, 0].text(0.5, 0.5, "no plan was adopted", ha="center", va="center", transform=axes[0, 0].transAxes)
    for ax in axes[:, 0]:
        ax.set_ylabel("y [m]")
    for ax in axes[-1]:
        ax.set_xlabel("x [m]")
    online_plans_legend(fig, trial)
    failed = sum(not p.ok for p in trial.online)
    shown_note = f" ({len(shown)} shown)" if len(shown) < len(adopted) else ""
    background = ", over the final map" if trial.layer is not None else ""
    fig.suptitle(f"{trial_title(trial)}\n{len(adopted)} of {len(trial.online)} online plans adopted{shown_note}, "
                 f"{failed} without a route{background}",
                 y=1 - 0.1 / fig.get_figheight(), va="top")
    return fig


def trial_figures(folder):
    """{"topdown": Figure, "ate": Figure, and "online_plans": Figure with online.json} of a `tgnav
    trial` folder."""
    trial = load_trial(folder)
    figures = {"topdown": trial_topdown_figure(trial), "ate": trial_ate_figure(trial)}
    if trial.online is not None:
        figures["online_plans"] = online_plans_figure(trial)
    return figures


# ---------------------------------------------------------------------------------------------
# plan


def plan_title(plan):
    source = plan["scene"].text() if plan.get("scene") else plan["map"]["file"].text()
    name = os.path.splitext(os.path.basename(source))[0]
    seed = f" seed {plan['seed'].integer()}" if plan.get("seed") else ""
    count = len(plan["classes"].items())
    return f"{name} {plan['planner'].text()}{seed}: {plan['status'].text()}, {count} homology classes"


def quality_scale(scores, threshold):
    """Colour map and norm of c_p_min: red below c_p,thr to green above when the threshold is
    known, a plain sequential scale over the scores otherwise; None without scores."""
    if not scores:
        return None
    if threshold is None:
        lo, hi = min(scores), max(scores)
        return colormaps["viridis"], colors.Normalize(lo - 0.5, hi + 0.5) if lo == hi else colors.Normalize(lo, hi)
    lo, hi = min(scores + [threshold - 1.0]), max(scores + [threshold + 1.0])
    return colormaps[QUALITY_CMAP], colors.TwoSlopeNorm(threshold, lo, hi)


def class_label(i, c):
    """"class 2, c_p,min 23.8, 7.5 m, infeasible" from what the class has."""
    parts = [f"class {i}"]
    if c.get("c_p_min"):
        parts.append(rf"$c_{{p,\min}}$ {c['c_p_min'].number():.3g}")
    if c.get("length_m"):
        parts.append(f"{c['length_m'].number():.1f} m")
    if c.get("feasible") and not c["feasible"].flag():
        parts.append("infeasible")
    return ", ".join(parts)


def draw_quality_bar(fig, ax, scale, threshold):
    bar = fig.colorbar(ScalarMappable(scale[1], scale[0]), ax=ax, location="bottom", shrink=0.6, aspect=35)
    bar.set_label(r"class $c_{p,\min}$ (information of its weakest segment)")
    bar.ax.xaxis.set_major_locator(MaxNLocator(nbins=6))  # labels that do not run into each other
    if threshold is not None:
        bar.ax.axvline(threshold, color="black", lw=1.5)
        bar.ax.text(threshold, 1.15, r"$c_{p,\mathrm{thr}}$", transform=bar.ax.get_xaxis_transform(), ha="center",
                    va="bottom", fontsize=8)


def draw_classes(fig, ax, classes, chosen, threshold):
    """Every class but the chosen one. Scenario plans (classes with c_p_min) are coloured by
    c_p_min (grey without one) with a colour bar, dashed when infeasible; grid plans get one
    colour per class (blue is the chosen path's)."""
    scored = any(isinstance(c.value, dict) and "c_p_min" in c.value for c in classes)
    scores = [c.get("c_p_min").number() if c.get("c_p_min") else math.nan for c in classes]
    scale = quality_scale([s for s in scores if math.isfinite(s)], threshold) if scored else None
    palette = [c for k, c in enumerate(colormaps["tab10"].colors) if k not in (0, 3)]
    for i, (c, score) in enumerate(zip(classes, scores)):
        if i == chosen:
            continue
        if not scored:
            colour = palette[i % len(palette)]
        else:
            colour = scale[0](scale[1](score)) if math.isfinite(score) else NO_SCORE
        infeasible = c.get("feasible") is not None and not c["feasible"].flag()
        draw_path(ax, xy_of(c["waypoints"].rows(2)), colour, 2.0, class_label(i, c),
                  dashes=(3, 2) if infeasible else None, zorder=2)
    if scale is not None:
        draw_quality_bar(fig, ax, scale, threshold)


def draw_roadmap(ax, roadmap):
    for k, edge in enumerate(roadmap["edges"].items()):
        xy = xy_of(edge.rows(2))
        ax.plot(xy[:, 0], xy[:, 1], color=ROADMAP, lw=0.7, alpha=0.7, zorder=1,
                label="roadmap (Voronoi)" if k == 0 else None)
    vertices = xy_of(roadmap["vertices"].rows(2))
    ax.plot(vertices[:, 0], vertices[:, 1], ls="", marker="o", ms=2.5, color=ROADMAP, zorder=1)


def yaw_arrows(path, spacing=0.8, length=0.5):
    """x, y, dx, dy of heading arrows along a 4-DoF path, one each `spacing` metres."""
    keep, since = [], math.inf
    for i in range(len(path)):
        if i > 0:
            since += float(np.linalg.norm(path[i, :3] - path[i - 1, :3]))
        if since >= spacing:
            keep.append(i)
            since = 0.0
    x, y, yaw = path[keep, 0], path[keep, 1], path[keep, 3]
    return x, y, length * np.cos(yaw), length * np.sin(yaw)


def draw_chosen(ax, path, label):
    xy = xy_of(path)
    draw_path(ax, xy, PLANNED, 2.6, label, zorder=4)
    if path.shape[1] >= 4 and len(path):
        ax.quiver(*yaw_arrows(path), angles="xy", scale_units="xy", scale=1.0, color=YAW, width=0.004,
                  headwidth=4.0, headlength=4.5, headaxislength=4.0, zorder=6)
        ax.plot([], [], ls="", marker=r"$\rightarrow$", ms=12, color=YAW, label="yaw (heading)")
    return xy


@styled
def plan_figure(plan, trajectory, layer):
    fig = new_figure()
    ax = fig.add_subplot()
    if layer is not None:
        draw_map(ax, layer)
    if plan.get("roadmap"):
        draw_roadmap(ax, plan["roadmap"])
    classes = plan["classes"].items()
    chosen = plan["chosen_class"].integer() if plan.get("chosen_class") else None
    if chosen is not None and not 0 <= chosen < len(classes):
        plan["chosen_class"].fail(f"{chosen} is not an index into classes ({len(classes)})")
    threshold = plan["c_p_threshold"].number() if plan.get("c_p_threshold") else None
    draw_classes(fig, ax, classes, chosen, threshold)
    path = plan["path"].rows(2)
    label = f"chosen path ({class_label(chosen, classes[chosen])})" if chosen is not None else "path"
    chosen_xy = draw_chosen(ax, path, label) if len(path) else np.empty((0, 2))
    draw_path(ax, trajectory, TRAJECTORY, 1.1, "trajectory", zorder=5)
    start, goal = plan_start_goal(plan, layer)
    draw_start_goal(ax, start, goal)
    map_legend(ax, layer)
    points = [xy_of(c["waypoints"].rows(2)) for c in classes] + [chosen_xy, trajectory]
    points += [np.array([xy]) for xy in (start, goal) if xy is not None]
    set_topdown_limits(ax, layer.extent if layer is not None else None, points)
    ax.set_title(plan_title(plan))
    legend_outside(ax)
    return fig


def plan_figures(folder):
    """{"plan": Figure} of a `tgnav plan` folder."""
    plan = read_json(os.path.join(folder, "plan.json"))
    trajectory = read_trajectory_xy(os.path.join(folder, "trajectory.csv"))
    return {"plan": plan_figure(plan, trajectory, load_map_layer(folder))}


# ---------------------------------------------------------------------------------------------
# map


def map_summary(summary):
    """One line about the mapping run from summary.json."""
    return (f"{summary['landmarks'].integer()} landmarks from {summary['frames'].integer()} frames at "
            f"{summary['survey_positions'].integer()} survey positions; voxels {summary['resolution_m'].number():g} m")


@styled
def map_figure(layer, summary):
    fig = new_figure()
    ax = fig.add_subplot()
    draw_map(ax, layer)
    draw_start_goal(ax, layer.start, layer.goal)
    map_legend(ax, layer)
    set_topdown_limits(ax, layer.extent, [np.array([xy]) for xy in (layer.start, layer.goal) if xy is not None])
    ax.set_title(f"{layer.title}: feature map" + (f"\n{map_summary(summary)}" if summary is not None else ""))
    legend_outside(ax)
    return fig


def map_figures(folder):
    """{"topdown": Figure} of a `tgnav map` folder."""
    layer = load_map_layer(folder)
    if layer is None:
        raise DataError(os.path.join(folder, "map.json"), "missing (a map folder needs map.json and map.png)")
    return {"topdown": map_figure(layer, read_json_optional(os.path.join(folder, "summary.json")))}


# ---------------------------------------------------------------------------------------------
# report


@dataclass
class ReportTrial:
    status: str
    vo_lost: tuple  # (x, y) or None
    gt_xy: "np.ndarray"  # the true path, n x 2; None without gt.tum or rows
    vo: tuple  # (distance, error) at the tracked frames; None without vo.csv or frames
    seed: int = 0
    oracle_class: int = None  # the class flown on request, or None
    c_p_threshold: float = None  # plan.json's, or None
    min_inliers: int = None  # the VO's lost threshold (config.yaml), or None
    frames: "VoFrames" = None  # every frame of vo.csv, or None without vo.csv or frames


@dataclass
class VoFrames:
    """A trial's vo.csv, per camera frame."""
    distance: "np.ndarray"  # travelled along the true camera path
    features: "np.ndarray"
    inliers: "np.ndarray"
    tracking: "np.ndarray"  # bool: status ok or weak (not lost)
    error: "np.ndarray"  # |p_est - p_true|, NaN where not tracked
    predicted_score: "np.ndarray"  # None without the column (the perception model's log det)
    predicted_landmarks: "np.ndarray"  # None without the column


VO_COLUMNS = ("status", "features", "inliers", "x_true", "y_true", "z_true", "x_est", "y_est", "z_est")
VO_OPTIONAL = ("predicted_score", "predicted_landmarks")


VO_EMPTY_CELL = re.compile(r"(?:(?<=,)|^)(?=,|$)", re.M)


def vo_numbers(path, header, body, names):
    """Columns `names` of the rows `body` as an n x len(names) float array, empty cells NaN; parsed
    by numpy in C (a report reads hundreds of vo.csv files)."""
    usecols = [header.index(name) for name in names]
    try:
        return np.loadtxt(VO_EMPTY_CELL.sub("nan", "\n".join(body)).splitlines(), delimiter=",", usecols=usecols,
                          dtype=float, ndmin=2, comments=None)
    except ValueError:
        for k, line in enumerate(body):  # slow, only to name the cell
            cells = line.split(",")
            for name, column in zip(names, usecols):
                parse_number(cells[column], path, k + 2, name, may_be_empty=True)
        raise


def read_vo_frames(path):
    """vo.csv read by its header names (any column order, unknown columns ignored), fast enough for
    hundreds of trials: a VoFrames, or None when it has no frames. Empty cells are NaN; blank
    lines end the rows (line numbers in errors count from the header)."""
    try:
        with open(path, encoding="utf-8") as f:
            lines = f.read().splitlines()
    except FileNotFoundError:
        raise DataError(path, "missing") from None
    except OSError as e:
        raise DataError(path, f"cannot read: {e.strerror}") from None
    except UnicodeDecodeError as e:
        raise DataError(path, f"not CSV text: {e}") from None
    while lines and not lines[-1].strip():
        lines.pop()
    if not lines:
        raise DataError(path, "empty: no header row")
    header = [name.strip() for name in lines[0].split(",")]
    missing = [column for column in VO_COLUMNS if column not in header]
    if missing:
        raise DataError(path, f"no column {', '.join(missing)} in the header row")
    body = lines[1:]
    for k, line in enumerate(body):
        if line.count(",") != len(header) - 1:
            raise DataError(path, f"line {k + 2}: {line.count(',') + 1} fields, the header has {len(header)}")
    if not body:
        return None
    optional = [c for c in VO_OPTIONAL if c in header]
    names = list(VO_COLUMNS[1:]) + optional
    numbers = dict(zip(names, vo_numbers(path, header, body, names).T))
    true = np.column_stack([numbers[c] for c in ("x_true", "y_true", "z_true")])
    est = np.column_stack([numbers[c] for c in ("x_est", "y_est", "z_est")])
    steps = np.linalg.norm(np.diff(true, axis=0), axis=1)
    column = header.index("status")
    status = np.array([line.split(",", column + 1)[column].strip() for line in body])
    return VoFrames(distance=np.cumsum(np.concatenate([[0.0], np.where(np.isfinite(steps), steps, 0.0)])),
                    features=numbers["features"], inliers=numbers["inliers"],
                    tracking=(status == "ok") | (status == "weak"), error=np.linalg.norm(est - true, axis=1),
                    **{c: numbers.get(c) for c in VO_OPTIONAL})


@dataclass
class ReportGroup:
    label: str
    scene: str
    successes: int
    plan_time: tuple  # (mean, std, n) or None
    trials: list

    def success_rate(self):
        return f"{self.successes}/{len(self.trials)}"


@dataclass
class ReportScene:
    name: str
    layer: MapLayer  # or None: figure 3 then spans the trajectories



def report_gt_xy(folder):
    path = os.path.join(folder, "gt.tum")
    if not os.path.exists(path):
        return None
    xy = xy_of(read_tum(path), 1, 2)
    return xy if len(xy) else None


def report_frames(folder):
    path = os.path.join(folder, "vo.csv")
    return read_vo_frames(path) if os.path.exists(path) else None


def optional_number(trial, key):
    return trial.get(key).number() if trial.get(key) else None


def load_report_trial(trial):
    folder = trial["folder"].text()
    frames = report_frames(folder)
    vo = None
    if frames is not None:
        tracked = np.isfinite(frames.error)
        vo = frames.distance[tracked], frames.error[tracked]
    min_inliers = optional_number(trial, "min_inliers")
    oracle = trial.get("oracle_class")
    return ReportTrial(
        status=trial["status"].text(),
        vo_lost=trial.get("vo_lost_position").xy() if trial.get("vo_lost_position") else None,
        gt_xy=report_gt_xy(folder),
        vo=vo,
        seed=trial["seed"].integer() if trial.get("seed") else 0,
        oracle_class=oracle.integer() if oracle else None,
        c_p_threshold=optional_number(trial, "c_p_threshold"),
        min_inliers=int(min_inliers) if min_inliers is not None else None,
        frames=frames,
    )


def load_report_group(group):
    stat = group.get("plan_time_s")
    return ReportGroup(
        label=group["label"].text(),
        scene=group["scene"].text(),
        successes=group["successes"].integer(),
        plan_time=(stat["mean"].number(), stat["std"].number(), stat["n"].integer()) if stat else None,
        trials=[load_report_trial(t) for t in group["trials"].items()],
    )


def load_report_scene(scene, folder):
    name = scene["name"].text()
    if not scene.get("map"):
        return ReportScene(name, None)
    layer = MapLayer(
        picture=read_png(os.path.join(folder, scene["map"].text())),
        extent=tuple(scene["extent_m"].numbers(4)),
        start=scene.get("start_xy").xy() if scene.get("start_xy") else None,
        goal=scene.get("goal_xy").xy() if scene.get("goal_xy") else None,
        title=name,
        legend=[],
    )
    return ReportScene(name, layer)


def group_colours(groups):
    """One colour per planner label, the same in every figure."""
    palette = colormaps["tab10"].colors
    labels = list(dict.fromkeys(g.label for g in groups))
    return {label: palette[i % len(palette)] for i, label in enumerate(labels)}


def trajectory_extent(groups, margin=0.5):
    """x0, x1, y0, y1 around every trial's true path."""
    paths = [t.gt_xy[np.isfinite(t.gt_xy).all(axis=1)] for g in groups for t in g.trials if t.gt_xy is not None]
    points = np.concatenate([p for p in paths if len(p)] or [np.zeros((1, 2))])
    lo, hi = points.min(axis=0) - margin, points.max(axis=0) + margin
    return lo[0], hi[0], lo[1], hi[1]


def left_out_note(fig, groups, attribute, file):
    """A note naming how many trials that flew have no `file` (so are not drawn)."""
    count = sum(getattr(t, attribute) is None and t.status != "plan_failed" for g in groups for t in g.trials)
    if count:
        fig.text(0.01, 0.01, f"{count} trial(s) without {file} left out", ha="left", va="bottom", fontsize=8,
                 color=FAILED)


@styled
def fig3_figure(scene, groups):
    layer = scene.layer
    x0, x1, y0, y1 = layer.extent if layer is not None else trajectory_extent(groups)
    columns = max(1, min(len(groups), 3))
    rows = max(1, math.ceil(len(groups) / columns))
    panel_w = 4.6
    # Axes of equal aspect: about 0.8 in of each panel's width go to the y labels, 0.9 in of its
    # height to the title and x labels.
    panel_h = (panel_w - 0.8) * (y1 - y0) / (x1 - x0) + 0.9
    fig = Figure(figsize=(panel_w * columns, panel_h * rows + 0.9))
    axes = fig.subplots(rows, columns, squeeze=False)
    for ax, group in zip(axes.flat, groups):
        if layer is not None:
            draw_map(ax, layer, interpolation="bilinear", alpha=0.85)
        for trial in group.trials:
            if trial.gt_xy is not None:
                colour = SUCCESS if trial.status == "success" else FAILED
                ax.plot(trial.gt_xy[:, 0], trial.gt_xy[:, 1], color=colour, lw=1.3, alpha=0.75, solid_capstyle="round")
        for trial in group.trials:
            if trial.vo_lost is not None:
                ax.plot(*trial.vo_lost, "x", color="black", ms=9, mew=2.4)
                ax.plot(*trial.vo_lost, "x", color=FAILED, ms=7, mew=1.2)
        if layer is not None:
            draw_start_goal(ax, layer.start, layer.goal)
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        ax.set_aspect("equal")
        ax.set_title(f"{group.label}: {group.success_rate()} VO success", fontsize=11)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
    for ax in list(axes.flat)[len(groups):]:
        ax.axis("off")
    legend = [
        Line2D([], [], color=SUCCESS, lw=2, label="VO success"),
        Line2D([], [], color=FAILED, lw=2, label="failed"),
        Line2D([], [], ls="", marker="x", color="black", ms=9, mew=2.4, label="VO lost"),
    ]
    if layer is not None and layer.start is not None:
        legend.append(Line2D([], [], **START_STYLE, label="start"))
    if layer is not None and layer.goal is not None:
        legend.append(Line2D([], [], **dict(GOAL_STYLE, ms=14), label="goal"))
    fig.legend(handles=legend, loc="lower center", ncol=len(legend), frameon=False, fontsize=9)
    left_out_note(fig, groups, "gt_xy", "gt.tum")
    fig.suptitle(f"{scene.name}: true trajectories (ground truth)", fontsize=12)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    return fig


def mean_curve(curves, grid):
    """Mean, min and max over the curves covering each grid distance (NaN where none does)."""
    stack = np.full((len(curves), grid.size), np.nan)
    for k, (d, e) in enumerate(curves):
        inside = grid <= d[-1]
        stack[k, inside] = np.interp(grid[inside], d, e)
    covered = np.any(~np.isnan(stack), axis=0)
    mean, lo, hi = (np.full(grid.size, np.nan) for _ in range(3))
    mean[covered] = np.nanmean(stack[:, covered], axis=0)
    lo[covered] = np.nanmin(stack[:, covered], axis=0)
    hi[covered] = np.nanmax(stack[:, covered], axis=0)
    return mean, lo, hi


@styled
def fig4_figure(scene, groups, colours):
    data = []  # per group: [(distance, error)], [(lost distance, error)]
    longest = 0.0
    for group in groups:
        curves = [t.vo for t in group.trials if t.vo is not None and t.vo[0].size]
        ends = [(t.vo[0][-1], t.vo[1][-1]) for t in group.trials
                if t.status == "vo_lost" and t.vo is not None and t.vo[0].size]
        longest = max([longest] + [d[-1] for d, _ in curves])
        data.append((curves, ends))
    fig = Figure(figsize=(10.0, 4.6))
    ax = fig.add_subplot()
    grid = np.linspace(0.0, longest if longest > 0 else 1.0, 400)
    for group, (curves, ends) in zip(groups, data):
        colour = colours[group.label]
        label = f"{group.label} ({group.success_rate()})"
        if not curves:
            ax.plot([], [], color=colour, lw=2, label=label + ", no tracked frames")
            continue
        mean, lo, hi = mean_curve(curves, grid)
        ax.fill_between(grid, lo, hi, color=colour, alpha=0.18, lw=0)
        ax.plot(grid, mean, color=colour, lw=2, label=label)
        for d, e in ends:
            ax.plot(d, e, "X", ms=10, mfc=colour, mec="black", mew=1.0, zorder=5)
    if any(ends for _, ends in data):
        ax.plot([], [], "X", ms=10, mfc="white", mec="black", ls="", label="VO lost (end of trial)")
    ax.set_xlim(0.0, 1.02 * grid[-1])  # room for a lost marker at the end
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel("distance travelled [m]")
    ax.set_ylabel("VO position error [m]")
    ax.set_title(f"{scene.name}: VO position error (legend: VO success rate)", fontsize=12)
    ax.grid(True, color="#e0e0e0")
    ax.legend(fontsize=9, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    fig.text(0.99, 0.01, "line: mean over the trials still tracking; band: min–max over them", ha="right",
             va="bottom", fontsize=8, color="#555555")
    left_out_note(fig, groups, "vo", "vo.csv")
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    return fig


@styled
def plan_time_figure(scenes, groups, colours):
    fig = Figure(figsize=(max(5.0, 1.0 + 0.9 * len(groups) + 0.6 * len(scenes)), 4.6))
    ax = fig.add_subplot()
    x, ticks, tick_labels, centres, top, bottom = 0.0, [], [], [], 0.0, math.inf
    for scene in scenes:
        first = x
        for group in (g for g in groups if g.scene == scene.name):
            if group.plan_time is None:
                x += 1.0
                continue
            mean, std, n = group.plan_time
            # On a log axis the lower bar must stay above zero.
            low = min(std, 0.95 * mean)
            ax.bar(x, mean, width=0.75, color=colours[group.label], edgecolor="black", lw=0.6,
                   yerr=[[low], [std]] if n > 1 else None, capsize=4, error_kw={"lw": 1})
            ax.text(x, (mean + std) * 1.12, f"{mean:.3g} s", ha="center", va="bottom", fontsize=8)
            ticks.append(x)
            tick_labels.append(group.label.replace(" [", "\n["))  # params on a line of their own
            top = max(top, mean + std)
            bottom = min(bottom, mean - low)
            x += 1.0
        centres.append(((first + x - 1.0) / 2.0, scene.name))
        x += 0.8
    ax.set_yscale("log")
    if top > 0:
        ax.set_ylim(max(bottom, 1e-6) / 3.0, top * 4.0)
    ax.set_xticks(ticks)
    ax.set_xticklabels(tick_labels, fontsize=8 if len(ticks) > 6 else 9)
    ax.set_ylabel("plan time [s]")
    below = -0.16 if any("\n" in t for t in tick_labels) else -0.12
    for centre, name in centres:
        ax.text(centre, below, name, transform=ax.get_xaxis_transform(), ha="center", va="top", fontsize=11,
                style="italic")
    ax.set_title("Planning time: mean ± std per group", fontsize=12)
    ax.grid(True, axis="y", which="both", color="#e6e6e6")
    ax.set_axisbelow(True)
    fig.tight_layout()
    return fig


TRACKING_PANEL_IN = (2.3, 1.45)  # one trial's panel in tracking_<scene>
TRACKING_COLUMNS = 10  # panels per row; a group with more trials takes more rows
FEATURES = "#9a9a9a"
INLIERS = "#1f5fbf"
TRACKING = "#2ca02c"


def lost_spans(distance, tracking):
    """(start, end) distances of the runs of frames that were not tracking."""
    lost = np.concatenate([[False], ~tracking, [False]]).astype(int)
    edges = np.flatnonzero(np.diff(lost))
    spans = []
    for begin, end in zip(edges[::2], edges[1::2]):
        stop = distance[end] if end < distance.size else distance[-1]
        spans.append((distance[begin - 1] if begin > 0 else distance[begin], stop))
    return spans


def tracking_panel(ax, trial):
    frames = trial.frames
    ax.plot(frames.distance, frames.features, color=FEATURES, lw=0.8, label="features")
    ax.plot(frames.distance, frames.inliers, color=INLIERS, lw=0.9, label="inliers")
    for begin, end in lost_spans(frames.distance, frames.tracking):
        ax.axvspan(begin, end, color=FAILED, alpha=0.15, lw=0)
    lost = ~frames.tracking
    if lost.any():
        ax.plot(frames.distance[lost], frames.inliers[lost], ls="", marker="x", ms=3, mew=0.8, color=FAILED,
                label="lost frame")
    if trial.min_inliers is not None:
        ax.axhline(trial.min_inliers, color=FAILED, lw=0.7, ls="--", label="min. inliers")


def tracking_layout(groups, max_columns):
    """(group, trial or None, first row of the group) per panel row: a group's trials in rows of
    at most `max_columns`."""
    rows = []
    for group in groups:
        trials = group.trials or [None]
        for start in range(0, len(trials), max_columns):
            rows.append((group, trials[start:start + max_columns], start == 0))
    return rows


def tracking_limits(groups):
    """x and y upper limits common to every panel: the longest distance, the most features."""
    frames = [t.frames for g in groups for t in g.trials if t.frames is not None]
    x = max([float(np.nanmax(f.distance)) for f in frames if f.distance.size] + [1.0])
    y = max([float(np.nanmax(np.concatenate([f.features, f.inliers]))) for f in frames if f.features.size] + [1.0])
    return 1.02 * x, 1.05 * y


def tracking_axes(fig, rows, columns):
    """rows x columns panels with the same limits set by hand: shared axes cost time quadratic in
    the panels, and a report may have hundreds."""
    margin = {"left": 1.0 / fig.get_figwidth(), "right": 1 - 0.2 / fig.get_figwidth(),
              "top": 1 - 0.55 / fig.get_figheight(), "bottom": 0.8 / fig.get_figheight()}
    return fig.subplots(rows, columns, squeeze=False, gridspec_kw=dict(hspace=0.45, wspace=0.08, **margin))


@styled
def tracking_figure(scene, groups):
    """One panel per trial (rows: groups, wrapped after TRACKING_COLUMNS trials): features and
    inliers against distance travelled, lost frames in red."""
    most = max([len(g.trials) for g in groups] + [1])
    columns = math.ceil(most / math.ceil(most / TRACKING_COLUMNS))  # wrapped rows about as long
    layout = tracking_layout(groups, columns)
    fig = Figure(figsize=(TRACKING_PANEL_IN[0] * columns + 1.2, TRACKING_PANEL_IN[1] * len(layout) + 1.0))
    axes = tracking_axes(fig, len(layout), columns)
    x_max, y_max = tracking_limits(groups)
    lowest = [max([r for r, (_, trials, _) in enumerate(layout) if len(trials) > c] or [0]) for c in range(columns)]
    for r, (row, (group, trials, first)) in enumerate(zip(axes, layout)):
        for c, (ax, trial) in enumerate(zip(row, trials)):
            if trial is None or trial.frames is None:
                ax.text(0.5, 0.5, "no vo.csv frames", ha="center", va="center", transform=ax.transAxes, fontsize=7)
            else:
                tracking_panel(ax, trial)
            if trial is not None:  # a text, not a title: titles are placed panel by panel, slowly
                ax.text(0.5, 1.02, f"seed {trial.seed}: {trial.status}", transform=ax.transAxes, ha="center",
                        va="bottom", fontsize=7, color=SUCCESS if trial.status == "success" else FAILED)
            ax.set_xlim(0.0, x_max)
            ax.set_ylim(0.0, y_max)
            ax.tick_params(labelsize=6, labelbottom=r == lowest[c], labelleft=c == 0)
            if r == lowest[c]:
                ax.set_xlabel("distance [m]", fontsize=7)
        for ax in row[len(trials):]:
            ax.axis("off")
        if first:
            row[0].set_ylabel(group.label.replace(" [", "\n["), fontsize=7)
    legend = [Line2D([], [], color=FEATURES, lw=1.5, label="features"),
              Line2D([], [], color=INLIERS, lw=1.5, label="inliers"),
              Line2D([], [], ls="", marker="x", color=FAILED, label="lost frame (shaded: lost stretch)"),
              Line2D([], [], color=FAILED, ls="--", lw=1, label="VO min. inliers")]
    fig.legend(handles=legend, loc="lower center", ncol=len(legend), frameon=False, fontsize=8)
    fig.suptitle(f"{scene.name}: VO tracking per trial (rows: planner groups)", fontsize=11,
                 y=1 - 0.1 / fig.get_figheight(), va="top")
    return fig


def binned_median(x, y, bins=24):
    """Bin centres and the median of y in each of `bins` equal bins of x (NaN where empty)."""
    edges = np.linspace(x.min(), x.max(), bins + 1) if x.size else np.zeros(bins + 1)
    which = np.clip(np.digitize(x, edges) - 1, 0, bins - 1)
    medians = np.array([np.median(y[which == k]) if np.any(which == k) else np.nan for k in range(bins)])
    return 0.5 * (edges[:-1] + edges[1:]), medians


def calibration_points(groups):
    """Every frame with a finite predicted_score: score, landmarks (NaN without), inliers, tracking."""
    parts = []
    for trial in (t for g in groups for t in g.trials):
        f = trial.frames
        if f is None or f.predicted_score is None:
            continue
        landmarks = f.predicted_landmarks if f.predicted_landmarks is not None else np.full(f.inliers.size, np.nan)
        keep = np.isfinite(f.predicted_score) & np.isfinite(f.inliers)
        parts.append(np.column_stack([f.predicted_score, landmarks, f.inliers, f.tracking])[keep])
    return np.concatenate(parts) if parts else None


def calibration_scatter(ax, x, inliers, tracking):
    for mask, colour, label, ms in ((tracking, TRACKING, "tracking (ok, weak)", 2.5), (~tracking, FAILED, "lost", 4)):
        ax.plot(x[mask], inliers[mask], ls="", marker=".", ms=ms, alpha=0.4, color=colour, rasterized=True,
                label=f"{label}: {int(mask.sum())} frames")
    if x.size:
        centres, medians = binned_median(x, inliers)
        ax.plot(centres, medians, color="black", lw=1.4, label="median inliers per bin")
    ax.grid(True, color="#e6e6e6")
    ax.set_ylabel("VO inliers")
    ax.set_ylim(bottom=0.0)


@styled
def calibration_figure(groups, points):
    """Predicted perception score (and landmarks in view) against the VO's inliers, every frame."""
    landmarks = np.isfinite(points[:, 1]).any()
    fig = Figure(figsize=(11.0 if landmarks else 6.5, 4.8), layout="constrained")
    axes = fig.subplots(1, 2 if landmarks else 1, squeeze=False)[0]
    tracking = points[:, 3].astype(bool)
    trials = [t for g in groups for t in g.trials]
    thresholds = sorted({t.c_p_threshold for t in trials if t.c_p_threshold is not None})
    min_inliers = sorted({t.min_inliers for t in trials if t.min_inliers is not None})
    calibration_scatter(axes[0], points[:, 0], points[:, 2], tracking)
    for k, threshold in enumerate(thresholds):
        axes[0].axvline(threshold, color=PLANNED, lw=1.2, ls="-.", label=r"$c_{p,thr}$" if k == 0 else None)
    axes[0].set_xlabel("predicted score (log det of the Fisher information)")
    if landmarks:
        finite = np.isfinite(points[:, 1])
        calibration_scatter(axes[1], points[finite, 1], points[finite, 2], tracking[finite])
        axes[1].set_xlabel("predicted landmarks in view")
    for ax in axes:
        for k, value in enumerate(min_inliers):
            ax.axhline(value, color=FAILED, lw=1.0, ls="--", label="VO min. inliers" if k == 0 else None)
    axes[0].legend(fontsize=7, loc="upper left", markerscale=4)
    counted = sum(t.frames is not None and t.frames.predicted_score is not None for t in trials)
    fig.suptitle(f"Perception model against the VO: {points.shape[0]} frames of {counted} trials", fontsize=11)
    return fig


def report_figures(folder):
    """{"fig3_<scene>", "fig4_<scene>", "tracking_<scene>" per scene, "plan_time", "calibration": Figure}
    of a `tgnav report` folder (tracking_<scene> only with vo.csv frames, calibration only when some
    vo.csv has predicted_score)."""
    doc = read_json(os.path.join(folder, "report.json"))
    scenes = [load_report_scene(s, folder) for s in doc["scenes"].items()]
    groups = [load_report_group(g) for g in doc["groups"].items()]
    colours = group_colours(groups)
    figures = {}
    for scene in scenes:
        scene_groups = [g for g in groups if g.scene == scene.name]
        figures[f"fig3_{scene.name}"] = fig3_figure(scene, scene_groups)
        figures[f"fig4_{scene.name}"] = fig4_figure(scene, scene_groups, colours)
        if any(t.frames is not None for g in scene_groups for t in g.trials):
            figures[f"tracking_{scene.name}"] = tracking_figure(scene, scene_groups)
    figures["plan_time"] = plan_time_figure(scenes, groups, colours)
    points = calibration_points(groups)
    if points is not None:  # no trial has predicted_score: no calibration plot (table2.md says so)
        figures["calibration"] = calibration_figure(groups, points)
    return figures


# ---------------------------------------------------------------------------------------------
# eval


EVAL_COLUMNS = ("t", "ref_x", "ref_y", "ref_z", "est_x", "est_y", "est_z", "error_m", "distance_m")
REFERENCE = "#202020"
ERROR_CMAP = "plasma"


def eval_title(summary):
    name = os.path.basename
    scale = f", scale {summary['alignment']['scale'].number():.4g}" if summary["align"].text() == "sim3" else ""
    return (f"{name(summary['est'].text())} against {name(summary['ref'].text())}: ATE ({summary['align'].text()}"
            f"{scale}) rmse {summary['ate']['rmse_m'].number():.3g} m over {summary['pairs'].integer()} pairs")


def rpe_note(rpe):
    if rpe["pairs"].integer() == 0:
        return f"RPE ({rpe['delta'].number():g} {rpe['unit'].text()}): no pairs"
    return (f"RPE ({rpe['delta'].number():g} {rpe['unit'].text()}): rmse {rpe['trans_rmse_m'].number():.3g} m "
            f"over {rpe['pairs'].integer()} pairs")


@styled
def eval_figure(summary, pairs):
    fig = new_figure(figsize=(11.0, 4.6))
    top, along = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.1, 1.0]})
    ref = np.column_stack([pairs["ref_x"], pairs["ref_y"]])
    est = np.column_stack([pairs["est_x"], pairs["est_y"]])
    error = pairs["error_m"]
    draw_path(top, ref, REFERENCE, 1.6, "reference", zorder=2)
    draw_path(top, est, "#b0b0b0", 0.8, None, zorder=3)
    low, high = float(error.min()), float(error.max())  # evo's colour scale: from the least to the largest
    norm = colors.Normalize(low, high) if high > low else colors.Normalize(low - 0.5, high + 0.5)
    top.scatter(est[:, 0], est[:, 1], c=error, cmap=ERROR_CMAP, norm=norm, s=10, zorder=4, label="estimate (aligned)")
    bar = fig.colorbar(ScalarMappable(norm, colormaps[ERROR_CMAP]), ax=top, shrink=0.8)
    bar.set_label("position error [m]")
    set_topdown_limits(top, None, [ref, est], margin=0.2)
    fig.set_size_inches(11.0, 4.6)  # set_topdown_limits sized it for a top-down panel alone
    top.legend(loc="best")
    rmse = summary["ate"]["rmse_m"].number()
    along.plot(pairs["distance_m"], error, color="C0", lw=1.2, label="position error")
    along.axhline(rmse, color="C3", lw=1.0, dashes=(4, 2), label=f"RMSE {rmse:.3g} m")
    along.set_xlabel("distance along the reference [m]")
    along.set_ylabel("position error [m]")
    along.set_ylim(0.0, 1.35 * high if high > 0 else 1.0)  # room for the legend above the curve
    along.grid(True, color="#e0e0e0")
    along.set_axisbelow(True)
    along.legend(loc="upper right", title=rpe_note(summary["rpe"]))
    fig.suptitle(eval_title(summary))
    return fig


def eval_figures(folder):
    """{"eval": Figure} of a `tgnav eval --out` folder."""
    summary = read_json(os.path.join(folder, "eval.json"))
    pairs = read_csv_columns(os.path.join(folder, "eval_pairs.csv"), EVAL_COLUMNS)
    if not len(pairs["t"]):
        raise DataError(os.path.join(folder, "eval_pairs.csv"), "no pairs")
    return {"eval": eval_figure(summary, pairs)}


# ---------------------------------------------------------------------------------------------
# Writing figures, and the command line


@styled
def save_figures(figures, out_dir, fmt="png"):
    """Writes each {name: Figure} to out_dir/<name>.<fmt> atomically; returns the paths."""
    if fmt not in FORMATS:
        raise ValueError(f"format '{fmt}': expected one of {', '.join(FORMATS)}")
    try:
        os.makedirs(out_dir, exist_ok=True)
    except OSError as e:
        raise DataError(out_dir, f"cannot create the folder: {e.strerror}") from None
    written = []
    for name, fig in figures.items():
        path = os.path.join(out_dir, f"{name}.{fmt}")
        temporary = os.path.join(out_dir, f".{name}.{fmt}.{os.getpid()}.tmp")
        try:
            fig.savefig(temporary, format=fmt, bbox_inches="tight", pad_inches=0.05, **SAVE_OPTIONS[fmt])
            os.replace(temporary, path)
        except OSError as e:
            raise DataError(path, f"cannot write: {e.strerror or e}") from None
        finally:
            if os.path.exists(temporary):
                os.remove(temporary)
        written.append(path)
    return written


def plot_trial(folder, out=None, fmt="png"):
    """topdown.<fmt>, ate.<fmt> (and online_plans.<fmt> with online.json) of a `tgnav trial` folder
    into `out` (default the folder)."""
    return save_figures(trial_figures(folder), out or folder, fmt)


def plot_plan(folder, out=None, fmt="png"):
    """plan.<fmt> of a `tgnav plan` folder into `out` (default the folder)."""
    return save_figures(plan_figures(folder), out or folder, fmt)


def plot_map(folder, out=None, fmt="png"):
    """topdown.<fmt> of a `tgnav map` folder into `out` (default the folder)."""
    return save_figures(map_figures(folder), out or folder, fmt)


def plot_report(folder, out=None, fmt="png"):
    """fig3_<scene>, fig4_<scene> and plan_time.<fmt> of a `tgnav report` folder into `out`."""
    return save_figures(report_figures(folder), out or folder, fmt)


def plot_eval(folder, out=None, fmt="png"):
    """eval.<fmt> of a `tgnav eval --out` folder into `out` (default the folder)."""
    return save_figures(eval_figures(folder), out or folder, fmt)


PLOTTERS = {"trial": plot_trial, "plan": plot_plan, "map": plot_map, "report": plot_report, "eval": plot_eval}


def one_line(text):
    return " ".join(str(text).split())


def main(argv=None):
    parser = argparse.ArgumentParser(prog=PROG, description="Draw tgnav's figures from a run folder's data files.")
    parser.add_argument("kind", choices=sorted(PLOTTERS), help="what DIR holds")
    parser.add_argument("dir", help="the run folder")
    parser.add_argument("--format", choices=FORMATS, default="png", help="figure file format (default png)")
    parser.add_argument("--out", help="folder the figures are written to (default DIR)")
    args = parser.parse_args(argv)
    if MISSING is not None:
        name = MISSING.name or "matplotlib"
        package = PACKAGES.get(name, "python3-matplotlib")
        print(f"{PROG}: figures skipped: cannot import {name} ({one_line(MISSING)}); install {package}",
              file=sys.stderr)
        return 3
    try:
        if not os.path.isdir(args.dir):
            raise DataError(args.dir, "no such folder")
        with warnings.catch_warnings():  # the contract: nothing printed on success
            warnings.simplefilter("ignore")
            PLOTTERS[args.kind](args.dir, args.out, args.format)
    except DataError as e:
        print(f"{PROG}: error: {one_line(e)}", file=sys.stderr)
        return 1
    except Exception as e:  # noqa: BLE001 - whatever it is, one line naming the folder
        print(f"{PROG}: error: {args.dir}: {type(e).__name__}: {one_line(e)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
