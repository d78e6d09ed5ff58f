"""Shared pieces of the example external planners (docs/PLANNER_PROTOCOL.md, version 1).

serve(plan_fn) speaks the protocol: it reads one JSON request per line on stdin, answers each
`type: "plan"` request with exactly one JSON line on stdout, and returns on `type: "shutdown"` or
at the end of the input. The rest are the helpers a grid planner needs: the ROS map_server map
(YAML + PGM), landmarks.csv, inflation, 8-connected A*, line-of-sight shortcutting and
densification.

Standard library + numpy only. Grids are indexed [iy, ix] with iy = 0 at the LOWEST y.
"""
import heapq
import json
import math
import os
import sys
import time
import traceback

import numpy as np

PROTOCOL = "tgnav-planner"
VERSION = 1
SQRT2 = math.sqrt(2.0)


def log(*parts):
    """Everything but the responses goes to stderr (the harness keeps its tail)."""
    print("[planner]", *parts, file=sys.stderr, flush=True)


class NoPath(Exception):
    """Raised by a plan function for an honest `status: "no_path"` (the message is the reason)."""


# ----------------------------------------------------------------------------------------------
# The protocol loop
# ----------------------------------------------------------------------------------------------

def make_response(req_id, t0, status="ok", **fields):
    """A response object: protocol, version, id, status, the given fields and, for an "ok" one,
    solve_time_s (perf_counter time since t0). Only keys the protocol knows may be given."""
    resp = {"protocol": PROTOCOL, "version": VERSION, "id": req_id, "status": status}
    resp.update(fields)
    if status == "ok":
        resp["solve_time_s"] = max(0.0, time.perf_counter() - t0)
    return resp


def no_path(req_id, reason):
    """A `no_path` response; the reason is made one line."""
    return {"protocol": PROTOCOL, "version": VERSION, "id": req_id, "status": "no_path",
            "reason": " ".join(str(reason).split()) or "no reason given"}


def _answer(req, plan_fn):
    """The response to one plan request (a dict); never raises."""
    req_id = req.get("id") if isinstance(req.get("id"), int) else 0
    if req.get("protocol") != PROTOCOL or req.get("version") != VERSION:
        reason = "request speaks protocol %r version %r; this planner speaks %s version %d" % (
            req.get("protocol"), req.get("version"), PROTOCOL, VERSION)
        log(reason)
        return no_path(req_id, reason)
    t0 = time.perf_counter()
    try:
        fields = plan_fn(req)
        resp = make_response(req_id, t0, "ok", **fields)
        json.dumps(resp, allow_nan=False)  # NaN or infinity would be refused: fail here instead
        return resp
    except NoPath as e:
        log("no path:", e)
        return no_path(req_id, e)
    except Exception as e:  # a bug or bad input: an honest no_path with the error, not a crash
        traceback.print_exc(file=sys.stderr)
        return no_path(req_id, "%s: %s" % (type(e).__name__, e))


def serve(plan_fn, stdin=None, stdout=None):
    """Answers plan requests until a shutdown line or the end of the input.

    plan_fn(request_dict) returns the response's route fields, e.g. {"path": [[x, y, z, yaw], ...],
    "scores": [...]}, or raises NoPath(reason). Anything it prints goes to stderr (sys.stdout is
    redirected while serving) so that stdout carries only response lines."""
    stdin = stdin or sys.stdin
    out = stdout or sys.stdout
    saved_stdout, sys.stdout = sys.stdout, sys.stderr
    try:
        while True:
            line = stdin.readline()
            if not line:
                log("end of input")
                return
            if not line.strip():
                continue
            try:
                req = json.loads(line)
            except ValueError as e:
                req = None
                log("request is not JSON:", e)
            if not isinstance(req, dict):
                # Not a request we can read: answer anyway so the harness is not left waiting.
                out.write(json.dumps(no_path(0, "request is not a JSON object")) + "\n")
                out.flush()
                continue
            kind = req.get("type")
            if kind == "shutdown":
                log("shutdown")
                return
            if kind != "plan":
                log("ignoring a request of type %r" % (kind,))
                continue
            resp = _answer(req, plan_fn)
            try:
                out.write(json.dumps(resp, allow_nan=False) + "\n")
                out.flush()
            except BrokenPipeError:
                log("the harness closed our output")
                return
    finally:
        sys.stdout = saved_stdout


