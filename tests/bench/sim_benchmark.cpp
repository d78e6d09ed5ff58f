// Rendering (RGB-D through EGL/llvmpipe) and physics stepping on the smoke scene.
#include <benchmark/benchmark.h>

#include <cmath>

#include "control/cascade.h"
#include "harness/config/config_io.h"
#include "harness/config/scene_config.h"
#include "harness/sim/camera.h"
#include "harness/sim/flight_loop.h"
#include "harness/sim/mujoco_sim.h"
#include "harness/sim/vehicle_model.h"

namespace tgnav::harness {
namespace {

struct Smoke {
  Smoke() {
    const SceneConfig scene = loadSceneConfig(std::string(TGNAV_SOURCE_DIR) + "/configs/scenes/smoke.yaml");
    VehicleModel vehicle = loadVehicleModel(scene.mjcf);
    model = std::move(vehicle.model);
    data = makeData(model.get());
    ids = vehicle.ids;
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
  Camera camera(smoke.model.get(), gl, config.on("front"), 0);  // models/quadrotor.yaml's camera
  camera.render(smoke.data.get());                              // first frame compiles shaders
  int i = 0;
  for (auto _ : state) {
    planner::Pose4 pose = smoke.start;
    pose.yaw_rad = 0.01 * (i++ % 100);  // a new view every frame
    setVehiclePose(smoke.model.get(), smoke.data.get(), smoke.ids, pose);
    benchmark::DoNotOptimize(camera.render(smoke.data.get()));
  }
  state.counters["ms_per_frame"] = benchmark::Counter(static_cast<double>(state.iterations()) / 1000.0,
                                                      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_RenderRgbd)->Args({320, 240})->Args({640, 480})->Unit(benchmark::kMillisecond)->UseRealTime();

// The camera noise of a D435-like sensor (configs/scenarios/*.yaml: sigma 2 levels, 0.002 z^2) on
// one frame: about 1.2 M Gaussian samples at 640x480.
void BM_CameraNoise(benchmark::State& state) {
  CameraConfig config;
  config.rgb_noise_sigma = 2.0;
  config.depth_noise_sigma_per_m2 = 0.002;
  CameraNoise noise(config, 1);
  const int w = static_cast<int>(state.range(0));
  const int h = static_cast<int>(state.range(1));
  RgbdFrame clean;
  clean.bgr = cv::Mat(h, w, CV_8UC3, cv::Scalar(90, 128, 170));
  clean.depth_m = cv::Mat(h, w, CV_32FC1, cv::Scalar(3.0));
  RgbdFrame frame;
  for (auto _ : state) {
    state.PauseTiming();
    clean.bgr.copyTo(frame.bgr);
    clean.depth_m.copyTo(frame.depth_m);
    state.ResumeTiming();
    noise.apply(&frame);
    benchmark::DoNotOptimize(frame.bgr.data);
  }
  state.counters["ms_per_frame"] = benchmark::Counter(static_cast<double>(state.iterations()) / 1000.0,
                                                      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_CameraNoise)->Args({320, 240})->Args({640, 480})->Unit(benchmark::kMillisecond);

void BM_PhysicsStep(benchmark::State& state) {
  Smoke smoke;
  const double hover = vehicleMass(smoke.model.get(), smoke.ids) * 9.81 / 4.0;
  for (int i = 0; i < 4; ++i) {
    smoke.data->ctrl[smoke.ids.motors[i]] = hover;
    smoke.data->act[smoke.ids.motor_act[i]] = hover;
  }
  for (auto _ : state) mj_step(smoke.model.get(), smoke.data.get());
  state.counters["us_per_step"] = benchmark::Counter(static_cast<double>(state.iterations()) / 1e6,
                                                     benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_PhysicsStep)->Unit(benchmark::kMicrosecond);

// One full controller cycle (position + attitude + rate + allocation), no simulator.
void BM_ControllerCycle(benchmark::State& state) {
  Smoke smoke;
  control::Cascade cascade(control::CascadeConfig{}, vehicleParamsFromModel(smoke.model.get(), smoke.ids));
  control::VehicleState s = vehicleState(smoke.data.get(), smoke.ids);
  control::TrajectorySetpoint sp;
  sp.p_WB = s.p_WB + Eigen::Vector3d(0.3, -0.2, 0.1);
  for (auto _ : state) {
    cascade.updatePosition(s, sp, 0.01);
    cascade.updateAttitude(s.q_WB);
    benchmark::DoNotOptimize(cascade.updateRate(s.w_B, 0.002));
  }
  state.counters["us_per_cycle"] = benchmark::Counter(static_cast<double>(state.iterations()) / 1e6,
                                                      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ControllerCycle)->Unit(benchmark::kMicrosecond);

// Closed-loop flight in the smoke scene without rendering: physics at 500 Hz, cascade at its
// rates; reports simulated seconds per wall-clock second.
void BM_ClosedLoopNoRender(benchmark::State& state) {
  Smoke smoke;
  FlightLoop loop(smoke.model.get(), smoke.data.get(), smoke.ids,
                  loadCascadeConfig(std::string(TGNAV_SOURCE_DIR) + "/configs/controller.yaml"));
  control::TrajectorySetpoint sp;
  sp.p_WB = smoke.start.p_WB;
  const double hover = vehicleMass(smoke.model.get(), smoke.ids) * 9.81 / 4.0;
  for (int i = 0; i < 4; ++i) smoke.data->act[smoke.ids.motor_act[i]] = hover;
  long steps = 0;
  for (auto _ : state) {
    sp.p_WB.y() = 0.5 * std::sin(0.5 * smoke.data->time);
    loop.step(sp);
    ++steps;
  }
  state.counters["real_time_factor"] =
      benchmark::Counter(static_cast<double>(steps) * smoke.model->opt.timestep, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ClosedLoopNoRender)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace
}  // namespace tgnav::harness

BENCHMARK_MAIN();
