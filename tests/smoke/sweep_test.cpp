// Sweeps through the `tgnav sweep` program on the smoke scene at 320x240: a sweep killed with -9
// mid-run resumes to the same index and metrics as an uninterrupted one, a corrupted trial
// folder is moved aside and run again, bad input is refused before anything runs, and the Slurm
// backend runs the same trials as a job array on a private single-node cluster
// (scripts/slurm_local.sh; skipped with its message where Slurm cannot be installed or run).
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "../harness/test_util.h"

namespace tgnav {
namespace {

namespace fs = std::filesystem;
using test::runShell;

const fs::path kSource = TGNAV_SOURCE_DIR;
const std::string kBin = TGNAV_BIN;

std::string readText(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A sweep of the smoke scene at 320x240 (each trial 5-10 s on two cores).
fs::path smokeSweep(const fs::path& dir, const std::string& runs) {
  return test::writeFile(dir / "sweep.yaml", "set: {camera.width_px: 320, camera.height_px: 240}\nruns:\n" + runs);
}
std::string run(const std::string& planners, const std::string& seeds) {
  return "  - {scenario: " + (kSource / "configs/scenarios/smoke.yaml").string() + ", planner: " + planners +
         ", seeds: " + seeds + "}\n";
}

std::string sweepCommand(const fs::path& sweep, const fs::path& out, const std::string& extra = "") {
  return kBin + " sweep --sweep " + sweep.string() + " --out " + out.string() + " --map-cache " + TGNAV_TEST_CACHE +
         " " + extra;
}

// index.csv rows by trial id, without their wall-clock columns (plan_time_s, wall_time_s); fails
// the test when an id appears twice.
std::map<std::string, std::string> readIndex(const fs::path& sweep_dir) {
  if (!fs::exists(sweep_dir / "index.csv")) return {};
  std::ifstream in(sweep_dir / "index.csv");
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.substr(0, 36), "id,scene,planner,samples,seed,params");
  std::map<std::string, std::string> rows;
  while (std::getline(in, line)) {
    std::vector<std::string> f(1);
    for (char c : line) {
      if (c == ',') {
        f.emplace_back();
      } else {
        f.back().push_back(c);
      }
    }
    EXPECT_EQ(f.size(), 18u) << line;
    if (f.size() != 18) continue;
    f[12].clear();  // plan_time_s
    f[13].clear();  // wall_time_s
    std::string row;
    for (const std::string& v : f) row += v + ",";
    EXPECT_TRUE(rows.emplace(f[0], row).second) << "trial " << f[0] << " is in the index twice";
  }
  return rows;
}

// metrics.json without its wall-clock figures.
std::string deterministicMetrics(const fs::path& trial) { return test::metricsWithout(trial, {"scenario"}); }

void expectSameResults(const fs::path& a, const fs::path& b) {
  const auto ia = readIndex(a);
  const auto ib = readIndex(b);
  EXPECT_EQ(ia, ib);
  for (const auto& [id, row] : ia) {
    EXPECT_EQ(deterministicMetrics(a / "trials" / id), deterministicMetrics(b / "trials" / id)) << id;
  }
}

int countOf(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t i = text.find(what); i != std::string::npos; i = text.find(what, i + 1)) ++n;
  return n;
}

TEST(Sweep, KilledSweepResumesToTheSameResultsAndCorruptedTrialsRunAgain) {
  const fs::path dir = test::tempDir();
  const fs::path sweep = smokeSweep(dir, run("[proposed, agnostic]", "[2, 3]"));

  // Uninterrupted.
  const test::CmdResult whole = runShell(sweepCommand(sweep, dir / "whole", "--jobs 2"));
  ASSERT_EQ(whole.rc, 0) << whole.output;
  EXPECT_NE(whole.output.find("4 of 4 trials done"), std::string::npos) << whole.output;
  ASSERT_EQ(readIndex(dir / "whole").size(), 4u);

  // Killed with -9 once the first trial is done (the others mid-flight), then resumed.
  const fs::path killed = dir / "killed";
  const test::CmdResult started = runShell("(" + sweepCommand(sweep, killed, "--jobs 2") + " > " +
                                           (dir / "killed.log").string() + " 2>&1 & echo $!)");
  const pid_t pid = std::stoi(started.output);
  const auto t0 = std::chrono::steady_clock::now();
  while (readIndex(killed).empty() && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(240)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_EQ(kill(pid, SIGKILL), 0);
  const std::size_t done_before = readIndex(killed).size();
  ASSERT_GE(done_before, 1u);
  ASSERT_LT(done_before, 4u) << "the sweep finished before it could be killed";

  // Its trials die with it (parent-death signal) and leave partial results; the re-run waits for
  // them to let go of the folder, then runs what is not finished.
  const test::CmdResult resumed = runShell(sweepCommand(sweep, killed, "--jobs 2"));
  ASSERT_EQ(resumed.rc, 0) << resumed.output;
  // A trial that was committing its results as the sweep died may still finish (nothing is lost),
  // so at least the trials done before the kill count as done.
  const std::size_t at = resumed.output.find("resuming: ");
  ASSERT_NE(at, std::string::npos) << resumed.output;
  const std::size_t done_after = std::stoul(resumed.output.substr(at + 10));
  EXPECT_GE(done_after, done_before) << resumed.output;
  EXPECT_LT(done_after, 4u) << resumed.output;
  expectSameResults(dir / "whole", killed);
  int reruns = 0;
  for (const auto& [id, row] : readIndex(killed)) {
    reruns += countOf(readText(killed / "logs" / (id + ".log")), "=== ") > 1;
  }
  EXPECT_GE(reruns, 1) << "no killed trial ran again";
  for (const auto& e : fs::directory_iterator(killed / "trials")) {
    EXPECT_NE(e.path().filename().string()[0], '.') << "staging folder left: " << e.path();
  }

  // Nothing left to do: a re-run says so and changes nothing.
  const test::CmdResult again = runShell(sweepCommand(sweep, killed));
  EXPECT_EQ(again.rc, 0) << again.output;
  EXPECT_NE(again.output.find("all 4 trials are done"), std::string::npos) << again.output;

  // A corrupted trial folder: --status tells, a re-run moves it aside and runs the trial again.
  const fs::path victim = killed / "trials" / "smoke__agnostic__s03" / "metrics.json";
  const std::string good = readText(victim);
  test::writeFile(victim, good.substr(0, good.size() / 2));
  const test::CmdResult status = runShell(kBin + " sweep --status --out " + killed.string());
  EXPECT_EQ(status.rc, 0) << status.output;
  EXPECT_NE(status.output.find("3 of 4 trials done"), std::string::npos) << status.output;
  EXPECT_NE(status.output.find("1 corrupted"), std::string::npos) << status.output;
  EXPECT_EQ(readIndex(killed).size(), 3u);  // --status refreshes the index
  const test::CmdResult repaired = runShell(sweepCommand(sweep, killed));
  ASSERT_EQ(repaired.rc, 0) << repaired.output;
  EXPECT_NE(repaired.output.find("trials/smoke__agnostic__s03 is corrupted (metrics.json does not parse"),
            std::string::npos)
      << repaired.output;
  EXPECT_TRUE(fs::exists(killed / "corrupt" / "smoke__agnostic__s03.1" / "metrics.json"));
  expectSameResults(dir / "whole", killed);
}

TEST(Sweep, BadInputIsRefusedBeforeAnythingRuns) {
  const fs::path dir = test::tempDir();
  const std::string smoke = (kSource / "configs/scenarios/smoke.yaml").string();
  struct Case {
    std::string sweep;  // file text ("" = a valid sweep)
    std::string args;   // besides --sweep and --out
    std::string expect;
  };
  const fs::path other = dir / "other";  // a folder holding some other sweep
  fs::create_directories(other);
  test::writeFile(other / "commands.txt", "x trial --scenario elsewhere.yaml\n");
  const fs::path stuff = dir / "stuff";
  fs::create_directories(stuff);
  test::writeFile(stuff / "notes.txt", "mine\n");
  const std::string valid = "seeds: 1\nruns:\n  - {scenario: " + smoke + ", planner: proposed}\n";
  const Case cases[] = {
      {"seeds: 1\nruns:\n  - {scenario: " + smoke + ", planner: proposed, axes: {vo.no_such_key: [1, 2]}}\n", "",
       "sweep.yaml:3: runs[0]: --set vo.no_such_key=1: unknown key 'vo.no_such_key'"},
      {"seeds: 1\nruns:\n  - scenario: " + smoke + "\n    planner: proposed\n    axes: {vo.min_inliers: []}\n", "",
       "sweep.yaml:5: runs[0].axes.vo.min_inliers: expected a non-empty list of values"},
      {valid, "--backend pbs", "--backend: 'pbs' is not local or slurm"},
      {valid, "--wait", "--wait: only for --backend slurm"},
      {valid, "--jobs -1", "--jobs: -1 must be >= 1"},
      {valid, "OTHER", "holds another sweep: its commands.txt differs"},
      {valid, "STUFF", "holds files but no sweep"},
  };
  int n = 0;
  for (const Case& c : cases) {
    const fs::path sweep = test::writeFile(dir / "sweep.yaml", c.sweep);
    fs::path out = dir / ("out" + std::to_string(n++));
    std::string args = c.args;
    if (args == "OTHER") out = other, args = "";
    if (args == "STUFF") out = stuff, args = "";
    const test::CmdResult r =
        runShell(kBin + " sweep --sweep " + sweep.string() + " --out " + out.string() + " " + args);
    SCOPED_TRACE(c.expect);
    EXPECT_EQ(r.rc, 2) << r.output;
    EXPECT_NE(r.output.find(c.expect), std::string::npos) << r.output;
    EXPECT_EQ(countOf(r.output, "\n"), 1) << r.output;
    if (out != other && out != stuff) {
      EXPECT_FALSE(fs::exists(out)) << "created " << out;
    }
  }
  EXPECT_EQ(readText(other / "commands.txt"), "x trial --scenario elsewhere.yaml\n");
  EXPECT_FALSE(fs::exists(other / "trials"));
  EXPECT_FALSE(fs::exists(stuff / "trials"));

  const test::CmdResult status = runShell(kBin + " sweep --status --out " + stuff.string());
  EXPECT_EQ(status.rc, 2) << status.output;
  EXPECT_NE(status.output.find("is not a sweep folder (no trials.csv)"), std::string::npos) << status.output;
}

// A private single-node Slurm cluster for one test (scripts/slurm_local.sh).
class SlurmSweep : public ::testing::Test {
 protected:
  void SetUp() override {
    // Unix socket paths are short: the cluster lives in a short folder of its own.
    cluster_ = fs::path("/tmp") / ("tgnav-slurm-" + std::to_string(getpid()));
    const test::CmdResult r = runShell((kSource / "scripts/slurm_local.sh").string() + " start " + cluster_.string() +
                                       " 2>" + (cluster_.string() + ".err"));
    const std::string err = readText(cluster_.string() + ".err");
    if (r.rc == 3) GTEST_SKIP() << "Slurm is not available here: " << err;
    ASSERT_EQ(r.rc, 0) << err << r.output;
    started_ = true;
    std::istringstream exports(r.output);
    for (std::string line; std::getline(exports, line);) {
      if (line.rfind("export ", 0) != 0) continue;
      const std::size_t eq = line.find('=');
      setenv(line.substr(7, eq - 7).c_str(), line.substr(eq + 1).c_str(), 1);
    }
  }
  void TearDown() override {
    if (started_) runShell((kSource / "scripts/slurm_local.sh").string() + " stop " + cluster_.string());
    fs::remove(cluster_.string() + ".err");
  }
  fs::path cluster_;
  bool started_ = false;
};

TEST_F(SlurmSweep, JobArrayRunsTheSweepLikeLocalAndRefusesDuplicates) {
  const fs::path dir = test::tempDir();
  const fs::path sweep = smokeSweep(dir, run("[proposed, agnostic]", "[2]"));

  // A submission Slurm refuses changes nothing.
  const test::CmdResult refused =
      runShell(sweepCommand(sweep, dir / "slurm", "--backend slurm --sbatch-arg=--partition=nope"));
  EXPECT_EQ(refused.rc, 2) << refused.output;
  EXPECT_NE(refused.output.find("sbatch failed (exit 1): sbatch: error: invalid partition specified: nope"),
            std::string::npos)
      << refused.output;
  EXPECT_FALSE(fs::exists(dir / "slurm" / "slurm" / "jobs.txt"));

  const test::CmdResult slurm = runShell(sweepCommand(sweep, dir / "slurm", "--backend slurm --jobs 2 --wait"));
  ASSERT_EQ(slurm.rc, 0) << slurm.output;
  EXPECT_NE(slurm.output.find("2 of 2 trials done"), std::string::npos) << slurm.output;
  const test::CmdResult status = runShell(kBin + " sweep --status --out " + (dir / "slurm").string());
  EXPECT_NE(status.output.find("slurm: no tasks queued or running"), std::string::npos) << status.output;

  const test::CmdResult local = runShell(sweepCommand(sweep, dir / "local", "--jobs 2"));
  ASSERT_EQ(local.rc, 0) << local.output;
  expectSameResults(dir / "local", dir / "slurm");

  // Submitted and not waited for: a second submission is refused while the first is queued or
  // running; --status follows it to the end.
  fs::create_directories(dir / "one");
  const fs::path one = smokeSweep(dir / "one", run("proposed", "[3]"));
  const test::CmdResult submitted = runShell(sweepCommand(one, dir / "async", "--backend slurm"));
  ASSERT_EQ(submitted.rc, 0) << submitted.output;
  EXPECT_NE(submitted.output.find("submitted Slurm job array"), std::string::npos) << submitted.output;
  const test::CmdResult twice = runShell(sweepCommand(one, dir / "async", "--backend slurm"));
  EXPECT_EQ(twice.rc, 2) << twice.output;
  EXPECT_NE(twice.output.find("still queued or running in Slurm"), std::string::npos) << twice.output;
  const auto t0 = std::chrono::steady_clock::now();
  std::string last;
  while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(180)) {
    last = runShell(kBin + " sweep --status --out " + (dir / "async").string()).output;
    if (last.find("1 of 1 trials done") != std::string::npos) break;
    std::this_thread::sleep_for(std::chrono::seconds(1));
  }
  EXPECT_NE(last.find("1 of 1 trials done (1 success)"), std::string::npos) << last;
  EXPECT_EQ(readIndex(dir / "async").size(), 1u);
}

}  // namespace
}  // namespace tgnav
