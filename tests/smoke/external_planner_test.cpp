// External planners through `tgnav trial` and `tgnav sweep` (docs/PLANNER_PROTOCOL.md) on the
// smoke scene at 320x240: a planner that misbehaves in any of the ways the protocol names ends its
// trial in plan_failed with the reason and its stderr, leaving nothing behind; a route given
// through the protocol flies exactly as the same route given as a file; the shipped example
// planners fly; a sweep with a crashing planner goes on.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "../harness/test_util.h"

namespace tgnav {
namespace {

const std::string kSource = TGNAV_SOURCE_DIR;
const std::string kScenario = kSource + "/configs/scenarios/smoke.yaml";
const std::string kSmall = " --set camera.width_px=320 --set camera.height_px=240";
const std::string kFake = "/usr/bin/python3 " + kSource + "/tests/data/planners/fake_planner.py";

std::string readText(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

nlohmann::json readJson(const std::filesystem::path& file) { return nlohmann::json::parse(readText(file)); }

// `tgnav trial` on the smoke scene with TMPDIR = `tmp` (where the planner's files go).
test::CmdResult trial(const std::string& args, const std::filesystem::path& tmp) {
  return test::runShell("TMPDIR=" + tmp.string() + " " + TGNAV_BIN + " trial --scenario " + kScenario +
                        " --map-cache " + TGNAV_TEST_CACHE + kSmall + " --no-figures " + args);
}

int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

// Live processes (zombies aside) whose command line, arguments joined by spaces, ends with `tail`.
int runningWith(const std::string& tail) {
  int n = 0;
  for (const auto& e : std::filesystem::directory_iterator("/proc")) {
    const std::string pid = e.path().filename().string();
    if (pid.find_first_not_of("0123456789") != std::string::npos) continue;
    std::string cmd = readText(e.path() / "cmdline");
    std::replace(cmd.begin(), cmd.end(), '\0', ' ');
    while (!cmd.empty() && cmd.back() == ' ') cmd.pop_back();
    const std::string stat = readText(e.path() / "stat");
    const std::size_t close = stat.rfind(')');
    const bool zombie = close != std::string::npos && close + 2 < stat.size() && stat[close + 2] == 'Z';
    if (!zombie && cmd.size() >= tail.size() && cmd.compare(cmd.size() - tail.size(), tail.size(), tail) == 0) ++n;
  }
  return n;
}

struct BadPlanner {
  const char* mode;
  const char* detail;  // what metrics.json's detail holds after "external planner fake: "
};

class ExternalPlannerFailure : public ::testing::TestWithParam<BadPlanner> {};

TEST_P(ExternalPlannerFailure, EndsInPlanFailedWithItsReasonAndNothingLost) {
  const BadPlanner& bad = GetParam();
  const auto dir = test::tempDir();
  const auto tmp = dir / "tmp";
  std::filesystem::create_directories(tmp);
  const auto out = dir / "trial";
  // 2 s where the planner hangs, to keep that case short; else ample, so that on a loaded machine a
  // slow answer (10^6 points take Python over 2 s there) is still the answer the case is about.
  const std::string timeout = std::string(bad.mode) == "hang" ? "2" : "60";
  const test::CmdResult run =
      trial("--planner-command '" + kFake + " " + bad.mode +
                "' --planner-name fake --set planner.external.timeout_s=" + timeout + " --out " + out.string(),
            tmp);
  ASSERT_EQ(run.rc, 0) << run.output;
  EXPECT_EQ(lines(run.output), 1) << run.output;
  EXPECT_NE(run.output.find("smoke fake seed 1: plan_failed (external planner fake: "), std::string::npos)
      << run.output;
  const nlohmann::json m = readJson(out / "metrics.json");
  EXPECT_EQ(m["status"], "plan_failed");
  EXPECT_EQ(m["planner"], "fake");
  EXPECT_EQ(m["plan_status"], "failed");
  const std::string detail = m["detail"];
  EXPECT_EQ(detail.rfind("external planner fake: ", 0), 0u) << detail;
  EXPECT_NE(detail.find(bad.detail), std::string::npos) << detail;
  EXPECT_EQ(detail.find('\n'), std::string::npos) << detail;
  const nlohmann::json plan = readJson(out / "plan.json");
  EXPECT_EQ(plan["external"]["status"], "failed");
  EXPECT_EQ(plan["external"]["detail"], detail);
  EXPECT_TRUE(std::filesystem::is_regular_file(out / "planner_stderr.txt"));
  EXPECT_TRUE(std::filesystem::is_regular_file(out / "config.yaml"));
  EXPECT_TRUE(std::filesystem::is_empty(tmp)) << "the planner's temporary files are left in " << tmp;
  // No planner process is left running.
  EXPECT_EQ(runningWith(std::string("fake_planner.py ") + bad.mode), 0);
}

INSTANTIATE_TEST_SUITE_P(
    Battery, ExternalPlannerFailure,
    ::testing::Values(BadPlanner{"hang", "no answer within 2 s (planner.external.timeout_s)"},
                      BadPlanner{"crash", "exited with status 139 (its command was killed by signal 11, SIGSEGV)"},
                      BadPlanner{"exit3", "exited with status 3 before answering"},
                      BadPlanner{"empty", "empty response"},
                      BadPlanner{"garbage", "invalid response: not JSON: Planning... done!"},
                      BadPlanner{"version2", "protocol version 2, expected 1"},
                      BadPlanner{"nan", "invalid response: not JSON (NaN and Infinity are not JSON numbers)"},
                      BadPlanner{"wall", "route refused: path: waypoint 2 at"},
                      BadPlanner{"line", "closer than the robot radius 0.38 m"},
                      BadPlanner{"oob", "is outside the scene's bounds"},
                      BadPlanner{"one", "invalid response: 'path' has 1 points, at least 2 needed"},
                      BadPlanner{"million", "invalid response: 'path' has 1000000 points, at most 100000 allowed"},
                      BadPlanner{"no_path", "no path: the fake planner finds nothing"}),
    [](const ::testing::TestParamInfo<BadPlanner>& info) { return std::string(info.param.mode); });

// The planner's stderr: its last 20 lines are kept.
TEST(ExternalPlanner, KeepsTheTailOfItsStderr) {
  const auto dir = test::tempDir();
  const auto out = dir / "trial";
  const test::CmdResult run =
      trial("--planner-command '" + kFake + " noisy' --planner-name noisy --out " + out.string(), dir);
  ASSERT_EQ(run.rc, 0) << run.output;
  const std::string tail = readText(out / "planner_stderr.txt");
  EXPECT_EQ(lines(tail), 20) << tail;
  EXPECT_EQ(tail.rfind("noisy planner: line 31 of its log\n", 0), 0u) << tail;
}

// A path answered through the protocol is the same trial as the same path given with --path:
// metrics equal but for the planner's own fields and wall-clock figures; same frames and poses.
TEST(ExternalPlanner, ARouteThroughTheProtocolFliesAsTheSameRouteGivenAsAFile) {
  const auto dir = test::tempDir();
  std::ofstream(dir / "around.json") << "[[-3,0,1,0],[-1,-1.2,1,0],[1,-1.2,1,0],[3,0,1,0]]\n";
  std::ofstream(dir / "around.csv") << "x,y,z,yaw\n-3,0,1,0\n-1,-1.2,1,0\n1,-1.2,1,0\n3,0,1,0\n";
  const test::CmdResult ext =
      trial("--seed 2 --planner-command '" + kFake + " fixed " + (dir / "around.json").string() +
                "' --planner-name fixed --out " + (dir / "ext").string(),
            dir);
  ASSERT_EQ(ext.rc, 0) << ext.output;
  const test::CmdResult file =
      trial("--seed 2 --path " + (dir / "around.csv").string() + " --out " + (dir / "file").string(), dir);
  ASSERT_EQ(file.rc, 0) << file.output;
  auto comparable = [&](const char* run) {
    return test::metricsWithout(dir / run, {"planner", "given_file", "plan_status"});
  };
  EXPECT_EQ(comparable("ext"), comparable("file"));
  for (const char* f : {"vo.csv", "gt.tum", "est.tum", "trajectory.csv"}) {
    EXPECT_EQ(readText(dir / "ext" / f), readText(dir / "file" / f)) << f;
  }
  const nlohmann::json m = readJson(dir / "ext/metrics.json");
  EXPECT_EQ(m["planner"], "fixed");
  EXPECT_EQ(m["plan_status"], "solved");
  EXPECT_NE(m["status"], "plan_failed");
  const nlohmann::json plan = readJson(dir / "ext/plan.json");
  EXPECT_EQ(plan["external"]["status"], "ok");
  EXPECT_EQ(plan["external"]["ended"], "exited with status 0");
  EXPECT_EQ(plan["external"]["planner_s"], 0.0);
  EXPECT_EQ(plan["path"].size(), 4u);
}

// A scenario names its external planner; `--planner external` flies it, and without one it is bad
// input naming what to give.
TEST(ExternalPlanner, AScenarioNamesItAndPlannerExternalFliesIt) {
  const auto dir = test::tempDir();
  std::ofstream(dir / "scenario.yaml") << "scene: " << kSource << "/configs/scenes/smoke.yaml\nseed: 1\n"
                                       << "planner:\n  external:\n    command: /usr/bin/python3 fake_planner.py "
                                          "no_path\n    name: mine\n    dir: "
                                       << kSource << "/tests/data/planners\n";
  const test::CmdResult run =
      test::runShell(std::string(TGNAV_BIN) + " trial --scenario " + (dir / "scenario.yaml").string() +
                     " --map-cache " + TGNAV_TEST_CACHE + " --planner external --out " + (dir / "out").string());
  ASSERT_EQ(run.rc, 0) << run.output;
  EXPECT_NE(run.output.find("smoke mine seed 1: plan_failed (external planner mine: no path: "), std::string::npos)
      << run.output;
  const test::CmdResult none = test::runShell(std::string(TGNAV_BIN) + " trial --scenario " + kScenario +
                                              " --planner external --out " + (dir / "none").string());
  EXPECT_EQ(none.rc, 2) << none.output;
  EXPECT_EQ(lines(none.output), 1) << none.output;
  EXPECT_NE(none.output.find("sets no planner.external.command"), std::string::npos) << none.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "none"));
  const test::CmdResult bad_name =
      trial("--planner-command true --planner-name 'a b' --out " + (dir / "bad").string(), dir);
  EXPECT_EQ(bad_name.rc, 2) << bad_name.output;
  EXPECT_NE(bad_name.output.find("--planner-name: 'a b'"), std::string::npos) << bad_name.output;
}

// The shipped example planners (scripts/planners/) plan around the pillar and fly what they plan.
TEST(ExternalPlanner, TheExamplePlannersFly) {
  const auto dir = test::tempDir();
  for (const char* name : {"astar", "landmark"}) {
    const auto out = dir / name;
    const test::CmdResult run = trial("--planner-command '/usr/bin/python3 " + kSource + "/scripts/planners/" + name +
                                          "_planner.py' --planner-name " + name + " --out " + out.string(),
                                      dir);
    ASSERT_EQ(run.rc, 0) << run.output;
    const nlohmann::json m = readJson(out / "metrics.json");
    EXPECT_EQ(m["planner"], name);
    EXPECT_NE(m["status"], "plan_failed") << m["detail"];
    EXPECT_NE(m["status"], "collision") << m["detail"];
    EXPECT_GT(m["vo_frames"].get<int>(), 100) << name;
    const nlohmann::json plan = readJson(out / "plan.json");
    EXPECT_EQ(plan["external"]["status"], "ok");
    EXPECT_TRUE(plan["external"]["planner_s"].is_number()) << name;
    // Around the pillar (|y| < 0.6 m at x = 0), not through it.
    const nlohmann::json& path = plan["path"];
    ASSERT_GE(path.size(), 3u);
    EXPECT_EQ(path.front()[0], -3.0);
    for (std::size_t i = 1; i < path.size(); ++i) {
      const double x0 = path[i - 1][0];
      const double x1 = path[i][0];
      if (x0 <= 0.0 && x1 >= 0.0) {
        const double y = path[i - 1][1].get<double>() + (path[i][1].get<double>() - path[i - 1][1].get<double>()) *
                                                            (0.0 - x0) / std::max(1e-9, x1 - x0);
        EXPECT_GT(std::abs(y), 0.6) << name;
      }
    }
  }
}

// With planner.external.classes the request names the topological classes; a planner that flies
// one and says which has it reported as the chosen class.
TEST(ExternalPlanner, ClassesAreSentWhenAskedAndTheChosenOneReported) {
  const auto dir = test::tempDir();
  const auto out = dir / "trial";
  const test::CmdResult run =
      trial("--planner-command '" + kFake +
                " class0' --planner-name classy --set planner.external.classes=true --out " + out.string(),
            dir);
  ASSERT_EQ(run.rc, 0) << run.output;
  const nlohmann::json m = readJson(out / "metrics.json");
  EXPECT_NE(m["status"], "plan_failed") << m["detail"];
  EXPECT_EQ(m["classes"], 2);  // around the pillar, either side
  EXPECT_EQ(m["chosen_class"], 0);
  EXPECT_EQ(readJson(out / "plan.json")["classes"].size(), 2u);
  // Without the key there are none, and a planner that needs them says so.
  const test::CmdResult none =
      trial("--planner-command '" + kFake + " class0' --planner-name classy --out " + (dir / "none").string(), dir);
  ASSERT_EQ(none.rc, 0) << none.output;
  EXPECT_EQ(readJson(dir / "none/metrics.json")["status"], "plan_failed");
}

// A sweep flies an external planner beside a built-in one; one that crashes is an outcome and the
// sweep goes on.
TEST(ExternalPlanner, ASweepGoesOnPastACrashingPlanner) {
  const auto dir = test::tempDir();
  std::ofstream(dir / "around.json") << "[[-3,0,1,0],[-1,-1.2,1,0],[1,-1.2,1,0],[3,0,1,0]]\n";
  std::ofstream(dir / "sweep.yaml")
      << "seeds: [1]\nset: {camera.width_px: 320, camera.height_px: 240}\nruns:\n  - scenario: " << kScenario
      << "\n    planner:\n      - agnostic\n      - {external: \"" << kFake << " crash\", name: crasher}\n"
      << "      - {external: \"" << kFake << " fixed around.json\", name: fixed, timeout_s: 5}\n";
  const test::CmdResult run =
      test::runShell(std::string(TGNAV_BIN) + " sweep --sweep " + (dir / "sweep.yaml").string() + " --map-cache " +
                     TGNAV_TEST_CACHE + " --out " + (dir / "out").string());
  ASSERT_EQ(run.rc, 0) << run.output;
  const std::string index = readText(dir / "out/index.csv");
  EXPECT_EQ(lines(index), 4) << index;
  for (const char* id : {"smoke__agnostic__s01", "smoke__crasher__s01", "smoke__fixed__s01"}) {
    EXPECT_NE(index.find(id), std::string::npos) << id << "\n" << index;
  }
  EXPECT_EQ(readJson(dir / "out/trials/smoke__crasher__s01/metrics.json")["status"], "plan_failed");
  const nlohmann::json fixed = readJson(dir / "out/trials/smoke__fixed__s01/metrics.json");
  EXPECT_NE(fixed["status"], "plan_failed") << fixed["detail"];
  EXPECT_EQ(fixed["planner"], "fixed");
  EXPECT_NE(readText(dir / "out/commands.txt").find("--planner-name fixed --planner-dir " + dir.string()),
            std::string::npos);
}

}  // namespace
}  // namespace tgnav
