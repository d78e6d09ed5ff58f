"""scripts/vo_replay.py with a stand-in for tgnav (a script that records the setpoints as the
sequence's ground truth and writes the VO's estimate as the variant's config asks): the camera's
offset turned by the yaw and the yaw unwrapped, the trial's end, each variant scored (jumps,
errors, the first loss), and bad input: one line naming the file, exit 2, nothing written; a
failing tgnav: exit 1 naming its log, the output folder not written.

Run: TGNAV_SCRIPTS_DIR=scripts /usr/bin/python3 -m unittest -v test_vo_replay (in tests/scripts).
"""
import csv
import importlib.util
import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

sys.dont_write_bytecode = True
SCRIPTS_DIR = os.environ.get("TGNAV_SCRIPTS_DIR") or os.path.join(os.path.dirname(__file__), "..", "..", "scripts")
SCRIPT = os.path.join(os.path.abspath(SCRIPTS_DIR), "vo_replay.py")

# The stand-in: `fly` writes the setpoints' positions as the recorded ground truth; `vo` copies it
# as the estimate, shifted 0.3 m in x from t >= 1 s when the config holds "jump", lost from
# t = 1.5 s when it holds "lose", and exits 3 when it holds "crash".
FAKE_TGNAV = r'''#!/usr/bin/python3
import json, os, sys
a = sys.argv[1:]
def opt(name):
    return a[a.index(name) + 1] if name in a else None
if a[0] == "fly":
    seq = opt("--record")
    os.makedirs(seq)
    os.makedirs(opt("--out"))
    with open(opt("--trajectory")) as f, open(os.path.join(seq, "groundtruth.txt"), "w") as g:
        next(f)
        for line in f:
            t, x, y, z = line.split(",")[:4]
            g.write(f"{t} {x} {y} {z} 0 0 0 1\n")
    sys.exit(0)
config = open(opt("--config")).read() if opt("--config") else ""
if "crash" in config:
    sys.exit(3)
out = opt("--out")
os.makedirs(out)
lost = 1.5 if "lose" in config else None
with open(os.path.join(opt("--sequence"), "groundtruth.txt")) as f, open(os.path.join(out, "est.tum"), "w") as e:
    for line in f:
        v = [float(x) for x in line.split()]
        if "jump" in config and v[0] >= 1.0 - 1e-9:
            v[1] += 0.3
        e.write(" ".join(str(x) for x in v) + "\n")
json.dump({"failed_at_s": lost}, open(os.path.join(out, "summary.json"), "w"))
'''

MJCF = """<mujoco><worldbody><body name="quad"><camera name="front" pos="0.1 0 0.05"/></body></worldbody></mujoco>"""


