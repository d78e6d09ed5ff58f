#!/usr/bin/python3
"""Fly a trial's views again and run the VO over them with other settings: a benchmark of the VO on
the views closed-loop flights really held (the hard ones included), each setting on the same frames.

For each TRIAL (a `tgnav trial` folder: metrics.json, config.yaml, gt.tum):
- its true camera path (gt.tum) becomes a body setpoint trajectory (the camera's offset in the body
  read from the vehicle's MJCF; velocities by central differences), up to the trial's end: 1 s
  before a collision, 2 s after the VO was first lost, or `--max-s`, whichever comes first;
- `tgnav fly --record` flies it in the trial's scene on ground truth and records the onboard camera
  at the trial's image size (a TUM RGB-D sequence; the vehicle tracks the path to a few centimetres,
  so the views are the trial's to within that);
- `tgnav vo` runs over the sequence once per variant: `default` (the built-in VO settings) and each
  `--variant NAME=FILE.yaml` (a vo::OdometryConfig file, e.g. `pose_depth: true`).

Scored per variant over the frames before its first loss, against the sequence's ground truth:
- `jumps`: frames whose position error moved more than `--jump-m` (0.1 m) from the frame before: a
  pose the VO tracked with its inliers but placed wrong;
- `max_error_m`, `final_error_m` (at its last frame before the loss, or the end);
- `lost_at_s` (empty: never lost).

Usage:
  /usr/bin/python3 scripts/vo_replay.py TRIAL... --out DIR [--variant NAME=FILE.yaml]... [--tgnav PATH]
      [--jump-m 0.1] [--max-s 60]
Writes DIR/replay.csv (trial, variant, frames, lost_at_s, jumps, max_error_m, final_error_m), the
sequences and VO runs under DIR/<trial>/, and prints each variant's totals. DIR must not exist; it
is built under DIR.partial and renamed at the end. Exit status 2 with one line naming the file and
what is wrong for bad input (nothing left behind); 1 when a tgnav run fails, naming its log (kept
under DIR.partial); DIR is not written either way.
"""
import argparse
import bisect
import csv
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import xml.etree.ElementTree as ET

import yaml

PROG = "vo_replay.py"
ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


class InputError(Exception):
    pass


class RunError(Exception):
    pass


def load_tum(path):
    """Rows [t, x, y, z, qx, qy, qz, qw] of a TUM trajectory file."""
    rows = []
    try:
        with open(path) as f:
            for n, line in enumerate(f, 1):
                if not line.strip() or line.startswith("#"):
                    continue
                parts = line.split()
                try:
                    values = [float(p) for p in parts[:8]]
                except ValueError:
                    raise InputError(f"{path}: line {n}: not a number in {line.strip()!r}")
                if len(values) != 8 or not all(math.isfinite(v) for v in values):
                    raise InputError(f"{path}: line {n}: expected 8 finite numbers (t x y z qx qy qz qw)")
                rows.append(values)
    except OSError as e:
        raise InputError(f"{path}: {e.strerror}")
    if not rows:
        raise InputError(f"{path}: no poses")
    return rows


def load_mapping(path, parse=yaml.safe_load, kind="YAML"):
    """The mapping a YAML (or, with json.load, JSON) file holds; InputError naming the file."""
    try:
        with open(path) as f:
            data = parse(f)
    except OSError as e:
        raise InputError(f"{path}: {e.strerror}")
    except (yaml.YAMLError, json.JSONDecodeError) as e:
        raise InputError(f"{path}: not {kind} ({str(e).splitlines()[0]})")
    if not isinstance(data, dict):
        raise InputError(f"{path}: expected a mapping")
    return data


def camera_offset(vehicle_yaml):
    """The onboard camera's position in the body frame, from the vehicle's MJCF."""
    vehicle = load_mapping(vehicle_yaml)
    for key in ("mjcf", "camera", "body"):
        if not isinstance(vehicle.get(key), str):
            raise InputError(f"{vehicle_yaml}: key '{key}' missing or not a string")
    mjcf = os.path.join(os.path.dirname(vehicle_yaml), vehicle["mjcf"])
    try:
        tree = ET.parse(mjcf)
    except (OSError, ET.ParseError) as e:
        raise InputError(f"{mjcf}: cannot read the MJCF ({e})")
    for body in tree.iter("body"):
        if body.get("name") != vehicle["body"]:
            continue
        for cam in body.iter("camera"):
            if cam.get("name") == vehicle["camera"]:
                try:
                    pos = [float(v) for v in (cam.get("pos") or "0 0 0").split()]
                except ValueError:
                    pos = []
                if len(pos) != 3:
                    raise InputError(f"{mjcf}: camera '{vehicle['camera']}': pos is not 3 numbers")
                return pos
    raise InputError(f"{mjcf}: no camera '{vehicle['camera']}' in body '{vehicle['body']}'")