# ----------------------------------------------------------------------------------------------
# Maps
# ----------------------------------------------------------------------------------------------

class Grid:
    """A 2-D occupancy grid: occupied[iy, ix] (iy = 0 at the lowest y), the world position of
    the corner of cell (0, 0) (`origin`, metres) and the cell size (`resolution`, metres)."""

    def __init__(self, occupied, origin, resolution):
        self.occupied = np.asarray(occupied, dtype=bool)
        self.origin = (float(origin[0]), float(origin[1]))
        self.resolution = float(resolution)

    @property
    def shape(self):
        return self.occupied.shape  # (rows = y, cols = x)

    def centre(self, ix, iy):
        """World x, y of a cell's centre (scalars or numpy arrays)."""
        return (self.origin[0] + (np.asarray(ix) + 0.5) * self.resolution,
                self.origin[1] + (np.asarray(iy) + 0.5) * self.resolution)

    def cell(self, x, y):
        """The cell (ix, iy) that holds a world point (ints or int arrays; may lie outside)."""
        ix = np.floor((np.asarray(x) - self.origin[0]) / self.resolution).astype(int)
        iy = np.floor((np.asarray(y) - self.origin[1]) / self.resolution).astype(int)
        return ix, iy

    def inside(self, ix, iy):
        h, w = self.shape
        return (np.asarray(ix) >= 0) & (np.asarray(ix) < w) & (np.asarray(iy) >= 0) & (np.asarray(iy) < h)


def read_map_yaml(path):
    """The simple `key: value` lines of a ROS map_server YAML (no PyYAML). Returns a dict with
    image (absolute path), resolution, origin [x, y, yaw], negate, occupied_thresh, free_thresh."""
    fields = {}
    with open(path) as f:
        for raw in f:
            line = raw.split("#", 1)[0].strip()
            if ":" not in line:
                continue
            key, value = (s.strip() for s in line.split(":", 1))
            fields[key] = value.strip("'\"")
    for key in ("image", "resolution", "origin"):
        if key not in fields:
            raise ValueError("%s: no '%s'" % (path, key))
    origin = [float(v) for v in fields["origin"].strip("[]").split(",")]
    if len(origin) < 2:
        raise ValueError("%s: origin %r is not [x, y, yaw]" % (path, fields["origin"]))
    image = fields["image"]
    if not os.path.isabs(image):
        image = os.path.join(os.path.dirname(os.path.abspath(path)), image)
    return {"image": image, "resolution": float(fields["resolution"]), "origin": origin,
            "negate": int(float(fields.get("negate", 0))),
            "occupied_thresh": float(fields.get("occupied_thresh", 0.65)),
            "free_thresh": float(fields.get("free_thresh", 0.196))}


def read_pgm(path):
    """A binary (P5) or ASCII (P2) PGM as a 2-D array of values scaled to 0..255, rows as in the
    file (the first row is the image's top)."""
    with open(path, "rb") as f:
        data = f.read()
    tokens, pos = [], 0
    while len(tokens) < 4:  # magic, width, height, maxval; '#' starts a comment in the header
        while pos < len(data) and data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        end = pos
        while end < len(data) and not data[end:end + 1].isspace():
            end += 1
        if end == pos:
            raise ValueError("%s: truncated PGM header" % path)
        tokens.append(data[pos:end])
        pos = end
    magic, width, height, maxval = tokens[0], int(tokens[1]), int(tokens[2]), int(tokens[3])
    if magic == b"P5":
        pos += 1  # exactly one whitespace byte ends the header
        dtype = np.dtype(">u2") if maxval > 255 else np.uint8
        count = width * height
        img = np.frombuffer(data, dtype=dtype, count=count, offset=pos)
    elif magic == b"P2":
        img = np.array(data[pos:].split()[:width * height], dtype=np.int64)
        if img.size != width * height:
            raise ValueError("%s: %d values, expected %d" % (path, img.size, width * height))
    else:
        raise ValueError("%s: not a P5 or P2 PGM (magic %r)" % (path, magic))
    img = img.reshape(height, width).astype(np.float64)
    return img * (255.0 / maxval) if maxval != 255 else img


