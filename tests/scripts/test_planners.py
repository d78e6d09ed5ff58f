"""scripts/planners/ (the example external planners of docs/PLANNER_PROTOCOL.md) on synthetic maps:
each speaks the protocol (one response line per plan request, ids, shutdown, a wrong version, a
failing request answered with no_path), flies from exactly the start to exactly the goal with
waypoints at most 0.5 m apart that keep the robot radius from every occupied cell; the A* planner
takes the short gap of a wall, the landmark planner the longer one past the landmarks.

Run: TGNAV_SCRIPTS_DIR=scripts /usr/bin/python3 -m unittest -v test_planners (in tests/scripts).
"""
import json
import math
import os
import select
import subprocess
import sys
import tempfile
import time
import unittest

sys.dont_write_bytecode = True
SCRIPTS_DIR = os.environ.get("TGNAV_SCRIPTS_DIR") or os.path.join(os.path.dirname(__file__), "..", "..", "scripts")
PLANNERS_DIR = os.path.join(os.path.abspath(SCRIPTS_DIR), "planners")
ASTAR = os.path.join(PLANNERS_DIR, "astar_planner.py")
LANDMARK = os.path.join(PLANNERS_DIR, "landmark_planner.py")
sys.path.insert(0, PLANNERS_DIR)

import numpy as np  # noqa: E402

import landmark_planner  # noqa: E402
import tgnav_planner as tp  # noqa: E402

RES = 0.1
RADIUS = 0.3
GAP_A = (1.4, 2.6)  # the short route's gap in the wall (x, metres), in a plain area
GAP_B = (7.0, 8.2)  # the longer route's gap, among landmarks
START = [4.0, 1.0, 1.2, 0.0]
GOAL = [4.0, 5.0, 1.5, math.pi / 2]


