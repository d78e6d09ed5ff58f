#include "harness/run/map_builder.h"

#include <chrono>
#include <cmath>
#include <cstring>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "harness/base/clock.h"
#include "harness/base/errors.h"
#include "harness/base/ordered_worker.h"
#include "harness/run/incremental_map.h"
#include "harness/sim/camera.h"
#include "harness/sim/mujoco_sim.h"
#include "harness/sim/scene_geometry.h"
#include "harness/sim/vehicle_model.h"

namespace tgnav::harness {

namespace {

using Clock = std::chrono::steady_clock;
// Rotor tips of models/quadrotor.xml (0.25 m arm + 0.12 m propeller), rounded down: the start
// and goal of a scene must leave at least this much room (a property of the scene, checked the
// same whatever vehicle flies it).
constexpr double kVehicleRadiusM = 0.3;
// Survey frames rendered ahead of their integration (bounds the memory of a fast renderer).
constexpr std::size_t kSurveyQueueFrames = 4;

}  // namespace

std::vector<planner::Pose4> surveyPoses(const SceneConfig& scene, const SceneGeometry& geometry) {
  const SurveyPlan& plan = scene.survey;
  std::vector<planner::Pose4> poses;
  const Eigen::Vector3d lo = scene.bounds_min_m;
  const Eigen::Vector3d hi = scene.bounds_max_m;
  // Grid centred in the bounds so that margins are equal on both sides.
  const int nx = static_cast<int>(std::floor((hi.x() - lo.x()) / plan.spacing_m));
  const int ny = static_cast<int>(std::floor((hi.y() - lo.y()) / plan.spacing_m));
  const double x0 = 0.5 * (lo.x() + hi.x()) - 0.5 * nx * plan.spacing_m;
  const double y0 = 0.5 * (lo.y() + hi.y()) - 0.5 * ny * plan.spacing_m;
  for (double z : plan.heights_m) {
    for (int i = 0; i <= nx; ++i) {
      for (int j = 0; j <= ny; ++j) {
        const Eigen::Vector3d p(x0 + i * plan.spacing_m, y0 + j * plan.spacing_m, z);
        if (geometry.signedDistance(p) < plan.clearance_m) continue;
        for (int k = 0; k < plan.yaw_count; ++k) {
          planner::Pose4 pose;
          pose.p_WB = p;
          pose.yaw_rad = -M_PI + 2.0 * M_PI * k / plan.yaw_count;
          poses.push_back(pose);
        }
      }
    }
  }
  if (poses.empty()) {
    throw InputError(scene.source.string() +
                     ": survey plan has no free pose (every grid position is within "
                     "survey.clearance_m of geometry)");
  }
  return poses;
}

planner::FeatureMap buildFeatureMap(const SceneConfig& scene, const MapBuildConfig& config, MapBuildStats* stats_out,
                                    const std::function<void(int, int)>& progress) {
  config.validate();
  const auto t_start = Clock::now();
  MapBuildStats stats;
  // The scene's own vehicle carries the survey camera, whatever vehicle a scenario flies: the
  // map is of the scene.
  VehicleModel vehicle = loadVehicleModel(scene.mjcf, scene.vehicle);
  ModelPtr model = std::move(vehicle.model);
  DataPtr data = makeData(model.get());
  mj_forward(model.get(), data.get());
  const SceneGeometry geometry(model.get(), data.get());
  checkStartGoalFree(scene, geometry, kVehicleRadiusM);
  const std::vector<planner::Pose4> poses = surveyPoses(scene, geometry);
  stats.survey_positions = static_cast<int>(poses.size()) / scene.survey.yaw_count;
  const VehicleIds& ids = vehicle.ids;
  EglContext gl;
  Camera camera(model.get(), gl, config.camera.on(vehicle.vehicle.camera), 0);
  const Intrinsics& k = camera.intrinsics();
  IncrementalMapper mapper(config, k);

  // This thread renders the survey; a worker integrates the frames in order (depth into the
  // occupancy, keypoints into the landmark tracks) while the next ones render: the same map as one
  // thread doing both in turn. The two touch different fields of `stats`.
  OrderedWorker<RgbdFrame> integrator(kSurveyQueueFrames, [&](RgbdFrame& frame) {
    Clock::time_point t0 = Clock::now();
    mapper.insertDepth(frame, config.occupancy_stride_px);
    stats.integrate_s += secondsSince(t0);
    t0 = Clock::now();
    mapper.observeFeatures(frame);
    stats.features_s += secondsSince(t0);
  });
  for (std::size_t f = 0; f < poses.size(); ++f) {
    const Clock::time_point t0 = Clock::now();
    setVehiclePose(model.get(), data.get(), ids, poses[f]);
    RgbdFrame frame = camera.render(data.get());
    stats.render_s += secondsSince(t0);
    integrator.submit(std::move(frame));
    ++stats.frames;
    if (progress) progress(static_cast<int>(f + 1), static_cast<int>(poses.size()));
  }
  integrator.finish();

  stats.keypoints = mapper.keypoints();
  stats.observations = mapper.observations();
  stats.landmarks_merged = mapper.tracks();
  IncrementalMapper::Built built = mapper.release();
  stats.dropped_few_observations = built.dropped_few_observations;
  stats.opportunities_s = built.opportunities_s;
  stats.dropped_not_embedded = built.dropped_not_embedded;
  planner::FeatureMap map = std::move(built.map);
  stats.landmarks = static_cast<int>(map.landmarks().size());
  for (const planner::Landmark& lm : map.landmarks()) stats.mean_detectability += lm.detectability();
  if (stats.landmarks > 0) stats.mean_detectability /= stats.landmarks;
  stats.total_s = secondsSince(t_start);
  if (stats_out != nullptr) *stats_out = stats;
  return map;
}

}  // namespace tgnav::harness