def load_grid(yaml_path, pgm_path=None):
    """The occupancy slice of a map_server map. A cell is occupied unless it is free (unknown
    cells count as occupied, as the harness's slice does). The PGM's first row is the highest y:
    it is flipped so that iy = 0 is the lowest."""
    meta = read_map_yaml(yaml_path)
    img = read_pgm(pgm_path or meta["image"])
    p = img / 255.0 if meta["negate"] else (255.0 - img) / 255.0  # occupancy probability
    occupied = ~(p < meta["free_thresh"])
    return Grid(np.flipud(occupied), meta["origin"][:2], meta["resolution"])


def read_landmarks(path):
    """landmarks.csv as (xyz (N, 3), observations (N,), opportunities (N,)); opportunities are 0
    (unknown) in maps saved before that column existed."""
    with open(path) as f:
        header = f.readline().strip().split(",")
    col = {name: i for i, name in enumerate(header)}
    for name in ("x", "y", "z", "observations"):
        if name not in col:
            raise ValueError("%s: no column '%s' in the header" % (path, name))
    names = ["x", "y", "z", "observations"] + (["opportunities"] if "opportunities" in col else [])
    rows = np.loadtxt(path, delimiter=",", skiprows=1, usecols=[col[n] for n in names], ndmin=2)
    rows = rows.reshape(-1, len(names))
    opportunities = rows[:, 4] if len(names) == 5 else np.zeros(len(rows))
    return rows[:, :3], rows[:, 3], opportunities


# ----------------------------------------------------------------------------------------------
# Grid search
# ----------------------------------------------------------------------------------------------

def inflate(occupied, radius_m, resolution):
    """Cells any point of which lies within radius_m of an occupied cell (the distance measured
    between the cells' squares, so that any point of a cell left free keeps radius_m from every
    occupied square). A disc structuring element applied with numpy shifts."""
    occupied = np.asarray(occupied, dtype=bool)
    h, w = occupied.shape
    r = int(math.ceil(radius_m / resolution)) + 1
    out = occupied.copy()
    for dy in range(-r, r + 1):
        for dx in range(-r, r + 1):
            gap = math.hypot(max(abs(dx) - 1, 0), max(abs(dy) - 1, 0)) * resolution  # square to square
            if (dx == 0 and dy == 0) or gap >= radius_m:
                continue
            # out[y, x] |= occupied[y + dy, x + dx] where both lie in the grid
            ys, yd = slice(max(dy, 0), h + min(dy, 0)), slice(max(-dy, 0), h + min(-dy, 0))
            xs, xd = slice(max(dx, 0), w + min(dx, 0)), slice(max(-dx, 0), w + min(-dx, 0))
            out[yd, xd] |= occupied[ys, xs]
    return out


def nearest_free(free, ix, iy):
    """The free cell nearest to (ix, iy) (which may lie outside the grid), or None."""
    h, w = free.shape
    if 0 <= ix < w and 0 <= iy < h and free[iy, ix]:
        return int(ix), int(iy)
    ys, xs = np.nonzero(free)
    if len(xs) == 0:
        return None
    k = int(np.argmin((xs - ix) ** 2 + (ys - iy) ** 2))
    return int(xs[k]), int(ys[k])


