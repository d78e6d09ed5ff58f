// tgnav plan: on a scene's feature map (--scenario: proposed, agnostic or rrtstar), or
// topological planning on a 2D occupancy grid (--grid: ROS map_server or MovingAI).
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "harness/cli.h"
#include "harness/errors.h"
#include "harness/grid_io.h"
#include "harness/map_cache.h"
#include "harness/output.h"
#include "harness/plan_run.h"
#include "harness/scenario.h"
#include "harness/trajectory_csv.h"
#include "planner/topological_planner.h"

namespace tgnav::cli {

namespace {

struct PlanOptions {
  std::string grid;
  std::string scenario;
  std::string start;
  std::string goal;
  std::string planner;
  long long seed = -1;  // -1: the scenario's
  int samples = 0;      // 0: planner.yaml's rrt_star.samples
  std::string map;
  std::string map_cache;
  std::string out;
  double resolution_m = 1.0;
  double robot_radius_m = 0.3;
  int max_classes = 10;
};

nlohmann::json rows(const std::vector<Eigen::Vector2d>& path) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& p : path) j.push_back({p.x(), p.y()});
  return j;
}

// Map (free white, occupied dark), GVD skeleton, graph edges and vertices, every class, the
// chosen path on top; start green, goal red. North (+y) up.
cv::Mat drawPlan(const planner::OccupancyGrid2D& grid, const planner::TopoPlan& plan, const Eigen::Vector2d& start,
                 const Eigen::Vector2d& goal) {
  const int scale = std::max(1, 800 / std::max(grid.width, grid.height));
  cv::Mat img(grid.height * scale, grid.width * scale, CV_8UC3, cv::Scalar(255, 255, 255));
  auto px = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector2d c = (p - grid.origin_m) / grid.resolution_m * scale;
    return cv::Point(static_cast<int>(c.x()), static_cast<int>(grid.height * scale - c.y()));
  };
  for (int iy = 0; iy < grid.height; ++iy) {
    for (int ix = 0; ix < grid.width; ++ix) {
      const cv::Rect cell(ix * scale, (grid.height - 1 - iy) * scale, scale, scale);
      if (grid.isOccupied(ix, iy)) {
        img(cell).setTo(cv::Scalar(70, 70, 70));
      } else if (!plan.gvd.empty() && plan.gvd[grid.index(ix, iy)]) {
        img(cell).setTo(cv::Scalar(235, 200, 150));
      }
    }
  }
  for (const auto& e : plan.graph.edges) {
    for (std::size_t i = 1; i < e.points_m.size(); ++i) {
      cv::line(img, px(e.points_m[i - 1]), px(e.points_m[i]), cv::Scalar(200, 120, 40), 1, cv::LINE_AA);
    }
  }
  for (const auto& v : plan.graph.vertices) cv::circle(img, px(v.p_m), 3, cv::Scalar(160, 60, 0), cv::FILLED);
  const cv::Scalar palette[] = {{60, 160, 60}, {200, 100, 200}, {40, 170, 230}, {180, 180, 40}, {120, 120, 240}};
  for (std::size_t c = 0; c < plan.classes.size(); ++c) {
    const auto& path = plan.classes[c].path;
    for (std::size_t i = 1; i < path.size(); ++i) {
      cv::line(img, px(path[i - 1]), px(path[i]), palette[c % 5], 2, cv::LINE_AA);
    }
  }
  if (plan.chosen >= 0) {
    const auto& path = plan.classes[plan.chosen].path;
    for (std::size_t i = 1; i < path.size(); ++i)
      cv::line(img, px(path[i - 1]), px(path[i]), cv::Scalar(0, 0, 220), 4, cv::LINE_AA);
  }
  cv::circle(img, px(start), 6, cv::Scalar(0, 170, 0), cv::FILLED);
  cv::circle(img, px(goal), 6, cv::Scalar(0, 0, 220), cv::FILLED);
  return img;
}

