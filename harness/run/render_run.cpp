#include "harness/run/render_run.h"

#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cstdio>
#include <opencv2/core.hpp>

#include "harness/base/errors.h"
#include "harness/config/config_io.h"
#include "harness/config/scene_config.h"
#include "harness/config/values.h"
#include "harness/io/staged_output.h"
#include "harness/io/tum_sequence.h"
#include "harness/sim/camera.h"
#include "harness/sim/egl_context.h"
#include "harness/sim/mujoco_sim.h"
#include "harness/sim/vehicle_model.h"

namespace tgnav::harness {

namespace {

// depth.png: millimetres.
constexpr double kDepthScale = 1000.0;

planner::Pose4 renderPose(const RenderJob& job, const SceneConfig& scene) {
  planner::Pose4 pose = scene.start;
  if (!job.pose.empty()) {
    const std::vector<double> v = parseNumbers(job.pose, 4, "--pose", "x,y,z,yaw (metres, radians)");
    pose.p_WB = Eigen::Vector3d(v[0], v[1], v[2]);
    pose.yaw_rad = v[3];
  } else if (scene.source == scene.mjcf) {
    throw InputError("--pose: required when --scene is an MJCF file (" + job.scene.string() + ")");
  }
  return pose;
}

CameraConfig renderCamera(const RenderJob& job) {
  CameraConfig c;
  if (!job.camera_config.empty()) c = loadCameraConfig(job.camera_config);
  if (job.width_px) c.width_px = *job.width_px;
  if (job.height_px) c.height_px = *job.height_px;
  try {
    c.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--width/--height: ") + e.what());
  }
  return c;
}

YAML::Node poseAndRenderer(const std::string& scene, const Eigen::Isometry3d& X_WC, const std::string& renderer) {
  const Eigen::Quaterniond q(X_WC.linear());
  YAML::Node extra(YAML::NodeType::Map);
  extra["scene"] = scene;
  extra["X_WC"]["translation_m"] =
      std::vector<double>{X_WC.translation().x(), X_WC.translation().y(), X_WC.translation().z()};
  extra["X_WC"]["translation_m"].SetStyle(YAML::EmitterStyle::Flow);
  extra["X_WC"]["quaternion_xyzw"] = std::vector<double>{q.x(), q.y(), q.z(), q.w()};
  extra["X_WC"]["quaternion_xyzw"].SetStyle(YAML::EmitterStyle::Flow);
  extra["renderer"] = renderer;
  return extra;
}

}  // namespace

std::string runRender(const RenderJob& job) {
  const SceneConfig scene = loadScene(job.scene);
  const planner::Pose4 pose = renderPose(job, scene);
  VehicleModel vehicle = loadVehicleModel(scene.mjcf, job.vehicle.empty() ? scene.vehicle : job.vehicle);
  const CameraConfig camera_config = renderCamera(job).on(vehicle.vehicle.camera);
  ModelPtr model = std::move(vehicle.model);
  DataPtr data = makeData(model.get());
  setVehiclePose(model.get(), data.get(), vehicle.ids, pose);

  EglContext gl;
  Camera camera(model.get(), gl, camera_config, job.seed);
  const auto t0 = std::chrono::steady_clock::now();
  const RgbdFrame frame = camera.render(data.get());
  const double render_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  cv::Mat depth_mm(frame.depth_m.size(), CV_16UC1);
  frame.depth_m.convertTo(depth_mm, CV_16UC1, kDepthScale);  // saturates; 0 stays invalid
  depth_mm.setTo(0, frame.depth_m > 65.535f);

  StagedDir staged(job.out);
  writeImageAtomic(staged.staging() / "rgb.png", frame.bgr);
  writeImageAtomic(staged.staging() / "depth.png", depth_mm);
  writeFileAtomic(
      staged.staging() / "intrinsics.yaml",
      intrinsicsYaml(camera.intrinsics(), kDepthScale, poseAndRenderer(job.scene.string(), frame.X_WC, gl.renderer())));
  staged.commit(OnExisting::kMerge);
  char line[512];
  std::snprintf(line, sizeof line,
                "tgnav render: %dx%d frame of %s in %.1f ms -> %s/{rgb.png,depth.png,intrinsics.yaml}",
                camera.intrinsics().width_px, camera.intrinsics().height_px, job.scene.string().c_str(), render_ms,
                staged.target().string().c_str());
  return line;
}

}  // namespace tgnav::harness
