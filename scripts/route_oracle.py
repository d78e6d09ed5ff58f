#!/usr/bin/python3
"""Can a vehicle that must see where it flies keep its VO to the goal? An oracle on a generated
scene's true layout (`generated.json` of `tgnav scene generate`), in the plane of the flight height.

The model (every block of a generated scene is full height, so the plane is exact for geometry):
- A view (a cell, a yaw) *tracks* when at least `--share` of its rays across the camera's field of
  view (75 deg) end, within the VO's depth range, on a rich or medium block. This is the rule the
  detour generator builds its premise with (harness/scenes/layout_detour.cpp: a third of the view).
- A view *observes* the cells along its rays up to the first block or the mapper's range
  (`trial.map_range_m`, 6 m): they become known free.
- The vehicle moves between neighbouring cells, with its clearance (the planners' robot radius),
  keeping its yaw, into cells already known free, and turns in place in steps of 5 deg; every
  view it holds on the way must track. It starts at the scene's start pose with what that view
  observes.

Three questions, each answered by a search over (cell, yaw) states:
- `prior`: every free cell is known from the start (a survey map): is there a tracking route?
- `explore`: only what tracking views have observed is known (online from no map): is there one?
  The known space grows with every view any reachable state holds, until nothing changes.
- `any_view`: the same exploration where every view tracks (the VO ignored): the check that the
  geometry alone lets an explorer through.
A flight that keeps the VO and never enters space it has not observed exists in this model only if
`explore` reaches the goal. Where `prior` does and `explore` does not, the unknown space alone
stands between the planners and the goal.

Usage:
  /usr/bin/python3 scripts/route_oracle.py SCENE_DIR_OR_GENERATED_JSON... [--out FILE.json] [--figure DIR]
Exit status 2 with one line naming the file for bad input.
"""
import argparse
import collections
import json
import math
import os
import sys

import numpy as np

TEXTURED = ("rich", "medium")


class InputError(Exception):
    pass


