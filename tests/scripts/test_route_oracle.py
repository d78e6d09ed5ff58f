"""scripts/route_oracle.py on synthetic generated scenes: a corridor textured only behind the start
is flyable looking back with a map (prior) but not explorable (every view that would observe the
way ahead is bare); texture along its side makes it explorable; with every view tracking the
geometry alone lets the explorer through. Bad input: one line naming the file and key, exit 2,
nothing written.

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


def corridor(north_level="plain", start=(1.0, 2.0, math.pi), goal=(7.0, 2.0, math.pi)):
    """A 12 m x 4 m corridor: its west wall (behind the start, which faces it) rich, the east and
    south walls plain, the north wall `north_level`."""
    surfaces = [box("wall_w", -0.05, WIDTH / 2, 0.05, WIDTH / 2 + 0.1, "rich"),
                box("wall_e", LENGTH + 0.05, WIDTH / 2, 0.05, WIDTH / 2 + 0.1, "plain"),
                box("wall_s", LENGTH / 2, -0.05, LENGTH / 2 + 0.1, 0.05, "plain"),
                box("wall_n", LENGTH / 2, WIDTH + 0.05, LENGTH / 2 + 0.1, 0.05, north_level)]
    return {"kind": "test", "room": {"min_m": [0, 0, 0], "max_m": [LENGTH, WIDTH, 3], "size_m": [LENGTH, WIDTH, 3]},
            "surfaces": surfaces, "start": [start[0], start[1], 1.0, start[2]],
            "goal": [goal[0], goal[1], 1.0, goal[2]]}


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
        self.assertTrue(r["any_view"]["reached"])

    def test_texture_along_the_side_makes_it_explorable(self):
        scene = corridor(north_level="medium")
        r = self.oracle(scene)
        self.assertTrue(r["explore"]["reached"])
        self.assertRoute(r["explore"], scene)
        # Every cell of the route but the start's was observed first from some view.
        self.assertIsNone(r["explore"]["seen_from"][0])
        self.assertTrue(all(v is not None for v in r["explore"]["seen_from"][1:]))

    def test_a_start_view_that_does_not_track_reaches_nothing(self):
        r = self.oracle(corridor(start=(1.0, 2.0, 0.0)))  # facing the plain east wall 11 m away
        self.assertFalse(r["prior"]["reached"])
        self.assertIn("start view", r["explore"]["why"])
        self.assertTrue(r["any_view"]["reached"])

    def test_bad_input_is_one_line_and_exit_2(self):
        out = os.path.join(self.dir.name, "bad.json")
        no_surfaces = corridor()
        del no_surfaces["surfaces"]
        shiny = corridor()
        shiny["surfaces"][1]["level"] = "shiny"
        blocked = corridor(goal=(12.0, 2.0, 0.0))  # in the east wall
        cases = [(self.write("a", no_surfaces), "key 'surfaces' missing"),
                 (self.write("b", shiny), "surfaces[1].level: 'shiny'"),
                 (self.write("c", blocked), "goal: [12.0, 2.0] has no free cell"),
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
