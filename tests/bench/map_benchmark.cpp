// Visibility queries on the smoke scene's feature map (built once, from rendering), and the online
// mapper's depth insertion down gallery's north corridor.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "harness/config/scene_config.h"
#include "harness/run/incremental_map.h"
#include "harness/run/map_builder.h"
#include "harness/sim/camera.h"
#include "harness/sim/mujoco_sim.h"
#include "harness/sim/scene_geometry.h"
#include "harness/sim/vehicle_model.h"

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

// Keyframes of a flight west along gallery's north corridor (22 m long, its far end beyond the
// camera's 10 m: a tenth of each image has no depth), with the D435-like depth noise.
struct CorridorFrames {
  CorridorFrames() {
    const SceneConfig scene = loadSceneConfig(std::string(TGNAV_SOURCE_DIR) + "/configs/scenes/gallery.yaml");
    VehicleModel vehicle = loadVehicleModel(scene.mjcf);
    DataPtr data = makeData(vehicle.model.get());
    EglContext gl;
    camera_config.depth_noise_sigma_per_m2 = 0.002;
    Camera camera(vehicle.model.get(), gl, camera_config.on("front"), 0);
    CameraNoise noise(camera_config, 1);
    k = camera.intrinsics();
    for (int i = 0; i < 8; ++i) {
      const planner::Pose4 pose{Eigen::Vector3d(4.0 - 0.5 * i, 8.4, 1.0), M_PI - 0.05 * (i % 3)};
      setVehiclePose(vehicle.model.get(), data.get(), vehicle.ids, pose);
      RgbdFrame frame = camera.render(data.get());
      noise.apply(&frame);
      frames.push_back(std::move(frame));
    }
  }
  CameraConfig camera_config;
  Intrinsics k;
  std::vector<RgbdFrame> frames;
};

// The online mapper's occupancy update (trial.map_range_m 10, map_short_of_surface, every 8th
// pixel), from an empty map each iteration; state.range(0) = 1: with trial.map_clear_no_return.
void BM_InsertDepthDownCorridor(benchmark::State& state) {
  static CorridorFrames corridor;
  MapBuildConfig config;
  config.max_range_m = 10.0;
  config.free_short_of_surface = true;
  config.no_return_depth_m = state.range(0) != 0 ? noReturnDepth(corridor.camera_config) : 0.0;
  for (auto _ : state) {
    IncrementalMapper mapper(config, corridor.k);
    for (const RgbdFrame& f : corridor.frames) mapper.insertDepth(f, 8);
    benchmark::DoNotOptimize(mapper.occupancy().size());
  }
  state.counters["ms_per_frame"] =
      benchmark::Counter(static_cast<double>(state.iterations() * corridor.frames.size()) / 1000.0,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_InsertDepthDownCorridor)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace tgnav::harness

BENCHMARK_MAIN();