def wall_map(gaps=(GAP_A, GAP_B)):
    """occupied[iy, ix] of a 10 m x 6 m room (0.1 m cells, iy = 0 at y = 0): a border and a wall
    across y = 2.8..3.2 with the given gaps."""
    occ = np.zeros((60, 100), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[28:32, :] = True
    for lo, hi in gaps:
        occ[28:32, int(round(lo / RES)):int(round(hi / RES))] = False
    return occ


def write_map(folder, occupied, name="occupancy", binary=True):
    """A map_server map: NAME.pgm (first row = highest y) and NAME.yaml naming it relatively."""
    img = np.where(occupied, 0, 254).astype(np.uint8)[::-1]
    h, w = img.shape
    pgm = os.path.join(folder, name + ".pgm")
    with open(pgm, "wb") as f:
        if binary:
            f.write(b"P5\n# tgnav test\n%d %d\n255\n" % (w, h) + img.tobytes())
        else:
            f.write(b"P2\n%d %d\n255\n" % (w, h) + "\n".join(" ".join(map(str, r)) for r in img).encode() + b"\n")
    yaml = os.path.join(folder, name + ".yaml")
    with open(yaml, "w") as f:
        f.write("image: %s.pgm\nresolution: %.3f\norigin: [0.0, 0.0, 0.0]  # x, y, yaw\nnegate: 0\n"
                "occupied_thresh: 0.65\nfree_thresh: 0.196\n" % (name, RES))
    return yaml, pgm


def write_landmarks(path, rng):
    """Landmarks on the wall faces and the east wall around gap B (detectability 0.5), and some
    around gap A that were never detected (observations 0: they count for nothing)."""
    rows = []

    def add(x, y, z, obs, opp):
        rows.append("%d,%.4f,%.4f,%.4f,%d,%d,0,0,1.5,%.2f,%.2f,%.2f,%s"
                    % (len(rows), x, y, z, obs, opp, x, y, z, "ab" * 32))

    for _ in range(900):
        x = rng.uniform(5.8, 9.8)
        if GAP_B[0] <= x <= GAP_B[1]:
            continue
        add(x, rng.choice([2.8, 3.2]), rng.uniform(1.0, 2.0), 5, 10)
    for _ in range(300):
        add(9.9, rng.uniform(1.0, 5.0), rng.uniform(1.0, 2.0), 5, 10)
        add(rng.uniform(0.2, 3.5), rng.choice([2.8, 3.2]), rng.uniform(1.0, 2.0), 0, 50)
    with open(path, "w") as f:
        f.write("id,x,y,z,observations,opportunities,ref_x,ref_y,ref_z,voxel_x,voxel_y,voxel_z,descriptor\n")
        f.write("\n".join(rows) + "\n")


def request(folder, req_id=1, yaml="occupancy.yaml", pgm="occupancy.pgm", **changes):
    """A plan request as docs/PLANNER_PROTOCOL.md writes it."""
    req = {"protocol": "tgnav-planner", "version": 1, "type": "plan", "id": req_id, "seed": 1,
           "time_budget_s": 10.0, "start": START, "goal": GOAL,
           "bounds": {"min": [0.0, 0.0, 0.0], "max": [10.0, 6.0, 3.0]},
           "flight_height_m": 1.5, "robot_radius_m": RADIUS, "check_band_m": [0.5, 2.5],
           "vehicle": {"nominal_speed_m_s": 0.4, "max_speed_m_s": 1.0, "max_accel_m_s2": 1.0,
                       "max_yaw_rate_rad_s": 0.6},
           "camera": {"width_px": 640, "height_px": 480, "rate_hz": 20.0, "hfov_rad": 1.31,
                      "vfov_rad": 1.05, "min_range_m": 0.3, "max_range_m": 3.0},
           "map": {"octomap": os.path.join(folder, "map.bt"), "landmarks": os.path.join(folder, "landmarks.csv"),
                   "occupancy_yaml": os.path.join(folder, yaml), "occupancy_pgm": os.path.join(folder, pgm),
                   "classes": None}}
    req.update(changes)
    return req


class Planner:
    """A planner process: send() a line, recv() the response line (with a timeout)."""

    def __init__(self, script, *args):
        self.p = subprocess.Popen([sys.executable, script, *args], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                  stderr=subprocess.PIPE)

    def send(self, obj):
        self.p.stdin.write((json.dumps(obj) + "\n").encode())
        self.p.stdin.flush()

    def recv(self, timeout=10.0):
        ready, _, _ = select.select([self.p.stdout], [], [], timeout)
        if not ready:
            raise AssertionError("no response within %.0f s" % timeout)
        return json.loads(self.p.stdout.readline())

    def ask(self, req):
        self.send(req)
        return self.recv()

    def shutdown(self):
        """Sends shutdown; returns (exit status, seconds to exit, what was left on stdout)."""
        t0 = time.monotonic()
        self.send({"protocol": "tgnav-planner", "version": 1, "type": "shutdown"})
        try:
            rc = self.p.wait(timeout=1.0)
        except subprocess.TimeoutExpired:
            self.p.kill()
            rc = None
        elapsed = time.monotonic() - t0
        rest = self.p.stdout.read()
        self.close()
        return rc, elapsed, rest

    def close(self):
        if self.p.poll() is None:
            self.p.kill()
            self.p.wait()
        for s in (self.p.stdin, self.p.stdout, self.p.stderr):
            s.close()


def box_distance(points, occupied):
    """Each 2-D point's distance to the nearest occupied cell's square."""
    iy, ix = np.nonzero(occupied)
    cx, cy = (ix + 0.5) * RES, (iy + 0.5) * RES
    dx = np.maximum(np.abs(points[:, None, 0] - cx[None, :]) - RES / 2, 0.0)
    dy = np.maximum(np.abs(points[:, None, 1] - cy[None, :]) - RES / 2, 0.0)
    return np.hypot(dx, dy).min(axis=1)


def crossing_x(path, y=3.0):
    """Where the path (first time) crosses the line y."""
    for a, b in zip(path[:-1], path[1:]):
        if (a[1] - y) * (b[1] - y) <= 0 and a[1] != b[1]:
            return a[0] + (b[0] - a[0]) * (y - a[1]) / (b[1] - a[1])
    raise AssertionError("the path does not cross y = %.1f" % y)


class Planners(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name
        self.occupied = wall_map()
        write_map(self.dir, self.occupied)
        write_map(self.dir, wall_map(gaps=()), name="blocked", binary=False)
        write_landmarks(os.path.join(self.dir, "landmarks.csv"), np.random.default_rng(7))

    def tearDown(self):
        self.tmp.cleanup()

    def check_route(self, resp, req_id=1, start=START):
        """The protocol's fields and the route's promises; returns the path as an array."""
        self.assertEqual(resp["protocol"], "tgnav-planner")
        self.assertEqual(resp["version"], 1)
        self.assertEqual(resp["id"], req_id)
        self.assertEqual(resp["status"], "ok", resp.get("reason"))
        self.assertLessEqual(set(resp), {"protocol", "version", "id", "status", "reason", "path", "trajectory",
                                         "scores", "homology_class", "solve_time_s"})
        path = np.array(resp["path"], dtype=float)
        self.assertEqual(path.shape[1], 4)
        self.assertGreaterEqual(len(path), 2)
        self.assertTrue(np.all(np.isfinite(path)))
        self.assertGreaterEqual(resp["solve_time_s"], 0.0)
        if "scores" in resp:
            self.assertEqual(len(resp["scores"]), len(path))
        np.testing.assert_allclose(path[0, :3], start[:3], atol=1e-6)
        np.testing.assert_allclose(path[-1, :2], GOAL[:2], atol=1e-6)
        # from the start's height up to the flight height along the first segment, then level
        self.assertTrue(np.all(np.diff(path[:, 2]) >= -1e-9))
        self.assertAlmostEqual(path[-1, 2], 1.5)
        steps = np.linalg.norm(np.diff(path[:, :3], axis=0), axis=1)
        self.assertLessEqual(steps.max(), 0.5 + 1e-6)
        self.assertTrue(np.all(path[:, :3] >= [0, 0, 0]) and np.all(path[:, :3] <= [10, 6, 3]))
        samples = np.concatenate([tp.segment_samples(a, b, 0.02) for a, b in zip(path[:-1], path[1:])])
        self.assertGreaterEqual(box_distance(samples, self.occupied).min(), RADIUS)
        self.assertTrue(np.all(np.abs(path[:, 3]) <= math.pi + 1e-9))
        return path

    def test_astar_takes_the_short_gap(self):
        planner = Planner(ASTAR)
        try:
            path = self.check_route(planner.ask(request(self.dir)))
            self.assertTrue(GAP_A[0] < crossing_x(path) < GAP_A[1], crossing_x(path))
            self.assertAlmostEqual(path[0, 3], START[3])
            self.assertAlmostEqual(path[-1, 3], GOAL[3])
            # the yaw of a waypoint is the direction of the segment that arrives at it
            d = path[2] - path[1]
            self.assertAlmostEqual(path[2, 3], math.atan2(d[1], d[0]), places=5)
            # the same process answers again (id 2), and a blocked map with no_path
            path2 = self.check_route(planner.ask(request(self.dir, req_id=2)), req_id=2)
            np.testing.assert_allclose(path2, path)
            resp = planner.ask(request(self.dir, req_id=3, yaml="blocked.yaml", pgm="blocked.pgm"))
            self.assertEqual((resp["id"], resp["status"]), (3, "no_path"))
            self.assertNotIn("path", resp)
            self.assertIn("unreachable", resp["reason"])
            # a start inside the inflation margin (0.35 m from the wall): it leaves from exactly there
            near = [4.0, 2.45, 1.5, 0.0]
            self.check_route(planner.ask(request(self.dir, req_id=4, start=near)), req_id=4, start=near)
            rc, elapsed, rest = planner.shutdown()
        finally:
            planner.close()
        self.assertEqual(rc, 0)
        self.assertLess(elapsed, 1.0)
        self.assertEqual(rest, b"")  # exactly one line per request

    def test_landmark_planner_takes_the_gap_with_landmarks(self):
        planner = Planner(LANDMARK)
        try:
            resp = planner.ask(request(self.dir))
            path = self.check_route(resp)
            self.assertTrue(GAP_B[0] < crossing_x(path) < GAP_B[1], crossing_x(path))
            scores = np.array(resp["scores"])
            self.assertTrue(np.all(scores >= 0))
            self.assertGreater(scores.max(), 10.0)  # it looks at the landmarks
            turns = np.abs(tp.wrap(np.diff(path[:, 3])))
            self.assertLessEqual(turns.max(), math.radians(45) + 1e-6)
            self.assertAlmostEqual(path[0, 3], START[3])
            resp2 = planner.ask(request(self.dir, req_id=2))
            self.check_route(resp2, req_id=2)
            rc, elapsed, _ = planner.shutdown()
        finally:
            planner.close()
        self.assertEqual((rc, elapsed < 1.0), (0, True))
        # --weight 0: perception-blind, it takes the short gap as A* does
        blind = Planner(LANDMARK, "--weight", "0")
        try:
            path = self.check_route(blind.ask(request(self.dir)))
            self.assertTrue(GAP_A[0] < crossing_x(path) < GAP_A[1], crossing_x(path))
            self.assertEqual(blind.shutdown()[0], 0)
        finally:
            blind.close()

    def test_wrong_version_bad_input_and_end_of_input(self):
        for script in (ASTAR, LANDMARK):
            planner = Planner(script)
            try:
                resp = planner.ask(dict(request(self.dir, req_id=4), version=2))
                self.assertEqual((resp["id"], resp["status"], resp["version"]), (4, "no_path", 1))
                self.assertIn("version 2", resp["reason"])
                # a request that makes the planner fail (a missing file): no_path with the error
                missing = request(self.dir, req_id=5, yaml="nowhere.yaml", pgm="nowhere.pgm")
                missing["map"]["landmarks"] = os.path.join(self.dir, "nowhere.csv")
                resp = planner.ask(missing)
                self.assertEqual((resp["id"], resp["status"]), (5, "no_path"))
                self.assertIn("nowhere", resp["reason"])
                self.check_route(planner.ask(request(self.dir, req_id=6)), req_id=6)  # still serving
                planner.p.stdin.close()  # end of input without a shutdown line: exits 0
                self.assertEqual(planner.p.wait(timeout=2.0), 0)
                self.assertIn(b"Traceback", planner.p.stderr.read())  # the failure is logged on stderr
            finally:
                planner.close()


class Helpers(unittest.TestCase):
    """tgnav_planner's and landmark_planner's pieces against slow, obvious versions."""

    def test_map_reading_flips_rows(self):
        with tempfile.TemporaryDirectory() as d:
            occ = np.zeros((5, 7), dtype=bool)
            occ[0, 1] = occ[4, 6] = True  # lowest y at x cell 1, highest y at x cell 6
            for binary in (True, False):
                yaml, pgm = write_map(d, occ, binary=binary)
                grid = tp.load_grid(yaml)  # the image found relative to the yaml
                np.testing.assert_array_equal(grid.occupied, occ)
                self.assertEqual((grid.origin, grid.resolution), ((0.0, 0.0), RES))
                self.assertEqual(tuple(int(v) for v in grid.cell(0.15, 0.05)), (1, 0))
                np.testing.assert_allclose(grid.centre(6, 4), (0.65, 0.45))

    def test_inflation_keeps_the_radius_from_every_square(self):
        occ = np.zeros((30, 30), dtype=bool)
        occ[15, 15] = occ[3, 27] = True
        blocked = tp.inflate(occ, 0.4, RES)
        iy, ix = np.mgrid[0:30, 0:30]
        corners = []  # the nearest point of each cell's square to each occupied square
        for oy, ox in zip(*np.nonzero(occ)):
            gx = np.maximum(np.abs(ix - ox) - 1, 0) * RES
            gy = np.maximum(np.abs(iy - oy) - 1, 0) * RES
            corners.append(np.hypot(gx, gy))
        np.testing.assert_array_equal(blocked, np.min(corners, axis=0) < 0.4)

    def test_visible_counts_match_a_direct_count(self):
        rng = np.random.default_rng(3)
        grid = tp.Grid(np.zeros((20, 30), dtype=bool), (-1.0, 2.0), 0.2)
        cam = {"min_range_m": 0.3, "max_range_m": 2.5, "vfov_rad": 1.05, "hfov_rad": 1.31}
        lm = np.stack([rng.uniform(-3, 7, 400), rng.uniform(0, 8, 400), rng.uniform(0.1, 2.9, 400)], axis=1)
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "landmarks.csv")
            with open(path, "w") as f:
                f.write("id,x,y,z,observations,opportunities\n")
                f.write("".join("%d,%f,%f,%f,1,%d\n" % (i, *p, 1 + i % 3) for i, p in enumerate(lm)))
            req = {"map": {"landmarks": path}, "camera": cam, "flight_height_m": 1.5}
            centres, sums, keys = landmark_planner.landmark_voxels(req, grid, 0.0)
        counts = landmark_planner.visible_counts(grid, keys, sums, cam)
        for iy, ix in [(0, 0), (10, 15), (19, 29), (5, 22)]:
            p = np.array([*grid.centre(ix, iy), 1.5])
            d = centres - p
            dh = np.hypot(d[:, 0], d[:, 1])
            dist = np.hypot(dh, d[:, 2])
            ok = (dist >= 0.3) & (dist <= 2.5) & (np.abs(d[:, 2]) <= dh * math.tan(0.525))
            self.assertAlmostEqual(counts[iy, ix], sums[ok].sum(), places=6)
        self.assertAlmostEqual(sums.sum(), np.sum(1.0 / (1 + np.arange(400) % 3)), places=6)


if __name__ == "__main__":
    unittest.main()
