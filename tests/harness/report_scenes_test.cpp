// `tgnav report`, the generalisation benchmark, on a synthetic sweep folder: flyable classes from
// the oracle trials (>= 2/3 VO success, grouped by scene and class whatever the planner), per-scene
// planner rows, selection accuracy over the scenes with a flyable class (n/a without), the
// predicted-flyable calibration from plan.json, and what runReport writes (scenes.csv only for
// several scenes or oracle trials, aggregate.csv always, both sections in table2.md).
#include "harness/experiments/report_scenes.h"

#include <gtest/gtest.h>

#include <sstream>

#include "harness/base/files.h"
#include "harness/experiments/report_run.h"
#include "harness/experiments/report_trial.h"
#include "test_util.h"

namespace tgnav::harness {
namespace {

namespace fs = std::filesystem;
using test::tempDir;
using test::writeFile;

struct Trial {
  std::string id;
  std::string scene;
  std::string planner = "proposed";
  int samples = 0;
  int seed = 1;
  std::string status = "success";
  int oracle = -1;       // -1: the planner chose
  int chosen = -1;       // metrics.json chosen_class; -1: null
  double c_p_min = 0.0;  // plan.json classes[chosen].c_p_min
  std::string goal = "0.1";
  bool plan_json = true;
};

std::string params(const Trial& t) { return t.oracle >= 0 ? "planner.oracle_class=" + std::to_string(t.oracle) : ""; }

// index.csv, trials.csv (with `unfinished` more) and per trial metrics.json and plan.json
// (c_p_threshold 5; RRT*'s plan.json lists its one path as class 0, as the planner writes it).
fs::path makeSweep(const fs::path& dir, const std::vector<Trial>& trials, int unfinished = 0) {
  std::string index =
      "id,scene,planner,samples,seed,params,status,path_length_m,planned_length_m,goal_error_m,"
      "final_distance_to_goal_m,ate_rmse_m,plan_time_s,wall_time_s,sim_time_s,vo_lost_at_s,distance_tracked_m,"
      "folder\n";
  std::string manifest = "id,scenario,scene,planner,samples,seed,params\n";
  for (const Trial& t : trials) {
    const std::string goal = t.status == "success" ? t.goal : "";
    index += t.id + "," + t.scene + "," + t.planner + "," + std::to_string(t.samples) + "," + std::to_string(t.seed) +
             "," + params(t) + "," + t.status + ",10,9," + goal + ",0.01,0.05,1,5,20,,8,trials/" + t.id + "\n";
    manifest += t.id + ",s.yaml," + t.scene + "," + t.planner + "," + std::to_string(t.samples) + "," +
                std::to_string(t.seed) + "," + params(t) + "\n";
    const fs::path folder = dir / "trials" / t.id;
    fs::create_directories(folder);
    const std::string chosen = t.chosen >= 0 ? std::to_string(t.chosen) : "null";
    writeFile(folder / "metrics.json", "{\"oracle_class\": " + (t.oracle >= 0 ? std::to_string(t.oracle) : "null") +
                                           ", \"chosen_class\": " + chosen + ", \"classes\": 3, \"c_p_min\": -99}");
    if (!t.plan_json) continue;
    const int in_plan = t.planner == "rrtstar" ? 0 : t.chosen;
    std::string classes;
    for (int k = 0; k <= std::max(in_plan, 0); ++k) {
      classes += std::string(k ? "," : "") + "{\"c_p_min\": " + (k == in_plan ? std::to_string(t.c_p_min) : "0") + "}";
    }
    writeFile(folder / "plan.json", "{\"c_p_threshold\": 5, \"classes\": [" + classes + "], \"chosen_class\": " +
                                        (t.chosen >= 0 ? std::to_string(in_plan) : "null") + "}");
  }
  for (int i = 0; i < unfinished; ++i) manifest += "later" + std::to_string(i) + ",s.yaml,alpha,proposed,0,9,\n";
  writeFile(dir / "index.csv", index);
  writeFile(dir / "trials.csv", manifest);
  return dir;
}

Trial oracle(const std::string& scene, int k, int seed, bool success, const std::string& planner = "proposed") {
  Trial t;
  t.id = scene + "_o" + std::to_string(k) + "_" + planner + "_s" + std::to_string(seed);
  t.scene = scene;
  t.planner = planner;
  t.seed = seed;
  t.oracle = k;
  t.chosen = k;
  t.c_p_min = k == 0 ? 8.0 : 2.0;  // class 0 predicted flyable, the others not
  t.status = success ? "success" : "vo_lost";
  return t;
}

Trial chose(const std::string& id, const std::string& scene, const std::string& planner, int chosen, double c_p_min,
            const std::string& status) {
  Trial t;
  t.id = id;
  t.scene = scene;
  t.planner = planner;
  t.samples = planner == "rrtstar" ? 300 : 0;
  t.chosen = chosen;
  t.c_p_min = c_p_min;
  t.status = status;
  return t;
}

// alpha: classes 0 (3/3) and 2 (2/3, oracle trials of two planners) flyable, 1 (1/3) not.
// beta: oracle trials, none flyable (1/3, 0/2). gamma: no oracle trials.
std::vector<Trial> benchmark() {
  std::vector<Trial> t = {
      oracle("alpha", 0, 1, true),
      oracle("alpha", 0, 2, true),
      oracle("alpha", 0, 3, true),
      oracle("alpha", 1, 1, false),
      oracle("alpha", 1, 2, true),
      oracle("alpha", 1, 3, false),
      oracle("alpha", 2, 1, true),
      oracle("alpha", 2, 2, false, "agnostic"),
      oracle("alpha", 2, 3, true, "agnostic"),
      oracle("beta", 0, 1, true),
      oracle("beta", 0, 2, false),
      oracle("beta", 0, 3, false),
      oracle("beta", 1, 1, false),
      oracle("beta", 1, 2, false),
  };
  t.push_back(chose("a_p1", "alpha", "proposed", 0, 8.0, "success"));
  t.push_back(chose("a_p2", "alpha", "proposed", 2, 6.0, "success"));
  t.push_back(chose("a_p3", "alpha", "proposed", 1, 2.0, "vo_lost"));
  t.push_back(chose("a_a1", "alpha", "agnostic", 1, 2.0, "vo_lost"));
  t.push_back(chose("a_a2", "alpha", "agnostic", 1, 5.0, "success"));  // c_p_min = threshold: predicted flyable
  t.push_back(chose("a_r1", "alpha", "rrtstar", 2, 9.0, "collision"));
  t.push_back(chose("a_r2", "alpha", "rrtstar", -1, 0.0, "plan_failed"));
  t.back().plan_json = false;
  t.push_back(chose("b_p1", "beta", "proposed", 0, 7.0, "vo_lost"));
  t.push_back(chose("c_p1", "gamma", "proposed", 0, 7.0, "success"));
  t.back().goal = "0.3";
  return t;
}

TEST(ReportScenes, FlyableIsTwoThirdsOfTheOracleTrials) {
  EXPECT_TRUE(isFlyable(2, 3));
  EXPECT_TRUE(isFlyable(3, 3));
  EXPECT_FALSE(isFlyable(1, 3));
  EXPECT_TRUE(isFlyable(4, 6));
  EXPECT_FALSE(isFlyable(3, 5));
  EXPECT_TRUE(isFlyable(1, 1));
  EXPECT_FALSE(isFlyable(0, 0));
  EXPECT_EQ(formatShare(2, 3), "2/3 (67%; 21–94%)");  // Wilson: scipy binomtest(2, 3).proportion_ci(method="wilson")
  EXPECT_EQ(formatShare(0, 0), "n/a");
}

TEST(ReportScenes, TrialFilesGiveClassesAndThePlansScore) {
  const fs::path dir = makeSweep(tempDir(), benchmark());
  const SweepIndex sweep = readSweep(dir);
  const IndexRow& o = sweep.rows[8];  // alpha, oracle class 2, agnostic
  EXPECT_EQ(o.oracle_class, 2);
  EXPECT_EQ(o.chosen_class, 2);
  EXPECT_EQ(o.classes, 3);
  EXPECT_EQ(o.c_p_threshold, 5.0);
  EXPECT_EQ(o.chosen_c_p_min, 2.0);    // plan.json's, not metrics.json's -99
  const IndexRow& r = sweep.rows[19];  // RRT*: plan.json's chosen_class is its one path
  EXPECT_EQ(r.id, "a_r1");
  EXPECT_FALSE(r.oracle_class);
  EXPECT_EQ(r.chosen_class, 2);
  EXPECT_EQ(r.chosen_c_p_min, 9.0);
  const IndexRow& failed = sweep.rows[20];  // no plan.json: metrics.json's score, no threshold
  EXPECT_FALSE(failed.chosen_class);
  EXPECT_EQ(failed.chosen_c_p_min, -99.0);
  EXPECT_FALSE(failed.c_p_threshold);
  EXPECT_EQ(trialMinInliers(dir / "trials/a_p1"), std::nullopt);  // no config.yaml
  writeFile(dir / "trials/a_p1/config.yaml", "vo:\n  min_inliers: 25\n");
  EXPECT_EQ(trialMinInliers(dir / "trials/a_p1"), 25);
  writeFile(dir / "trials/a_p1/config.yaml", "seed: 1\n");
  EXPECT_EQ(trialMinInliers(dir / "trials/a_p1"), 30);  // the VO's default
  writeFile(dir / "trials/a_p1/vo.csv", "t,status,inliers,predicted_score,predicted_landmarks,reason\n");
  EXPECT_TRUE(voCsvHasColumn(dir / "trials/a_p1", "predicted_score"));
  EXPECT_FALSE(voCsvHasColumn(dir / "trials/a_p1", "predicted"));
  EXPECT_FALSE(voCsvHasColumn(dir / "trials/a_p2", "predicted_score"));
}

TEST(ReportScenes, PerSceneFlyableClassesAndPlannerRows) {
  const SweepIndex sweep = readSweep(makeSweep(tempDir(), benchmark()));
  const std::vector<SceneReport> scenes = sceneReports(sweep.rows);
  ASSERT_EQ(scenes.size(), 3u);
  const SceneReport& alpha = scenes[0];
  EXPECT_EQ(alpha.scene, "alpha");
  EXPECT_EQ(alpha.classes, 3);
  ASSERT_EQ(alpha.oracle.size(), 3u);
  EXPECT_EQ(alpha.oracle[2].trials, 3);  // proposed's and agnostic's oracle trials together
  EXPECT_EQ(alpha.oracle[2].successes, 2);
  EXPECT_EQ(alpha.oracle[1].successes, 1);
  EXPECT_EQ(alpha.flyableClasses(), (std::vector<int>{0, 2}));
  EXPECT_EQ(alpha.oracle[0].c_p_min, 8.0);
  ASSERT_EQ(alpha.planners.size(), 3u);
  EXPECT_EQ(alpha.planners[0].label, "Proposed");
  EXPECT_EQ(alpha.planners[0].trials, 3);
  EXPECT_EQ(alpha.planners[0].successes, 2);
  EXPECT_EQ(alpha.planners[0].chose_flyable, 2);
  EXPECT_EQ(alpha.planners[0].goal_error_median_m, 0.1);
  EXPECT_EQ(alpha.planners[1].chose_flyable, 0);
  EXPECT_EQ(alpha.planners[2].label, "R-300");
  EXPECT_EQ(alpha.planners[2].chose_flyable, 1);  // class 2; the failed plan chose none
  EXPECT_FALSE(alpha.planners[2].goal_error_median_m);
  EXPECT_TRUE(scenes[1].flyableClasses().empty());
  EXPECT_EQ(scenes[1].oracle.size(), 2u);
  EXPECT_TRUE(scenes[2].oracle.empty());
  EXPECT_EQ(scenes[2].planners[0].goal_error_median_m, 0.3);
  EXPECT_TRUE(wantsSceneTable(sweep.rows));
}

TEST(ReportScenes, SelectionAccuracyOverScenesWithAFlyableClass) {
  const SweepIndex sweep = readSweep(makeSweep(tempDir(), benchmark()));
  const std::vector<AggregateRow> rows = aggregateRows(sweep.rows, sceneReports(sweep.rows));
  ASSERT_EQ(rows.size(), 4u);
  const AggregateRow& p = rows[0];
  EXPECT_EQ(p.label, "Proposed");
  EXPECT_EQ(p.trials, 5);  // not its oracle trials
  EXPECT_EQ(p.scenes, 3);
  EXPECT_EQ(p.covered_scenes, 1);  // alpha only
  EXPECT_EQ(p.covered_trials, 3);
  EXPECT_EQ(p.covered_successes, 2);
  EXPECT_EQ(p.chose_flyable, 2);      // selection accuracy 2/3
  EXPECT_EQ(p.predicted_flyable, 4);  // c_p_min 8, 6, 7, 7 >= 5
  EXPECT_EQ(p.predicted_successes, 3);
  const AggregateRow& a = rows[1];
  EXPECT_EQ(a.label, "AP");
  EXPECT_EQ(a.chose_flyable, 0);
  EXPECT_EQ(a.covered_trials, 2);
  EXPECT_EQ(a.predicted_flyable, 1);  // at the threshold
  EXPECT_EQ(a.predicted_successes, 1);
  const AggregateRow& r = rows[2];
  EXPECT_EQ(r.label, "R-300");
  EXPECT_EQ(r.chose_flyable, 1);
  EXPECT_EQ(r.covered_trials, 2);
  EXPECT_EQ(r.predicted_flyable, 1);
  EXPECT_EQ(r.predicted_successes, 0);
  const AggregateRow& o = rows[3];
  EXPECT_TRUE(o.oracle);
  EXPECT_EQ(o.trials, 14);
  EXPECT_EQ(o.predicted_flyable, 6);  // the class-0 trials
  EXPECT_EQ(o.predicted_successes, 4);

  const std::string csv = aggregateCsv(rows);
  EXPECT_NE(csv.find("\nProposed,proposed,0,,5,3,1,3,2,0.6666666667,2,0.6666666667,4,3,0.75\n"), std::string::npos)
      << csv;
  EXPECT_NE(csv.find("\nOracle,oracle,0,,14,,,,,,,,6,4,0.6666666667\n"), std::string::npos) << csv;
}

TEST(ReportScenes, WithoutOracleTrialsSelectionIsNotApplicable) {
  std::vector<Trial> trials = {chose("p1", "alpha", "proposed", 0, 8.0, "success"),
                               chose("p2", "alpha", "proposed", 1, 1.0, "vo_lost")};
  const SweepIndex sweep = readSweep(makeSweep(tempDir(), trials));
  EXPECT_FALSE(wantsSceneTable(sweep.rows));
  const auto scenes = sceneReports(sweep.rows);
  const auto rows = aggregateRows(sweep.rows, scenes);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].covered_trials, 0);
  EXPECT_EQ(rows[0].predicted_flyable, 1);
  const std::string md = generalisationMarkdown(scenes, rows, false);
  EXPECT_EQ(md.find("## Per scene"), std::string::npos);
  EXPECT_NE(md.find("| Proposed |      2 |                      0 of 1 |              n/a |                n/a |"
                    "           1/1 (100%; 21–100%) |"),
            std::string::npos)
      << md;
}

