#include "harness/run/plan_job.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>
#include <tuple>

#include "harness/base/clock.h"
#include "harness/base/errors.h"
#include "harness/config/scenario.h"
#include "harness/config/values.h"
#include "harness/config/yaml_util.h"
#include "harness/io/grid_io.h"
#include "harness/io/movingai_scen.h"
#include "harness/io/staged_output.h"
#include "harness/io/topdown.h"
#include "harness/io/trajectory_csv.h"
#include "harness/run/map_cache.h"
#include "harness/run/plan_run.h"
#include "planner/topological_planner.h"

namespace tgnav::harness {

namespace {

// Pixels across the map layer, whatever the map's size.
constexpr int kLayerPixels = 800;

nlohmann::json rows(const std::vector<Eigen::Vector2d>& path) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& p : path) j.push_back({p.x(), p.y()});
  return j;
}

// The grid as a figure background: free white, occupied dark, the GVD skeleton light blue.
MapLayer gridLayer(const planner::OccupancyGrid2D& grid, const planner::TopoPlan& plan, const Eigen::Vector2d& start,
                   const Eigen::Vector2d& goal, const std::string& title) {
  const int scale = std::max(1, kLayerPixels / std::max(grid.width, grid.height));
  MapLayer layer;
  layer.image = cv::Mat(grid.height * scale, grid.width * scale, CV_8UC3, cv::Scalar(255, 255, 255));
  for (int iy = 0; iy < grid.height; ++iy) {
    for (int ix = 0; ix < grid.width; ++ix) {
      if (grid.isOccupied(ix, iy)) {
        layer.image(cv::Rect(ix * scale, (grid.height - 1 - iy) * scale, scale, scale)).setTo(cv::Scalar(70, 70, 70));
      }
    }
  }
  // The GVD lives on the planner's working grid, k x k cells per map cell.
  const int k = plan.working_factor;
  const int work_w = grid.width * k;
  const int work_h = grid.height * k;
  if (plan.gvd.size() == static_cast<std::size_t>(work_w) * work_h) {
    for (int wy = 0; wy < work_h; ++wy) {
      for (int wx = 0; wx < work_w; ++wx) {
        if (!plan.gvd[static_cast<std::size_t>(wy) * work_w + wx]) continue;
        const int x0 = wx * scale / k;
        const int y0 = (work_h - 1 - wy) * scale / k;
        const int side = std::max(1, scale / k);
        layer.image(cv::Rect(x0, y0, side, side)).setTo(cv::Scalar(235, 200, 150));
      }
    }
  }
  layer.extent_m[0] = grid.origin_m.x();
  layer.extent_m[1] = grid.origin_m.x() + grid.width * grid.resolution_m;
  layer.extent_m[2] = grid.origin_m.y();
  layer.extent_m[3] = grid.origin_m.y() + grid.height * grid.resolution_m;
  layer.start_xy = start;
  layer.goal_xy = goal;
  layer.title = title;
  layer.legend = {
      {"occupied", cv::Vec3b(70, 70, 70)}, {"free", cv::Vec3b(255, 255, 255)}, {"GVD", cv::Vec3b(150, 200, 235)}};
  return layer;
}

planner::TopoPlannerConfig gridPlannerConfig(double robot_radius_m, int max_classes) {
  planner::TopoPlannerConfig config;
  config.robot_radius_m = robot_radius_m;
  config.max_classes = max_classes;
  try {
    config.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--robot-radius/--max-classes: ") + e.what());
  }
  return config;
}