def load_module():
    spec = importlib.util.spec_from_file_location("vo_replay", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def quaternion_facing(yaw):
    """(qx, qy, qz, qw) of a camera whose optical axis (z) points along yaw in the world's xy plane,
    its x axis along -y_B (MuJoCo's camera on the body: xyaxes 0 -1 0 0 0 1)."""
    # Columns: x_C = (sin yaw, -cos yaw, 0), y_C = (0, 0, -1), z_C = (cos yaw, sin yaw, 0).
    r = [[math.sin(yaw), 0.0, math.cos(yaw)], [-math.cos(yaw), 0.0, math.sin(yaw)], [0.0, -1.0, 0.0]]
    qw = math.sqrt(max(0.0, 1.0 + r[0][0] + r[1][1] + r[2][2])) / 2.0
    qx = math.copysign(math.sqrt(max(0.0, 1.0 + r[0][0] - r[1][1] - r[2][2])) / 2.0, r[2][1] - r[1][2])
    qy = math.copysign(math.sqrt(max(0.0, 1.0 - r[0][0] + r[1][1] - r[2][2])) / 2.0, r[0][2] - r[2][0])
    qz = math.copysign(math.sqrt(max(0.0, 1.0 - r[0][0] - r[1][1] + r[2][2])) / 2.0, r[1][0] - r[0][1])
    return qx, qy, qz, qw


class VoReplayTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name
        self.tgnav = os.path.join(self.dir, "tgnav")
        with open(self.tgnav, "w") as f:
            f.write(FAKE_TGNAV)
        os.chmod(self.tgnav, 0o755)
        with open(os.path.join(self.dir, "v.xml"), "w") as f:
            f.write(MJCF)
        with open(os.path.join(self.dir, "v.yaml"), "w") as f:
            f.write("mjcf: v.xml\nbody: quad\ncamera: front\n")
        self.trial = self.make_trial("trial_a", sim_time_s=3.0)
        self.configs = {}
        for name in ("jump", "lose", "crash"):
            path = os.path.join(self.dir, name + ".yaml")
            with open(path, "w") as f:
                f.write(f"# {name}\npose_depth: true\n")
            self.configs[name] = path

    def tearDown(self):
        self.tmp.cleanup()

    def make_trial(self, name, sim_time_s, collision_t=None, lost_t=None):
        trial = os.path.join(self.dir, name)
        os.makedirs(trial)
        with open(os.path.join(trial, "metrics.json"), "w") as f:
            json.dump({"sim_time_s": sim_time_s, "vo_lost_at_s": lost_t,
                       "collision": {"t_s": collision_t} if collision_t is not None else None}, f)
        with open(os.path.join(trial, "config.yaml"), "w") as f:
            f.write(f"scene: {self.dir}/scene.yaml\nvehicle: {self.dir}/v.yaml\ncamera:\n  width_px: 64\n"
                    f"  height_px: 48\n")
        with open(os.path.join(trial, "gt.tum"), "w") as f:
            f.write("# timestamp tx ty tz qx qy qz qw\n")
            for i in range(31):
                t = 0.1 * i
                q = quaternion_facing(0.0)
                f.write(f"{t:.2f} {t:.3f} 0 1 {q[0]} {q[1]} {q[2]} {q[3]}\n")
        return trial

    def run_script(self, *args):
        return subprocess.run([sys.executable, SCRIPT, *args, "--tgnav", self.tgnav], capture_output=True, text=True)

    def rows(self, out):
        with open(os.path.join(out, "replay.csv")) as f:
            return {r["variant"]: r for r in csv.DictReader(f)}

    def test_each_variant_is_scored_on_the_same_frames(self):
        out = os.path.join(self.dir, "out")
        r = self.run_script(self.trial, "--out", out, "--variant", f"jumpy={self.configs['jump']}",
                            "--variant", f"lost={self.configs['lose']}")
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = self.rows(out)
        self.assertEqual(set(rows), {"default", "jumpy", "lost"})
        self.assertEqual(rows["default"]["jumps"], "0")
        self.assertEqual(float(rows["default"]["max_error_m"]), 0.0)
        self.assertEqual(rows["default"]["frames"], "31")
        self.assertEqual(rows["default"]["lost_at_s"], "")
        self.assertEqual(rows["jumpy"]["jumps"], "1")
        self.assertAlmostEqual(float(rows["jumpy"]["max_error_m"]), 0.3, places=4)
        self.assertAlmostEqual(float(rows["jumpy"]["final_error_m"]), 0.3, places=4)
        self.assertEqual(rows["lost"]["frames"], "15")  # 0.0 .. 1.4 s, before the loss
        self.assertEqual(rows["lost"]["lost_at_s"], "1.500")
        self.assertIn("jumpy: 1 sequences, 1 jumps, 1 with an error above 0.2 m", r.stdout)
        self.assertFalse(os.path.exists(out + ".partial"))

    def test_the_replay_ends_before_a_collision_and_after_a_loss(self):
        collided = self.make_trial("collided", sim_time_s=3.0, collision_t=2.0)
        lost = self.make_trial("lost", sim_time_s=3.0, lost_t=0.5)
        out = os.path.join(self.dir, "out")
        r = self.run_script(collided, lost, "--out", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(out, "replay.csv")) as f:
            frames = {row["trial"]: int(row["frames"]) for row in csv.DictReader(f)}
        self.assertEqual(frames, {"collided": 11, "lost": 26})  # up to 1.0 s; up to 2.5 s

    def test_setpoints_take_the_camera_offset_back_along_the_yaw_and_unwrap_it(self):
        m = load_module()
        gt = []
        for i, yaw in enumerate([3.0, 3.1, -3.1, -3.0]):
            gt.append([0.1 * i, 1.0, 2.0, 1.05, *quaternion_facing(yaw)])
        sp = m.setpoints(gt, [0.1, 0.0, 0.05], 10.0)
        self.assertEqual(len(sp), 4)
        for row, yaw in zip(sp, [3.0, 3.1, 2 * math.pi - 3.1, 2 * math.pi - 3.0]):
            self.assertAlmostEqual(row[4], yaw, places=9)
            self.assertAlmostEqual(row[1], 1.0 - 0.1 * math.cos(yaw), places=9)
            self.assertAlmostEqual(row[2], 2.0 - 0.1 * math.sin(yaw), places=9)
            self.assertAlmostEqual(row[3], 1.0, places=9)
        # The body moves as the camera turns about it: velocities by central differences.
        self.assertAlmostEqual(sp[1][5], (sp[2][1] - sp[0][1]) / 0.2, places=9)
        self.assertAlmostEqual(sp[2][6], (sp[3][2] - sp[1][2]) / 0.2, places=9)
        self.assertAlmostEqual(sp[0][5], (sp[1][1] - sp[0][1]) / 0.1, places=9)

    def assert_refused(self, args, says, code=2):
        out = os.path.join(self.dir, "refused")
        r = self.run_script(*args, "--out", out)
        self.assertEqual(r.returncode, code, r.stderr)
        lines = r.stderr.strip().splitlines()
        self.assertEqual(len(lines), 1, r.stderr)
        self.assertIn(says, lines[0])
        self.assertFalse(os.path.exists(out))
        return out

    def test_bad_input_is_one_line_naming_the_file_and_nothing_is_written(self):
        out = self.assert_refused([os.path.join(self.dir, "nowhere")], "nowhere/metrics.json")
        self.assertFalse(os.path.exists(out + ".partial"))
        with open(os.path.join(self.trial, "gt.tum"), "a") as f:
            f.write("3.1 1 2 nan 0 0 0 1\n")
        self.assert_refused([self.trial], "gt.tum: line 33")
        with open(os.path.join(self.trial, "gt.tum"), "w") as f:
            f.write("0 0 0 1 0 0 0 1\n0.1 0 0 1 0 0 0 1\n0.1 0 0 1 0 0 0 1\n")
        self.assert_refused([self.trial], "gt.tum: time 0.1 does not increase")
        self.assert_refused([self.trial, "--variant", "bad"], "--variant 'bad'")
        self.assert_refused([self.trial, "--variant", f"default={self.configs['jump']}"], "is taken")
        with open(os.path.join(self.trial, "config.yaml"), "w") as f:
            f.write("scene: s.yaml\n")
        self.assert_refused([self.trial], "config.yaml: key 'vehicle'")
        os.makedirs(os.path.join(self.dir, "exists"))
        r = self.run_script(self.trial, "--out", os.path.join(self.dir, "exists"))
        self.assertEqual(r.returncode, 2)
        self.assertIn("exists (choose a new --out)", r.stderr)

    def test_a_failing_tgnav_is_named_with_its_log(self):
        out = self.assert_refused([self.trial, "--variant", f"c={self.configs['crash']}"], "exited 3", code=1)
        self.assertIn("vo_c.log", self.run_script(self.trial, "--out", out + "2", "--variant",
                                                   f"c={self.configs['crash']}").stderr)
        self.assertTrue(os.path.exists(os.path.join(out + ".partial", "trial_a", "vo_c.log")))


if __name__ == "__main__":
    unittest.main()