TEST(ReportScenes, RunReportWritesTheTablesAndTheMarkdownSections) {
  const fs::path dir = makeSweep(tempDir(), benchmark(), 2);
  ReportJob job;
  job.dir = dir;
  job.no_plots = true;
  const ReportRunResult r = runReport(job);
  EXPECT_TRUE(fs::exists(dir / "report/scenes.csv"));
  EXPECT_TRUE(fs::exists(dir / "report/aggregate.csv"));
  const std::string md = readTextFile(dir / "report/table2.md");
  EXPECT_EQ(md, r.markdown);
  EXPECT_NE(md.find("23 of 25 trials finished."), std::string::npos) << md;
  EXPECT_NE(md.find("## Per scene"), std::string::npos);
  EXPECT_NE(md.find("| *alpha* |       3 |                           3 |             9 | 0, 2    |"), std::string::npos)
      << md;
  EXPECT_NE(md.find("| *beta*  |       3 |                           2 |             5 | none    |"),
            std::string::npos);
  EXPECT_NE(md.find("| *gamma* |       3 |                           0 |             0 | n/a     |"),
            std::string::npos);
  EXPECT_NE(md.find("|         |     2 |        2/3 |    2.00 | no                | yes     |"), std::string::npos)
      << md;
  EXPECT_NE(md.find("| Proposed             |      5 |                      1 of 3 | 2/3 (67%; 21–94%) |"
                    "  2/3 (67%; 21–94%) |             3/4 (75%; 30–95%) |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("1 of 3 scene(s) have a flyable class"), std::string::npos);
  const std::string scenes = readTextFile(dir / "report/scenes.csv");
  EXPECT_NE(scenes.find("\nalpha,oracle,Oracle 2,,0,,2,3,2,0.6666666667,,,1,2,5,3,3,0;2\n"), std::string::npos)
      << scenes;
  EXPECT_NE(scenes.find("\nalpha,planner,R-300,rrtstar,300,,,2,0,0,,1,,,,3,3,0;2\n"), std::string::npos) << scenes;
  EXPECT_NE(scenes.find("\ngamma,planner,Proposed,proposed,0,,,1,1,1,0.3,,,,,3,0,\n"), std::string::npos) << scenes;
}

}  // namespace
}  // namespace tgnav::harness
