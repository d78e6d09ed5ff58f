#!/usr/bin/python3
"""Can a vehicle that must see where it flies keep its VO to the goal? An oracle on a scene's true
layout, in the plane of the flight height: a generated scene (`generated.json` of `tgnav scene
generate`) or a scene file of configs/scenes with its MJCF.

The model:
- The blocks: a generated scene's surfaces (all full height, so the plane is exact), or the MJCF's
  axis-aligned box and cylinder geoms that reach into the flight height +- 0.3 m (the planners'
  slice). A generated block is textured when rich or medium; a geom when its material has a texture
  from a file (colours and builtin checkers are plain).
- A view (a cell, a yaw) *tracks* when at least `--share` of its rays across the camera's field of
  view (75 deg) end, within `--track-range`, on a textured block. A third within 7 m is the rule
  the detour generator builds its premise with (harness/scenes/layout_detour.cpp: the long route's
  views). `--check-views` measures the rule against the VO's frames of flown trials.
- A view *observes* the cells along its rays up to the first block or the mapper's range
  (`trial.map_range_m`, 6 m): they become known free.
- The vehicle moves between neighbouring cells (0.2 m) clear of every block by the planners' robot
  radius, keeping its yaw, and turns in place in steps of 5 deg; every view it holds on the way
  must track. It starts at the scene's start pose.

Four questions, each a search over (cell, yaw) states:
- `prior`: every free cell is known (a survey map). Is there a tracking route?
- `explore`: only what reached views observed is known, and a move goes into known space (online
  from no map, a map kept). The known space grows with every view any reachable state holds, until
  nothing changes: a flight that keeps the VO and never enters space it has not observed exists in
  the model exactly when `explore` reaches the goal (it may have to fly elsewhere to look).
- `look_ahead`: each move lies within `--look-half-deg` of the yaw held (the trial's look-ahead
  rule, everywhere, no map kept): the vehicle sees each step from where it is.
- `any_view`: `explore` with every view tracking: the geometry alone lets an explorer through.
Where `prior` reaches the goal and `explore` does not, the unknown space alone stands between a
VO-keeping flight and the goal; where `explore` does and `look_ahead` does not, only a flight that
looks elsewhere than where it goes, and remembers, gets there.

Usage:
  /usr/bin/python3 scripts/route_oracle.py SCENE... [--out FILE.json] [--figure DIR]
  /usr/bin/python3 scripts/route_oracle.py --check-views TRIAL_OR_SWEEP... [--scene-root DIR] [--out FILE.json]
SCENE: a folder of tgnav scene generate, its generated.json, or a scene file (.yaml) of configs/scenes.
Exit status 2 with one line naming the file for bad input, nothing written.
"""
import argparse
import collections
import csv
import json
import math
import os
import sys
import xml.etree.ElementTree as ET

import numpy as np
import yaml
from scipy import ndimage

TEXTURED = ("rich", "medium")
MODES = ("prior", "explore", "look_ahead", "any_view")


class InputError(Exception):
    pass


def numbers(file, where, text, count):
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        values = []
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise InputError(f"{file}: {where}: '{text}' is not {count} numbers")
    return values