void runPlanGrid(const PlanOptions& opt) {
  if (opt.start.empty() || opt.goal.empty()) throw InputError("--grid needs --start X,Y and --goal X,Y");
  if (!opt.planner.empty() && opt.planner != "agnostic") {
    throw InputError("--planner: '" + opt.planner + "' needs a scene's feature map; with --grid only 'agnostic' runs");
  }
  planner::TopoPlannerConfig config;
  config.robot_radius_m = opt.robot_radius_m;
  config.max_classes = opt.max_classes;
  try {
    config.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--robot-radius/--max-classes: ") + e.what());
  }
  const planner::OccupancyGrid2D grid = harness::loadGridMap(opt.grid, opt.resolution_m);
  const std::vector<double> s = parseNumbers(opt.start, 2, "--start", "X,Y (metres, map frame)");
  const std::vector<double> g = parseNumbers(opt.goal, 2, "--goal", "X,Y (metres, map frame)");
  const Eigen::Vector2d start(s[0], s[1]);
  const Eigen::Vector2d goal(g[0], g[1]);

  const auto t0 = std::chrono::steady_clock::now();
  const planner::TopologicalPlanner topo(grid, config);
  const planner::TopoPlan plan = topo.solve(start, goal);
  const double plan_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (plan.status == planner::PlanStatus::kInvalidStart || plan.status == planner::PlanStatus::kInvalidGoal) {
    const bool is_start = plan.status == planner::PlanStatus::kInvalidStart;
    std::ostringstream msg;
    msg << (is_start ? "--start" : "--goal") << ": '" << (is_start ? opt.start : opt.goal) << "' in " << opt.grid
        << " is outside the map, in an obstacle or within the robot radius (" << config.robot_radius_m << " m) of one";
    throw InputError(msg.str());
  }

  nlohmann::ordered_json j;
  j["planner"] = "agnostic";
  j["status"] = planner::toString(plan.status);
  j["plan_time_s"] = plan_s;
  j["map"] = {{"file", opt.grid},
              {"width", grid.width},
              {"height", grid.height},
              {"resolution_m", grid.resolution_m},
              {"origin", {grid.origin_m.x(), grid.origin_m.y()}}};
  j["start"] = {start.x(), start.y()};
  j["goal"] = {goal.x(), goal.y()};
  j["robot_radius_m"] = config.robot_radius_m;
  j["class_cap"] = config.max_classes;
  j["expansions"] = plan.expansions;
  j["graph"] = {{"vertices", plan.graph.vertices.size()}, {"edges", plan.graph.edges.size()}};
  j["classes"] = nlohmann::json::array();
  for (const auto& c : plan.classes) {
    j["classes"].push_back({{"h_signature", c.h_signature}, {"length_m", c.length_m}, {"waypoints", rows(c.path)}});
  }
  j["chosen_class"] = plan.chosen >= 0 ? nlohmann::json(plan.chosen) : nlohmann::json(nullptr);
  j["path"] = plan.chosen >= 0 ? rows(plan.classes[plan.chosen].path) : nlohmann::json::array();

  const std::filesystem::path out(opt.out);
  harness::makeOutputDir(out);
  harness::writeFileAtomic(out / "plan.json", j.dump(2) + "\n");
  harness::writeImageAtomic(out / "plan.png", drawPlan(grid, plan, start, goal));
  if (plan.chosen >= 0) {
    std::printf("tgnav plan: %s, %zu homology classes (cap %d), shortest %.2f m, %.3f s -> %s/{plan.json,plan.png}\n",
                planner::toString(plan.status), plan.classes.size(), config.max_classes,
                plan.classes[plan.chosen].length_m, plan_s, out.string().c_str());
  } else {
    std::printf("tgnav plan: %s (no path from start to goal), %.3f s -> %s/{plan.json,plan.png}\n",
                planner::toString(plan.status), plan_s, out.string().c_str());
  }
}

