#!/usr/bin/env python3
"""A perception-aware example planner for tgnav's external planner protocol
(docs/PLANNER_PROTOCOL.md): a grid route that prefers places where the camera sees landmarks,
and a yaw that looks at them.

1. Each landmark of landmarks.csv counts with its detectability, min(1, observations /
   opportunities) (1 where opportunities are unknown): the chance that a frame with it in view
   detects it. Landmarks below --min-ratio are left out.
2. For every cell, `count` = the landmarks a camera at flight_height_m there could see in some
   horizontal direction: within camera.min_range_m..max_range_m and within +-vfov/2 of level
   (walls do not occlude in this model). Computed with FFT convolutions, one per height band.
3. blindness = exp(-count / --scale) in [0, 1] (default 250, set from the built-in planner's
   gate, not fitted: 50 expected detections in a 75 deg view is about 240 all around); A* runs on the inflated slice (as
   astar_planner.py) with each step's cost multiplied by 1 + --weight * blindness.
4. Line-of-sight shortcuts are taken only where the straight segment is not blinder (mean
   blindness along it) than the cells it replaces; waypoints at most 0.5 m apart.
5. Yaw: at each waypoint, of the travel direction and travel +-30 deg, +-60 deg, the one with the
   most landmarks inside the horizontal FOV (ties: travel direction); the change between
   consecutive waypoints is then limited to 45 deg. The start keeps its yaw; the last waypoint
   is chosen as the others (arriving with the goal's yaw could look at a blank wall: the built-in
   planners do not force it either). scores = the landmarks in view at each waypoint (weighted
   by detectability).

    tgnav trial --scenario configs/scenarios/storage.yaml \\
        --planner-command "/usr/bin/python3 scripts/planners/landmark_planner.py" --planner-name landmarks

Standard library + numpy only.
"""
import argparse
import math
import os
import sys

import numpy as np

sys.dont_write_bytecode = True  # no __pycache__ left in the repository by a trial
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import tgnav_planner as tp  # noqa: E402

YAW_OFFSETS = np.radians([0.0, 30.0, -30.0, 60.0, -60.0])  # travel direction first: it wins ties
MAX_YAW_STEP = math.radians(45.0)  # between consecutive waypoints
SHORTCUT_TOLERANCE = 0.02  # a shortcut may be this much blinder (mean blindness) than the cells it replaces


def landmark_voxels(req, grid, min_ratio):
    """The landmarks that can matter, merged per voxel (the grid's cells, res-thick height bands
    around flight_height_m): voxel centres (N, 3), summed detectability (N,), and their indices
    (ix, iy, iz) with iz counted from the flight height."""
    xyz, obs, opp = tp.read_landmarks(req["map"]["landmarks"])
    cam, z = req["camera"], float(req["flight_height_m"])
    weight = np.where(opp > 0, np.minimum(1.0, obs / np.maximum(opp, 1.0)), 1.0)
    res = grid.resolution
    reach = float(cam["max_range_m"])
    ix, iy = grid.cell(xyz[:, 0], xyz[:, 1])
    iz = np.floor((xyz[:, 2] - z) / res).astype(int)
    r_cells = int(math.ceil(reach / res))
    h, w = grid.shape
    keep = (weight >= min_ratio) & (weight > 0) & (np.abs(xyz[:, 2] - z) <= reach * math.sin(cam["vfov_rad"] / 2) + res)
    keep &= (ix >= -r_cells) & (ix < w + r_cells) & (iy >= -r_cells) & (iy < h + r_cells)
    if not np.any(keep):
        return np.zeros((0, 3)), np.zeros(0), np.zeros((0, 3), dtype=int)
    keys = np.stack([ix[keep], iy[keep], iz[keep]], axis=1)
    keys, inverse = np.unique(keys, axis=0, return_inverse=True)
    sums = np.bincount(inverse.ravel(), weights=weight[keep], minlength=len(keys))
    cx, cy = grid.centre(keys[:, 0], keys[:, 1])
    centres = np.stack([cx, cy, z + (keys[:, 2] + 0.5) * res], axis=1)
    return centres, sums, keys


def _fast_size(n):
    """The smallest 2^a 3^b 5^c >= n (quick FFT lengths)."""
    best = 1 << int(math.ceil(math.log2(max(n, 1))))
    p2 = 1
    while p2 < best:
        p3 = p2
        while p3 < best:
            p5 = p3
            while p5 < n:
                p5 *= 5
            best = min(best, p5)
            p3 *= 3
        p2 *= 2
    return best


def visible_counts(grid, keys, sums, cam):
    """For each cell, the (weighted) landmarks a camera at the flight height in its centre could
    see in some horizontal direction: in range and within +-vfov/2 of level. One FFT convolution
    of the voxel counts with a ring-shaped kernel per height band."""
    h, w = grid.shape
    res = grid.resolution
    r = int(math.ceil(cam["max_range_m"] / res))
    if len(sums) == 0:
        return np.zeros((h, w))
    offsets = np.arange(-r, r + 1) * res
    dh = np.hypot(offsets[None, :], offsets[:, None])  # horizontal distance to each offset cell
    tan_half = math.tan(cam["vfov_rad"] / 2)
    shape = (_fast_size(h + 4 * r), _fast_size(w + 4 * r))
    spectrum = None
    for band in np.unique(keys[:, 2]):
        sel = keys[:, 2] == band
        hist = np.zeros((h + 2 * r, w + 2 * r))  # the grid extended by the range on every side
        np.add.at(hist, (keys[sel, 1] + r, keys[sel, 0] + r), sums[sel])
        dz = (band + 0.5) * res
        dist = np.hypot(dh, dz)
        kernel = (dist >= cam["min_range_m"]) & (dist <= cam["max_range_m"]) & (abs(dz) <= dh * tan_half)
        if not kernel.any():
            continue
        term = np.fft.rfft2(hist, shape) * np.fft.rfft2(kernel.astype(float), shape)
        spectrum = term if spectrum is None else spectrum + term
    if spectrum is None:
        return np.zeros((h, w))
    full = np.fft.irfft2(spectrum, shape)
    return np.maximum(full[2 * r:2 * r + h, 2 * r:2 * r + w], 0.0)  # FFT round-off can dip below 0


