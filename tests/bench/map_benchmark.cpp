// Visibility queries on the smoke scene's feature map (built once, from rendering).
#include <benchmark/benchmark.h>

#include <random>

#include "harness/run/map_builder.h"
#include "harness/sim/mujoco_sim.h"
#include "harness/sim/scene_geometry.h"

namespace tgnav::harness {
namespace {

struct SmokeMap {
  SmokeMap()
      : scene(loadSceneConfig(std::string(TGNAV_SOURCE_DIR) + "/configs/scenes/smoke.yaml")),
        map(buildFeatureMap(scene, MapBuildConfig{}, nullptr)) {
    ModelPtr model = loadModel(scene.mjcf);
    DataPtr data = makeData(model.get());
    mj_forward(model.get(), data.get());
    const SceneGeometry geometry(model.get(), data.get());
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> x(scene.bounds_min_m.x(), scene.bounds_max_m.x());
    std::uniform_real_distribution<double> y(scene.bounds_min_m.y(), scene.bounds_max_m.y());
    while (queries.size() < 200) {
      const Eigen::Vector3d p(x(rng), y(rng), scene.flight_height_m);
      if (geometry.signedDistance(p) > 0.4) queries.push_back(p);
    }
  }
  SceneConfig scene;
  planner::FeatureMap map;
  std::vector<Eigen::Vector3d> queries;
};

SmokeMap& smokeMap() {
  static SmokeMap instance;
  return instance;
}

void BM_VisibleFrom(benchmark::State& state) {
  SmokeMap& s = smokeMap();
  const planner::VisibilityConfig config;
  std::size_t i = 0;
  long visible = 0;
  for (auto _ : state) {
    visible += static_cast<long>(s.map.visibleFrom(s.queries[i++ % s.queries.size()], config).size());
  }
  state.counters["queries_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["landmarks_per_query"] = static_cast<double>(visible) / state.iterations();
}
BENCHMARK(BM_VisibleFrom)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace tgnav::harness

BENCHMARK_MAIN();