void runPlanScenario(const PlanOptions& opt) {
  if (!opt.start.empty() || !opt.goal.empty()) {
    throw InputError("--start/--goal: with --scenario, start and goal come from the scenario or its scene");
  }
  const harness::PlannerName name =
      harness::parsePlannerName(opt.planner.empty() ? "proposed" : opt.planner, "--planner");
  if (opt.samples != 0 && name != harness::PlannerName::kRrtStar) {
    throw InputError("--samples: only the rrtstar planner takes a sample budget");
  }
  if (opt.samples < 0) throw InputError("--samples: " + std::to_string(opt.samples) + " must be >= 1");
  if (opt.seed < -1) throw InputError("--seed: " + std::to_string(opt.seed) + " must be >= 0");
  const harness::Scenario scenario = harness::loadScenario(opt.scenario);
  const std::uint64_t seed = opt.seed >= 0 ? static_cast<std::uint64_t>(opt.seed) : scenario.seed;
  const std::filesystem::path out(opt.out);
  const planner::FeatureMap map = harness::loadSceneFeatureMap(scenario.scene, opt.map, opt.map_cache, "tgnav plan");
  const harness::PlanRun run = harness::runPlanner(scenario, map, name, seed, opt.samples);
  harness::makeOutputDir(out);
  const planner::TrajectoryReport& tr = run.trajectory;
  if (tr.trajectory) {
    harness::writeFileAtomic(out / "trajectory.csv", harness::trajectoryCsv(harness::setpoints(
                                                         run, scenario.planner.trajectory.sample_rate_hz)));
  }
  harness::writeFileAtomic(out / "plan.json", harness::planJson(scenario, run).dump(2) + "\n");
  harness::writeImageAtomic(out / "plan.png", harness::drawPlanImage(scenario, map, run));
  const planner::Plan& plan = run.report.plan;
  if (plan.chosen >= 0) {
    const planner::CandidatePath& c = plan.candidates[static_cast<std::size_t>(plan.chosen)];
    std::printf(
        "tgnav plan: %s %s, %zu homology classes, chose class %d (%.2f m, c_p,min %.1f), %.3f s; "
        "trajectory %s (%.1f s, clearance %.2f m, %.3f s) -> %s/{plan.json,plan.png%s}\n",
        harness::toString(name), planner::toString(plan.status), run.report.topo.classes.size(),
        run.chosen_topology_class, c.length_m, c.c_p_min, run.plan_time_s(), planner::toString(tr.status),
        tr.duration_s, tr.min_clearance_m, run.trajectory_s, out.string().c_str(),
        tr.trajectory ? ",trajectory.csv" : "");
    if (tr.status == planner::TrajectoryStatus::kFallback) {
      std::fprintf(stderr,
                   "tgnav plan: trajectory optimisation failed (%s); trajectory.csv flies the path itself, "
                   "stopping at every point\n",
                   tr.reason.c_str());
    }
    if (!tr.trajectory) throw std::runtime_error("trajectory: " + tr.reason + " (plan.json and plan.png written)");
  } else {
    std::printf("tgnav plan: %s %s (no path from start to goal), %.3f s -> %s/{plan.json,plan.png}\n",
                harness::toString(name), planner::toString(plan.status), run.plan_time_s(), out.string().c_str());
  }
}

}  // namespace

void addPlanCommand(CLI::App& app) {
  auto opt = std::make_shared<PlanOptions>();
  CLI::App* cmd = app.add_subcommand(
      "plan",
      "Plan on a scene's feature map (--scenario) or on a 2D occupancy grid (--grid); writes plan.json, plan.png");
  auto* scenario = cmd->add_option("--scenario", opt->scenario, "Scenario YAML (configs/scenarios/*.yaml)");
  auto* grid = cmd->add_option("--grid", opt->grid, "ROS map_server .yaml (+ .pgm) or MovingAI .map");
  scenario->excludes(grid);
  cmd->add_option("--planner", opt->planner,
                  "proposed | agnostic | rrtstar (default: proposed with --scenario, agnostic with --grid)");
  cmd->add_option("--samples", opt->samples, "rrtstar: iteration budget N (default: planner config)");
  cmd->add_option("--seed", opt->seed, "Random seed (default: the scenario's)");
  cmd->add_option("--map", opt->map, "Feature map folder from `tgnav map` (default: cached by content)");
  cmd->add_option("--map-cache", opt->map_cache,
                  "Cache folder for feature maps (default: $TGNAV_CACHE_DIR or ~/.cache/tgnav)");
  cmd->add_option("--start", opt->start, "--grid: start X,Y in metres (map frame, y up)");
  cmd->add_option("--goal", opt->goal, "--grid: goal X,Y in metres (map frame, y up)");
  cmd->add_option("--resolution", opt->resolution_m, "--grid: metres per cell of a MovingAI map")
      ->capture_default_str();
  cmd->add_option("--robot-radius", opt->robot_radius_m, "--grid: clearance kept from obstacles, metres")
      ->capture_default_str();
  cmd->add_option("--max-classes", opt->max_classes, "--grid: cap on the homology classes searched")
      ->capture_default_str();
  cmd->add_option("--out", opt->out, "Output directory")->required();
  cmd->callback([opt] {
    if (opt->scenario.empty() == opt->grid.empty()) throw InputError("plan: give one of --scenario FILE or --grid MAP");
    if (opt->grid.empty()) {
      runPlanScenario(*opt);
    } else {
      runPlanGrid(*opt);
    }
  });
}

}  // namespace tgnav::cli