def camera_yaw(q):
    """Yaw of the camera's optical axis (its z) in the world, from (qx, qy, qz, qw)."""
    qx, qy, qz, qw = q
    return math.atan2(2.0 * (qy * qz - qw * qx), 2.0 * (qx * qz + qw * qy))


def setpoints(gt, offset, end_s):
    """Body setpoints [t, x, y, z, yaw (unwrapped), vx, vy, vz] along a camera path up to end_s."""
    rows = []
    for g in gt:
        if g[0] > end_s:
            break
        yaw = camera_yaw(g[4:8])
        c, s = math.cos(yaw), math.sin(yaw)
        rows.append([g[0], g[1] - (c * offset[0] - s * offset[1]), g[2] - (s * offset[0] + c * offset[1]),
                     g[3] - offset[2], yaw])
    if len(rows) < 2:
        raise InputError(f"fewer than 2 poses before {end_s:.2f} s")
    for a, b in zip(rows, rows[1:]):
        if not b[0] > a[0]:
            raise InputError(f"time {b[0]} does not increase (after {a[0]})")
    for i in range(1, len(rows)):
        step = rows[i][4] - rows[i - 1][4]
        rows[i][4] -= 2.0 * math.pi * round(step / (2.0 * math.pi))
    out = []
    for i, r in enumerate(rows):
        a, b = rows[max(0, i - 1)], rows[min(len(rows) - 1, i + 1)]
        dt = b[0] - a[0]
        out.append(r + [(b[k] - a[k]) / dt for k in (1, 2, 3)])
    return out


def end_time(metrics, metrics_path, max_s):
    def number(key):
        v = metrics.get(key)
        if v is None:
            return None
        if not isinstance(v, (int, float)) or not math.isfinite(v):
            raise InputError(f"{metrics_path}: key '{key}' is {v!r}, not a finite number")
        return float(v)
    end = number("sim_time_s")
    if end is None:
        raise InputError(f"{metrics_path}: key 'sim_time_s' missing")
    collision = metrics.get("collision")
    if isinstance(collision, dict) and isinstance(collision.get("t_s"), (int, float)):
        end = min(end, collision["t_s"] - 1.0)
    lost = number("vo_lost_at_s")
    if lost is not None:
        end = min(end, lost + 2.0)
    return min(end, max_s)


def score(gt, est, lost_at_s, jump_m):
    """jumps, max error, final error over the estimate's frames before lost_at_s."""
    times = [g[0] for g in gt]
    prev = None
    jumps, worst, final, frames = 0, 0.0, 0.0, 0
    for e in est:
        if lost_at_s is not None and e[0] >= lost_at_s - 1e-9:
            break
        i = bisect.bisect_left(times, e[0] - 1e-6)
        if i >= len(gt) or abs(gt[i][0] - e[0]) > 1e-3:
            continue
        err = [e[k] - gt[i][k] for k in (1, 2, 3)]
        if prev is not None and math.dist(err, prev) > jump_m:
            jumps += 1
        worst = max(worst, math.hypot(*err))
        final = math.hypot(*err)
        frames += 1
        prev = err
    return frames, jumps, worst, final


def run(cmd, log):
    with open(log, "w") as f:
        rc = subprocess.call(cmd, stdout=f, stderr=subprocess.STDOUT)
    if rc != 0:
        raise RunError(f"{' '.join(cmd[:2])} exited {rc} (log: {log})")


def parse_variants(specs):
    variants = [("default", None)]
    for spec in specs:
        name, sep, path = spec.partition("=")
        if not sep or not name or not path or not name.replace("_", "").isalnum():
            raise InputError(f"--variant {spec!r}: expected NAME=FILE.yaml (NAME letters, digits, _)")
        if any(name == n for n, _ in variants):
            raise InputError(f"--variant {spec!r}: the name '{name}' is taken")
        load_mapping(path)
        variants.append((name, os.path.abspath(path)))
    return variants


