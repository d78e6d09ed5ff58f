#include "harness/run/plan_job.h"

#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "harness/base/errors.h"
#include "harness/config/scenario.h"
#include "harness/config/values.h"
#include "harness/io/grid_io.h"
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
      const cv::Rect cell(ix * scale, (grid.height - 1 - iy) * scale, scale, scale);
      if (grid.isOccupied(ix, iy)) {
        layer.image(cell).setTo(cv::Scalar(70, 70, 70));
      } else if (!plan.gvd.empty() && plan.gvd[grid.index(ix, iy)]) {
        layer.image(cell).setTo(cv::Scalar(235, 200, 150));
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

planner::TopoPlannerConfig gridPlannerConfig(const GridPlanJob& job) {
  planner::TopoPlannerConfig config;
  config.robot_radius_m = job.robot_radius_m;
  config.max_classes = job.max_classes;
  try {
    config.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--robot-radius/--max-classes: ") + e.what());
  }
  return config;
}

nlohmann::ordered_json gridPlanJson(const GridPlanJob& job, const planner::OccupancyGrid2D& grid,
                                    const planner::TopoPlan& plan, const Eigen::Vector2d& start,
                                    const Eigen::Vector2d& goal, double plan_s) {
  nlohmann::ordered_json j;
  j["planner"] = "agnostic";
  j["status"] = planner::toString(plan.status);
  j["plan_time_s"] = plan_s;
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
  const std::string files = std::string("{plan.json,plan.") + toString(job.figure_format);
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
  Scenario scenario = loadScenario(job.scenario);
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
  const planner::TopoPlannerConfig config = gridPlannerConfig(job);
  const planner::OccupancyGrid2D grid = loadGridMap(job.grid, job.resolution_m);
  const std::vector<double> s = parseNumbers(job.start, 2, "--start", "X,Y (metres, map frame)");
  const std::vector<double> g = parseNumbers(job.goal, 2, "--goal", "X,Y (metres, map frame)");
  const Eigen::Vector2d start(s[0], s[1]);
  const Eigen::Vector2d goal(g[0], g[1]);

  const auto t0 = std::chrono::steady_clock::now();
  const planner::TopologicalPlanner topo(grid, config);
  const planner::TopoPlan plan = topo.solve(start, goal);
  const double plan_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (plan.status == planner::PlanStatus::kInvalidStart || plan.status == planner::PlanStatus::kInvalidGoal) {
    const bool is_start = plan.status == planner::PlanStatus::kInvalidStart;
    std::ostringstream msg;
    msg << (is_start ? "--start" : "--goal") << ": '" << (is_start ? job.start : job.goal) << "' in "
        << job.grid.string() << " is outside the map, in an obstacle or within the robot radius ("
        << config.robot_radius_m << " m) of one";
    throw InputError(msg.str());
  }

  StagedDir staged(job.out);
  writeFileAtomic(staged.staging() / "plan.json", gridPlanJson(job, grid, plan, start, goal, plan_s).dump(2) + "\n");
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

}  // namespace tgnav::harness
