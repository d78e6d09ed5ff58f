#pragma once
// `tgnav report`, the generalisation benchmark: which homology classes of a scene the VO can fly
// (from its oracle trials), and per planner how often it flew one.
//
// Oracle trials are those with an oracle_class (metrics.json); they are grouped by (scene, class)
// whatever their planner and params. A class is *flyable* when the VO tracked to the goal
// (status success) in at least 2/3 of its oracle trials (2 of 3 seeds). The other trials are
// grouped per scene as Table II groups them (planner, samples, params).
//
// Outputs: scenes.csv and a "Per scene" Markdown section (when the sweep has more than one scene or
// any oracle trial), aggregate.csv and an "Aggregate" Markdown section (always): per planner the VO
// success over the scenes with a flyable class, the selection accuracy (share of those trials whose
// chosen class is flyable; n/a without such scenes) and, over all its trials whose chosen class
// was predicted flyable (c_p_min >= c_p_threshold of plan.json), the share that succeeded.
#include <optional>
#include <string>
#include <vector>

#include "harness/experiments/report.h"

namespace tgnav::harness {

// At least 2/3 of `trials` (> 0) succeeded.
bool isFlyable(int successes, int trials);

// The oracle trials of one class of a scene.
struct OracleClass {
  int index = 0;  // the homology class K
  int trials = 0;
  int successes = 0;
  bool flyable = false;
  std::optional<double> c_p_min;        // the class's weakest segment score (plan.json of the first trial that has it)
  std::optional<double> c_p_threshold;  // and the threshold it is held against
};

// The trials of one planner group in one scene (no oracle trials).
struct ScenePlanner {
  std::string label;  // plannerLabel()
  std::string planner;
  int samples = 0;
  std::string params;
  int trials = 0;
  int successes = 0;
  std::optional<double> goal_error_median_m;  // successful trials
  int chose_flyable = 0;                      // trials whose chosen class is flyable
};

struct SceneReport {
  std::string scene;
  std::optional<int> classes;       // homology classes the scene has (the most any trial saw)
  std::vector<OracleClass> oracle;  // by class index
  std::vector<ScenePlanner> planners;
  std::vector<int> flyableClasses() const;
  bool hasFlyable() const { return !flyableClasses().empty(); }
};

// Per scene in order of first appearance.
std::vector<SceneReport> sceneReports(const std::vector<IndexRow>& rows);
// More than one scene, or any oracle trial: the per-scene table is worth printing.
bool wantsSceneTable(const std::vector<IndexRow>& rows);

// The aggregate of one planner group over all scenes (oracle: the oracle trials of every class).
struct AggregateRow {
  std::string label;  // plannerLabel(), or "Oracle"
  std::string planner;
  int samples = 0;
  std::string params;
  bool oracle = false;
  int trials = 0;
  int scenes = 0;               // scenes it was run in
  int covered_scenes = 0;       // of those, the ones with a flyable class
  int covered_trials = 0;       // its trials there
  int covered_successes = 0;    // VO success there
  int chose_flyable = 0;        // of covered_trials, those whose chosen class is flyable
  int predicted_flyable = 0;    // trials whose chosen class has c_p_min >= c_p_threshold
  int predicted_successes = 0;  // of those, VO success
};

// Planner groups in order of first appearance, then the oracle row when there are oracle trials.
std::vector<AggregateRow> aggregateRows(const std::vector<IndexRow>& rows, const std::vector<SceneReport>& scenes);

// "k/n (p%; lo–hi%)" with the 95 % Wilson interval (statistics.h), or "n/a" for n = 0.
std::string formatShare(int k, int n);

std::string scenesCsv(const std::vector<SceneReport>& scenes);
std::string aggregateCsv(const std::vector<AggregateRow>& rows);
// "## Per scene" (when `per_scene`) and "## Aggregate" sections for table2.md.
std::string generalisationMarkdown(const std::vector<SceneReport>& scenes, const std::vector<AggregateRow>& rows,
                                   bool per_scene);

}  // namespace tgnav::harness
