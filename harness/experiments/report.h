#pragma once
// `tgnav report`: a sweep folder (made by `tgnav sweep`) aggregated into the paper's Table II
// and the data its figures are drawn from (scripts/tgnav_plots.py draws them); the per-scene and
// generalisation tables are in report_scenes.h.
//
// Sweep folder contract:
//   DIR/trials.csv   every trial of the sweep: id,scenario,scene,planner,samples,seed,params
//   DIR/index.csv    finished trials: id,scene,planner,samples,seed,params,status,<metrics>,folder
//   DIR/trials/<id>/ one `tgnav trial` output folder (metrics.json, gt.tum, vo.csv, config.yaml)
// Empty cells are nulls; params are `key=value;key=value` assignments of extra sweep axes.
//
// The table follows the paper: one row per (scene, planner, samples, params) group, in order of
// first appearance in index.csv; goal error only over successful trials (Table II's caption).
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace tgnav::harness {

// Trial outcomes as metrics.json and index.csv spell them.
inline const std::vector<std::string>& trialStatusNames() {
  static const std::vector<std::string> names = {"success",  "drifted", "vo_lost",     "collision",
                                                 "diverged", "timeout", "plan_failed", "no_path"};
  return names;
}

// One finished trial: a row of index.csv, plus what its metrics.json adds.
struct IndexRow {
  int line = 0;  // in index.csv (the header is line 1)
  std::string id;
  std::string scene;
  std::string planner;  // proposed | agnostic | rrtstar
  int samples = 0;      // rrtstar's sample budget, 0 for the others
  std::uint64_t seed = 0;
  std::string params;                   // "key=value;key=value" or ""
  std::string status;                   // one of trialStatusNames()
  std::optional<double> path_length_m;  // flown, ground truth
  std::optional<double> planned_length_m;
  std::optional<double> goal_error_m;  // null when the VO did not track to the end
  std::optional<double> final_distance_to_goal_m;
  std::optional<double> ate_rmse_m;
  std::optional<double> plan_time_s;
  std::optional<double> wall_time_s;
  std::optional<double> sim_time_s;
  std::optional<double> vo_lost_at_s;
  std::optional<double> distance_tracked_m;
  std::filesystem::path folder;  // absolute
  // From metrics.json: whether any camera frame was tracked (unknown: not in metrics.json) and
  // where the VO was first lost (x, y, z of the body in W).
  std::optional<bool> tracked_frames;
  std::optional<std::vector<double>> vo_lost_position;
  // The homology classes (report_trial.h): the oracle's class (none: the planner chose), the class
  // flown (an index into plan.json's classes, the same for every planner of a scene), how many the
  // scene has; from plan.json the chosen class's weakest segment score and the planner's threshold.
  std::optional<int> oracle_class;
  std::optional<int> chosen_class;
  std::optional<int> classes;
  std::optional<double> chosen_c_p_min;
  std::optional<double> c_p_threshold;
};

struct SweepIndex {
  std::filesystem::path dir;  // absolute
  std::vector<IndexRow> rows;
  std::optional<int> manifest_trials;  // rows of trials.csv; none when the sweep has no manifest
};

// Parses index.csv text (`file` names it in messages; folders are taken relative to `dir`) and
// checks every row's folder holds metrics.json, which is read. InputError naming file:line, the
// column and the value for a wrong header, field count, number, planner or status, a duplicate
// id, a missing folder or metrics.json; "no finished trials yet" for an index without rows.
std::vector<IndexRow> parseIndexCsv(const std::string& text, const std::filesystem::path& file,
                                    const std::filesystem::path& dir);

// Reads DIR/index.csv and DIR/trials.csv (optional; its header is checked when present).
// InputError when DIR is missing or is not a sweep folder.
SweepIndex readSweep(const std::filesystem::path& dir);

// mean ± sample standard deviation (n - 1) of n values; std is 0 for n = 1.
struct Summary {
  int n = 0;
  double mean = 0.0;
  double std = 0.0;
};
std::optional<Summary> summarise(const std::vector<double>& values);

// The paper's planner names: "Proposed", "AP", "R-<samples>", with params in brackets.
std::string plannerLabel(const std::string& planner, int samples, const std::string& params);

struct ReportGroup {
  std::string scene;
  std::string planner;
  int samples = 0;
  std::string params;
  std::string label;                // plannerLabel()
  std::vector<std::size_t> trials;  // indices into the rows
};
// Groups by (scene, planner, samples, params) in order of first appearance.
std::vector<ReportGroup> groupTrials(const std::vector<IndexRow>& rows);

// One row of Table II.
struct TableRow {
  std::string scene;
  std::string planner;
  int samples = 0;
  std::string params;
  std::string label;
  int trials = 0;                                     // finished
  int successes = 0;                                  // status success
  int drifted = 0;                                    // status drifted
  std::optional<Summary> length_m;                    // flown length, trials that flew (not plan_failed)
  std::optional<Summary> goal_error_m;                // trials whose VO tracked to the goal (success, drifted)
  std::optional<Summary> plan_time_s;                 // all trials with a plan time
  std::optional<Summary> ate_rmse_m;                  // trials with tracked frames
  std::vector<std::pair<std::string, int>> outcomes;  // status -> count, trialStatusNames() order
};
TableRow tableRow(const ReportGroup& group, const std::vector<IndexRow>& rows);
std::vector<TableRow> tableRows(const std::vector<ReportGroup>& groups, const std::vector<IndexRow>& rows);

// `value` to 3 significant figures as the paper prints it: 15.9, 0.118, 1.58, 164 (never with
// an exponent).
std::string formatSig3(double value);
// "15.9 ± 0.4" (the std to the mean's decimals), just the mean for n = 1, "–" for none.
std::string formatSummary(const std::optional<Summary>& s);
// "8 success, 2 vo_lost".
std::string formatOutcomes(const std::vector<std::pair<std::string, int>>& outcomes);

// A Markdown table with padded columns (readable on a terminal); `right` aligns a column right.
std::string markdownTable(const std::vector<std::string>& header, const std::vector<bool>& right,
                          const std::vector<std::vector<std::string>>& cells);
// Text for a Markdown cell ('|' escaped).
std::string markdownCell(std::string s);
// A number for a CSV cell (%.10g).
std::string csvNumber(double v);

// Machine-friendly table: raw numbers, mean and std in separate columns, empty cells for none.
std::string table2Csv(const std::vector<TableRow>& rows);
// Title, "<finished> of <manifest> trials finished", the table with each scene named once at the
// top of its block, and the goal-error footnote.
std::string table2Markdown(const std::vector<TableRow>& rows, int finished, std::optional<int> manifest,
                           const std::string& sweep_name);

}  // namespace tgnav::harness
