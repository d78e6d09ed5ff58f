// Sweep files: expansion into trials, their ids and arguments, the checks of bad sweeps, the
// manifest, and how trial folders are judged (absent, interrupted, corrupted, done) for resuming.
// Then runSweep and sweepStatus without the CLI, with stand-ins for `tgnav trial`, sbatch and
// squeue: the local pool, resuming, failures, tidying, and the Slurm backend's submissions.
#include "harness/experiments/sweep.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <exception>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <set>
#include <sstream>

#include "harness/base/shell.h"
#include "harness/config/scenario.h"
#include "harness/experiments/sweep_folder.h"
#include "harness/experiments/sweep_runner.h"
#include "tests/harness/test_util.h"

namespace tgnav::harness {
namespace {

namespace fs = std::filesystem;

// A sweep file in a temp dir whose scenario paths point at the repo's scenarios.
fs::path sweepFile(const fs::path& dir, const std::string& body) {
  const std::string scenarios = (test::sourceDir() / "configs/scenarios").string();
  std::string text = body;
  for (std::size_t i = text.find("SC/"); i != std::string::npos; i = text.find("SC/", i)) {
    text.replace(i, 3, scenarios + "/");
  }
  return test::writeFile(dir / "sweep.yaml", text);
}

TEST(Sweep, GeneratedScenesAreWrittenOnceAndCheckedOnEveryLoad) {
  const fs::path dir = test::tempDir();
  const fs::path file = sweepFile(dir,
                                  "runs:\n"
                                  "  - generated: [{kind: room, seeds: [5, 6]}, {kind: corridors, seeds: [5]}]\n"
                                  "    planner: proposed\n"
                                  "    seeds: [1]\n");
  const fs::path scenes = dir / "out" / "scenes";
  const Sweep s = loadSweep(file, scenes);
  ASSERT_EQ(s.trials.size(), 3u);
  EXPECT_EQ(s.trials[0].id, "room-5__proposed__s01");
  EXPECT_EQ(s.trials[2].id, "corridors-5__proposed__s01");
  EXPECT_EQ(s.trials[1].scenario, scenes / "room-6" / "scenarios" / "room-6.yaml");
  EXPECT_EQ(s.trials[1].scene, "room-6");
  // Loaded again: the same trials, the scenes checked, not rewritten.
  const auto written = fs::last_write_time(scenes / "room-5" / "room-5.xml");
  EXPECT_EQ(loadSweep(file, scenes).trials.size(), 3u);
  EXPECT_EQ(fs::last_write_time(scenes / "room-5" / "room-5.xml"), written);
  // A scene that is not what the generator writes is refused, naming the file.
  test::writeFile(scenes / "room-6" / "scenes" / "room-6.yaml", "mjcf: ../room-6.xml\n");
  EXPECT_NE(test::inputError([&] { loadSweep(file, scenes); }).find("room-6.yaml"), std::string::npos);
  // Without a sweep folder, or with a bad kind or seed: one line naming the key.
  EXPECT_NE(test::inputError([&] { loadSweep(file); }).find("runs[0].generated"), std::string::npos);
  const fs::path bad_kind =
      test::writeFile(dir / "k.yaml", "runs:\n  - {generated: {kind: cave, seeds: [1]}, planner: proposed}\n");
  EXPECT_NE(test::inputError([&] { loadSweep(bad_kind, dir / "k"); }).find("cave"), std::string::npos);
  const fs::path bad_seed =
      test::writeFile(dir / "s.yaml", "runs:\n  - {generated: {kind: room, seeds: [-1]}, planner: proposed}\n");
  EXPECT_NE(test::inputError([&] { loadSweep(bad_seed, dir / "s"); }).find("-1"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "k"));
  EXPECT_FALSE(fs::exists(dir / "s"));
  const fs::path both = test::writeFile(
      dir / "b.yaml", "runs:\n  - {generated: {kind: room, seeds: [1]}, scenario: x.yaml, planner: proposed}\n");
  EXPECT_NE(test::inputError([&] { loadSweep(both, dir / "b"); }).find("either"), std::string::npos);
}

TEST(Sweep, ExpandsRunsAsCartesianProductsInOrder) {
  const fs::path dir = test::tempDir();
  const Sweep s = loadSweep(sweepFile(dir,
                                      "seeds: 2\n"
                                      "set: {camera.width_px: 320}\n"
                                      "runs:\n"
                                      "  - scenario: SC/smoke.yaml\n"
                                      "    planner: [proposed, agnostic]\n"
                                      "  - scenario: [SC/smoke.yaml, SC/storage.yaml]\n"
                                      "    planner: rrtstar\n"
                                      "    samples: [300, 1000]\n"
                                      "    seeds: [7]\n"
                                      "    axes: {vo.min_inliers: [15, 25]}\n"));
  ASSERT_EQ(s.trials.size(), 2u * 2u + 2u * 2u * 2u * 1u);
  std::vector<std::string> ids;
  for (const SweepTrial& t : s.trials) ids.push_back(t.id);
  EXPECT_EQ(ids[0], "smoke__proposed__s01");
  EXPECT_EQ(ids[1], "smoke__proposed__s02");
  EXPECT_EQ(ids[2], "smoke__agnostic__s01");
  EXPECT_EQ(ids[4], "smoke__rrtstar-300__vo.min_inliers=15__s07");
  EXPECT_EQ(ids[5], "smoke__rrtstar-300__vo.min_inliers=25__s07");
  EXPECT_EQ(ids[6], "smoke__rrtstar-1000__vo.min_inliers=15__s07");
  EXPECT_EQ(ids[8], "storage__rrtstar-300__vo.min_inliers=15__s07");
  EXPECT_EQ(std::set<std::string>(ids.begin(), ids.end()).size(), ids.size());

  const SweepTrial& t = s.trials[5];
  EXPECT_EQ(t.scene, "smoke");
  EXPECT_EQ(t.planner, "rrtstar");
  EXPECT_EQ(t.samples, 300);
  EXPECT_EQ(t.seed, 7u);
  EXPECT_EQ(t.params, "vo.min_inliers=25");
  ASSERT_EQ(t.set.size(), 2u);
  EXPECT_EQ(t.set[0], (std::pair<std::string, std::string>("camera.width_px", "320")));
  EXPECT_EQ(t.set[1], (std::pair<std::string, std::string>("vo.min_inliers", "25")));
  EXPECT_TRUE(t.scenario.is_absolute());
  EXPECT_EQ(s.trials[8].scene, "storage");

  const std::vector<std::string> args = trialArguments(t, "trials/x");
  const std::vector<std::string> expected{
      "trial", "--scenario", t.scenario.string(),   "--planner", "rrtstar",           "--samples", "300",     "--seed",
      "7",     "--set",      "camera.width_px=320", "--set",     "vo.min_inliers=25", "--out",     "trials/x"};
  EXPECT_EQ(args, expected);
}

TEST(Sweep, RrtStarWithoutSamplesTakesTheConfiguredBudget) {
  const fs::path dir = test::tempDir();
  const Sweep s = loadSweep(sweepFile(dir, "seeds: [3]\nruns:\n  - {scenario: SC/smoke.yaml, planner: rrtstar}\n"));
  ASSERT_EQ(s.trials.size(), 1u);
  EXPECT_EQ(s.trials[0].samples, 1000);  // configs/planner.yaml
  EXPECT_EQ(s.trials[0].id, "smoke__rrtstar-1000__s03");
}

TEST(Sweep, TrackModelIsAFileRelativeToTheSweep) {
  const fs::path dir = test::tempDir();
  fs::copy_file(test::sourceDir() / "configs/track_model.json", dir / "model.json");
  const Sweep s = loadSweep(sweepFile(dir,
                                      "seeds: [1]\nruns:\n  - {scenario: SC/smoke.yaml, planner: proposed, set: "
                                      "{planner.information.track_model: model.json}}\n  - {scenario: SC/smoke.yaml, "
                                      "planner: agnostic, set: {planner.information.track_model: none}}\n"));
  ASSERT_EQ(s.trials.size(), 2u);
  const std::pair<std::string, std::string> absolute{"planner.information.track_model", (dir / "model.json").string()};
  const std::vector<std::pair<std::string, std::string>> expected{absolute};
  EXPECT_EQ(s.trials[0].set, expected);
  EXPECT_EQ(s.trials[1].set.back(), (std::pair<std::string, std::string>{"planner.information.track_model", "none"}));
  const std::string msg = test::inputError([&] {
    loadSweep(sweepFile(dir,
                        "seeds: [1]\nset: {planner.information.track_model: gone.json}\nruns:\n  - "
                        "{scenario: SC/smoke.yaml, planner: proposed}\n"));
  });
  EXPECT_NE(msg.find("planner.information.track_model: file " + (dir / "gone.json").string() + " not found"),
            std::string::npos)
      << msg;
}

TEST(Sweep, VehicleAxisIsAFileRelativeToTheSweepNamedByItsStem) {
  const fs::path dir = test::tempDir();
  const std::string hex = (test::sourceDir() / "models/vehicles/hexarotor.yaml").string();
  for (const char* f : {"hexarotor.xml", "hexarotor_gains.yaml"}) {
    fs::copy_file(test::sourceDir() / "models/vehicles" / f, dir / f);
  }
  fs::copy_file(hex, dir / "hexcopy.yaml");
  const Sweep s = loadSweep(sweepFile(dir,
                                      "seeds: [1]\nruns:\n  - {scenario: SC/smoke.yaml, planner: proposed, axes: "
                                      "{vehicle: [" +
                                          hex + ", ./hexcopy.yaml]}}\n"));
  ASSERT_EQ(s.trials.size(), 2u);
  EXPECT_EQ(s.trials[0].params, "vehicle=" + hex);
  EXPECT_EQ(s.trials[1].params, "vehicle=" + (dir / "hexcopy.yaml").string());  // absolute: runs anywhere
  EXPECT_EQ(s.trials[0].id, "smoke__proposed__vehicle=hexarotor__s01");
  EXPECT_EQ(s.trials[1].id, "smoke__proposed__vehicle=hexcopy__s01");
  EXPECT_EQ(paramsLabel(s.trials[0].params), "vehicle=hexarotor");
  const std::string msg = test::inputError([&] {
    loadSweep(sweepFile(dir,
                        "seeds: [1]\nruns:\n  - {scenario: SC/smoke.yaml, planner: proposed, set: {vehicle: "
                        "nope.yaml}}\n"));
  });
  EXPECT_NE(msg.find("vehicle: file " + (dir / "nope.yaml").string() + " not found"), std::string::npos) << msg;
  // Trials are named by the vehicle's file name: two vehicles of one name in one sweep collide.
  fs::create_directories(dir / "other");
  fs::copy_file(hex, dir / "other" / "hexarotor.yaml");
  fs::copy_file(dir / "hexarotor.xml", dir / "other" / "hexarotor.xml");
  fs::copy_file(dir / "hexarotor_gains.yaml", dir / "other" / "hexarotor_gains.yaml");
  const std::string twice = test::inputError([&] {
    loadSweep(sweepFile(dir, "seeds: [1]\nruns:\n  - {scenario: SC/smoke.yaml, planner: proposed, axes: {vehicle: [" +
                                 hex + ", other/hexarotor.yaml]}}\n"));
  });
  EXPECT_NE(twice.find("smoke__proposed__vehicle=hexarotor__s01 is listed twice"), std::string::npos) << twice;
}

TEST(Sweep, ListValuesAndTheirIds) {
  const fs::path dir = test::tempDir();
  const Sweep s = loadSweep(sweepFile(dir,
                                      "seeds: 1\nruns:\n  - scenario: SC/smoke.yaml\n    planner: proposed\n"
                                      "    axes: {goal: [[4, 0.5, 1.2, 0], [4, -0.5, 1.2, 0]]}\n"));
  ASSERT_EQ(s.trials.size(), 2u);
  EXPECT_EQ(s.trials[0].set[0].second, "[4, 0.5, 1.2, 0]");
  EXPECT_EQ(s.trials[0].id, "smoke__proposed__goal=_4__0.5__1.2__0___s01");
  // The manifest stays plain CSV: the list's commas are shown as spaces.
  EXPECT_EQ(parseManifest(manifestCsv(s.trials), "m").at(0).params, "goal=[4  0.5  1.2  0]");
}

// Each bad sweep: an InputError naming the file, its line and the offending key or value.
struct BadSweep {
  const char* body;
  const char* expect;  // a part of the message
};

TEST(Sweep, BadSweepsAreRejectedWithFileLineAndKey) {
  const BadSweep cases[] = {
      {"seeds: 2\nruns:\n  - {scenario: SC/smoke.yaml, planner: proposed, axes: {vo.no_such_key: [1, 2]}}\n",
       "no_such_key"},
      {"seeds: 2\nruns:\n  - {scenario: SC/smoke.yaml, planner: proposed, set: {camera.width_px: -5}}\n", "width_px"},
      {"seeds: 2\nruns:\n  - {scenario: SC/smoke.yaml, planner: proposed, axes: {vo.min_inliers: []}}\n",
       "axes.vo.min_inliers: expected a non-empty list"},
      {"seeds: 2\nruns:\n  - {scenario: SC/smoke.yaml, planner: []}\n", "runs[0].planner: empty list"},
      {"seeds: []\nruns:\n  - {scenario: SC/smoke.yaml, planner: proposed}\n", "seeds"},
      {"seeds: 2\nruns:\n  - {scenario: SC/smoke.yaml, planner: dijkstra}\n", "dijkstra"},
      {"seeds: 2\nruns:\n  - {scenario: SC/smoke.yaml, planner: proposed, samples: 300}\n",
       "only the rrtstar planner takes a sample budget"},
      {"seeds: 2\nruns:\n  - {scenario: SC/smoke.yaml, planner: rrtstar, samples: 0}\n", "samples: '0'"},
      {"seeds: 2\nruns:\n  - {scenario: SC/nowhere.yaml, planner: proposed}\n", "nowhere.yaml"},
      {"seeds: 2\nruns:\n  - {scenario: SC/smoke.yaml, planner: proposed, colour: red}\n", "colour"},
      {"seeds: 2\nruns:\n  - {scenario: SC/smoke.yaml, planner: proposed}\n"
       "  - {scenario: SC/smoke.yaml, planner: [agnostic, proposed]}\n",
       "smoke__proposed__s01 is listed twice"},
      {"runs:\n  - {scenario: SC/smoke.yaml, planner: proposed}\n", "no seeds"},
      {"seeds: 2\nruns: []\n", "non-empty list of runs"},
      {"seeds: 2\n", "'runs' is missing"},
      {"seeds: 2\nruns:\n  - {scenario: SC/smoke.yaml, planner: proposed, set: {seed: 4}}\n", "seeds"},
  };
  const fs::path dir = test::tempDir();
  for (const BadSweep& c : cases) {
    const fs::path file = sweepFile(dir, c.body);
    const std::string message = test::inputError([&] { loadSweep(file); });
    SCOPED_TRACE(c.body);
    EXPECT_NE(message.find(file.string() + ":"), std::string::npos) << message;  // file:line
    EXPECT_NE(message.find(c.expect), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

TEST(Sweep, ManifestRoundTripsAndRejectsBadRows) {
  const fs::path dir = test::tempDir();
  const Sweep s = loadSweep(sweepFile(
      dir,
      "seeds: 2\nruns:\n  - {scenario: SC/smoke.yaml, planner: rrtstar, samples: 300, set: {vo.min_inliers: 15}}\n"));
  const std::vector<SweepTrial> back = parseManifest(manifestCsv(s.trials), "trials.csv");
  ASSERT_EQ(back.size(), s.trials.size());
  for (std::size_t i = 0; i < back.size(); ++i) {
    EXPECT_EQ(back[i].id, s.trials[i].id);
    EXPECT_EQ(back[i].scene, s.trials[i].scene);
    EXPECT_EQ(back[i].planner, s.trials[i].planner);
    EXPECT_EQ(back[i].samples, s.trials[i].samples);
    EXPECT_EQ(back[i].seed, s.trials[i].seed);
    EXPECT_EQ(back[i].params, s.trials[i].params);
  }
  const std::string header = "id,scenario,scene,planner,samples,seed,params\n";
  EXPECT_NE(test::inputError([&] { parseManifest("id,foo\n", "m.csv"); }).find("m.csv:1"), std::string::npos);
  EXPECT_NE(test::inputError([&] { parseManifest(header + "a,b,c\n", "m.csv"); }).find("m.csv:2: expected 7"),
            std::string::npos);
  EXPECT_NE(test::inputError([&] { parseManifest(header + "a,s,smoke,proposed,0,x1,\n", "m.csv"); }).find("x1"),
            std::string::npos);
  EXPECT_NE(test::inputError([&] { parseManifest(header + "../a,s,smoke,proposed,0,1,\n", "m.csv"); }).find("../a"),
            std::string::npos);
}

TEST(Sweep, CommandsAreShellQuoted) {
  EXPECT_EQ(shellWord("trials/a=b"), "trials/a=b");
  EXPECT_EQ(shellWord("goal=[4, 0.5]"), "'goal=[4, 0.5]'");
  EXPECT_EQ(shellWord("it's"), "'it'\\''s'");
  EXPECT_EQ(shellWord(""), "''");
}

// ---- trial folders ------------------------------------------------------------------------

SweepTrial smokeTrial() {
  SweepTrial t;
  t.id = "smoke__rrtstar-300__s02";
  t.scene = "smoke";
  t.planner = "rrtstar";
  t.samples = 300;
  t.seed = 2;
  return t;
}

std::string metricsJson(const std::string& status = "success", const std::string& goal = "0.05",
                        const std::string& seed = "2") {
  return "{\"scene\": \"smoke\", \"planner\": \"rrtstar\", \"samples\": 300, \"seed\": " + seed + ", \"status\": \"" +
         status +
         "\", \"path_length_m\": 7.5, \"planned_length_m\": 7.0, "
         "\"goal_error_m\": " +
         goal +
         ", \"final_distance_to_goal_m\": 0.01, \"ate_rmse_m\": 0.02, "
         "\"plan_time_s\": 0.2, \"wall_time_s\": 6.0, \"sim_time_s\": 25.0, \"vo_lost_at_s\": null, "
         "\"distance_tracked_m\": 7.4}";
}

TEST(SweepFolder, StatesOfTrialFolders) {
  const fs::path dir = test::tempDir();
  const SweepTrial t = smokeTrial();
  const fs::path f = dir / t.id;
  EXPECT_EQ(inspectTrialFolder(t, f).state, TrialState::kAbsent);

  fs::create_directories(f);
  test::writeFile(f / "INCOMPLETE", "interrupted\n");
  TrialFolder got = inspectTrialFolder(t, f);
  EXPECT_EQ(got.state, TrialState::kIncomplete);
  EXPECT_NE(got.problem.find("INCOMPLETE"), std::string::npos);
  fs::remove(f / "INCOMPLETE");
  EXPECT_EQ(inspectTrialFolder(t, f).state, TrialState::kIncomplete);  // killed before metrics.json

  test::writeFile(f / "metrics.json", metricsJson());
  got = inspectTrialFolder(t, f);
  ASSERT_EQ(got.state, TrialState::kDone) << got.problem;
  EXPECT_EQ(got.metrics["status"], "success");

  const std::pair<std::string, std::string> corrupt[] = {
      {metricsJson().substr(0, 60), "does not parse"},
      {"[1, 2]", "not an object"},
      {metricsJson("crashed"), "'status'"},
      {metricsJson("success", "\"far\""), "'goal_error_m'"},
      {metricsJson("success", "0.05", "9"), "another trial"},
      {"{\"status\": \"success\"}", "has no 'path_length_m'"},
  };
  for (const auto& [text, expect] : corrupt) {
    test::writeFile(f / "metrics.json", text);
    got = inspectTrialFolder(t, f);
    EXPECT_EQ(got.state, TrialState::kCorrupt) << text;
    EXPECT_NE(got.problem.find(expect), std::string::npos) << got.problem;
  }
  fs::remove_all(f);
  test::writeFile(f, "a file, not a folder");
  EXPECT_EQ(inspectTrialFolder(t, f).state, TrialState::kCorrupt);
}

TEST(SweepFolder, IndexHasEachFinishedTrialOnceInManifestOrder) {
  const fs::path dir = test::tempDir();
  std::vector<SweepTrial> trials;
  std::vector<TrialFolder> folders;
  for (int seed : {1, 2, 3}) {
    SweepTrial t = smokeTrial();
    t.seed = static_cast<std::uint64_t>(seed);
    t.id = "smoke__rrtstar-300__s0" + std::to_string(seed);
    const fs::path f = dir / t.id;
    fs::create_directories(f);
    if (seed != 2) {
      test::writeFile(f / "metrics.json", metricsJson(seed == 3 ? "vo_lost" : "success", seed == 3 ? "null" : "0.05",
                                                      std::to_string(seed)));
    }
    trials.push_back(t);
    folders.push_back(inspectTrialFolder(t, f));
  }
  const std::string index = indexCsv(trials, folders);
  std::istringstream in(index);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], kIndexHeader);
  EXPECT_EQ(lines[1],
            "smoke__rrtstar-300__s01,smoke,rrtstar,300,1,,success,7.5,7.0,0.05,0.01,0.02,0.2,6.0,25.0,,7.4,"
            "trials/smoke__rrtstar-300__s01");
  EXPECT_EQ(lines[2].substr(0, 50), "smoke__rrtstar-300__s03,smoke,rrtstar,300,3,,vo_lo");
  EXPECT_NE(lines[2].find(",vo_lost,7.5,7.0,,0.01,"), std::string::npos) << lines[2];  // no goal error
}

// ---- running sweeps -------------------------------------------------------------------------

std::string readText(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path executable(const fs::path& file, const std::string& text) {
  test::writeFile(file, text);
  fs::permissions(file, fs::perms::owner_all, fs::perm_options::add);
  return file;
}

// A stand-in for the tgnav program: `trial ... --seed K --out DIR` writes the metrics.json of a
// finished trial into DIR; the seed in $FAKE_FAIL_SEED fails instead (exit 3).
fs::path fakeTgnav(const fs::path& dir) {
  return executable(dir / "fake_tgnav",
                    "#!/bin/bash\n"
                    "while [ $# -gt 0 ]; do case $1 in --out) out=$2 ;; --seed) seed=$2 ;; esac; shift; done\n"
                    "[ \"$seed\" = \"${FAKE_FAIL_SEED:-}\" ] && { echo \"boom: seed $seed\" >&2; exit 3; }\n"
                    "mkdir -p \"$out\" && cat > \"$out/metrics.json\" <<EOF\n" +
                        metricsJson("success", "0.05", "$seed") + "\nEOF\n");
}

// A sweep of `seeds` smoke trials (rrtstar-300) into dir/out, run by the stand-in.
SweepOptions smokeSweep(const fs::path& dir, int seeds) {
  SweepOptions o;
  o.sweep = sweepFile(dir, "seeds: " + std::to_string(seeds) +
                               "\nruns:\n  - {scenario: SC/smoke.yaml, planner: rrtstar, samples: 300}\n")
                .string();
  o.out = (dir / "out").string();
  o.jobs = 2;
  o.map_cache = TGNAV_TEST_CACHE;
  o.program = fakeTgnav(dir);
  return o;
}

// The trial ids in index.csv, in order.
std::vector<std::string> indexIds(const fs::path& out) {
  std::istringstream in(readText(out / "index.csv"));
  std::vector<std::string> ids;
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, kIndexHeader);
  while (std::getline(in, line)) ids.push_back(line.substr(0, line.find(',')));
  return ids;
}

// An environment variable set for one scope (unset after it when it was unset or empty before).
struct ScopedEnv {
  ScopedEnv(const char* n, const std::string& v) : name(n), old(getenv(n) ? getenv(n) : "") { setenv(n, v.c_str(), 1); }
  ~ScopedEnv() { old.empty() ? unsetenv(name) : setenv(name, old.c_str(), 1); }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;
  ScopedEnv(ScopedEnv&&) = delete;
  ScopedEnv& operator=(ScopedEnv&&) = delete;
  const char* name;
  std::string old;
};

// What fn() returns (rc) and prints (out, err); an exception passes through (the printing is dropped).
struct Captured {
  int rc = -1;
  std::string out, err;
};
Captured capture(const std::function<int()>& fn) {
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  Captured c;
  std::exception_ptr error;
  try {
    c.rc = fn();
  } catch (...) {
    error = std::current_exception();
  }
  c.out = testing::internal::GetCapturedStdout();
  c.err = testing::internal::GetCapturedStderr();
  if (error) std::rethrow_exception(error);
  return c;
}

TEST(SweepFolder, StagingNamesAreThoseOfTgnavTrial) {
  EXPECT_TRUE(isTrialStaging(".smoke__rrtstar-300__s01.tmp-1234"));
  EXPECT_FALSE(isTrialStaging(".smoke__rrtstar-300__s01.old-1234"));
  EXPECT_TRUE(isTrialLeftover(".smoke__rrtstar-300__s01.tmp-1234"));
  EXPECT_TRUE(isTrialLeftover(".smoke__rrtstar-300__s01.old-1234"));
  for (const char* name : {"smoke__rrtstar-300__s01", ".", ".keep", "smoke.tmp-12"}) {
    EXPECT_FALSE(isTrialStaging(name)) << name;
    EXPECT_FALSE(isTrialLeftover(name)) << name;
  }
}

TEST(SweepRunner, OptionsAreCheckedBeforeAnythingIsWritten) {
  const fs::path dir = test::tempDir();
  const SweepOptions good = smokeSweep(dir, 1);
  const std::pair<void (*)(SweepOptions*), const char*> cases[] = {
      {[](SweepOptions* o) { o->out.clear(); }, "--out: required"},
      {[](SweepOptions* o) { o->sweep.clear(); }, "--sweep: required (or --status)"},
      {[](SweepOptions* o) { o->backend = "pbs"; }, "--backend: 'pbs' is not local or slurm"},
      {[](SweepOptions* o) { o->jobs = -1; }, "--jobs: -1 must be >= 1"},
      {[](SweepOptions* o) { o->wait = true; }, "--wait: only for --backend slurm"},
      {[](SweepOptions* o) { o->sbatch_args.push_back("-p"); }, "--sbatch-arg: only for --backend slurm"},
  };
  for (const auto& [change, expect] : cases) {
    SweepOptions o = good;
    change(&o);
    EXPECT_EQ(test::inputError([&] { runSweep(o); }), expect);
  }
  EXPECT_FALSE(fs::exists(good.out));
  EXPECT_NE(test::inputError([&] { sweepStatus(dir); }).find("is not a sweep folder (no trials.csv)"),
            std::string::npos);
}

TEST(SweepRunner, LocalRunResumesReportsFailuresAndTidies) {
  const fs::path dir = test::tempDir();
  const SweepOptions opt = smokeSweep(dir, 3);
  const fs::path out = opt.out;

  // Seed 3 fails: the others are done, the failure is listed with its log's last line.
  Captured c = [&] {
    const ScopedEnv fail("FAKE_FAIL_SEED", "3");
    return capture([&] { return runSweep(opt); });
  }();
  EXPECT_EQ(c.rc, 1) << c.err;
  EXPECT_NE(c.err.find("tgnav sweep: 3 trials to run, 2 at a time -> " + out.string()), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("trial smoke__rrtstar-300__s03 failed (exit 3)"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("1 trials failed to run"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("  smoke__rrtstar-300__s03 (exit 3): boom: seed 3"), std::string::npos) << c.err;
  EXPECT_NE(c.out.find("tgnav sweep: 2 of 3 trials done (2 success); this run: 2 trials in"), std::string::npos)
      << c.out;
  EXPECT_EQ(indexIds(out), (std::vector<std::string>{"smoke__rrtstar-300__s01", "smoke__rrtstar-300__s02"}));
  EXPECT_NE(readText(out / "commands.txt").find("smoke__rrtstar-300__s03 trial --scenario"), std::string::npos);

  SweepStatus s = sweepStatus(out);
  EXPECT_EQ(s.dir, fs::path(out));
  EXPECT_EQ(s.trials, 3u);
  EXPECT_EQ(s.counts.done, 2);
  EXPECT_EQ(s.counts.absent, 1);
  EXPECT_FALSE(s.slurm.submitted);

  // A killed trial's staging folders, and a corrupted finished one: tidied, and run again.
  fs::create_directories(out / "trials" / ".smoke__rrtstar-300__s03.tmp-99999");
  fs::create_directories(out / "trials" / ".smoke__rrtstar-300__s01.old-99999");
  test::writeFile(out / "trials" / ".keep", "not a trial's\n");
  EXPECT_EQ(sweepStatus(out).running, 1u);
  test::writeFile(out / "trials" / "smoke__rrtstar-300__s02" / "metrics.json", "{\"scene\": ");
  EXPECT_EQ(sweepStatus(out).counts.corrupt, 1);
  c = capture([&] { return runSweep(opt); });
  EXPECT_EQ(c.rc, 0) << c.err;
  EXPECT_NE(c.err.find("trials/smoke__rrtstar-300__s02 is corrupted (metrics.json does not parse"), std::string::npos)
      << c.err;
  EXPECT_NE(c.err.find("resuming: 1 of 3 trials already done"), std::string::npos) << c.err;
  EXPECT_NE(c.out.find("3 of 3 trials done (3 success); this run: 2 trials in"), std::string::npos) << c.out;
  EXPECT_TRUE(fs::exists(out / "corrupt" / "smoke__rrtstar-300__s02.1" / "metrics.json"));
  EXPECT_FALSE(fs::exists(out / "trials" / ".smoke__rrtstar-300__s03.tmp-99999"));
  EXPECT_FALSE(fs::exists(out / "trials" / ".smoke__rrtstar-300__s01.old-99999"));
  EXPECT_TRUE(fs::exists(out / "trials" / ".keep"));
  EXPECT_EQ(indexIds(out).size(), 3u);
  EXPECT_EQ(readText(out / "logs" / "smoke__rrtstar-300__s01.log").find("=== ", 1), std::string::npos);  // ran once
  EXPECT_NE(readText(out / "logs" / "smoke__rrtstar-300__s03.log").find("=== ", 1), std::string::npos);

  // Nothing left: said, and nothing runs.
  c = capture([&] { return runSweep(opt); });
  EXPECT_EQ(c.rc, 0);
  EXPECT_EQ(c.out, "tgnav sweep: all 3 trials are done (3 success) -> " + out.string() + "/index.csv\n");
  EXPECT_EQ(sweepStatus(out).counts.done, 3);
  EXPECT_EQ(sweepStatus(out).running, 0u);

  // The folder holds this sweep: another one is refused.
  SweepOptions other = opt;
  other.sweep = test::writeFile(dir / "other.yaml", readText(opt.sweep) + "set: {camera.width_px: 320}\n").string();
  EXPECT_NE(test::inputError([&] {
              runSweep(other);
            }).find("holds another sweep: its commands.txt differs from " + other.sweep + "'s at line 1"),
            std::string::npos);
}

TEST(SweepRunner, TrialsRunSnapshotsOfTheirScenariosThatEditingTheConfigsDoesNotChange) {
  // A scenario whose trial settings live in a file beside it, as configs/trial.yaml does. Online
  // from no map, so that no survey map is built for it (minutes under the sanitizers).
  const fs::path dir = test::tempDir();
  fs::create_directories(dir / "cfg");
  const std::string online = "mode: online\nstate_source: vo\n";
  const fs::path trial_yaml = test::writeFile(dir / "cfg" / "mine_trial.yaml", online + "goal_radius_m: 0.4\n");
  const fs::path scenario = test::writeFile(dir / "cfg" / "mine.yaml",
                                            "scene: " + (test::sourceDir() / "configs/scenes/smoke.yaml").string() +
                                                "\nseed: 1\ntrial_config: mine_trial.yaml\n");
  SweepOptions opt = smokeSweep(dir, 3);
  opt.sweep = test::writeFile(dir / "sweep.yaml",
                              "seeds: 3\nruns:\n  - {scenario: cfg/mine.yaml, planner: rrtstar, samples: 300}\n");
  const fs::path out = opt.out;
  const fs::path snapshot = out / "scenarios" / "mine.yaml";

  Captured c = [&] {
    const ScopedEnv fail("FAKE_FAIL_SEED", "3");
    return capture([&] { return runSweep(opt); });
  }();
  EXPECT_EQ(c.rc, 1) << c.err;
  EXPECT_EQ(c.err.find("building the feature map"), std::string::npos) << c.err;
  ASSERT_TRUE(fs::exists(snapshot));
  EXPECT_EQ(readText(snapshot).rfind("# tgnav sweep: the resolved scenario of " + scenario.string() + ",", 0), 0u);
  EXPECT_DOUBLE_EQ(loadScenario(snapshot).trial.goal_radius_m, 0.4);
  const std::string commands = readText(out / "commands.txt");
  EXPECT_NE(commands.find("rrtstar-300__s03 trial --scenario " + snapshot.string() + " "), std::string::npos)
      << commands;
  EXPECT_EQ(commands.find(scenario.string()), std::string::npos) << commands;

  // The configs edited before the sweep is resumed: the trial left runs on the snapshot.
  test::writeFile(trial_yaml, online + "goal_radius_m: 0.6\n");
  const std::string held = readText(snapshot);
  c = capture([&] { return runSweep(opt); });
  EXPECT_EQ(c.rc, 0) << c.err;
  EXPECT_EQ(readText(snapshot), held);
  EXPECT_EQ(readText(out / "commands.txt"), commands);
  EXPECT_EQ(indexIds(out).size(), 3u);
  std::error_code ec;
  EXPECT_EQ(std::distance(fs::directory_iterator(out / "scenarios", ec), fs::directory_iterator()), 1);

  // A folder made before snapshots (its commands name the scenario itself) is resumed as it was.
  const fs::path old_out = dir / "old";
  fs::create_directories(old_out);
  std::string old_commands = commands;
  for (std::size_t i = old_commands.find(snapshot.string()); i != std::string::npos;
       i = old_commands.find(snapshot.string(), i)) {
    old_commands.replace(i, snapshot.string().size(), scenario.string());
  }
  test::writeFile(old_out / "commands.txt", old_commands);
  opt.out = old_out.string();
  c = capture([&] { return runSweep(opt); });
  EXPECT_EQ(c.rc, 0) << c.err;
  EXPECT_FALSE(fs::exists(old_out / "scenarios"));
  EXPECT_EQ(readText(old_out / "commands.txt"), old_commands);
}

TEST(SweepRunner, SlurmBackendSubmitsAJobArrayAndRefusesWhileItRuns) {
  const fs::path dir = test::tempDir();
  SweepOptions opt = smokeSweep(dir, 3);
  opt.backend = "slurm";
  opt.jobs = 0;
  const fs::path out = opt.out;
  const fs::path bin = dir / "bin";  // stand-ins for sbatch and squeue
  fs::create_directories(bin);
  executable(bin / "sbatch",
             "#!/bin/bash\n"
             "if [ -n \"${FAKE_SBATCH_FAIL:-}\" ]; then echo 'sbatch: error: invalid partition' >&2; exit 1; fi\n"
             "echo \"$*\" > \"$(dirname \"$0\")/sbatch.args\"; echo '4242;cluster'\n");
  executable(bin / "squeue",
             "#!/bin/bash\n"
             "if [ -n \"${FAKE_SQUEUE_FAIL:-}\" ]; then echo 'squeue: error: no controller' >&2; exit 1; fi\n"
             "cat \"$(dirname \"$0\")/queue\" 2>/dev/null; exit 0\n");
  const ScopedEnv path("PATH", bin.string() + ":" + getenv("PATH"));

  {
    const ScopedEnv fail("FAKE_SBATCH_FAIL", "1");
    const std::string refused = test::inputError([&] { capture([&] { return runSweep(opt); }); });
    EXPECT_NE(refused.find("sbatch failed (exit 1): sbatch: error: invalid partition; nothing was submitted"),
              std::string::npos)
        << refused;
  }
  EXPECT_FALSE(fs::exists(out / "slurm" / "jobs.txt") || fs::exists(out / "slurm" / "array-1.sh"));

  Captured c = capture([&] { return runSweep(opt); });
  ASSERT_EQ(c.rc, 0) << c.err;
  EXPECT_NE(c.out.find("submitted Slurm job array 4242 (3 trials, at most 3 at once)"), std::string::npos) << c.out;
  EXPECT_EQ(readText(out / "slurm" / "jobs.txt"), "4242 array-1.sh 3\n");
  const std::string args = readText(bin / "sbatch.args");
  EXPECT_EQ(args.rfind("--parsable --array=0-2%3 ", 0), 0u) << args;
  const std::string script = readText(out / "slurm" / "array-1.sh");
  EXPECT_NE(script.find("#SBATCH --job-name=tgnav-sweep-"), std::string::npos) << script;
  EXPECT_NE(script.find("  1) id=smoke__rrtstar-300__s02; args=(trial --scenario"), std::string::npos) << script;
  EXPECT_NE(script.find("--threads 1 --no-figures --force --map-cache"), std::string::npos) << script;
  EXPECT_NE(script.find(opt.program.string() + " sweep --status --out ."), std::string::npos) << script;

  SweepStatus s = sweepStatus(out);
  EXPECT_TRUE(s.slurm.submitted);
  EXPECT_TRUE(s.slurm.error.empty()) << s.slurm.error;
  EXPECT_TRUE(s.slurm.states.empty());

  test::writeFile(bin / "queue", "4242_0 RUNNING\n4242_1 PENDING\n");
  s = sweepStatus(out);
  EXPECT_EQ(s.slurm.states, (std::map<std::string, int>{{"PENDING", 1}, {"RUNNING", 1}}));
  const std::string busy = test::inputError([&] { runSweep(opt); });
  EXPECT_NE(busy.find("2 tasks of this sweep are still queued or running in Slurm (job 4242)"), std::string::npos)
      << busy;
  EXPECT_FALSE(fs::exists(out / "slurm" / "array-2.sh"));
  {
    const ScopedEnv fail("FAKE_SQUEUE_FAIL", "1");
    s = sweepStatus(out);
    EXPECT_NE(s.slurm.error.find("squeue failed (exit 1): squeue: error: no controller"), std::string::npos)
        << s.slurm.error;
  }
}

}  // namespace
}  // namespace tgnav::harness
