// Topological planning (EDT + GVD + graph + homology classes + shortening) on the gallery scene
// rasterised at 5 cm at flight height: 440 x 400 cells, start and goal from the scene. And on
// benchmark-sized grid maps (`tgnav plan --grid`), made by the tests' generators: a map's
// preprocessing (working grid, distance field, GVD) and then its queries, timed apart. And the
// cost of asking an external planner (docs/PLANNER_PROTOCOL.md) beyond the planner's own time.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <fstream>

#include "../planner/grid_maps.h"
#include "harness/config/scenario.h"
#include "harness/config/scene_config.h"
#include "harness/run/external_plan.h"
#include "harness/run/map_cache.h"
#include "harness/run/plan_run.h"
#include "harness/sim/mujoco_sim.h"
#include "harness/sim/scene_geometry.h"
#include "planner/topological_planner.h"
#include "planner/trajectory_generator.h"

namespace tgnav::harness {
namespace {

struct GalleryGrid {
  GalleryGrid() : scene(loadSceneConfig(std::string(TGNAV_SOURCE_DIR) + "/configs/scenes/gallery.yaml")) {
    ModelPtr model = loadModel(scene.mjcf);
    DataPtr data = makeData(model.get());
    mj_forward(model.get(), data.get());
    const SceneGeometry geometry(model.get(), data.get());
    const double res = 0.05;
    const Eigen::Vector2d lo = scene.bounds_min_m.head<2>();
    const Eigen::Vector2d extent = scene.bounds_max_m.head<2>() - lo;
    grid = planner::OccupancyGrid2D(static_cast<int>(std::lround(extent.x() / res)),
                                    static_cast<int>(std::lround(extent.y() / res)), res, lo);
    for (int y = 0; y < grid.height; ++y) {
      for (int x = 0; x < grid.width; ++x) {
        const Eigen::Vector2d c = grid.centreOf(x, y);
        grid.set(x, y, geometry.signedDistance({c.x(), c.y(), scene.flight_height_m}) < 0.0);
      }
    }
  }
  SceneConfig scene;
  planner::OccupancyGrid2D grid;
};

void BM_TopologicalPlanGallery(benchmark::State& state) {
  static const GalleryGrid g;
  int classes = 0;
  for (auto _ : state) {
    const planner::TopologicalPlanner planner(g.grid, planner::TopoPlannerConfig{});
    const planner::TopoPlan plan = planner.solve(g.scene.start.p_WB.head<2>(), g.scene.goal.p_WB.head<2>());
    classes = static_cast<int>(plan.classes.size());
  }
  state.counters["ms_per_plan"] = benchmark::Counter(static_cast<double>(state.iterations()) / 1000.0,
                                                     benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["classes"] = classes;
  state.counters["cells"] = static_cast<double>(g.grid.width) * g.grid.height;
}
BENCHMARK(BM_TopologicalPlanGallery)->Unit(benchmark::kMillisecond)->UseRealTime();

// 0: game-like, 530 x 481 at 1 m, 160 building blocks; 1: 530 x 481 rooms of 12 cells with
// one-cell doors; 2: a map_server-sized 2000 x 2000 at 0.05 m with 300 blocks; 3: a warehouse
// like MovingAI's warehouse-10-20-10-2-1, 159 x 61 (161 x 63 with its border) at 1 m, 200 shelves
// of 10 x 2 cells, one-cell aisles. Robot radius 0.3 m.
planner::OccupancyGrid2D benchGrid(int kind) {
  using namespace planner::testmaps;
  if (kind == 0) return gridFromMovingAi(blocksMap(530, 481, 160, 1), 1.0);
  if (kind == 1) return gridFromMovingAi(roomsMap(530, 481, 12, 1), 1.0);
  if (kind == 3) return gridFromMovingAi(warehouseMap(10, 20, 10, 2, 1, 25, 1), 1.0);
  return gridFromMovingAi(blocksMap(2000, 2000, 300, 1), 0.05);
}

void BM_GridPreprocess(benchmark::State& state) {
  const planner::OccupancyGrid2D grid = benchGrid(static_cast<int>(state.range(0)));
  planner::TopoPlannerConfig config;
  int k = 0;
  for (auto _ : state) {
    const planner::TopologicalPlanner planner(grid, config);
    k = planner.workingFactor();
  }
  state.counters["cells"] = static_cast<double>(grid.width) * grid.height;
  state.counters["working_factor"] = k;
}
BENCHMARK(BM_GridPreprocess)
    ->Arg(0)
    ->Arg(1)
    ->Arg(2)
    ->Arg(3)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);

// Ten random reachable queries per iteration on one preprocessed map: ms per query.
void BM_GridQuery(benchmark::State& state) {
  const planner::OccupancyGrid2D grid = benchGrid(static_cast<int>(state.range(0)));
  planner::TopoPlannerConfig config;
  const planner::TopologicalPlanner planner(grid, config);
  const auto queries = planner::testmaps::randomQueries(grid, 10, config.robot_radius_m, 3, /*connected_only=*/true);
  int solved = 0;
  for (auto _ : state) {
    solved = 0;
    for (const auto& [s, g] : queries) {
      solved += planner.solve(grid.centreOf(s.x(), s.y()), grid.centreOf(g.x(), g.y())).status ==
                planner::PlanStatus::kSolved;
    }
  }
  state.counters["ms_per_query"] = benchmark::Counter(static_cast<double>(state.iterations()) * queries.size() / 1000.0,
                                                      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["solved"] = solved;
}
BENCHMARK(BM_GridQuery)->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

// Trajectory generation (B-spline position + yaw optimisation, checks) for the shortest gallery
// class of at least 40 m, with the yaw along the direction of travel, at the default settings.
void BM_TrajectoryGallery40m(benchmark::State& state) {
  static const GalleryGrid g;
  static const planner::TopologicalPlanner topo(g.grid, planner::TopoPlannerConfig{});
  static const planner::TopoPlan plan = topo.solve(g.scene.start.p_WB.head<2>(), g.scene.goal.p_WB.head<2>());
  std::size_t best = plan.classes.size() - 1;  // sorted by length
  for (std::size_t i = plan.classes.size(); i-- > 0;) {
    if (plan.classes[i].length_m >= 40.0) best = i;
  }
  const auto& path = plan.classes[best].path;
  planner::TrajectoryRequest request;
  for (std::size_t i = 0; i < path.size(); ++i) {
    const Eigen::Vector2d d = path[std::min(i + 1, path.size() - 1)] - path[i == path.size() - 1 ? i - 1 : i];
    request.path.push_back(
        {Eigen::Vector3d(path[i].x(), path[i].y(), g.scene.flight_height_m), std::atan2(d.y(), d.x())});
  }
  request.start_yaw_rad = g.scene.start.yaw_rad;
  request.obstacle_points = &plan.obstacle_points;
  const planner::PlanarClearance field(topo.field());
  planner::TrajectoryReport report;
  for (auto _ : state) report = planner::generateTrajectory(request, field, planner::TrajectoryConfig{});
  state.counters["ms_per_trajectory"] = benchmark::Counter(static_cast<double>(state.iterations()) / 1000.0,
                                                           benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["path_length_m"] = plan.classes[best].length_m;
  state.counters["duration_s"] = report.duration_s;
  state.counters["iterations"] = report.iterations;
  state.counters["optimised"] = report.status == planner::TrajectoryStatus::kOptimised;
}
BENCHMARK(BM_TrajectoryGallery40m)->Unit(benchmark::kMillisecond)->UseRealTime();

// One external plan request on the smoke scenario (its feature map from the cache, built on first
// use; the fixed route goes around the pillar), from writing the map slice to the route checked: Arg(0) a /bin/sh
// planner that answers a fixed path at once (the protocol's own cost: process start, request, response, parse, checks),
// Arg(1) the same from Python (tests/data/planners/fake_planner.py fixed; adds the interpreter's
// start-up). ms_overhead = the whole call less the planner's reported solve_time_s (0).
void BM_ExternalPlannerOverhead(benchmark::State& state) {
  const std::string src = TGNAV_SOURCE_DIR;
  Scenario scenario = loadScenario(src + "/configs/scenarios/smoke.yaml");
  const std::string response =
      R"({"protocol":"tgnav-planner","version":1,"id":1,"status":"ok","path":[[-3,0,1,0],[-1,-1.2,1,0],)"
      R"([1,-1.2,1,0],[3,0,1,0]],)"
      R"("solve_time_s":0})";
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "tgnav-bench-external";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "path.json") << "[[-3,0,1,0],[-1,-1.2,1,0],[1,-1.2,1,0],[3,0,1,0]]\n";
  scenario.planner.external.dir = dir.string();
  scenario.planner.external.command =
      state.range(0) == 0 ? "read line; printf '%s\\n' '" + response + "'; read line"
                          : "/usr/bin/python3 " + src + "/tests/data/planners/fake_planner.py fixed path.json";
  std::filesystem::path map_dir;
  const planner::FeatureMap map = loadSceneFeatureMap(scenario.scene, "", "", "planner_benchmark", &map_dir);
  PlanRun run;
  buildPlanningVoxels(scenario, map, &run);
  double total_s = 0.0;
  double overhead_s = 0.0;
  bool ok = true;
  for (auto _ : state) {
    const ExternalPlan plan = askExternalPlanner(scenario, map_dir, *run.voxels, 1);
    ok = ok && plan.ok;
    if (!plan.ok) state.SetLabel(plan.detail);
    total_s += plan.total_s();
    overhead_s += plan.total_s() - plan.planner_s.value_or(0.0);
  }
  const auto n = static_cast<double>(state.iterations());
  state.counters["ms_total"] = 1000.0 * total_s / n;
  state.counters["ms_overhead"] = 1000.0 * overhead_s / n;
  state.counters["solved"] = ok ? 1 : 0;
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_ExternalPlannerOverhead)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace tgnav::harness

BENCHMARK_MAIN();