def load_scene(path):
    """The generated.json of a scene folder (or the file itself)."""
    file = os.path.join(path, "generated.json") if os.path.isdir(path) else path
    try:
        with open(file) as f:
            scene = json.load(f)
    except (OSError, ValueError) as e:
        raise InputError(f"{file}: cannot read a generated scene: {e}")
    for key in ("room", "surfaces", "start", "goal"):
        if key not in scene:
            raise InputError(f"{file}: key '{key}' missing (not a generated.json of tgnav scene generate)")
    for i, s in enumerate(scene["surfaces"]):
        if s.get("type") not in ("box", "cylinder"):
            raise InputError(f"{file}: surfaces[{i}].type: '{s.get('type')}' is not box or cylinder")
        if s.get("level") not in ("rich", "medium", "faint", "plain"):
            raise InputError(f"{file}: surfaces[{i}].level: '{s.get('level')}' is not rich, medium, faint or plain")
    for key in ("start", "goal"):
        if not (isinstance(scene[key], list) and len(scene[key]) == 4):
            raise InputError(f"{file}: {key}: {scene[key]!r} is not [x, y, z, yaw]")
    scene["_file"] = file
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
        """For rays from points (x0, y0) (arrays, n) at angles (m): the distance to the first
        block (max_range where none) and whether that block is textured, each n x m."""
        steps = np.arange(1, int(math.ceil(max_range / (0.5 * self.fine))) + 1) * 0.5 * self.fine
        dist = np.full((len(x0), len(angles)), max_range)
        tex = np.zeros((len(x0), len(angles)), bool)
        c, s = np.cos(angles), np.sin(angles)
        for j in range(len(angles)):
            px = x0[:, None] + steps[None, :] * c[j]
            py = y0[:, None] + steps[None, :] * s[j]
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
    from scipy import ndimage
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
    dist, tex = plane.march(X[free], Y[free], angles, max(args.vo_range, args.map_range))
    half = math.radians(args.hfov_deg) / 2
    half_rays = int(round(half / (2 * math.pi / n_rays)))
    view_rays = 2 * half_rays + 1
    good = tex & (dist <= args.vo_range) & (dist >= args.min_range)
    # tracks[c, k]: the view at yaw k*yaw_step from cell c sees enough texture.
    shifts = np.arange(-half_rays, half_rays + 1)
    tracks = np.zeros((len(cells), n_yaw), bool)
    for k in range(n_yaw):
        cols = (k * rays_per_yaw + shifts) % n_rays
        tracks[:, k] = good[:, cols].sum(axis=1) >= args.share * view_rays

    fired = np.zeros((len(cells), n_rays), bool)
    samples = np.arange(0.0, args.map_range, step * 0.5)

    def observe(c, k, known, observer):
        """Marks known the cells a view observes (along its rays to the first block or the map
        range); returns those newly known. Each ray from a cell is walked once."""
        new = []
        x0, y0 = X[tuple(cells[c])], Y[tuple(cells[c])]
        cols = (k * rays_per_yaw + shifts) % n_rays
        cols = cols[~fired[c, cols]]
        fired[c, cols] = True
        for col in cols:
            d = samples[samples < min(dist[c, col], args.map_range)]
            i = ((x0 + d * math.cos(angles[col]) - lo[0]) // step).astype(int)
            j = ((y0 + d * math.sin(angles[col]) - lo[1]) // step).astype(int)
            inside = (i >= 0) & (j >= 0) & (i < nx) & (j < ny)
            o = index[i[inside], j[inside]]
            o = o[o >= 0]
            o = np.unique(o[~known[o]])
            known[o] = True
            observer[o] = c * n_yaw + k
            new.extend(o.tolist())
        return new

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
    adjacency = []
    for c in range(len(cells)):
        adj = []
        for di, dj in neighbours:
            i, j = cells[c][0] + di, cells[c][1] + dj
            if 0 <= i < nx and 0 <= j < ny and index[i, j] >= 0:
                adj.append(index[i, j])
        adjacency.append(adj)

    def search(known_all, track_all):
        ok = np.ones_like(tracks) if track_all else tracks
        if not ok[start, start_yaw]:
            return {"reached": False, "why": "the start view does not track", "known_share": 0.0}
        known = np.ones(len(cells), bool) if known_all else np.zeros(len(cells), bool)
        fired[:] = False
        observer = np.full(len(cells), -1)  # the state (c * n_yaw + k) that first observed each cell
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
            if not known_all:
                looking.append(state)

        known[start] = True
        visit((start, start_yaw), None)
        while queue:
            while looking:
                for o in observe(*looking.pop(), known, observer):
                    for w, wprev in waiting.pop(o, []):
                        visit(w, wprev)
            c, k = queue.popleft()
            if c == goal:
                path = []
                s = (c, k)
                while s is not None:
                    path.append(s)
                    s = parent[s]
                path.reverse()
                def pose(c, k):
                    return [float(X[tuple(cells[c])]), float(Y[tuple(cells[c])]), k * args.yaw_step_deg]

                xy = [pose(*p) for p in path]
                # Where each cell of the path was first observed from ([x, y, yaw_deg]; none: known
                # from the start, a survey).
                seen_from = [pose(*divmod(int(observer[p[0]]), n_yaw)) if observer[p[0]] >= 0 else None for p in path]
                return {"reached": True, "known_share": float(known.mean()), "path": xy, "seen_from": seen_from,
                        "path_length_m": float(sum(math.dist(a[:2], b[:2]) for a, b in zip(xy, xy[1:])))}
            for dk in (-1, 1):
                visit((c, (k + dk) % n_yaw), (c, k))
            for n in adjacency[c]:
                if known[n]:
                    visit((n, k), (c, k))
                elif ok[n, k]:
                    waiting[n].append(((n, k), (c, k)))
        return {"reached": False, "why": "no tracking state reaches the goal", "known_share": float(known.mean())}

    result = {"scene": scene["_file"], "cells": int(len(cells)),
              "tracking_share": float(tracks.mean()),
              "prior": search(True, False), "explore": search(False, False), "any_view": search(False, True)}
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
    for key, style in (("prior", "w--"), ("explore", "m-")):
        if result[key]["reached"]:
            p = np.array(result[key]["path"])
            ax.plot(p[:, 0], p[:, 1], style, lw=2, label=f"{key}: {result[key]['path_length_m']:.1f} m")
    if result["explore"]["reached"]:
        views = np.array(sorted({tuple(v) for v in result["explore"]["seen_from"] if v is not None}))
        if len(views):
            yaw = np.radians(views[:, 2])
            ax.quiver(views[:, 0], views[:, 1], np.cos(yaw), np.sin(yaw), color="orange", scale=25, width=0.004,
                      label="views that observed the explore route")
    ax.plot(*scene["start"][:2], "wo", ms=9, mec="k", label="start")
    ax.plot(*scene["goal"][:2], "y*", ms=14, mec="k", label="goal")
    ax.set_aspect("equal")
    ax.set_title(f"{os.path.basename(os.path.dirname(scene['_file']))}: prior {'yes' if result['prior']['reached'] else 'no'}, "
                 f"explore {'yes' if result['explore']['reached'] else 'no'} (red: rich/medium blocks)")
    ax.legend(loc="lower left", fontsize=8)
    os.makedirs(out_dir, exist_ok=True)
    name = os.path.basename(os.path.dirname(os.path.abspath(scene["_file"]))) or "scene"
    fig.savefig(os.path.join(out_dir, f"{name}_oracle.png"), dpi=110, bbox_inches="tight")
    plt.close(fig)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scenes", nargs="+", help="scene folders of tgnav scene generate, or their generated.json")
    ap.add_argument("--out", help="write the results as JSON here")
    ap.add_argument("--figure", help="write one figure per scene into this folder")
    ap.add_argument("--cell", type=float, default=0.2, help="the search's cell, m (0.2)")
    ap.add_argument("--fine", type=float, default=0.05, help="the layout's raster, m (0.05)")
    ap.add_argument("--radius", type=float, default=0.38, help="clearance, m (the planners' robot radius, 0.38)")
    ap.add_argument("--share", type=float, default=1 / 3, help="share of a view's rays on texture that tracks (1/3)")
    ap.add_argument("--vo-range", type=float, default=10.0, help="the VO's depth range, m (10)")
    ap.add_argument("--min-range", type=float, default=0.3, help="the camera's nearest depth, m (0.3)")
    ap.add_argument("--map-range", type=float, default=6.0, help="the online mapper's range, m (6)")
    ap.add_argument("--hfov-deg", type=float, default=75.0, help="the camera's horizontal field of view (75)")
    ap.add_argument("--yaw-step-deg", type=float, default=5.0, help="the yaws searched (5)")
    args = ap.parse_args(argv)
    for name in ("cell", "fine", "share", "vo_range", "map_range", "hfov_deg", "yaw_step_deg"):
        v = getattr(args, name)
        if not (v > 0 and math.isfinite(v)):
            raise InputError(f"--{name.replace('_', '-')}: {v} must be a positive number")
    if not (0 < args.share <= 1) or args.radius < 0 or 360 % args.yaw_step_deg:
        raise InputError(f"--share {args.share} must lie in (0, 1], --radius {args.radius} >= 0, "
                         f"--yaw-step-deg {args.yaw_step_deg} must divide 360")
    results = []
    for path in args.scenes:
        scene = load_scene(path)
        r = analyse(scene, args)
        if args.figure:
            figure(r, scene, args.figure)
        del r["_draw"]
        results.append(r)
        print(f"{scene['_file']}: prior {'yes' if r['prior']['reached'] else 'no'}, "
              f"explore {'yes' if r['explore']['reached'] else 'no'} (known {r['explore']['known_share']:.2f}), "
              f"any_view {'yes' if r['any_view']['reached'] else 'no'}, views that track {r['tracking_share']:.2f}")
    print(f"explore reaches the goal in {sum(r['explore']['reached'] for r in results)}/{len(results)}, "
          f"prior in {sum(r['prior']['reached'] for r in results)}/{len(results)}")
    if args.out:
        tmp = args.out + ".tmp"
        with open(tmp, "w") as f:
            json.dump({"settings": vars(args), "scenes": results}, f, indent=1)
        os.replace(tmp, args.out)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except InputError as e:
        print(f"route_oracle.py: {e}", file=sys.stderr)
        sys.exit(2)
