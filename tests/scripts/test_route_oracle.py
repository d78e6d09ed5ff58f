"""scripts/route_oracle.py on synthetic generated scenes: a corridor textured only behind the start
is flyable looking back with a map (prior) but not explorable (every view that would observe the
way ahead is bare); texture along its side makes it explorable; with every view tracking the
geometry alone lets the explorer through. The same corridor as an MJCF scene file gives the same
answers (a material with a file texture is textured; geoms outside the flight band are left out).
--check-views counts a trial's VO frames by the rule's share at the true pose. Bad input: one
line naming the file and key, exit 2, nothing written.

Run: TGNAV_SCRIPTS_DIR=scripts /usr/bin/python3 -m unittest -v test_route_oracle (in tests/scripts).
"""
import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

sys.dont_write_bytecode = True
SCRIPTS_DIR = os.environ.get("TGNAV_SCRIPTS_DIR") or os.path.join(os.path.dirname(__file__), "..", "..", "scripts")
SCRIPT = os.path.join(os.path.abspath(SCRIPTS_DIR), "route_oracle.py")

LENGTH, WIDTH = 12.0, 4.0


def box(name, cx, cy, hx, hy, level):
    return {"name": name, "type": "box", "centre_m": [cx, cy, 1.5], "half_size_m": [hx, hy, 1.5], "level": level,
            "obstacle": None, "textures": {}}


def corridor(north_level="plain", start=(1.0, 2.0, math.pi), goal=(5.0, 2.0, math.pi)):
    """A 12 m x 4 m corridor: its west wall (behind the start, which faces it) rich, the east and
    south walls plain, the north wall `north_level`."""
    surfaces = [box("wall_w", -0.05, WIDTH / 2, 0.05, WIDTH / 2 + 0.1, "rich"),
                box("wall_e", LENGTH + 0.05, WIDTH / 2, 0.05, WIDTH / 2 + 0.1, "plain"),
                box("wall_s", LENGTH / 2, -0.05, LENGTH / 2 + 0.1, 0.05, "plain"),
                box("wall_n", LENGTH / 2, WIDTH + 0.05, LENGTH / 2 + 0.1, 0.05, north_level)]
    return {"kind": "test", "room": {"min_m": [0, 0, 0], "max_m": [LENGTH, WIDTH, 3], "size_m": [LENGTH, WIDTH, 3]},
            "surfaces": surfaces, "start": [start[0], start[1], 1.0, start[2]],
            "goal": [goal[0], goal[1], 1.0, goal[2]]}


MJCF = """<mujoco>
  <asset>
    <texture name="art" type="2d" file="art.png"/>
    <texture name="floor" type="2d" builtin="checker" rgb1="0.5 0.5 0.5" rgb2="0.52 0.52 0.52" width="8" height="8"/>
    <material name="art" texture="art"/>
    <material name="floor" texture="floor"/>
    <material name="wall" rgba="0.8 0.8 0.8 1"/>
  </asset>
  <worldbody>
    <geom name="floor" type="plane" size="6 2 0.05" material="floor"/>
    <geom name="wall_w" type="box" pos="-0.05 2 1.5" size="0.05 2.1 1.5" material="art"/>
    <geom name="wall_e" type="box" pos="12.05 2 1.5" size="0.05 2.1 1.5" material="wall"/>
    <geom name="wall_s" type="box" pos="6 -0.05 1.5" size="6.1 0.05 1.5" material="wall"/>
    <geom name="wall_n" type="box" pos="6 4.05 1.5" size="6.1 0.05 1.5" material="wall"/>
    <geom name="high_art" type="box" pos="6 3.9 2.7" size="6 0.05 0.2" material="art"/>
    %s
  </worldbody>
</mujoco>
"""


class RouteOracleTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.dir.cleanup()

    def write(self, name, scene):
        folder = os.path.join(self.dir.name, name)
        os.makedirs(folder)
        with open(os.path.join(folder, "generated.json"), "w") as f:
            json.dump(scene, f)
        return folder

    def run_oracle(self, *args):
        return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True, timeout=170)

    def oracle(self, scene, *extra):
        out = os.path.join(self.dir.name, "out.json")
        r = self.run_oracle(self.write("scene", scene), "--out", out, *extra)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(out) as f:
            return json.load(f)["scenes"][0]

    def assertRoute(self, route, scene):
        """A route from the start's cell to the goal's, between neighbouring cells."""
        path = route["path"]
        self.assertLess(math.dist(path[0][:2], scene["start"][:2]), 0.3)
        self.assertLess(math.dist(path[-1][:2], scene["goal"][:2]), 0.3)
        for a, b in zip(path, path[1:]):
            self.assertLess(math.dist(a[:2], b[:2]), 0.2 * math.sqrt(2) + 1e-6)

    def test_texture_only_behind_is_flyable_with_a_map_but_not_explorable(self):
        scene = corridor()
        r = self.oracle(scene)
        self.assertTrue(r["prior"]["reached"])
        self.assertRoute(r["prior"], scene)
        # Flown with a map, every view looks back at the west wall (yaws 90-270 deg).
        self.assertTrue(all(90 <= p[2] <= 270 for p in r["prior"]["path"]))
        self.assertFalse(r["explore"]["reached"])
        self.assertLess(r["explore"]["known_share"], 0.5)
        self.assertFalse(r["look_ahead"]["reached"])
        self.assertTrue(r["any_view"]["reached"])

    def test_texture_along_the_side_makes_it_explorable(self):
        scene = corridor(north_level="medium")
        r = self.oracle(scene)
        self.assertTrue(r["explore"]["reached"])
        self.assertRoute(r["explore"], scene)
        # Looking at the north wall the vehicle can also look where it goes east (yaws within
        # 27.6 deg of its moves).
        self.assertTrue(r["look_ahead"]["reached"])
        self.assertRoute(r["look_ahead"], scene)
        for a, b in zip(r["look_ahead"]["path"], r["look_ahead"]["path"][1:]):
            if a[:2] != b[:2]:
                heading = math.degrees(math.atan2(b[1] - a[1], b[0] - a[0]))
                self.assertLessEqual(abs((heading - a[2] + 180) % 360 - 180), 27.6 + 1e-6)

    def test_routes_are_written_as_paths_tgnav_trial_flies(self):
        scene = corridor(north_level="medium")
        paths = os.path.join(self.dir.name, "paths")
        self.oracle(scene, "--paths", paths)
        self.assertEqual(sorted(os.listdir(paths)), ["scene_explore.csv", "scene_prior.csv"])
        with open(os.path.join(paths, "scene_explore.csv")) as f:
            lines = f.read().split()
        self.assertEqual(lines[0], "x,y,z,yaw")
        rows = [[float(v) for v in line.split(",")] for line in lines[1:]]
        self.assertEqual(rows[0], [1.0, 2.0, 1.0, round(math.pi, 4)])  # the start, its yaw
        self.assertEqual(rows[-1][:3], [5.0, 2.0, 1.0])                 # the goal
        for a, b in zip(rows, rows[1:]):
            self.assertLess(math.dist(a[:2], b[:2]), 0.5)  # neighbouring cells; the start and goal within a cell of theirs
            self.assertLessEqual(abs(b[3] - a[3]), math.pi)  # unwrapped: no jump of a turn

    def test_a_start_view_that_does_not_track_reaches_nothing(self):
        r = self.oracle(corridor(start=(1.0, 2.0, 0.0)))  # facing the plain east wall 11 m away
        self.assertFalse(r["prior"]["reached"])
        self.assertIn("start view", r["explore"]["why"])
        self.assertTrue(r["any_view"]["reached"])

    def write_mjcf(self, name, extra=""):
        folder = os.path.join(self.dir.name, name)
        os.makedirs(folder)
        with open(os.path.join(folder, "corridor.xml"), "w") as f:
            f.write(MJCF % extra)
        scene = os.path.join(folder, "corridor.yaml")
        with open(scene, "w") as f:
            f.write("mjcf: corridor.xml\nflight_height_m: 1.0\nstart: [1.0, 2.0, 1.0, 3.1416]\n"
                    "goal: [5.0, 2.0, 1.0, 3.1416]\nbounds:\n  min: [0, 0, 0]\n  max: [12, 4, 3]\n")
        return scene

    def test_an_mjcf_scene_file_reads_as_the_same_corridor(self):
        out = os.path.join(self.dir.name, "out.json")
        r = self.run_oracle(self.write_mjcf("m"), "--out", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(out) as f:
            got = json.load(f)["scenes"][0]
        # The art 2.5 m up on the north wall is outside the flight band: still not explorable.
        self.assertTrue(got["prior"]["reached"])
        self.assertFalse(got["explore"]["reached"])
        self.assertEqual(got["prior"]["path"], self.oracle(corridor())["prior"]["path"])
        r = self.run_oracle(self.write_mjcf("rot", '<geom name="tilted" type="box" pos="5 2 1" size="0.2 0.2 1" euler="0 0 30"/>'))
        self.assertEqual(r.returncode, 2)
        self.assertIn("geom 'tilted': rotated", r.stderr)
        r = self.run_oracle(self.write_mjcf("size", '<geom name="thin" type="box" pos="5 2 1" size="0.2 x 1"/>'))
        self.assertEqual(r.returncode, 2)
        self.assertIn("geom 'thin' size: '0.2 x 1' is not 3 numbers", r.stderr)
        scene = self.write_mjcf("height")
        with open(scene) as f:
            text = f.read()
        with open(scene, "w") as f:
            f.write(text.replace("flight_height_m: 1.0", "flight_height_m: high"))
        r = self.run_oracle(scene)
        self.assertEqual(r.returncode, 2)
        self.assertIn("flight_height_m: 'high' is not a number", r.stderr)

    def write_trial(self, scene_folder):
        """A trial in the corridor: 40 frames looking back west at the art (tracked), then 10
        looking east at the plain wall (lost)."""
        trial = os.path.join(self.dir.name, "trial")
        os.makedirs(trial)
        os.makedirs(os.path.join(scene_folder, "scenes"))
        with open(os.path.join(trial, "config.yaml"), "w") as f:
            f.write(f"scene: {os.path.join(scene_folder, 'scenes', 'corridor.yaml')}\n")
        gt, vo = ["# timestamp tx ty tz qx qy qz qw"], ["t,status,inliers"]
        for i in range(50):
            yaw = math.pi if i < 40 else 0.0
            # The camera's axes in the world (x right, y down, z forward, level) are R's columns.
            c, s_ = math.cos(yaw), math.sin(yaw)
            m = [[s_, 0.0, c], [-c, 0.0, s_], [0.0, -1.0, 0.0]]
            w = math.sqrt(1 + m[0][0] + m[1][1] + m[2][2]) / 2
            qx, qy, qz = (m[2][1] - m[1][2]) / (4 * w), (m[0][2] - m[2][0]) / (4 * w), (m[1][0] - m[0][1]) / (4 * w)
            gt.append(f"{i * 0.05:.2f} 2.0 2.0 1.0 {qx} {qy} {qz} {w}")
            vo.append(f"{i * 0.05:.2f},{'ok' if i < 40 else 'lost'},{500 if i < 40 else 0}")
        for name, rows in (("gt.tum", gt), ("vo.csv", vo)):
            with open(os.path.join(trial, name), "w") as f:
                f.write("\n".join(rows) + "\n")
        return trial

    def test_check_views_counts_the_frames_by_the_rule(self):
        scene_folder = os.path.join(self.dir.name, "scene")
        self.write("scene", corridor())
        trial = self.write_trial(scene_folder)
        out = os.path.join(self.dir.name, "check.json")
        r = self.run_oracle("--check-views", trial, "--out", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(out) as f:
            got = json.load(f)["check_views"]
        self.assertEqual(got["frames"], 49)  # the VO's first frame left out
        self.assertEqual(got["lost"], 10)
        self.assertEqual(got["rule_tracks"], {"frames": 39, "lost": 0})
        self.assertEqual(sum(b["frames"] for b in got["bins"]), 49)
        with open(os.path.join(trial, "vo.csv")) as f:
            vo = f.read()
        with open(os.path.join(trial, "vo.csv"), "w") as f:
            f.write(vo.replace("t,status,inliers", "t,status,matches"))
        r = self.run_oracle("--check-views", trial)
        self.assertEqual(r.returncode, 2)
        self.assertIn("vo.csv: column 'inliers' missing", r.stderr)
        os.remove(os.path.join(trial, "config.yaml"))
        r = self.run_oracle("--check-views", trial)
        self.assertEqual(r.returncode, 2)
        self.assertIn("config.yaml: cannot read", r.stderr)

    def test_bad_input_is_one_line_and_exit_2(self):
        out = os.path.join(self.dir.name, "bad.json")
        no_surfaces = corridor()
        del no_surfaces["surfaces"]
        shiny = corridor()
        shiny["surfaces"][1]["level"] = "shiny"
        blocked = corridor(goal=(12.0, 2.0, 0.0))  # in the east wall
        no_centre = corridor()
        del no_centre["surfaces"][0]["centre_m"]
        text_start = corridor()
        text_start["start"][1] = "two"
        flat_room = corridor()
        flat_room["room"]["max_m"] = [0, 4, 3]
        cases = [(self.write("a", no_surfaces), "key 'surfaces' missing"),
                 (self.write("b", shiny), "surfaces[1].level: 'shiny'"),
                 (self.write("c", blocked), "goal: [12.0, 2.0] has no free cell"),
                 (self.write("e", no_centre), "surfaces[0].centre_m: None is not 2 or more numbers"),
                 (self.write("f", text_start), "start: [1.0, 'two', 1.0, 3.14"),
                 (self.write("g", flat_room), "room: min_m [0, 0, 0] is not below max_m [0, 4, 3]"),
                 (os.path.join(self.dir.name, "none"), "cannot read")]
        for folder, message in cases:
            r = self.run_oracle(folder, "--out", out)
            self.assertEqual(r.returncode, 2, r.stderr)
            self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
            self.assertIn(message, r.stderr)
            self.assertIn(folder, r.stderr)  # the file: the folder's generated.json, or the path given
            self.assertFalse(os.path.exists(out))
        r = self.run_oracle(self.write("d", corridor()), "--share", "1.5")
        self.assertEqual(r.returncode, 2)
        self.assertIn("--share 1.5", r.stderr)


if __name__ == "__main__":
    unittest.main()
