// Topological planning (EDT + GVD + graph + homology classes + shortening) on the gallery scene
// rasterised at 5 cm at flight height: 440 x 400 cells, start and goal from the scene.
#include <benchmark/benchmark.h>

#include "harness/config/scene_config.h"
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

}  // namespace
}  // namespace tgnav::harness

BENCHMARK_MAIN();