def astar(free, start, goal, cost=None):
    """8-connected A* on a bool grid free[iy, ix] from cell start (ix, iy) to cell goal.

    A step costs its length in cells times, with `cost` (a float array >= 1 per cell), the mean
    of the two cells' costs. Diagonal steps do not cut corners. Returns the cells [(ix, iy), ...]
    from start to goal, or None where the goal cannot be reached."""
    h, w = free.shape
    free_flat = free.ravel().tolist()  # Python lists: much faster than numpy scalars in the loop
    mult = None if cost is None else np.asarray(cost, dtype=float).ravel().tolist()
    h_scale = 1.0 if cost is None else float(np.min(np.asarray(cost)[free])) if free.any() else 1.0
    s, g = start[1] * w + start[0], goal[1] * w + goal[0]
    if not (free_flat[s] and free_flat[g]):
        return None
    gx, gy = goal
    moves = [(1, 0, 1.0), (-1, 0, 1.0), (0, 1, 1.0), (0, -1, 1.0),
             (1, 1, SQRT2), (1, -1, SQRT2), (-1, 1, SQRT2), (-1, -1, SQRT2)]

    def heuristic(x, y):  # octile distance times the cheapest cell cost: admissible
        dx, dy = abs(x - gx), abs(y - gy)
        return h_scale * (dx + dy + (SQRT2 - 2.0) * min(dx, dy))

    best = [math.inf] * (w * h)
    parent = [-1] * (w * h)
    closed = bytearray(w * h)
    best[s] = 0.0
    heap = [(heuristic(*start), 0.0, s)]
    while heap:
        _, g_cur, cur = heapq.heappop(heap)
        if closed[cur]:
            continue
        closed[cur] = 1
        if cur == g:
            break
        cx, cy = cur % w, cur // w
        for dx, dy, step in moves:
            nx, ny = cx + dx, cy + dy
            if nx < 0 or ny < 0 or nx >= w or ny >= h:
                continue
            nb = ny * w + nx
            if closed[nb] or not free_flat[nb]:
                continue
            if dx and dy and not (free_flat[cy * w + nx] and free_flat[ny * w + cx]):
                continue  # no corner cutting
            g_new = g_cur + (step if mult is None else step * 0.5 * (mult[cur] + mult[nb]))
            if g_new < best[nb]:
                best[nb] = g_new
                parent[nb] = cur
                heapq.heappush(heap, (g_new + heuristic(nx, ny), g_new, nb))
    if not closed[g]:
        return None
    cells, cur = [], g
    while cur != -1:
        cells.append((cur % w, cur // w))
        cur = parent[cur]
    return cells[::-1]


def segment_samples(a, b, step):
    """Points from a to b (2-D) at most `step` apart, both ends included: an (n, 2) array."""
    a, b = np.asarray(a, dtype=float)[:2], np.asarray(b, dtype=float)[:2]
    n = max(1, int(math.ceil(np.linalg.norm(b - a) / step)))
    t = np.linspace(0.0, 1.0, n + 1)[:, None]
    return a + t * (b - a)


def segment_free(grid, free, a, b):
    """Whether the segment a-b stays in free cells, sampled at half-cell steps."""
    pts = segment_samples(a, b, 0.5 * grid.resolution)
    ix, iy = grid.cell(pts[:, 0], pts[:, 1])
    if not np.all(grid.inside(ix, iy)):
        return False
    return bool(np.all(free[iy, ix]))


def shortcut(points, grid, free, accept=None):
    """Greedy line-of-sight shortcutting of a polyline (a list of 2-D points): from each kept point
    jump to the farthest next point in sight (and that accept(i, j) allows, when given). Adjacent
    points are always kept connected (a start inside the inflation still leaves by its first step)."""
    if len(points) <= 2:
        return list(points)
    out, i = [points[0]], 0
    while i < len(points) - 1:
        j = i + 1
        while j + 1 < len(points) and segment_free(grid, free, points[i], points[j + 1]) and \
                (accept is None or accept(i, j + 1)):
            j += 1
        out.append(points[j])
        i = j
    return out


def densify(points, max_step):
    """Inserts points so that consecutive ones (3-D, any length) are at most max_step apart.
    Returns (points as an (n, d) array, the index of the input segment each point ends)."""
    pts = np.asarray(points, dtype=float)
    out, seg = [pts[0]], [0]
    for k in range(1, len(pts)):
        n = max(1, int(math.ceil(np.linalg.norm(pts[k] - pts[k - 1]) / max_step - 1e-9)))
        for t in range(1, n + 1):
            out.append(pts[k - 1] + (pts[k] - pts[k - 1]) * (t / n))
            seg.append(k)
    return np.array(out), seg


def wrap(angle):
    """An angle (or array) wrapped to [-pi, pi)."""
    return (np.asarray(angle) + math.pi) % (2.0 * math.pi) - math.pi


# ----------------------------------------------------------------------------------------------
# The common route: start and goal to a shortcut-ready polyline
# ----------------------------------------------------------------------------------------------

def free_space(req, margin_m):
    """The grid of a request and the cells a route may use: not within robot_radius_m + margin_m
    of an occupied cell, and with their centre inside the request's bounds."""
    maps = req["map"]
    grid = load_grid(maps["occupancy_yaml"], maps.get("occupancy_pgm"))
    free = ~inflate(grid.occupied, float(req["robot_radius_m"]) + margin_m, grid.resolution)
    h, w = grid.shape
    cx, cy = grid.centre(np.arange(w), np.arange(h))
    lo, hi = req["bounds"]["min"], req["bounds"]["max"]
    free &= ((cy >= lo[1]) & (cy <= hi[1]))[:, None] & ((cx >= lo[0]) & (cx <= hi[0]))[None, :]
    return grid, free


def grid_route(req, grid, free, cost=None):
    """The A* route from the request's start to its goal as a polyline of 2-D points: the exact
    start, the centres of the cells A* went through, the exact goal. Where the start or goal cell
    is not free the search starts (ends) at the nearest free cell. NoPath where none exists."""
    start, goal = req["start"], req["goal"]
    ends = []
    for name, p in (("start", start), ("goal", goal)):
        ix, iy = grid.cell(p[0], p[1])
        c = nearest_free(free, int(ix), int(iy))
        if c is None:
            raise NoPath("no free cell on the map (robot radius %.2f m)" % req["robot_radius_m"])
        if c != (int(ix), int(iy)):
            log("%s (%.2f, %.2f) is not in a free cell: searching from the nearest one, %s"
                % (name, p[0], p[1], c))
        ends.append(c)
    cells = astar(free, ends[0], ends[1], cost)
    if cells is None:
        raise NoPath("goal unreachable: no route keeps %.2f m from the obstacles" % req["robot_radius_m"])
    ix = np.array([c[0] for c in cells])
    iy = np.array([c[1] for c in cells])
    cx, cy = grid.centre(ix, iy)
    return [np.array(start[:2], dtype=float)] + [np.array(p) for p in zip(cx, cy)] + \
        [np.array(goal[:2], dtype=float)]


def waypoints_3d(req, points_2d, max_step=0.5):
    """Densified 3-D waypoints (the start's z first, flight_height_m after) from a 2-D polyline;
    returns (n, 3) points and, for each point, the index of the input segment it ends."""
    z = float(req["flight_height_m"])
    pts = [[points_2d[0][0], points_2d[0][1], float(req["start"][2])]] + \
        [[p[0], p[1], z] for p in points_2d[1:]]
    return densify(pts, max_step)


def path_rows(xyz, yaw):
    """The response's path: [[x, y, z, yaw], ...] as plain floats (unrounded: the start and goal
    come back exactly as the request gave them)."""
    return [[float(p[0]), float(p[1]), float(p[2]), float(a)] for p, a in zip(xyz, yaw)]
