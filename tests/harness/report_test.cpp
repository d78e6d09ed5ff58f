// `tgnav report`: the aggregation of a sweep's index.csv into Table II (groups in order of first
// appearance, mean ± sample std, goal error over successful trials only, k/n, the paper's
// planner names), its CSV and Markdown forms, the refusal of bad input with file:line and column,
// and the command end to end: nothing written on bad input, tables kept when the plots fail, and
// (where matplotlib is installed) the figures.
#include "harness/experiments/report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "test_util.h"

namespace tgnav::harness {
namespace {

namespace fs = std::filesystem;
using test::inputError;
using test::tempDir;
using test::writeFile;

const char* kHeader =
    "id,scene,planner,samples,seed,params,status,path_length_m,planned_length_m,goal_error_m,"
    "final_distance_to_goal_m,ate_rmse_m,plan_time_s,wall_time_s,sim_time_s,vo_lost_at_s,distance_tracked_m,folder";

// One index.csv row; numbers as text so that tests can write empty or malformed cells.
struct Row {
  std::string id;
  std::string scene = "storage";
  std::string planner = "proposed";
  std::string samples = "0";
  std::string seed = "1";
  std::string params;
  std::string status = "success";
  std::string length = "10";
  std::string goal = "0.1";
  std::string ate = "0.05";
  std::string plan = "1";
  std::string lost_at;
  std::string metrics = "{}";  // the stub folder's metrics.json
};

std::string csvRow(const Row& r) {
  return r.id + "," + r.scene + "," + r.planner + "," + r.samples + "," + r.seed + "," + r.params + "," + r.status +
         "," + r.length + ",9," + r.goal + ",0.01," + r.ate + "," + r.plan + ",5,20," + r.lost_at + ",8,trials/" + r.id;
}

// A sweep folder: index.csv of `rows` (plus `extra` lines appended verbatim), stub trial folders
// with their metrics.json, and trials.csv listing the rows and `unfinished` more trials.
fs::path makeSweep(const fs::path& dir, const std::vector<Row>& rows, int unfinished = 0,
                   const std::string& extra = "") {
  std::string index = std::string(kHeader) + "\n";
  std::string manifest = "id,scenario,scene,planner,samples,seed,params\n";
  for (const Row& r : rows) {
    index += csvRow(r) + "\n";
    manifest += r.id + ",s.yaml," + r.scene + "," + r.planner + "," + r.samples + "," + r.seed + "," + r.params + "\n";
    fs::create_directories(dir / "trials" / r.id);
    writeFile(dir / "trials" / r.id / "metrics.json", r.metrics);
  }
  for (int i = 0; i < unfinished; ++i) manifest += "later" + std::to_string(i) + ",s.yaml,storage,proposed,0,9,\n";
  writeFile(dir / "index.csv", index + extra);
  writeFile(dir / "trials.csv", manifest);
  return dir;
}

Row row(const std::string& id) {
  Row r;
  r.id = id;
  return r;
}

// ---------------------------------------------------------------------------------------------
// Statistics and formatting

TEST(ReportStats, MeanAndSampleStandardDeviation) {
  const auto s = summarise({1.0, 2.0, 3.0, 4.0});
  ASSERT_TRUE(s);
  EXPECT_EQ(s->n, 4);
  EXPECT_DOUBLE_EQ(s->mean, 2.5);
  EXPECT_DOUBLE_EQ(s->std, std::sqrt(5.0 / 3.0));  // n - 1 in the denominator
  const auto one = summarise({7.5});
  ASSERT_TRUE(one);
  EXPECT_DOUBLE_EQ(one->mean, 7.5);
  EXPECT_DOUBLE_EQ(one->std, 0.0);
  EXPECT_FALSE(summarise({}));
}

TEST(ReportFormat, ThreeSignificantFiguresAsThePaper) {
  EXPECT_EQ(formatSig3(15.94), "15.9");
  EXPECT_EQ(formatSig3(0.1183), "0.118");
  EXPECT_EQ(formatSig3(9.856), "9.86");
  EXPECT_EQ(formatSig3(1.58), "1.58");
  EXPECT_EQ(formatSig3(0.08349), "0.0835");
  EXPECT_EQ(formatSig3(164.1), "164");
  EXPECT_EQ(formatSig3(12345.6), "12346");
  EXPECT_EQ(formatSig3(9.996), "10.0");  // rounding carries into a new digit
  EXPECT_EQ(formatSig3(0.0), "0");
  EXPECT_EQ(formatSig3(-2.345), "-2.35");
}

TEST(ReportFormat, SummaryShowsStdToTheMeansDecimalsAndOnlyTheMeanForOneTrial) {
  EXPECT_EQ(formatSummary(Summary{10, 15.94, 0.42}), "15.9 ± 0.4");
  EXPECT_EQ(formatSummary(Summary{3, 0.1183, 0.0216}), "0.118 ± 0.022");
  EXPECT_EQ(formatSummary(Summary{1, 0.1183, 0.0}), "0.118");
  EXPECT_EQ(formatSummary(std::nullopt), "–");
  EXPECT_EQ(formatOutcomes({{"success", 8}, {"vo_lost", 2}}), "8 success, 2 vo_lost");
}

TEST(ReportLabels, PaperPlannerNamesWithParamsInBrackets) {
  EXPECT_EQ(plannerLabel("proposed", 0, ""), "Proposed");
  EXPECT_EQ(plannerLabel("agnostic", 0, ""), "AP");
  EXPECT_EQ(plannerLabel("rrtstar", 2000, ""), "R-2000");
  EXPECT_EQ(plannerLabel("rrtstar", 300, "w_p=2;k=1"), "R-300 [w_p=2;k=1]");
}

// ---------------------------------------------------------------------------------------------
// Aggregation

TEST(ReportAggregation, GroupsInOrderOfFirstAppearanceWithExactStatistics) {
  const fs::path dir = tempDir();
  std::vector<Row> rows;
  // storage: proposed, R-300, agnostic interleaved; then gallery; a params group.
  Row p1 = row("p1"), r1 = row("r1"), p2 = row("p2"), a1 = row("a1"), r2 = row("r2"), g1 = row("g1"), w1 = row("w1");
  r1.planner = r2.planner = "rrtstar";
  r1.samples = r2.samples = "300";
  a1.planner = "agnostic";
  g1.scene = "gallery";
  w1.params = "w_p=2";
  p1.length = "15";
  p1.goal = "0.1";
  p1.plan = "1.5";
  p1.ate = "0.02";
  p2.length = "17";
  p2.goal = "0.3";
  p2.plan = "2.5";
  p2.ate = "0.04";
  // R-300: one success, one collision whose VO tracked to the end (a goal error that must not
  // count), one plan failure (no flight: no length, no ATE; its plan time counts).
  r1.goal = "0.2";
  r2.status = "collision";
  r2.goal = "5.0";
  r2.length = "3";
  Row r3 = row("r3");
  r3.planner = "rrtstar";
  r3.samples = "300";
  r3.status = "plan_failed";
  r3.length = "0";
  r3.goal = "";
  r3.ate = "0";
  r3.plan = "4";
  r3.metrics = R"({"vo_ok": 0, "vo_weak": 0})";
  // agnostic: VO lost, goal error empty.
  a1.status = "vo_lost";
  a1.goal = "";
  a1.lost_at = "7.5";
  a1.metrics = R"({"vo_ok": 100, "vo_weak": 3, "vo_lost_position": [1.0, 2.0, 1.0]})";
  rows = {p1, r1, p2, a1, r2, g1, w1, r3};
  const SweepIndex sweep = readSweep(makeSweep(dir, rows, 2));
  ASSERT_EQ(sweep.rows.size(), 8u);
  ASSERT_TRUE(sweep.manifest_trials);
  EXPECT_EQ(*sweep.manifest_trials, 10);
  EXPECT_EQ(sweep.rows[0].folder, fs::absolute(dir / "trials/p1").lexically_normal());
  ASSERT_TRUE(sweep.rows[3].vo_lost_position);
  EXPECT_EQ((*sweep.rows[3].vo_lost_position)[1], 2.0);
  EXPECT_EQ(sweep.rows[3].vo_lost_at_s, 7.5);
  EXPECT_FALSE(sweep.rows[3].goal_error_m);

  const auto groups = groupTrials(sweep.rows);
  ASSERT_EQ(groups.size(), 5u);
  EXPECT_EQ(groups[0].label, "Proposed");
  EXPECT_EQ(groups[1].label, "R-300");
  EXPECT_EQ(groups[2].label, "AP");
  EXPECT_EQ(groups[3].label, "Proposed");
  EXPECT_EQ(groups[3].scene, "gallery");
  EXPECT_EQ(groups[4].label, "Proposed [w_p=2]");
  EXPECT_EQ(groups[0].trials, (std::vector<std::size_t>{0, 2}));
  EXPECT_EQ(groups[1].trials, (std::vector<std::size_t>{1, 4, 7}));

  const auto table = tableRows(groups, sweep.rows);
  const TableRow& prop = table[0];
  EXPECT_EQ(prop.trials, 2);
  EXPECT_EQ(prop.successes, 2);
  ASSERT_TRUE(prop.length_m && prop.goal_error_m && prop.plan_time_s && prop.ate_rmse_m);
  EXPECT_DOUBLE_EQ(prop.length_m->mean, 16.0);
  EXPECT_DOUBLE_EQ(prop.length_m->std, std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(prop.goal_error_m->mean, 0.2);
  EXPECT_DOUBLE_EQ(prop.goal_error_m->std, std::sqrt(0.02));
  EXPECT_DOUBLE_EQ(prop.plan_time_s->mean, 2.0);
  EXPECT_DOUBLE_EQ(prop.ate_rmse_m->mean, 0.03);

  const TableRow& rrt = table[1];
  EXPECT_EQ(rrt.trials, 3);
  EXPECT_EQ(rrt.successes, 1);
  ASSERT_TRUE(rrt.goal_error_m);
  EXPECT_EQ(rrt.goal_error_m->n, 1);  // the collision's goal error is left out
  EXPECT_DOUBLE_EQ(rrt.goal_error_m->mean, 0.2);
  ASSERT_TRUE(rrt.length_m);
  EXPECT_EQ(rrt.length_m->n, 2);  // the plan failure did not fly
  EXPECT_DOUBLE_EQ(rrt.length_m->mean, 6.5);
  EXPECT_EQ(rrt.plan_time_s->n, 3);
  EXPECT_DOUBLE_EQ(rrt.plan_time_s->mean, 2.0);
  EXPECT_EQ(rrt.ate_rmse_m->n, 2);
  EXPECT_EQ(formatOutcomes(rrt.outcomes), "1 success, 1 collision, 1 plan_failed");

  const TableRow& ap = table[2];
  EXPECT_EQ(ap.successes, 0);
  EXPECT_FALSE(ap.goal_error_m);
  EXPECT_EQ(ap.ate_rmse_m->n, 1);
  EXPECT_EQ(formatOutcomes(ap.outcomes), "1 vo_lost");
}

TEST(ReportAggregation, MarkdownLayoutFollowsTableTwo) {
  const fs::path dir = tempDir();
  Row p1 = row("p1"), p2 = row("p2"), a1 = row("a1"), g1 = row("g1");
  p1.length = "15.9";
  p2.length = "16.1";
  p1.goal = "0.1";
  p2.goal = "0.136";
  p1.plan = "1.5";
  p2.plan = "1.7";
  p1.ate = "0.02";
  p2.ate = "0.04";
  a1.planner = "agnostic";
  a1.status = "vo_lost";
  a1.goal = "";
  g1.scene = "gallery";
  g1.planner = "rrtstar";
  g1.samples = "15000";
  g1.plan = "164.1";
  const SweepIndex sweep = readSweep(makeSweep(dir, {p1, p2, a1, g1}, 1));
  const auto table = tableRows(groupTrials(sweep.rows), sweep.rows);
  const std::string md = table2Markdown(table, 4, sweep.manifest_trials, "paper");

  std::vector<std::string> lines;
  std::istringstream in(md);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  ASSERT_EQ(lines.size(), 11u) << md;
  EXPECT_EQ(lines[0], "# Table II: paper");
  EXPECT_EQ(lines[2], "4 of 5 trials finished.");
  // Header, alignment row, one row per group, the scene named once per block.
  EXPECT_EQ(lines[4],
            "| Scene     | Planner  | Trials | Length (m) | Goal error (m)* |    VO success | Drifted | Plan time (s) |"
            "    ATE RMSE (m) | Outcomes  |");
  EXPECT_EQ(lines[5],
            "| --------- | -------- | -----: | ---------: | --------------: | ------------: | ------: | ------------: |"
            " --------------: | --------- |");
  EXPECT_EQ(lines[6],
            "| *storage* | Proposed |      2 | 16.0 ± 0.1 |   0.118 ± 0.025 | 2/2 (34–100%) |     0/2 |   1.60 ± 0.14 |"
            " 0.0300 ± 0.0141 | 2 success |");
  // One trial: the mean alone, to 3 significant figures; no goal error without a success. VO
  // success with its 95 % Wilson interval (scipy: 2/2 0.342-1, 0/1 0-0.793, 1/1 0.207-1).
  EXPECT_EQ(lines[7],
            "|           | AP       |      1 |       10.0 |               – |   0/1 (0–79%) |     0/1 |          1.00 |"
            "          0.0500 | 1 vo_lost |");
  EXPECT_EQ(lines[8],
            "| *gallery* | R-15000  |      1 |       10.0 |           0.100 | 1/1 (21–100%) |     0/1 |           164 |"
            "          0.0500 | 1 success |");
  EXPECT_NE(lines[10].find("over the trials whose VO tracked to the goal (success and drifted"), std::string::npos);
}

// A drifted trial is not a success, is counted in its own column, and its goal error counts:
// leaving it out would flatter the group's goal error.
TEST(ReportAggregation, DriftedTrialsAreCountedApartAndInTheGoalError) {
  const fs::path dir = tempDir();
  Row p1 = row("p1"), p2 = row("p2");
  p1.goal = "0.1";
  p2.goal = "0.5";
  p2.status = "drifted";
  const SweepIndex sweep = readSweep(makeSweep(dir, {p1, p2}));
  const auto table = tableRows(groupTrials(sweep.rows), sweep.rows);
  ASSERT_EQ(table.size(), 1u);
  EXPECT_EQ(table[0].successes, 1);
  EXPECT_EQ(table[0].drifted, 1);
  ASSERT_TRUE(table[0].goal_error_m);
  EXPECT_EQ(table[0].goal_error_m->n, 2);
  EXPECT_DOUBLE_EQ(table[0].goal_error_m->mean, 0.3);
  EXPECT_EQ(formatOutcomes(table[0].outcomes), "1 success, 1 drifted");
}

TEST(ReportAggregation, CsvHasRawNumbersInSeparateColumns) {
  const fs::path dir = tempDir();
  Row p1 = row("p1"), p2 = row("p2");
  p1.length = "1";
  p2.length = "2";
  p2.status = "timeout";
  const SweepIndex sweep = readSweep(makeSweep(dir, {p1, p2}));
  const std::string csv = table2Csv(tableRows(groupTrials(sweep.rows), sweep.rows));
  std::istringstream in(csv);
  std::string header, line, rest;
  std::getline(in, header);
  std::getline(in, line);
  EXPECT_FALSE(std::getline(in, rest));
  EXPECT_EQ(header,
            "scene,planner,samples,params,label,trials,successes,vo_success_rate,length_n,length_mean_m,length_std_m,"
            "goal_error_n,goal_error_mean_m,goal_error_std_m,plan_time_n,plan_time_mean_s,plan_time_std_s,ate_n,"
            "ate_rmse_mean_m,ate_rmse_std_m,success,drifted,vo_lost,collision,diverged,timeout,plan_failed,no_path");
  EXPECT_EQ(line, "storage,proposed,0,,Proposed,2,1,0.5,2,1.5,0.7071067812,1,0.1,0,2,1,0,2,0.05,0,1,0,0,0,0,1,0,0");
}

// ---------------------------------------------------------------------------------------------
// Bad input: one line naming the file, the line and the column or value

TEST(ReportBadInput, MissingFolderOrIndex) {
  const fs::path dir = tempDir();
  EXPECT_NE(inputError([&] { readSweep(dir / "nope"); }).find("nope: no such directory"), std::string::npos);
  EXPECT_NE(inputError([&] { readSweep(dir); }).find("is not a sweep folder: no index.csv"), std::string::npos);
  writeFile(dir / "index.csv", std::string(kHeader) + "\n");
  EXPECT_NE(inputError([&] { readSweep(dir); }).find("index.csv: no finished trials yet"), std::string::npos);
}

TEST(ReportBadInput, HeaderMismatchNamesTheColumn) {
  const fs::path dir = tempDir();
  std::string header = kHeader;
  header.replace(header.find("planner"), 7, "planer");
  writeFile(dir / "index.csv", header + "\n" + csvRow(row("a")) + "\n");
  const std::string e = inputError([&] { readSweep(dir); });
  EXPECT_NE(e.find("index.csv:1: header column 3 is 'planer', expected 'planner'"), std::string::npos) << e;
}

// The message of readSweep on a sweep whose second row is `bad` (the first is fine).
std::string errorWithRow(const fs::path& dir, const Row& bad, const std::string& extra = "") {
  makeSweep(dir, {row("ok"), bad}, 0, extra);
  return inputError([&] { readSweep(dir); });
}

TEST(ReportBadInput, RowErrorsNameFileLineAndColumn) {
  const fs::path dir = tempDir();
  Row r = row("b");
  r.plan = "1.2s";
  EXPECT_NE(errorWithRow(dir, r).find("index.csv:3: column plan_time_s: '1.2s' is not a number"), std::string::npos);
  r = row("b");
  r.length = "nan";
  EXPECT_NE(errorWithRow(dir, r).find("index.csv:3: column path_length_m: 'nan' is not a number"), std::string::npos);
  r = row("b");
  r.status = "crashed";
  EXPECT_NE(errorWithRow(dir, r).find("index.csv:3: column status: 'crashed' is not one of success, drifted, vo_lost"),
            std::string::npos);
  r = row("b");
  r.planner = "a*star";
  EXPECT_NE(errorWithRow(dir, r).find("index.csv:3: column planner: 'a*star' is not one of proposed, agnostic, "
                                      "rrtstar nor an external planner's name"),
            std::string::npos);
  r = row("b");
  r.samples = "-3";
  EXPECT_NE(errorWithRow(dir, r).find("index.csv:3: column samples: '-3' is not an integer"), std::string::npos);
  r = row("b");
  r.seed = "";
  EXPECT_NE(errorWithRow(dir, r).find("index.csv:3: column seed: is empty"), std::string::npos);
  fs::remove_all(dir / "trials");
  EXPECT_NE(errorWithRow(dir, row("b"), "x,storage,proposed\n").find("index.csv:4: 3 fields, expected 18"),
            std::string::npos);
}

TEST(ReportBadInput, MissingTrialFolderOrMetrics) {
  const fs::path dir = tempDir();
  makeSweep(dir, {row("a"), row("b")});
  fs::remove(dir / "trials/b/metrics.json");
  std::string e = inputError([&] { readSweep(dir); });
  EXPECT_NE(e.find("index.csv:3: trial b: trials/b/metrics.json is missing"), std::string::npos) << e;
  fs::remove_all(dir / "trials/b");
  e = inputError([&] { readSweep(dir); });
  EXPECT_NE(e.find("index.csv:3: trial b: trials/b is missing"), std::string::npos) << e;
  writeFile(dir / "trials/a/metrics.json", "{\"status\": ");
  e = inputError([&] { readSweep(dir); });
  EXPECT_NE(e.find("trials/a/metrics.json: not valid JSON"), std::string::npos) << e;
}

TEST(ReportBadInput, DuplicateOrUnlistedTrial) {
  const fs::path dir = tempDir();
  makeSweep(dir, {row("a"), row("b")}, 0, csvRow(row("a")) + "\n");
  std::string e = inputError([&] { readSweep(dir); });
  EXPECT_NE(e.find("index.csv:4: column id: trial 'a' is already on line 2"), std::string::npos) << e;
  makeSweep(dir, {row("a"), row("b")});
  writeFile(dir / "trials.csv", "id,scenario,scene,planner,samples,seed,params\na,s.yaml,storage,proposed,0,1,\n");
  e = inputError([&] { readSweep(dir); });
  EXPECT_NE(e.find("index.csv:3: column id: trial 'b' is not in"), std::string::npos) << e;
  writeFile(dir / "trials.csv", "id,scene\n");
  e = inputError([&] { readSweep(dir); });
  EXPECT_NE(e.find("trials.csv:1: header column 2 is 'scene', expected 'scenario'"), std::string::npos) << e;
}

// ---------------------------------------------------------------------------------------------
// The command

#ifdef TGNAV_BIN
std::string tgnav() { return TGNAV_BIN; }

TEST(ReportCommand, BadInputWritesNothingAndExitsTwo) {
  const fs::path dir = tempDir();
  Row r = row("b");
  r.status = "exploded";
  makeSweep(dir, {row("a"), r});
  const test::CmdResult run = test::runShell(tgnav() + " report " + dir.string());
  EXPECT_EQ(run.rc, 2) << run.output;
  EXPECT_NE(run.output.find("tgnav: error: " + (dir / "index.csv").string() + ":3: column status: 'exploded'"),
            std::string::npos)
      << run.output;
  EXPECT_FALSE(fs::exists(dir / "report"));
}

TEST(ReportCommand, TablesStayWhenThePlotsFail) {
  const fs::path dir = tempDir();
  makeSweep(dir, {row("a"), row("b")});
  // No python: the tables are written, the failure is one line, exit 1.
  test::CmdResult run = test::runShell("TGNAV_PYTHON=/nonexistent/python3 " + tgnav() + " report " + dir.string() +
                                       " --no-map --out " + (dir / "out").string());
  EXPECT_EQ(run.rc, 1) << run.output;
  EXPECT_NE(run.output.find("tgnav: error: plots failed: /nonexistent/python3 not found"), std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("| *storage* | Proposed |"), std::string::npos) << run.output;
  EXPECT_GT(fs::file_size(dir / "out/table2.csv"), 0u);
  EXPECT_GT(fs::file_size(dir / "out/table2.md"), 0u);
  // --no-plots: only the tables, exit 0.
  run = test::runShell(tgnav() + " report " + dir.string() + " --no-plots");
  EXPECT_EQ(run.rc, 0) << run.output;
  EXPECT_TRUE(fs::exists(dir / "report/table2.md"));
  EXPECT_FALSE(fs::exists(dir / "report/report.json"));
}

std::string python() {
  const char* p = std::getenv("TGNAV_PYTHON");
  return p != nullptr && *p != '\0' ? p : "/usr/bin/python3";
}

// A trial of the smoke scene flown along y = 0 from the start; VO lost after `tracked` frames.
void writeSmokeTrial(const fs::path& folder, int tracked) {
  writeFile(folder / "config.yaml",
            "scene: " + (test::sourceDir() / "configs/scenes/smoke.yaml").string() + "\nseed: 1\n");
  std::ostringstream gt, vo;
  gt << "# timestamp tx ty tz qx qy qz qw\n";
  vo << "t,status,features,with_depth,matches,inliers,keyframe,x_true,y_true,z_true,x_est,y_est,z_est,reason\n";
  for (int i = 0; i <= 60; ++i) {
    const double t = 0.1 * i, x = -3.0 + 0.1 * i, y = 0.3 * std::sin(0.2 * i);
    gt << t << ' ' << x << ' ' << y << " 1 -0.5 0.5 -0.5 0.5\n";
    vo << t << (i < tracked ? ",ok" : ",lost") << ",500,400,300,200,0," << x << ',' << y << ",1,";
    if (i < tracked)
      vo << x + 0.002 * i << ',' << y << ",1";
    else
      vo << ",,";
    vo << ",\n";
  }
  writeFile(folder / "gt.tum", gt.str());
  writeFile(folder / "vo.csv", vo.str());
}

TEST(ReportCommand, DrawsTheFigures) {
  if (test::runShell(python() + " -c 'import matplotlib'").rc != 0) {
    GTEST_SKIP() << python() << " has no matplotlib (install python3-matplotlib or set TGNAV_PYTHON)";
  }
  const fs::path dir = tempDir();
  Row p1 = row("p1"), a1 = row("a1");
  p1.scene = a1.scene = "smoke";
  a1.planner = "agnostic";
  a1.status = "vo_lost";
  a1.goal = "";
  a1.metrics = R"({"vo_ok": 30, "vo_weak": 0, "vo_lost_position": [0.0, 0.1, 1.0]})";
  makeSweep(dir, {p1, a1});
  writeSmokeTrial(dir / "trials/p1", 61);
  writeSmokeTrial(dir / "trials/a1", 30);
  const test::CmdResult run = test::runShell(tgnav() + " report " + dir.string() + " --map-cache " + TGNAV_TEST_CACHE);
  ASSERT_EQ(run.rc, 0) << run.output;
  for (const char* f : {"table2.csv", "table2.md", "report.json"}) {
    ASSERT_TRUE(fs::exists(dir / "report" / f)) << f;
    EXPECT_GT(fs::file_size(dir / "report" / f), 0u) << f;
  }
  for (const char* f : {"map_smoke.png", "fig3_smoke.png", "fig4_smoke.png", "tracking_smoke.png", "plan_time.png"}) {
    ASSERT_TRUE(fs::exists(dir / "report" / f)) << f;
    EXPECT_GT(fs::file_size(dir / "report" / f), 10000u) << f;  // a picture, not an empty canvas
  }
  std::ifstream in(dir / "report/report.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["groups"].size(), 2u);
  EXPECT_EQ(j["groups"][1]["label"], "AP");
  EXPECT_EQ(j["groups"][1]["trials"][0]["folder"], (dir / "trials/a1").string());
  EXPECT_EQ(j["groups"][1]["trials"][0]["vo_lost_position"][1], 0.1);
  EXPECT_EQ(j["scenes"][0]["map"], "map_smoke.png");
  EXPECT_EQ(j["scenes"][0]["extent_m"][0], -4.0);
  EXPECT_EQ(j["scenes"][0]["extent_m"][3], 3.0);
  EXPECT_EQ(j["groups"][1]["trials"][0]["min_inliers"], 30);  // the VO's default: config.yaml has no vo section
  EXPECT_TRUE(j["groups"][1]["trials"][0]["oracle_class"].is_null());
  // No vo.csv has the perception model's prediction: no calibration plot, and table2.md says so.
  EXPECT_FALSE(fs::exists(dir / "report/calibration.png"));
  EXPECT_NE(run.output.find("no calibration plot"), std::string::npos) << run.output;
  EXPECT_TRUE(fs::exists(dir / "report/aggregate.csv"));
  EXPECT_FALSE(fs::exists(dir / "report/scenes.csv"));  // one scene, no oracle trials
}
#endif

}  // namespace
}  // namespace tgnav::harness