def replay(trials, out, variants, tgnav, jump_m, max_s):
    rows = []
    names = set()
    for trial in trials:
        name = os.path.basename(os.path.normpath(trial))
        if name in names:
            raise InputError(f"{trial}: a trial of the same folder name is already listed")
        names.add(name)
        metrics_path = os.path.join(trial, "metrics.json")
        metrics = load_mapping(metrics_path, json.load, "JSON")
        config_path = os.path.join(trial, "config.yaml")
        config = load_mapping(config_path)
        for key in ("scene", "vehicle"):
            if not isinstance(config.get(key), str):
                raise InputError(f"{config_path}: key '{key}' missing or not a path")
        camera = config.get("camera") if isinstance(config.get("camera"), dict) else {}
        width, height = camera.get("width_px"), camera.get("height_px")
        if not isinstance(width, int) or not isinstance(height, int):
            raise InputError(f"{config_path}: keys 'camera.width_px', 'camera.height_px' missing or not integers")
        offset = camera_offset(config["vehicle"])
        gt_path = os.path.join(trial, "gt.tum")
        try:
            sp = setpoints(load_tum(gt_path), offset, end_time(metrics, metrics_path, max_s))
        except InputError as e:
            raise InputError(f"{gt_path}: {e}") if not str(e).startswith(gt_path) else e
        folder = os.path.join(out, name)
        os.makedirs(folder)
        traj = os.path.join(folder, "setpoints.csv")
        with open(traj, "w") as f:
            f.write("t,x,y,z,yaw,vx,vy,vz\n")
            for r in sp:
                f.write(",".join(f"{v:.6f}" for v in r) + "\n")
        seq = os.path.join(folder, "seq")
        run([tgnav, "fly", "--scene", config["scene"], "--vehicle", config["vehicle"], "--trajectory", traj,
             "--out", os.path.join(folder, "fly"), "--record", seq, "--width", str(width), "--height", str(height)],
            os.path.join(folder, "fly.log"))
        gt = load_tum(os.path.join(seq, "groundtruth.txt"))
        for variant, path in variants:
            vo_dir = os.path.join(folder, "vo_" + variant)
            cmd = [tgnav, "vo", "--sequence", seq, "--out", vo_dir] + (["--config", path] if path else [])
            run(cmd, os.path.join(folder, f"vo_{variant}.log"))
            summary_path = os.path.join(vo_dir, "summary.json")
            with open(summary_path) as f:
                summary = json.load(f)
            lost = summary.get("failed_at_s")
            frames, jumps, worst, final = score(gt, load_tum(os.path.join(vo_dir, "est.tum")), lost, jump_m)
            rows.append({"trial": name, "variant": variant, "frames": frames,
                         "lost_at_s": "" if lost is None else f"{lost:.3f}", "jumps": jumps,
                         "max_error_m": f"{worst:.4f}", "final_error_m": f"{final:.4f}"})
            print(f"{PROG}: {name} {variant}: {frames} frames, {jumps} jumps, max {worst:.3f} m, "
                  f"final {final:.3f} m" + ("" if lost is None else f", lost at {lost:.2f} s"), flush=True)
    return rows


def totals(rows, variants):
    lines = []
    for variant, _ in variants:
        r = [x for x in rows if x["variant"] == variant]
        if not r:
            continue
        finals = [float(x["final_error_m"]) for x in r]
        lines.append(f"{variant}: {len(r)} sequences, {sum(x['jumps'] for x in r)} jumps, "
                     f"{sum(float(x['max_error_m']) > 0.2 for x in r)} with an error above 0.2 m, "
                     f"{sum(x['lost_at_s'] != '' for x in r)} lost, median final error "
                     f"{statistics.median(finals):.3f} m")
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(prog=PROG, description=__doc__.splitlines()[0])
    parser.add_argument("trials", nargs="+", metavar="TRIAL")
    parser.add_argument("--out", required=True)
    parser.add_argument("--variant", action="append", default=[], metavar="NAME=FILE.yaml")
    parser.add_argument("--tgnav", default=os.path.join(ROOT, "build", "harness", "tgnav"))
    parser.add_argument("--jump-m", type=float, default=0.1)
    parser.add_argument("--max-s", type=float, default=60.0)
    args = parser.parse_args(argv)
    out = os.path.abspath(args.out)
    partial = out + ".partial"
    try:
        if not (math.isfinite(args.jump_m) and args.jump_m > 0):
            raise InputError(f"--jump-m {args.jump_m}: must be > 0")
        if not (math.isfinite(args.max_s) and args.max_s > 0):
            raise InputError(f"--max-s {args.max_s}: must be > 0")
        if os.path.exists(out):
            raise InputError(f"{out}: exists (choose a new --out)")
        if not os.access(args.tgnav, os.X_OK):
            raise InputError(f"{args.tgnav}: not an executable (build it, or name it with --tgnav)")
        variants = parse_variants(args.variant)
        shutil.rmtree(partial, ignore_errors=True)
        os.makedirs(partial)
        rows = replay(args.trials, partial, variants, os.path.abspath(args.tgnav), args.jump_m, args.max_s)
        with open(os.path.join(partial, "replay.csv"), "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
            w.writeheader()
            w.writerows(rows)
        os.rename(partial, out)
    except InputError as e:
        shutil.rmtree(partial, ignore_errors=True)
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 2
    except (RunError, OSError, ValueError, KeyError) as e:
        # Left at DIR.partial for its logs; DIR itself is not written.
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 1
    for line in totals(rows, variants):
        print(f"{PROG}: {line}")
    print(f"{PROG}: {len(rows)} runs -> {os.path.join(out, 'replay.csv')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
