#include "harness/experiments/report_run.h"

#include <algorithm>
#include <set>

#include "harness/base/errors.h"
#include "harness/config/scenario.h"
#include "harness/experiments/report_scenes.h"
#include "harness/experiments/report_trial.h"
#include "harness/experiments/statistics.h"
#include "harness/io/staged_output.h"
#include "harness/io/topdown.h"
#include "harness/run/map_cache.h"

namespace tgnav::harness {

namespace {

namespace fs = std::filesystem;

// Pixels across a scene's map image.
constexpr double kMapPixels = 900.0;
// Occupancy band around the flight height drawn in the background, as the trial figures have it.
constexpr double kMapBandM = 0.3;

// The scene backgrounds, each from the first trial of its scene, in order of appearance; with
// --no-map only their names (figure 3 then autoscales and has no start or goal marker).
std::vector<SceneBackground> backgrounds(const SweepIndex& sweep, const fs::path& report_dir, const ReportJob& opt) {
  std::vector<SceneBackground> out;
  std::set<std::string> done;
  for (const IndexRow& row : sweep.rows) {
    if (!done.insert(row.scene).second) continue;
    if (opt.no_map) {
      SceneBackground bg;
      bg.scene = row.scene;
      out.push_back(bg);
    } else {
      out.push_back(sceneBackground(row.scene, row.folder, report_dir, opt.map_cache));
    }
  }
  return out;
}

template <typename T>
nlohmann::json orNull(const std::optional<T>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

nlohmann::json summaryJson(const std::optional<Summary>& s) {
  if (!s) return nullptr;
  return {{"n", s->n}, {"mean", s->mean}, {"std", s->std}};
}

// What the figures leave out, for table2.md: the calibration plot needs the perception model's
// prediction per camera frame (vo.csv's predicted_score).
std::string figureNotes(const SweepIndex& sweep) {
  const bool any = std::any_of(sweep.rows.begin(), sweep.rows.end(),
                               [](const IndexRow& r) { return voCsvHasColumn(r.folder, "predicted_score"); });
  if (any) return "";
  return "\nFigures: no calibration plot (calibration): no trial's vo.csv has a predicted_score column.\n";
}

// Writes report.json and the map images and runs the figures; "" or why they failed.
std::string reportFigures(const SweepIndex& sweep, const std::vector<ReportGroup>& groups,
                          const std::vector<TableRow>& table, const fs::path& report_dir, const ReportJob& job) {
  try {
    const auto scenes = backgrounds(sweep, report_dir, job);
    writeFileAtomic(report_dir / "report.json", reportJson(sweep, groups, table, scenes).dump(2) + "\n");
  } catch (const std::exception& e) {
    return e.what();
  }
  const FigureOutcome drawn = drawFigures("report", report_dir, job.figure_format);
  return drawn.status == FigureOutcome::Status::kDrawn ? "" : drawn.message;
}

}  // namespace

SceneBackground sceneBackground(const std::string& scene, const fs::path& trial_folder, const fs::path& report_dir,
                                const std::string& map_cache) {
  const Scenario scenario = loadScenario(trial_folder / "config.yaml");
  const SceneConfig& sc = scenario.scene;
  const Eigen::Vector3d extent = sc.bounds_max_m - sc.bounds_min_m;
  if (!(extent.x() > 0.0 && extent.y() > 0.0)) {
    throw InputError((trial_folder / "config.yaml").string() + ": scene " + scene + " has empty bounds");
  }
  const double m_per_px = std::max(extent.x(), extent.y()) / kMapPixels;
  Topdown topdown(sc, m_per_px);
  topdown.drawMap(loadSceneFeatureMap(sc, "", map_cache, "tgnav report"), kMapBandM);
  SceneBackground bg;
  bg.scene = scene;
  bg.drawn = true;
  bg.image = "map_" + scene + ".png";
  writeImageAtomic(report_dir / bg.image, topdown.image());
  // The image covers whole pixels, so it may reach a little past bounds_max.x / below bounds_min.y.
  bg.extent_m[0] = sc.bounds_min_m.x();
  bg.extent_m[1] = sc.bounds_min_m.x() + topdown.image().cols * m_per_px;
  bg.extent_m[2] = sc.bounds_max_m.y() - topdown.image().rows * m_per_px;
  bg.extent_m[3] = sc.bounds_max_m.y();
  bg.start_xy[0] = sc.start.p_WB.x();
  bg.start_xy[1] = sc.start.p_WB.y();
  bg.goal_xy[0] = sc.goal.p_WB.x();
  bg.goal_xy[1] = sc.goal.p_WB.y();
  return bg;
}

nlohmann::json reportJson(const SweepIndex& sweep, const std::vector<ReportGroup>& groups,
                          const std::vector<TableRow>& table, const std::vector<SceneBackground>& scenes) {
  nlohmann::json j;
  j["sweep_dir"] = sweep.dir.string();
  j["finished"] = sweep.rows.size();
  j["manifest_trials"] = sweep.manifest_trials ? nlohmann::json(*sweep.manifest_trials) : nlohmann::json(nullptr);
  j["scenes"] = nlohmann::json::array();
  for (const SceneBackground& s : scenes) {
    nlohmann::json scene = {
        {"name", s.scene}, {"map", nullptr}, {"extent_m", nullptr}, {"start_xy", nullptr}, {"goal_xy", nullptr}};
    if (s.drawn) {
      scene["map"] = s.image;
      scene["extent_m"] = {s.extent_m[0], s.extent_m[1], s.extent_m[2], s.extent_m[3]};
      scene["start_xy"] = {s.start_xy[0], s.start_xy[1]};
      scene["goal_xy"] = {s.goal_xy[0], s.goal_xy[1]};
    }
    j["scenes"].push_back(scene);
  }
  j["groups"] = nlohmann::json::array();
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const ReportGroup& group = groups[g];
    const TableRow& t = table[g];
    nlohmann::json trials = nlohmann::json::array();
    for (const std::size_t i : group.trials) {
      const IndexRow& r = sweep.rows[i];
      trials.push_back(
          {{"id", r.id},
           {"seed", r.seed},
           {"folder", r.folder.string()},
           {"status", r.status},
           {"path_length_m", orNull(r.path_length_m)},
           {"goal_error_m", orNull(r.goal_error_m)},
           {"plan_time_s", orNull(r.plan_time_s)},
           {"vo_lost_at_s", orNull(r.vo_lost_at_s)},
           {"distance_tracked_m", orNull(r.distance_tracked_m)},
           {"vo_lost_position", r.vo_lost_position ? nlohmann::json(*r.vo_lost_position) : nlohmann::json(nullptr)},
           {"oracle_class", orNull(r.oracle_class)},
           {"chosen_class", orNull(r.chosen_class)},
           {"c_p_threshold", orNull(r.c_p_threshold)},
           {"min_inliers", orNull(trialMinInliers(r.folder))}});
    }
    j["groups"].push_back({{"label", group.label},
                           {"scene", group.scene},
                           {"planner", group.planner},
                           {"samples", group.samples},
                           {"params", group.params},
                           {"successes", t.successes},
                           {"drifted", t.drifted},
                           {"length_m", summaryJson(t.length_m)},
                           {"goal_error_m", summaryJson(t.goal_error_m)},
                           {"plan_time_s", summaryJson(t.plan_time_s)},
                           {"ate_rmse_m", summaryJson(t.ate_rmse_m)},
                           {"trials", trials}});
  }
  return j;
}

ReportRunResult runReport(const ReportJob& job) {
  const SweepIndex sweep = readSweep(job.dir);
  ReportRunResult r;
  r.out = job.out.empty() ? sweep.dir / "report" : fs::absolute(job.out).lexically_normal();
  std::error_code ec;
  if (fs::exists(r.out, ec) && !fs::is_directory(r.out, ec)) {
    throw InputError("--out: " + r.out.string() + " exists and is not a directory");
  }
  const std::vector<ReportGroup> groups = groupTrials(sweep.rows);
  const std::vector<TableRow> table = tableRows(groups, sweep.rows);
  r.markdown =
      table2Markdown(table, static_cast<int>(sweep.rows.size()), sweep.manifest_trials, sweep.dir.filename().string());
  r.groups = groups.size();
  r.trials = sweep.rows.size();
  const bool per_scene = wantsSceneTable(sweep.rows);
  const std::vector<SceneReport> scenes = sceneReports(sweep.rows);
  const std::vector<AggregateRow> aggregate = aggregateRows(sweep.rows, scenes);
  r.markdown += generalisationMarkdown(scenes, aggregate, per_scene);
  const std::vector<PairedComparison> comparisons = pairedComparisons(sweep.rows, groups);
  r.markdown += comparisonsMarkdown(comparisons);
  if (!job.no_plots) r.markdown += figureNotes(sweep);
  makeOutputDir(r.out);
  writeFileAtomic(r.out / "table2.csv", table2Csv(table));
  if (per_scene) {
    writeFileAtomic(r.out / "scenes.csv", scenesCsv(scenes));
  } else {
    fs::remove(r.out / "scenes.csv", ec);  // from an earlier report of this folder
  }
  writeFileAtomic(r.out / "aggregate.csv", aggregateCsv(aggregate));
  writeFileAtomic(r.out / "comparisons.csv", comparisonsCsv(comparisons));
  writeFileAtomic(r.out / "table2.md", r.markdown);
  if (!job.no_plots) r.figures_failed = reportFigures(sweep, groups, table, r.out, job);
  return r;
}

}  // namespace tgnav::harness