nlohmann::ordered_json gridPlanJson(const GridPlanJob& job, const planner::OccupancyGrid2D& grid,
                                    const planner::TopoPlan& plan, const Eigen::Vector2d& start,
                                    const Eigen::Vector2d& goal, double preprocess_s, double query_s) {
  nlohmann::ordered_json j;
  j["planner"] = "agnostic";
  j["status"] = planner::toString(plan.status);
  j["plan_time_s"] = preprocess_s + query_s;
  j["preprocess_time_s"] = preprocess_s;
  j["query_time_s"] = query_s;
  j["working_factor"] = plan.working_factor;
  j["map"] = {{"file", job.grid.string()},
              {"width", grid.width},
              {"height", grid.height},
              {"resolution_m", grid.resolution_m},
              {"origin", {grid.origin_m.x(), grid.origin_m.y()}}};
  j["start"] = {start.x(), start.y()};
  j["goal"] = {goal.x(), goal.y()};
  j["robot_radius_m"] = job.robot_radius_m;
  j["class_cap"] = job.max_classes;
  j["expansions"] = plan.expansions;
  j["graph"] = {{"vertices", plan.graph.vertices.size()}, {"edges", plan.graph.edges.size()}};
  nlohmann::json vertices = nlohmann::json::array();
  for (const auto& v : plan.graph.vertices) vertices.push_back({v.p_m.x(), v.p_m.y()});
  nlohmann::json edges = nlohmann::json::array();
  for (const auto& e : plan.graph.edges) edges.push_back(rows(e.points_m));
  j["roadmap"] = {{"vertices", vertices}, {"edges", edges}};
  j["classes"] = nlohmann::json::array();
  for (const auto& c : plan.classes) {
    j["classes"].push_back({{"h_signature", c.h_signature}, {"length_m", c.length_m}, {"waypoints", rows(c.path)}});
  }
  j["chosen_class"] = plan.chosen >= 0 ? nlohmann::json(plan.chosen) : nlohmann::json(nullptr);
  j["path"] = plan.chosen >= 0 ? rows(plan.classes[plan.chosen].path) : nlohmann::json::array();
  return j;
}

std::string scenarioSummary(const ScenarioPlanJob& job, const PlanRun& run, const std::filesystem::path& out) {
  const planner::Plan& plan = run.plan;
  const planner::TrajectoryReport& tr = run.trajectory;
  const std::string files = std::string("{plan.json,config.yaml,plan.") + toString(job.figure_format);
  char line[1024];
  if (plan.chosen < 0) {
    std::snprintf(line, sizeof line, "tgnav plan: %s %s (no path from start to goal), %.3f s -> %s/%s}",
                  planner::toString(job.planner), planner::toString(plan.status), run.plan_time_s(),
                  out.string().c_str(), files.c_str());
    return line;
  }
  const planner::CandidatePath& c = plan.candidates[static_cast<std::size_t>(plan.chosen)];
  std::snprintf(line, sizeof line,
                "tgnav plan: %s %s, %zu homology classes, chose class %d (%.2f m, c_p,min %.1f), %.3f s; "
                "trajectory %s (%.1f s, clearance %.2f m, %.3f s) -> %s/%s%s}",
                planner::toString(job.planner), planner::toString(plan.status), plan.topo.classes.size(),
                plan.chosen_class, c.length_m, c.c_p_min, run.plan_time_s(), planner::toString(tr.status),
                tr.duration_s, tr.min_clearance_m, run.trajectory_s, out.string().c_str(), files.c_str(),
                tr.trajectory ? ",trajectory.csv" : "");
  return line;
}

}  // namespace

PlanJobResult runScenarioPlan(const ScenarioPlanJob& job) {
  const YamlDoc overrides = YamlDoc::fromOverrides(job.set);
  Scenario scenario = loadScenario(job.scenario, &overrides);
  if (job.homology_class) applyOracleClass(*job.homology_class, job.planner, &scenario);
  const std::uint64_t seed = job.seed.value_or(scenario.seed);
  const planner::FeatureMap map = loadSceneFeatureMap(scenario.scene, job.map, job.map_cache, "tgnav plan");
  const PlanRun run = runPlanner(scenario, map, job.planner, seed, job.samples,
                                 job.homology_class ? "--class" : "planner.oracle_class");

  StagedDir staged(job.out);
  const std::filesystem::path& dir = staged.staging();
  const planner::TrajectoryReport& tr = run.trajectory;
  if (tr.trajectory) {
    writeFileAtomic(dir / "trajectory.csv", trajectoryCsv(setpoints(run, scenario.planner.trajectory.sample_rate_hz)));
  }
  writeFileAtomic(dir / "plan.json", planJson(scenario, run).dump(2) + "\n");
  writeFileAtomic(dir / "config.yaml", runConfigYaml("plan", scenario, run));
  writeMapLayer(dir, sceneMapLayer(scenario.scene, map, scenario.planner.perception.slice_half_height_m));
  PlanJobResult result;
  result.figures = drawFigures("plan", dir, job.figure_format);
  staged.commit(OnExisting::kMerge);
  result.summary = scenarioSummary(job, run, staged.target());
  if (tr.status == planner::TrajectoryStatus::kFallback) {
    result.warning = "tgnav plan: trajectory optimisation failed (" + tr.reason +
                     "); trajectory.csv flies the path itself, stopping at every point";
  }
  result.trajectory_failed = run.plan.chosen >= 0 && !tr.trajectory;
  if (result.trajectory_failed) result.warning = "trajectory: " + tr.reason + " (plan.json written)";
  return result;
}