def view_counts(xyz, yaws, centres, sums, cam):
    """(n, m) landmarks (weighted) inside the camera's view from waypoint xyz[i] looking along
    yaws[i, k]: in range, within +-vfov/2 of level and within +-hfov/2 of the yaw."""
    out = np.zeros(yaws.shape)
    if len(sums) == 0:
        return out
    for i, p in enumerate(xyz):
        d = centres - p
        dh = np.hypot(d[:, 0], d[:, 1])
        dist = np.hypot(dh, d[:, 2])
        ok = (dist >= cam["min_range_m"]) & (dist <= cam["max_range_m"]) & \
            (np.abs(d[:, 2]) <= dh * math.tan(cam["vfov_rad"] / 2))
        if not ok.any():
            continue
        bearing = np.arctan2(d[ok, 1], d[ok, 0])
        inside = np.abs(tp.wrap(bearing[None, :] - yaws[i][:, None])) <= cam["hfov_rad"] / 2
        out[i] = inside @ sums[ok]
    return out


def choose_yaw(xyz, start_yaw, centres, sums, cam):
    """Per-waypoint yaw (see the module's step 5) and the landmarks in view with it."""
    n = len(xyz)
    d = np.diff(xyz[:, :2], axis=0)
    travel = np.concatenate([[start_yaw], np.arctan2(d[:, 1], d[:, 0])])
    candidates = travel[:, None] + YAW_OFFSETS[None, :]
    counts = view_counts(xyz, candidates, centres, sums, cam)
    yaw = candidates[np.arange(n), np.argmax(counts, axis=1)]  # argmax: the first best, travel on ties
    yaw[0] = start_yaw
    for i in range(1, n):  # turn at most MAX_YAW_STEP per waypoint
        yaw[i] = yaw[i - 1] + np.clip(tp.wrap(yaw[i] - yaw[i - 1]), -MAX_YAW_STEP, MAX_YAW_STEP)
    yaw = tp.wrap(yaw)
    scores = view_counts(xyz, yaw[:, None], centres, sums, cam)[:, 0]
    return yaw, scores


def blindness_accept(route, grid, blind):
    """accept(i, j) for tp.shortcut: the straight segment route[i]-route[j] is not blinder (mean
    blindness along it, up to SHORTCUT_TOLERANCE) than the polyline points i..j it replaces."""
    h, w = grid.shape

    def at(points):
        ix, iy = grid.cell(points[:, 0], points[:, 1])
        return blind[np.clip(iy, 0, h - 1), np.clip(ix, 0, w - 1)]

    cum = np.concatenate([[0.0], np.cumsum(at(np.array(route)))])

    def accept(i, j):
        along = at(tp.segment_samples(route[i], route[j], 0.5 * grid.resolution)).mean()
        replaced = (cum[j + 1] - cum[i]) / (j + 1 - i)
        return along <= replaced + SHORTCUT_TOLERANCE

    return accept


def make_plan(args):
    """The plan function for tp.serve."""

    def plan(req):
        grid, free = tp.free_space(req, args.margin)
        cam = req["camera"]
        centres, sums, keys = landmark_voxels(req, grid, args.min_ratio)
        count = visible_counts(grid, keys, sums, cam)
        blind = np.exp(-count / args.scale)
        route = tp.grid_route(req, grid, free, cost=1.0 + args.weight * blind)
        route = tp.shortcut(route, grid, free, accept=blindness_accept(route, grid, blind))
        xyz, _ = tp.waypoints_3d(req, route, args.max_step)
        yaw, scores = choose_yaw(xyz, float(req["start"][3]), centres, sums, cam)
        length = float(np.sum(np.linalg.norm(np.diff(xyz, axis=0), axis=1)))
        tp.log("request %s: %d landmark voxels, %d waypoints, %.2f m, mean in view %.1f"
               % (req.get("id"), len(sums), len(xyz), length, float(np.mean(scores))))
        return {"path": tp.path_rows(xyz, yaw), "scores": [round(float(s), 4) for s in scores]}

    return plan


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--weight", type=float, default=3.0,
                    help="step cost multiplier is 1 + WEIGHT * blindness (default 3)")
    ap.add_argument("--scale", type=float, default=250.0,
                    help="blindness = exp(-landmarks in range / SCALE) (default 250: the built-in planner's 50 "
                         "expected detections in a 75 deg view is about 240 all around)")
    ap.add_argument("--min-ratio", type=float, default=0.0,
                    help="leave out landmarks whose observations/opportunities is below this (default 0)")
    ap.add_argument("--margin", type=float, default=0.1,
                    help="metres of clearance kept beyond robot_radius_m (default 0.1)")
    ap.add_argument("--max-step", type=float, default=0.5,
                    help="largest distance between consecutive waypoints, metres (default 0.5)")
    args = ap.parse_args(argv)
    if not (args.weight >= 0 and args.scale > 0 and args.margin >= 0 and args.max_step > 0):
        ap.error("--weight and --margin must be >= 0, --scale and --max-step > 0")
    tp.serve(make_plan(args))
    return 0


if __name__ == "__main__":
    sys.exit(main())