def load_mjcf_scene(file):
    """A scene file of configs/scenes (mjcf, flight_height_m, start, goal, bounds) as a layout:
    the MJCF's box and cylinder geoms (axis-aligned; a rotated one is refused) that reach into the
    flight height +- 0.3 m (the planners' slice) are the blocks; a geom whose material has a texture
    from a file is rich, any other (a colour, a builtin checker) plain."""
    try:
        with open(file) as f:
            doc = yaml.safe_load(f)
    except (OSError, yaml.YAMLError) as e:
        raise InputError(f"{file}: cannot read a scene file: {e}")
    for key in ("mjcf", "flight_height_m", "start", "goal", "bounds"):
        if not isinstance(doc, dict) or key not in doc:
            raise InputError(f"{file}: key '{key}' missing (not a scene file of configs/scenes)")
    mjcf = os.path.join(os.path.dirname(file), doc["mjcf"])
    try:
        root = ET.parse(mjcf).getroot()
    except (OSError, ET.ParseError) as e:
        raise InputError(f"{file}: mjcf: cannot read '{mjcf}': {e}")
    textures = {t.get("name"): t for t in root.iter("texture")}
    textured = set()
    for m in root.iter("material"):
        t = textures.get(m.get("texture"))
        if t is not None and t.get("builtin") in (None, "none"):
            textured.add(m.get("name"))
    height = doc["flight_height_m"]
    if not (isinstance(height, (int, float)) and not isinstance(height, bool) and math.isfinite(height)):
        raise InputError(f"{file}: flight_height_m: {height!r} is not a number")
    if not isinstance(doc["bounds"], dict):
        raise InputError(f"{file}: bounds: {doc['bounds']!r} is not an object with min and max")
    bounds = {k: number_list(file, f"bounds.{k}", doc["bounds"].get(k), 3) for k in ("min", "max")}
    surfaces = []
    for g in root.iter("geom"):
        kind = g.get("type", "sphere")
        if kind not in ("box", "cylinder"):
            continue
        name = g.get("name", f"geom{len(surfaces)}")
        if any(g.get(a) for a in ("euler", "quat", "axisangle", "zaxis", "xyaxes", "fromto")):
            raise InputError(f"{mjcf}: geom '{name}': rotated geoms are not supported by the plane model")
        pos = numbers(mjcf, f"geom '{name}' pos", g.get("pos", "0 0 0"), 3)
        size = numbers(mjcf, f"geom '{name}' size", g.get("size", ""), 3 if kind == "box" else 2)
        half_z = size[2] if kind == "box" else size[1]
        if pos[2] + half_z < height - 0.3 or pos[2] - half_z > height + 0.3:
            continue
        surfaces.append({"name": name, "type": kind, "centre_m": pos,
                         "half_size_m": size[:2] if kind == "box" else [size[0], half_z],
                         "level": "rich" if g.get("material") in textured else "plain"})
    return {"room": {"min_m": bounds["min"], "max_m": bounds["max"]}, "surfaces": surfaces, "start": doc["start"], "goal": doc["goal"]}


def load_scene(path):
    """The generated.json of a scene folder (or the file itself), or a scene file of
    configs/scenes (.yaml) with its MJCF."""
    file = os.path.join(path, "generated.json") if os.path.isdir(path) else path
    if file.endswith((".yaml", ".yml")):
        scene = load_mjcf_scene(file)
        return check_scene(file, scene)
    try:
        with open(file) as f:
            scene = json.load(f)
    except (OSError, ValueError) as e:
        raise InputError(f"{file}: cannot read a generated scene: {e}")
    return check_scene(file, scene)


def number_list(file, key, value, count):
    """`value` as `count` finite numbers (at least `count` with count < 0), or InputError."""
    ok = isinstance(value, list) and (len(value) == count or (count < 0 and len(value) >= -count))
    ok = ok and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in value)
    if not ok:
        raise InputError(f"{file}: {key}: {value!r} is not {abs(count)}{'' if count > 0 else ' or more'} numbers")
    return value


def check_scene(file, scene):
    if not isinstance(scene, dict):
        raise InputError(f"{file}: not a JSON object (not a generated.json of tgnav scene generate)")
    for key in ("room", "surfaces", "start", "goal"):
        if key not in scene:
            raise InputError(f"{file}: key '{key}' missing (not a generated.json of tgnav scene generate)")
    room = scene["room"]
    if not isinstance(room, dict):
        raise InputError(f"{file}: room: {room!r} is not an object with min_m and max_m")
    lo = number_list(file, "room.min_m", room.get("min_m"), -2)
    hi = number_list(file, "room.max_m", room.get("max_m"), -2)
    if not (lo[0] < hi[0] and lo[1] < hi[1]):
        raise InputError(f"{file}: room: min_m {lo} is not below max_m {hi}")
    if not isinstance(scene["surfaces"], list):
        raise InputError(f"{file}: surfaces: not a list")
    for i, s in enumerate(scene["surfaces"]):
        if not isinstance(s, dict) or s.get("type") not in ("box", "cylinder"):
            raise InputError(f"{file}: surfaces[{i}].type: '{s.get('type') if isinstance(s, dict) else s}' "
                             "is not box or cylinder")
        if s.get("level") not in ("rich", "medium", "faint", "plain"):
            raise InputError(f"{file}: surfaces[{i}].level: '{s.get('level')}' is not rich, medium, faint or plain")
        number_list(file, f"surfaces[{i}].centre_m", s.get("centre_m"), -2)
        half = number_list(file, f"surfaces[{i}].half_size_m", s.get("half_size_m"), -2)
        if min(half[:2]) <= 0:
            raise InputError(f"{file}: surfaces[{i}].half_size_m: {half} is not positive")
    for key in ("start", "goal"):
        number_list(file, key, scene[key], 4)  # [x, y, z, yaw]
    scene["_file"] = file
    base = os.path.basename(file)
    scene["_name"] = (os.path.basename(os.path.dirname(os.path.abspath(file))) if base == "generated.json"
                      else os.path.splitext(base)[0])
    return scene


