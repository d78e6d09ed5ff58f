#pragma once
// The `tgnav report` job: a sweep folder aggregated into the paper's Table II (table2.csv,
// table2.md), the generalisation tables (report_scenes.h: scenes.csv, aggregate.csv and their
// sections of table2.md) and the figures (fig3_<scene> trajectories over the map, fig4_<scene> VO
// error against distance travelled, tracking_<scene> features and inliers per trial, plan_time,
// calibration), drawn by scripts/tgnav_plots.py from report.json and the scenes' map images. Bad
// input (not a sweep, a malformed index) is refused before anything is written; when the figures
// fail the tables are still there.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/experiments/report.h"
#include "harness/io/figures.h"

namespace tgnav::harness {

struct SceneBackground {
  std::string scene;
  bool drawn = false;                 // false: no map, extent, start or goal (figure 3 autoscales)
  std::string image;                  // file name in the report folder
  double extent_m[4] = {0, 0, 0, 0};  // x_min, x_max, y_min, y_max of the image
  double start_xy[2] = {0, 0};
  double goal_xy[2] = {0, 0};
};

// The background of `scene` from the config.yaml of one of its trials (a loadable scenario): its
// feature map (from the cache under `map_cache`, "" for the default; built when absent) drawn by
// Topdown and written to report_dir/map_<scene>.png.
SceneBackground sceneBackground(const std::string& scene, const std::filesystem::path& trial_folder,
                                const std::filesystem::path& report_dir, const std::string& map_cache);

// report.json: what the report figures (scripts/tgnav_plots.py report) need (groups with their trials' absolute
// folders, statuses, VO-lost positions, oracle and chosen classes, c_p_threshold and the VO's
// min_inliers from config.yaml; per scene the background image and its extent).
nlohmann::json reportJson(const SweepIndex& sweep, const std::vector<ReportGroup>& groups,
                          const std::vector<TableRow>& table, const std::vector<SceneBackground>& scenes);

struct ReportJob {
  std::filesystem::path dir;  // the sweep folder
  std::filesystem::path out;  // default: dir/report
  std::string map_cache;      // "" = the default cache
  bool no_map = false;        // trajectories without the map background
  bool no_plots = false;      // tables only (no report.json, no figures)
  FigureFormat figure_format = FigureFormat::kPng;
};

struct ReportRunResult {
  std::filesystem::path out;
  std::string markdown;  // table2.md (Table II and the generalisation sections)
  std::size_t groups = 0;
  std::size_t trials = 0;
  std::string figures_failed;  // why the figures are missing, or ""
};

ReportRunResult runReport(const ReportJob& job);

}  // namespace tgnav::harness
