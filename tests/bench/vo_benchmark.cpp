// Visual odometry speed and accuracy on a rendered sequence: the smoke scene's flight around the
// pillar (configs/trajectories/smoke_around_pillar.csv up to 1.5 m short of the east wall), 20 Hz,
// camera noise on (rgb sigma 2, depth 0.002 z^2), at 320x240 and 640x480. Ours (vo/odometry.h)
// against OpenCV contrib's cv::rgbd::RgbdOdometry (dense photometric + depth) on the same frames.
// Ours with local bundle adjustment (ba 1, the default) and without (ba 0); the time includes BA,
// amortised over the frames. Counters: ms per frame, ATE after SE(3) alignment and the final
// (goal) error anchored at the first frame, both in % of the distance travelled.
#include <benchmark/benchmark.h>

#include <chrono>
#include <map>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <opencv2/rgbd.hpp>

#include "harness/config/scene_config.h"
#include "harness/io/trajectory_csv.h"
#include "harness/sim/camera.h"
#include "harness/sim/egl_context.h"
#include "harness/sim/mujoco_sim.h"
#include "harness/sim/vehicle_model.h"
#include "vo/metrics.h"
#include "vo/odometry.h"

namespace tgnav::harness {
namespace {

struct Sequence {
  std::vector<RgbdFrame> frames;
  Intrinsics intrinsics;
};

const Sequence& sequence(int width) {
  static std::map<int, Sequence> cache;
  auto it = cache.find(width);
  if (it != cache.end()) return it->second;
  const SceneConfig scene = loadSceneConfig(std::string(TGNAV_SOURCE_DIR) + "/configs/scenes/smoke.yaml");
  const control::SetpointTrajectory traj =
      readTrajectoryCsv(std::string(TGNAV_SOURCE_DIR) + "/configs/trajectories/smoke_around_pillar.csv");
  VehicleModel vehicle = loadVehicleModel(scene.mjcf);
  ModelPtr model = std::move(vehicle.model);
  DataPtr data = makeData(model.get());
  const VehicleIds& ids = vehicle.ids;
  static const EglContext gl;
  CameraConfig config;
  config.width_px = width;
  config.height_px = width * 3 / 4;
  config.rgb_noise_sigma = 2.0;
  config.depth_noise_sigma_per_m2 = 0.002;
  Camera camera(model.get(), gl, config.on(vehicle.vehicle.camera), 7);
  Sequence s;
  s.intrinsics = camera.intrinsics();
  for (double t = traj.startTime(); t <= traj.endTime(); t += 0.05) {
    const control::TrajectorySetpoint sp = traj.sample(t);
    if (sp.p_WB.x() > 2.5) break;
    setVehiclePose(model.get(), data.get(), ids, planner::Pose4{sp.p_WB, sp.yaw_rad});
    RgbdFrame f = camera.render(data.get());
    f.t_s = t;
    s.frames.push_back(std::move(f));
  }
  return cache.emplace(width, std::move(s)).first->second;
}

void report(benchmark::State& state, const Sequence& s, const std::vector<vo::StampedPose>& est, int lost,
            double seconds, int frames) {
  std::vector<vo::StampedPose> gt;
  for (const RgbdFrame& f : s.frames) gt.push_back({f.t_s, f.X_WC});
  const auto pairs = vo::associate(est, gt);
  const double distance = vo::distanceTravelled(pairs);
  state.counters["ms_per_frame"] = 1e3 * seconds / frames;
  state.counters["ate_percent"] = 100.0 * vo::absoluteTrajectoryError(pairs, true).rmse_m / distance;
  state.counters["goal_error_percent"] = 100.0 * vo::goalError(pairs) / distance;
  state.counters["lost_frames"] = lost;
  state.counters["frames"] = static_cast<double>(s.frames.size());
}

void BM_VoOurs(benchmark::State& state) {
  const Sequence& s = sequence(static_cast<int>(state.range(0)));
  const Intrinsics& k = s.intrinsics;
  std::vector<vo::StampedPose> est;
  int lost = 0, frames = 0;
  double seconds = 0.0;
  for (auto _ : state) {
    vo::OdometryConfig config;
    config.ba.enabled = state.range(1) != 0;
    vo::RgbdOdometry odometry(k, config, s.frames.front().X_WC);
    est.clear();
    lost = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (const RgbdFrame& f : s.frames) {
      const vo::FrameResult r = odometry.track(f.t_s, f.bgr, f.depth_m);
      lost += r.status == vo::TrackingStatus::kLost;
      if (r.status != vo::TrackingStatus::kLost) est.push_back({f.t_s, r.X_WC});
    }
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    frames += static_cast<int>(s.frames.size());
  }
  report(state, s, est, lost, seconds, frames);
}
BENCHMARK(BM_VoOurs)
    ->ArgNames({"width", "ba"})
    ->ArgsProduct({{320, 640}, {1, 0}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

// cv::rgbd::RgbdOdometry frame to frame; a failed frame keeps the last pose (it has no map).
void BM_VoOpenCvRgbdOdometry(benchmark::State& state) {
  const Sequence& s = sequence(static_cast<int>(state.range(0)));
  const Intrinsics& k = s.intrinsics;
  const cv::Mat K = (cv::Mat_<float>(3, 3) << k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  std::vector<vo::StampedPose> est;
  int lost = 0, frames = 0;
  double seconds = 0.0;
  for (auto _ : state) {
    cv::Ptr<cv::rgbd::RgbdOdometry> odometry = cv::rgbd::RgbdOdometry::create(K, 0.2f, 8.0f);
    est.clear();
    lost = 0;
    Eigen::Isometry3d X_WC = s.frames.front().X_WC;
    cv::Mat prev_gray, prev_depth;
    const auto t0 = std::chrono::steady_clock::now();
    for (const RgbdFrame& f : s.frames) {
      cv::Mat gray;
      cv::cvtColor(f.bgr, gray, cv::COLOR_BGR2GRAY);
      if (!prev_gray.empty()) {
        cv::Mat Rt;
        if (odometry->compute(prev_gray, prev_depth, cv::Mat(), gray, f.depth_m, cv::Mat(), Rt)) {
          Eigen::Matrix4d T;
          for (int r = 0; r < 4; ++r) {
            for (int c = 0; c < 4; ++c) T(r, c) = Rt.at<double>(r, c);
          }
          X_WC = X_WC * Eigen::Isometry3d(T);  // Rt: previous camera from current (srcRt)
        } else {
          ++lost;
        }
      }
      est.push_back({f.t_s, X_WC});
      prev_gray = gray;
      prev_depth = f.depth_m;
    }
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    frames += static_cast<int>(s.frames.size());
  }
  report(state, s, est, lost, seconds, frames);
}
BENCHMARK(BM_VoOpenCvRgbdOdometry)->Arg(320)->Arg(640)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

}  // namespace
}  // namespace tgnav::harness

BENCHMARK_MAIN();
