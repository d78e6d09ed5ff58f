// Topological planning (EDT + GVD + graph + homology classes + shortening) on the gallery scene
// rasterised at 5 cm at flight height: 440 x 400 cells, start and goal from the scene.
#include <benchmark/benchmark.h>

#include "harness/mujoco_sim.h"
#include "harness/scene_config.h"
#include "harness/scene_geometry.h"
#include "planner/topological_planner.h"

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

}  // namespace
}  // namespace tgnav::harness

BENCHMARK_MAIN();