PlanJobResult runGridPlan(const GridPlanJob& job) {
  const planner::TopoPlannerConfig config = gridPlannerConfig(job.robot_radius_m, job.max_classes);
  const planner::OccupancyGrid2D grid = loadGridMap(job.grid, job.resolution_m);
  const std::vector<double> s = parseNumbers(job.start, 2, "--start", "X,Y (metres, map frame)");
  const std::vector<double> g = parseNumbers(job.goal, 2, "--goal", "X,Y (metres, map frame)");
  const Eigen::Vector2d start(s[0], s[1]);
  const Eigen::Vector2d goal(g[0], g[1]);

  const auto t0 = std::chrono::steady_clock::now();
  const planner::TopologicalPlanner topo(grid, config);
  const double preprocess_s = secondsSince(t0);
  const auto t1 = std::chrono::steady_clock::now();
  const planner::TopoPlan plan = topo.solve(start, goal);
  const double query_s = secondsSince(t1);
  const double plan_s = preprocess_s + query_s;
  if (plan.status == planner::PlanStatus::kInvalidStart || plan.status == planner::PlanStatus::kInvalidGoal) {
    const bool is_start = plan.status == planner::PlanStatus::kInvalidStart;
    std::ostringstream msg;
    msg << (is_start ? "--start" : "--goal") << ": '" << (is_start ? job.start : job.goal) << "' in "
        << job.grid.string() << " is outside the map, in an obstacle or within the robot radius ("
        << config.robot_radius_m << " m) of one";
    throw InputError(msg.str());
  }

  StagedDir staged(job.out);
  writeFileAtomic(staged.staging() / "plan.json",
                  gridPlanJson(job, grid, plan, start, goal, preprocess_s, query_s).dump(2) + "\n");
  writeMapLayer(staged.staging(), gridLayer(grid, plan, start, goal, job.grid.filename().string()));
  PlanJobResult result;
  result.figures = drawFigures("plan", staged.staging(), job.figure_format);
  staged.commit(OnExisting::kMerge);
  const std::string where = staged.target().string() + "/{plan.json,plan." + toString(job.figure_format) + "}";
  char line[1024];
  if (plan.chosen >= 0) {
    std::snprintf(line, sizeof line, "tgnav plan: %s, %zu homology classes (cap %d), shortest %.2f m, %.3f s -> %s",
                  planner::toString(plan.status), plan.classes.size(), config.max_classes,
                  plan.classes[plan.chosen].length_m, plan_s, where.c_str());
  } else {
    std::snprintf(line, sizeof line, "tgnav plan: %s (no path from start to goal), %.3f s -> %s",
                  planner::toString(plan.status), plan_s, where.c_str());
  }
  result.summary = line;
  return result;
}

namespace {

// The .scen rows to run (one bucket, if asked), checked against the map: sizes, bounds, and
// start and goal on free cells.
std::vector<ScenRow> scenRows(const GridScenJob& job, const planner::OccupancyGrid2D& grid) {
  std::vector<ScenRow> rows = loadMovingAiScen(job.scen);
  checkScenAgainstMap(job.scen, rows, grid);
  if (job.bucket) {
    rows.erase(std::remove_if(rows.begin(), rows.end(), [&](const ScenRow& r) { return r.bucket != *job.bucket; }),
               rows.end());
    if (rows.empty()) {
      throw InputError("--bucket: " + std::to_string(*job.bucket) + " has no rows in " + job.scen.string());
    }
  }
  for (const ScenRow& r : rows) {
    for (const auto& [what, x, y] : {std::tuple<const char*, int, int>{"start", r.start_x, r.start_y},
                                     std::tuple<const char*, int, int>{"goal", r.goal_x, r.goal_y}}) {
      if (grid.isOccupied(x, grid.height - 1 - y)) {
        throw InputError(job.scen.string() + ":" + std::to_string(r.line) + ": " + what + " (" + std::to_string(x) +
                         ", " + std::to_string(y) + ") is an obstacle cell of " + job.grid.string());
      }
    }
  }
  return rows;
}

}  // namespace

