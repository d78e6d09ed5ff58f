// Sweep files: expansion into trials, their ids and arguments, the checks of bad sweeps, the
// manifest, and how trial folders are judged (absent, interrupted, corrupted, done) for resuming.
#include "harness/sweep.h"

#include <gtest/gtest.h>

#include <fstream>
#include <set>

#include "harness/shell.h"
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
    if (seed != 2)
      test::writeFile(f / "metrics.json", metricsJson(seed == 3 ? "vo_lost" : "success", seed == 3 ? "null" : "0.05",
                                                      std::to_string(seed)));
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

}  // namespace
}  // namespace tgnav::harness