class Plane:
    """The layout rasterised at `fine` m: which surface (index, -1 none) covers each cell."""

    def __init__(self, scene, fine):
        lo = np.array(scene["room"]["min_m"][:2], float) - 0.2
        hi = np.array(scene["room"]["max_m"][:2], float) + 0.2
        self.lo, self.fine = lo, fine
        self.shape = tuple(np.ceil((hi - lo) / fine).astype(int))
        xs = lo[0] + (np.arange(self.shape[0]) + 0.5) * fine
        ys = lo[1] + (np.arange(self.shape[1]) + 0.5) * fine
        X, Y = np.meshgrid(xs, ys, indexing="ij")
        self.label = np.full(self.shape, -1, dtype=np.int32)
        for i, s in enumerate(scene["surfaces"]):
            cx, cy = s["centre_m"][:2]
            if s["type"] == "box":
                hx, hy = s["half_size_m"][:2]
                inside = (np.abs(X - cx) <= hx) & (np.abs(Y - cy) <= hy)
            else:
                inside = np.hypot(X - cx, Y - cy) <= s["half_size_m"][0]
            self.label[inside] = i
        self.textured = np.array([s["level"] in TEXTURED for s in scene["surfaces"]] + [False])

    def cell(self, x, y):
        return (np.floor((np.asarray(x) - self.lo[0]) / self.fine).astype(int),
                np.floor((np.asarray(y) - self.lo[1]) / self.fine).astype(int))

    def march(self, x0, y0, angles, max_range):
        """For rays from points (x0, y0) (arrays, n) at angles (m, the same for every point, or
        n x m): the distance to the first block (max_range where none) and whether that block is
        textured, each n x m."""
        steps = np.arange(1, int(math.ceil(max_range / (0.5 * self.fine))) + 1) * 0.5 * self.fine
        angles = np.broadcast_to(angles, (len(x0), np.shape(angles)[-1]))
        dist = np.full(angles.shape, max_range)
        tex = np.zeros(angles.shape, bool)
        c, s = np.cos(angles), np.sin(angles)
        for j in range(angles.shape[1]):
            px = x0[:, None] + steps[None, :] * c[:, j, None]
            py = y0[:, None] + steps[None, :] * s[:, j, None]
            ix, iy = self.cell(px, py)
            ok = (ix >= 0) & (iy >= 0) & (ix < self.shape[0]) & (iy < self.shape[1])
            lab = np.where(ok, self.label[np.clip(ix, 0, self.shape[0] - 1), np.clip(iy, 0, self.shape[1] - 1)], -1)
            hit = lab >= 0
            first = np.where(hit.any(axis=1), hit.argmax(axis=1), -1)
            has = first >= 0
            dist[has, j] = steps[first[has]]
            tex[has, j] = self.textured[lab[has, first[has]]]
        return dist, tex