PlanJobResult runGridScen(const GridScenJob& job) {
  const planner::TopoPlannerConfig config = gridPlannerConfig(job.robot_radius_m, job.max_classes);
  if (job.grid.extension() != ".map") {
    throw InputError("--scen: " + job.scen.string() + " needs a MovingAI .map as --grid, got " + job.grid.string());
  }
  const planner::OccupancyGrid2D grid = loadMovingAiMap(job.grid, job.resolution_m);
  const std::vector<ScenRow> rows = scenRows(job, grid);
  const double res = grid.resolution_m;

  const auto t0 = std::chrono::steady_clock::now();
  const planner::TopologicalPlanner topo(grid, config);
  const double preprocess_s = secondsSince(t0);
  std::ostringstream csv;
  csv << "line,bucket,start_x,start_y,goal_x,goal_y,status,classes,length_m,optimal_m,ratio,query_time_s\n";
  int found = 0;
  double worst_ratio = 0.0;
  double sum_ratio = 0.0;
  double sum_query = 0.0;
  double max_query = 0.0;
  for (const ScenRow& r : rows) {
    const Eigen::Vector2d start = scenCellCentre(r.start_x, r.start_y, grid.height, res);
    const Eigen::Vector2d goal = scenCellCentre(r.goal_x, r.goal_y, grid.height, res);
    const auto tq = std::chrono::steady_clock::now();
    const planner::TopoPlan plan = topo.solve(start, goal);
    const double query_s = secondsSince(tq);
    sum_query += query_s;
    max_query = std::max(max_query, query_s);
    const double optimal_m = r.optimal_length * res;
    char line[512];
    if (plan.chosen >= 0) {
      const double length = plan.classes[plan.chosen].length_m;
      const double ratio = optimal_m > 0.0 ? length / optimal_m : 1.0;
      ++found;
      sum_ratio += ratio;
      worst_ratio = std::max(worst_ratio, ratio);
      std::snprintf(line, sizeof line, "%d,%d,%d,%d,%d,%d,%s,%zu,%.6f,%.6f,%.6f,%.6f\n", r.line, r.bucket, r.start_x,
                    r.start_y, r.goal_x, r.goal_y, planner::toString(plan.status), plan.classes.size(), length,
                    optimal_m, ratio, query_s);
    } else {
      std::snprintf(line, sizeof line, "%d,%d,%d,%d,%d,%d,%s,0,,%.6f,,%.6f\n", r.line, r.bucket, r.start_x, r.start_y,
                    r.goal_x, r.goal_y, planner::toString(plan.status), optimal_m, query_s);
    }
    csv << line;
  }
  const int n = static_cast<int>(rows.size());
  nlohmann::ordered_json summary;
  summary["map"] = {{"file", job.grid.string()}, {"width", grid.width}, {"height", grid.height}, {"resolution_m", res}};
  summary["scen"] = job.scen.string();
  summary["bucket"] = job.bucket ? nlohmann::json(*job.bucket) : nlohmann::json(nullptr);
  summary["robot_radius_m"] = job.robot_radius_m;
  summary["class_cap"] = job.max_classes;
  summary["working_factor"] = topo.workingFactor();
  summary["rows"] = n;
  summary["found"] = found;
  summary["mean_ratio"] = found > 0 ? nlohmann::json(sum_ratio / found) : nlohmann::json(nullptr);
  summary["max_ratio"] = found > 0 ? nlohmann::json(worst_ratio) : nlohmann::json(nullptr);
  summary["preprocess_time_s"] = preprocess_s;
  summary["mean_query_time_s"] = sum_query / n;
  summary["max_query_time_s"] = max_query;

  StagedDir staged(job.out);
  writeFileAtomic(staged.staging() / "scen.csv", csv.str());
  writeFileAtomic(staged.staging() / "scen.json", summary.dump(2) + "\n");
  staged.commit(OnExisting::kMerge);
  char line[1024];
  std::snprintf(line, sizeof line,
                "tgnav plan: %d of %d scenarios found a path (length / optimal: mean %.4f, max %.4f); graph %.3f s, "
                "query mean %.3f s, max %.3f s -> %s/{scen.csv,scen.json}",
                found, n, found > 0 ? sum_ratio / found : 0.0, worst_ratio, preprocess_s, sum_query / n, max_query,
                staged.target().string().c_str());
  PlanJobResult result;
  result.summary = line;
  return result;
}

}  // namespace tgnav::harness
