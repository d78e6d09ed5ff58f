"""A planner that misbehaves on purpose, for the external planner tests (docs/PLANNER_PROTOCOL.md).

Usage: fake_planner.py MODE [ARG]. Each mode answers the first plan request in one way:
  line      a straight path from the start to the goal (flyable only where nothing is in between)
  fixed     the path in the JSON file ARG ([[x, y, z, yaw], ...]), with solve_time_s 0 (the bench)
  trajectory a straight trajectory from the start toward the goal, 0.2 m/s
  hang      never answers        crash   dies of SIGSEGV     exit3   exits with status 3
  empty     an empty line        close   closes stdout       garbage a line that is not JSON
  version2  protocol version 2   nan     a NaN coordinate    wall    a waypoint inside an obstacle
  oob       a waypoint out of bounds                         one     a path of one point
  million   a path of 10^6 points                            no_path status no_path
  noisy     writes 50 lines to stderr, then answers as `line`
  class0    the path of class 0 of the classes file (planner.external.classes), as homology class 0
Standard library only.
"""
import json
import os
import signal
import sys
import time


def respond(obj):
    sys.stdout.write(json.dumps(obj) + "\n")
    sys.stdout.flush()


def base(request):
    return {"protocol": "tgnav-planner", "version": 1, "id": request["id"], "status": "ok"}


def straight(request, n=20):
    s, g = request["start"], request["goal"]
    return [[s[0] + (g[0] - s[0]) * i / (n - 1), s[1] + (g[1] - s[1]) * i / (n - 1), s[2], s[3]] for i in range(n)]


def first_occupied(request):
    """The centre of an occupied cell of the occupancy slice, inside the scene's bounds."""
    meta = {}
    with open(request["map"]["occupancy_yaml"]) as f:
        for line in f:
            key, _, value = line.partition(":")
            meta[key.strip()] = value.strip()
    res = float(meta["resolution"])
    ox, oy = [float(v) for v in meta["origin"].strip("[]").split(",")[:2]]
    with open(request["map"]["occupancy_pgm"], "rb") as f:
        data = f.read()
    header = data.split(b"\n", 3)
    w, h = [int(v) for v in header[1].split()]
    pixels = header[3]
    lo, hi = request["bounds"]["min"], request["bounds"]["max"]
    for row in range(h):
        for col in range(w):
            if pixels[row * w + col] == 0:
                x, y = ox + (col + 0.5) * res, oy + (h - 1 - row + 0.5) * res
                if lo[0] < x < hi[0] and lo[1] < y < hi[1]:
                    return x, y
    raise RuntimeError("no occupied cell")


def answer(mode, arg, request):
    r = base(request)
    s = request["start"]
    if mode in ("line", "noisy"):
        if mode == "noisy":
            for i in range(50):
                print("noisy planner: line %d of its log" % (i + 1), file=sys.stderr)
        r["path"] = straight(request)
        r["scores"] = [1.0] * len(r["path"])
        r["solve_time_s"] = 0.001
    elif mode == "fixed":
        with open(arg) as f:
            r["path"] = json.load(f)
        r["solve_time_s"] = 0.0
    elif mode == "trajectory":
        g = request["goal"]
        dx, dy = g[0] - s[0], g[1] - s[1]
        d = max((dx * dx + dy * dy) ** 0.5, 1e-9)
        r["trajectory"] = [[0.1 * i, s[0] + 0.02 * i * dx / d, s[1] + 0.02 * i * dy / d, s[2], s[3]] for i in range(50)]
    elif mode == "hang":
        time.sleep(3600)
    elif mode == "crash":
        os.kill(os.getpid(), signal.SIGSEGV)
    elif mode == "exit3":
        print("fake planner: giving up", file=sys.stderr)
        sys.exit(3)
    elif mode == "empty":
        sys.stdout.write("\n")
        sys.stdout.flush()
        time.sleep(3600)
        return None
    elif mode == "close":
        sys.stdout.close()
        time.sleep(3600)
        return None
    elif mode == "garbage":
        sys.stdout.write("Planning... done!\n")
        sys.stdout.flush()
        time.sleep(3600)
        return None
    elif mode == "version2":
        r["version"] = 2
        r["path"] = straight(request)
    elif mode == "nan":
        r["path"] = straight(request)
        r["path"][3][1] = float("nan")
    elif mode == "wall":
        x, y = first_occupied(request)
        r["path"] = [s[:], [x, y, s[2], s[3]], request["goal"]]
    elif mode == "oob":
        hi = request["bounds"]["max"]
        r["path"] = [s[:], [hi[0] + 5.0, s[1], s[2], s[3]]]
    elif mode == "one":
        r["path"] = [s[:]]
    elif mode == "million":
        r["path"] = [s[:]] * 1000000
    elif mode == "class0":
        with open(request["map"]["classes"]) as f:
            first = json.load(f)["classes"][0]
        r["path"] = [s[:]] + first["path"][1:]
        r["homology_class"] = first["index"]
    elif mode == "no_path":
        r = {"protocol": "tgnav-planner", "version": 1, "id": request["id"], "status": "no_path",
             "reason": "the fake planner finds nothing"}
    return r


def main():
    mode = sys.argv[1]
    arg = sys.argv[2] if len(sys.argv) > 2 else None
    for line in sys.stdin:
        request = json.loads(line)
        if request.get("type") == "shutdown":
            return 0
        r = answer(mode, arg, request)
        if r is not None:
            respond(r)
    return 0


if __name__ == "__main__":
    sys.exit(main())