def analyse(scene, args):
    plane = Plane(scene, args.fine)
    lo = plane.lo
    step = args.cell
    nx = int((plane.shape[0] * plane.fine) // step)
    ny = int((plane.shape[1] * plane.fine) // step)
    xs = lo[0] + (np.arange(nx) + 0.5) * step
    ys = lo[1] + (np.arange(ny) + 0.5) * step
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    # Clearance: a cell is free for the vehicle when no block lies within the robot radius.
    blocked_fine = plane.label >= 0
    clearance = ndimage.distance_transform_edt(~blocked_fine) * plane.fine
    fx, fy = plane.cell(X, Y)
    free = clearance[np.clip(fx, 0, plane.shape[0] - 1), np.clip(fy, 0, plane.shape[1] - 1)] >= args.radius
    rmin, rmax = np.array(scene["room"]["min_m"][:2]), np.array(scene["room"]["max_m"][:2])
    free &= (X > rmin[0]) & (X < rmax[0]) & (Y > rmin[1]) & (Y < rmax[1])
    cells = np.argwhere(free)
    index = -np.ones((nx, ny), int)
    index[free] = np.arange(len(cells))

    n_yaw = int(round(360 / args.yaw_step_deg))
    rays_per_yaw = 4  # rays every yaw_step/4 all round
    n_rays = n_yaw * rays_per_yaw
    angles = np.arange(n_rays) * 2 * math.pi / n_rays
    dist, tex = plane.march(X[free], Y[free], angles, max(args.track_range, args.map_range))
    half = math.radians(args.hfov_deg) / 2
    half_rays = int(round(half / (2 * math.pi / n_rays)))
    view_rays = 2 * half_rays + 1
    good = tex & (dist <= args.track_range) & (dist >= args.min_range)
    # tracks[c, k]: the view at yaw k*yaw_step from cell c sees enough texture.
    shifts = np.arange(-half_rays, half_rays + 1)
    tracks = np.zeros((len(cells), n_yaw), bool)
    for k in range(n_yaw):
        cols = (k * rays_per_yaw + shifts) % n_rays
        tracks[:, k] = good[:, cols].sum(axis=1) >= args.share * view_rays

    fired = np.zeros((len(cells), n_rays), bool)
    samples = np.arange(0.0, args.map_range, step * 0.5)

    def observe(c, k, known):
        """Marks known the cells a view observes (along its rays to the first block or the map
        range); returns those newly known. Each ray from a cell is walked once."""
        x0, y0 = X[tuple(cells[c])], Y[tuple(cells[c])]
        cols = (k * rays_per_yaw + shifts) % n_rays
        cols = cols[~fired[c, cols]]
        if not len(cols):
            return []
        fired[c, cols] = True
        reach = np.minimum(dist[c, cols], args.map_range)
        d = np.where(samples[None, :] < reach[:, None], samples[None, :], 0.0)  # beyond reach: the cell itself
        i = ((x0 + d * np.cos(angles[cols])[:, None] - lo[0]) // step).astype(int)
        j = ((y0 + d * np.sin(angles[cols])[:, None] - lo[1]) // step).astype(int)
        inside = (i >= 0) & (j >= 0) & (i < nx) & (j < ny)
        o = index[i[inside], j[inside]]
        o = o[o >= 0]
        o = np.unique(o[~known[o]])
        known[o] = True
        return o.tolist()

    def locate(pose, what):
        """The free cell nearest the pose, which must lie within one cell of it."""
        d = np.hypot(X[free] - pose[0], Y[free] - pose[1])
        best = int(np.argmin(d))
        if d[best] > step:
            raise InputError(f"{scene['_file']}: {what}: {pose[:2]} has no free cell within {step} m "
                             f"(robot radius {args.radius} m)")
        return best

    start = locate(scene["start"], "start")
    goal = locate(scene["goal"], "goal")
    start_yaw = int(round((scene["start"][3] % (2 * math.pi)) / math.radians(args.yaw_step_deg))) % n_yaw
    neighbours = [(-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)]
    adjacency = []  # per cell: (neighbour, the move's heading in yaw steps, fractional)
    for c in range(len(cells)):
        adj = []
        for di, dj in neighbours:
            i, j = cells[c][0] + di, cells[c][1] + dj
            if 0 <= i < nx and 0 <= j < ny and index[i, j] >= 0:
                adj.append((index[i, j], math.degrees(math.atan2(dj, di)) / args.yaw_step_deg))
        adjacency.append(adj)

    def in_look(heading, k):
        """Whether a move along `heading` (yaw steps) lies within the look-ahead's half field of
        view of yaw k."""
        off = abs((heading - k + n_yaw / 2) % n_yaw - n_yaw / 2) * args.yaw_step_deg
        return off <= args.look_half_deg + 1e-9

    def search(mode):
        """prior: all known; explore: known is what reached views observed; look_ahead: a move is
        into the view's own look-ahead cone (no memory); any_view: explore, every view tracking."""
        ok = np.ones_like(tracks) if mode == "any_view" else tracks
        if not ok[start, start_yaw]:
            return {"reached": False, "why": "the start view does not track", "known_share": 0.0}
        mapping = mode in ("explore", "any_view")
        known = np.zeros(len(cells), bool) if mapping else np.ones(len(cells), bool)
        fired[:] = False
        seen = np.zeros_like(tracks)
        waiting = collections.defaultdict(list)
        queue = collections.deque()
        looking = []  # states whose view has not yet been added to the known space
        parent = {}

        def visit(state, prev):
            c, k = state
            if seen[c, k] or not ok[c, k]:
                return
            seen[c, k] = True
            parent[state] = prev
            queue.append(state)
            if mapping:
                looking.append(state)

        known[start] = True
        visit((start, start_yaw), None)
        while queue:
            while looking:
                for o in observe(*looking.pop(), known):
                    for w, wprev in waiting.pop(o, []):
                        visit(w, wprev)
            c, k = queue.popleft()
            if c == goal:
                path = []
                s = (c, k)
                while s is not None:
                    path.append(s)
                    s = parent[s]
                xy = [[float(X[tuple(cells[p[0]])]), float(Y[tuple(cells[p[0]])]), p[1] * args.yaw_step_deg]
                      for p in reversed(path)]
                return {"reached": True, "known_share": float(known.mean()), "path": xy,
                        "path_length_m": float(sum(math.dist(a[:2], b[:2]) for a, b in zip(xy, xy[1:])))}
            for dk in (-1, 1):
                visit((c, (k + dk) % n_yaw), (c, k))
            for n, heading in adjacency[c]:
                if mode == "look_ahead":
                    if in_look(heading, k):
                        visit((n, k), (c, k))
                elif known[n]:
                    visit((n, k), (c, k))
                elif ok[n, k]:
                    waiting[n].append(((n, k), (c, k)))
        # Where it got: the free cells some tracking state reached (all of them: the search ran out).
        return {"reached": False, "why": "no tracking state reaches the goal", "known_share": float(known.mean()),
                "_reached": seen.any(axis=1)}

    result = {"scene": scene["_file"], "cells": int(len(cells)), "tracking_share": float(tracks.mean())}
    for mode in MODES:
        result[mode] = search(mode)
        if "_reached" in result[mode]:
            result[mode]["reached_share"] = float(result[mode]["_reached"].mean())
    result["_draw"] = (X, Y, free, cells, tracks)
    return result


def figure(result, scene, out_dir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    X, Y, free, cells, tracks = result["_draw"]
    share = np.full(free.shape, np.nan)
    share[free] = tracks.mean(axis=1)
    fig, ax = plt.subplots(figsize=(8, 6))
    m = ax.pcolormesh(X, Y, share, shading="nearest", cmap="viridis", vmin=0, vmax=1)
    fig.colorbar(m, ax=ax, label="share of yaws whose view tracks")
    for s in scene["surfaces"]:
        colour = "tab:red" if s["level"] in TEXTURED else "0.3"
        cx, cy = s["centre_m"][:2]
        if s["type"] == "box":
            hx, hy = s["half_size_m"][:2]
            ax.add_patch(plt.Rectangle((cx - hx, cy - hy), 2 * hx, 2 * hy, color=colour))
        else:
            ax.add_patch(plt.Circle((cx, cy), s["half_size_m"][0], color=colour))
    for key, style in (("prior", "w--"), ("explore", "m-"), ("look_ahead", "c:")):
        if result[key]["reached"]:
            p = np.array(result[key]["path"])
            ax.plot(p[:, 0], p[:, 1], style, lw=2, label=f"{key}: {result[key]['path_length_m']:.1f} m")
    if "_reached" in result["look_ahead"]:
        reach = np.zeros(free.shape)
        reach[free] = result["look_ahead"]["_reached"]
        ax.contour(X, Y, reach, levels=[0.5], colors="cyan", linewidths=1.5)
        ax.plot([], [], "c-", label="look_ahead: where it got")
    ax.plot(*scene["start"][:2], "wo", ms=9, mec="k", label="start")
    ax.plot(*scene["goal"][:2], "y*", ms=14, mec="k", label="goal")
    ax.set_aspect("equal")
    ax.set_title(f"{scene['_name']}: prior {'yes' if result['prior']['reached'] else 'no'}, "
                 f"explore {'yes' if result['explore']['reached'] else 'no'}, "
                 f"look_ahead {'yes' if result['look_ahead']['reached'] else 'no'} (red: textured)")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.06), ncol=3, fontsize=8)
    os.makedirs(out_dir, exist_ok=True)
    fig.savefig(os.path.join(out_dir, f"{scene['_name']}_oracle.png"), dpi=110, bbox_inches="tight")
    plt.close(fig)


# --- --check-views: the view rule against the VO's frames of flown trials -----------------------

def view_shares(plane, x, y, yaw, args):
    """The share of each view's rays (61 across the field of view) that end on a textured block
    within the track range, for views at (x, y) looking along yaw (arrays)."""
    half = math.radians(args.hfov_deg) / 2
    dist, tex = plane.march(x, y, yaw[:, None] + np.linspace(-half, half, 61)[None, :], args.track_range)
    return (tex & (dist >= args.min_range) & (dist <= args.track_range)).mean(axis=1)


def trial_folders(path):
    """A trial folder (vo.csv, gt.tum, config.yaml), or every trial of a sweep folder (index.csv)."""
    index = os.path.join(path, "index.csv")
    if os.path.isfile(index):
        with open(index) as f:
            rows = list(csv.DictReader(f))
        if rows and "folder" not in rows[0]:
            raise InputError(f"{index}: column 'folder' missing (not a sweep's index.csv)")
        return [os.path.join(path, r["folder"]) for r in rows]
    if not os.path.isfile(os.path.join(path, "vo.csv")):
        raise InputError(f"{path}: neither a trial folder (vo.csv) nor a sweep folder (index.csv)")
    return [path]


def trial_scene(folder, scene_root):
    """The scene a trial flew: its config.yaml's scene (a generated scene's generated.json two
    folders up), or, where that file is gone, the file of that name in scene_root."""
    file = os.path.join(folder, "config.yaml")
    try:
        with open(file) as f:
            scene = (yaml.safe_load(f) or {}).get("scene")
    except (OSError, yaml.YAMLError) as e:
        raise InputError(f"{file}: cannot read: {e}")
    if not isinstance(scene, str):
        raise InputError(f"{file}: key 'scene' missing")
    if not os.path.exists(scene) and scene_root:
        scene = os.path.join(scene_root, os.path.basename(scene))
    generated = os.path.join(os.path.dirname(os.path.dirname(scene)), "generated.json")
    if os.path.isfile(generated):
        return load_scene(generated)
    if not os.path.isfile(scene):
        raise InputError(f"{file}: scene: '{scene}' does not exist (--scene-root names a folder of scene files)")
    return load_scene(scene)


def check_views(paths, args):
    """Per VO frame of the trials (the first, the VO's start, left out): the view rule's share at
    the true camera pose, the inliers and whether the frame was lost."""
    share, inliers, lost = [], [], []
    for path in paths:
        for folder in trial_folders(path):
            scene = trial_scene(folder, args.scene_root)
            plane = Plane(scene, args.fine)
            try:
                gt = np.loadtxt(os.path.join(folder, "gt.tum"), ndmin=2)
                with open(os.path.join(folder, "vo.csv")) as f:
                    frames = list(csv.DictReader(f))
            except (OSError, ValueError) as e:
                raise InputError(f"{folder}: cannot read gt.tum or vo.csv: {e}")
            if gt.shape[1] != 8 or not frames:
                raise InputError(f"{folder}/gt.tum: not 8 columns (TUM), or vo.csv has no frame")
            missing = [c for c in ("t", "status", "inliers") if c not in frames[0]]
            if missing:
                raise InputError(f"{folder}/vo.csv: column '{missing[0]}' missing")
            try:
                t_all = [float(r["t"]) for r in frames[1:]]
                inl_all = [int(r["inliers"] or 0) for r in frames[1:]]
            except (TypeError, ValueError) as e:
                raise InputError(f"{folder}/vo.csv: a row's t or inliers is not a number: {e}")
            t = np.array(t_all)
            rows = np.clip(np.searchsorted(gt[:, 0], t - 1e-6), 0, len(gt) - 1)
            qx, qy, qz, qw = gt[rows, 4], gt[rows, 5], gt[rows, 6], gt[rows, 7]
            yaw = np.arctan2(2 * (qy * qz - qw * qx), 2 * (qx * qz + qw * qy))  # the optical axis (camera z)
            for a in range(0, len(t), 256):
                share.extend(view_shares(plane, gt[rows[a:a + 256], 1], gt[rows[a:a + 256], 2], yaw[a:a + 256], args))
            inliers.extend(inl_all)
            lost.extend(r["status"] == "lost" for r in frames[1:])
    share, inliers, lost = np.array(share), np.array(inliers), np.array(lost)
    bins = [0.0, 0.1, 0.2, args.share, 0.5, 1.0 + 1e-9]
    table = []
    for a, b in zip(bins, bins[1:]):
        k = (share >= a) & (share < b)
        table.append({"share_from": a, "share_to": min(b, 1.0), "frames": int(k.sum()),
                      "lost": int((lost & k).sum()),
                      "inliers_median": float(np.median(inliers[k])) if k.any() else None,
                      "below_30_inliers": float(np.mean(inliers[k] < 30)) if k.any() else None})
        print(f"share [{a:.2f}, {min(b, 1.0):.2f}): {k.sum():6d} frames, lost {int((lost & k).sum()):3d}, "
              + (f"inliers median {np.median(inliers[k]):4.0f}, < 30 in {np.mean(inliers[k] < 30):.3f}" if k.any() else ""))
    tracks = share >= args.share
    print(f"views the rule says track (share >= {args.share:.3f}): {int(tracks.sum())} frames, {int((lost & tracks).sum())} lost; "
          f"the others: {int((~tracks).sum())} frames, {int((lost & ~tracks).sum())} lost")
    return {"frames": int(len(share)), "lost": int(lost.sum()), "bins": table,
            "rule_tracks": {"frames": int(tracks.sum()), "lost": int((lost & tracks).sum())}}


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scenes", nargs="+", help="scene folders of tgnav scene generate, their generated.json, or scene "
                    "files of configs/scenes; with --check-views, trial or sweep folders")
    ap.add_argument("--check-views", action="store_true",
                    help="instead: the view rule against the VO's frames of flown trials (trial or sweep folders)")
    ap.add_argument("--scene-root", help="with --check-views: a folder of scene files, for trials whose scene moved")
    ap.add_argument("--out", help="write the results as JSON here")
    ap.add_argument("--figure", help="write one figure per scene into this folder")
    ap.add_argument("--paths", help="write each route found as a path CSV for tgnav trial --path into this folder")
    ap.add_argument("--cell", type=float, default=0.2, help="the search's cell, m (0.2)")
    ap.add_argument("--fine", type=float, default=0.05, help="the layout's raster, m (0.05)")
    ap.add_argument("--radius", type=float, default=0.38, help="clearance, m (the planners' robot radius, 0.38)")
    ap.add_argument("--share", type=float, default=1 / 3, help="share of a view's rays on texture that tracks (1/3)")
    ap.add_argument("--track-range", type=float, default=7.0,
                    help="texture farther than this does not count toward a view's share, m (7: the detour "
                         "generator's kRouteViewRangeM; the VO's depth reaches 10)")
    ap.add_argument("--min-range", type=float, default=0.3, help="the camera's nearest depth, m (0.3)")
    ap.add_argument("--map-range", type=float, default=6.0, help="the online mapper's range, m (6)")
    ap.add_argument("--hfov-deg", type=float, default=75.0, help="the camera's horizontal field of view (75)")
    ap.add_argument("--yaw-step-deg", type=float, default=5.0, help="the yaws searched (5)")
    ap.add_argument("--look-half-deg", type=float, default=27.6,
                    help="look_ahead: the half cone a move must lie in (27.6: the trial's look-ahead, "
                         "planner::lookAheadHalfFov at the defaults)")
    args = ap.parse_args(argv)
    for name in ("cell", "fine", "share", "track_range", "map_range", "hfov_deg", "yaw_step_deg", "look_half_deg"):
        v = getattr(args, name)
        if not (v > 0 and math.isfinite(v)):
            raise InputError(f"--{name.replace('_', '-')}: {v} must be a positive number")
    if not (0 < args.share <= 1) or args.radius < 0 or 360 % args.yaw_step_deg:
        raise InputError(f"--share {args.share} must lie in (0, 1], --radius {args.radius} >= 0, "
                         f"--yaw-step-deg {args.yaw_step_deg} must divide 360")
    if args.check_views:
        report = check_views(args.scenes, args)
        write_json(args.out, {"settings": vars(args), "check_views": report})
        return 0
    results = []
    for path in args.scenes:
        scene = load_scene(path)
        r = analyse(scene, args)
        if args.figure:
            figure(r, scene, args.figure)
        if args.paths:
            write_paths(r, scene, args.paths)
        del r["_draw"]
        for mode in MODES:
            r[mode].pop("_reached", None)
        results.append(r)
        print(f"{scene['_file']}: " + ", ".join(f"{m} " + (f"{r[m]['path_length_m']:.1f} m" if r[m]["reached"] else "no")
                                                  for m in MODES)
              + f" (views that track {r['tracking_share']:.2f}, explore knew {r['explore']['known_share']:.2f})")
    print("reach the goal: " + ", ".join(f"{m} {sum(r[m]['reached'] for r in results)}/{len(results)}"
                                         for m in MODES))
    write_json(args.out, {"settings": vars(args), "scenes": results})
    return 0


def write_paths(result, scene, out_dir):
    """Each route found (prior, explore) as a 4-DoF path CSV for `tgnav trial --path` (x,y,z,yaw),
    at the start's height: the scene's start, one point per cell with the last yaw held there
    (unwrapped, so the trajectory turns the way the search did), and the goal's position."""
    height = scene["start"][2]
    os.makedirs(out_dir, exist_ok=True)
    for mode in ("prior", "explore"):
        if not result[mode]["reached"]:
            continue
        points = []
        for x, y, yaw in result[mode]["path"]:
            if points and math.dist(points[-1][:2], (x, y)) < 1e-9:
                points[-1][2] = yaw
            else:
                points.append([x, y, yaw])
        yaws = np.unwrap([scene["start"][3]] + [math.radians(p[2]) for p in points])  # [i + 1]: points[i]
        rows = [(scene["start"][0], scene["start"][1], yaws[0])]
        rows += [(p[0], p[1], yaws[i + 1]) for i, p in enumerate(points[1:-1], start=1)]
        rows.append((scene["goal"][0], scene["goal"][1], yaws[-1]))
        with open(os.path.join(out_dir, f"{scene['_name']}_{mode}.csv"), "w") as f:
            f.write("x,y,z,yaw\n" + "".join(f"{x:.3f},{y:.3f},{height:.3f},{yaw:.4f}\n" for x, y, yaw in rows))


def write_json(path, doc):
    """Whole or not at all."""
    if path:
        tmp = path + ".tmp"
        with open(tmp, "w") as f:
            json.dump(doc, f, indent=1)
        os.replace(tmp, path)


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except InputError as e:
        print(f"route_oracle.py: {e}", file=sys.stderr)
        sys.exit(2)
