// Rendering (RGB-D through EGL/llvmpipe) and physics stepping on the smoke scene.
#include <benchmark/benchmark.h>

#include <cmath>

#include "harness/camera.h"
#include "harness/mujoco_sim.h"
#include "harness/scene_config.h"

namespace tgnav::harness {
namespace {

struct Smoke {
  Smoke() {
    const SceneConfig scene = loadSceneConfig(std::string(TGNAV_SOURCE_DIR) + "/configs/scenes/smoke.yaml");
    model = loadModel(scene.mjcf);
    data = makeData(model.get());
    ids = VehicleIds::find(model.get(), "smoke");
    start = scene.start;
    setVehiclePose(model.get(), data.get(), ids, start);
  }
  ModelPtr model;
  DataPtr data;
  VehicleIds ids;
  planner::Pose4 start;
};

void BM_RenderRgbd(benchmark::State& state) {
  Smoke smoke;
  EglContext gl;
  CameraConfig config;
  config.width_px = static_cast<int>(state.range(0));
  config.height_px = static_cast<int>(state.range(1));
  Camera camera(smoke.model.get(), gl, config, 0);
  camera.render(smoke.data.get());  // first frame compiles shaders
  int i = 0;
  for (auto _ : state) {
    planner::Pose4 pose = smoke.start;
    pose.yaw_rad = 0.01 * (i++ % 100);  // a new view every frame
    setVehiclePose(smoke.model.get(), smoke.data.get(), smoke.ids, pose);
    benchmark::DoNotOptimize(camera.render(smoke.data.get()));
  }
  state.counters["ms_per_frame"] =
      benchmark::Counter(static_cast<double>(state.iterations()) / 1000.0,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_RenderRgbd)->Args({320, 240})->Args({640, 480})->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_PhysicsStep(benchmark::State& state) {
  Smoke smoke;
  const double hover = vehicleMass(smoke.model.get(), smoke.ids) * 9.81 / 4.0;
  for (int i = 0; i < 4; ++i) {
    smoke.data->ctrl[smoke.ids.motors[i]] = hover;
    smoke.data->act[smoke.ids.motor_act[i]] = hover;
  }
  for (auto _ : state) mj_step(smoke.model.get(), smoke.data.get());
  state.counters["us_per_step"] =
      benchmark::Counter(static_cast<double>(state.iterations()) / 1e6,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_PhysicsStep)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace tgnav::harness

BENCHMARK_MAIN();
