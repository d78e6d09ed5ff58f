// tgnav render: one RGB-D frame of a scene from a given vehicle pose, for looking at scenes.
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>

#include "harness/camera.h"
#include "harness/cli.h"
#include "harness/config_io.h"
#include "harness/egl_context.h"
#include "harness/errors.h"
#include "harness/mujoco_sim.h"
#include "harness/output.h"
#include "harness/scene_config.h"

namespace tgnav::cli {

namespace {

struct RenderOptions {
  std::string scene;
  std::string pose;
  std::string out;
  std::string camera_config;
  int width_px = 0;
  int height_px = 0;
  bool width_given = false;
  bool height_given = false;
  std::uint64_t seed = 0;
};

std::string intrinsicsYaml(const harness::Intrinsics& k, const Eigen::Isometry3d& X_WC,
                           const std::string& scene, const std::string& renderer) {
  const Eigen::Quaterniond q(X_WC.linear());
  YAML::Emitter out;
  out << YAML::Comment("Pinhole intrinsics of rgb.png/depth.png; depth.png is uint16, depth_scale "
                       "units per metre, 0 = invalid. Camera frame: x right, y down, z forward.");
  out << YAML::BeginMap;
  out << YAML::Key << "scene" << YAML::Value << scene;
  out << YAML::Key << "width" << YAML::Value << k.width_px;
  out << YAML::Key << "height" << YAML::Value << k.height_px;
  out << YAML::Key << "fx" << YAML::Value << k.fx;
  out << YAML::Key << "fy" << YAML::Value << k.fy;
  out << YAML::Key << "cx" << YAML::Value << k.cx;
  out << YAML::Key << "cy" << YAML::Value << k.cy;
  out << YAML::Key << "depth_scale" << YAML::Value << 1000;
  out << YAML::Key << "X_WC" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "translation_m" << YAML::Value << YAML::Flow << YAML::BeginSeq
      << X_WC.translation().x() << X_WC.translation().y() << X_WC.translation().z() << YAML::EndSeq;
  out << YAML::Key << "quaternion_xyzw" << YAML::Value << YAML::Flow << YAML::BeginSeq << q.x()
      << q.y() << q.z() << q.w() << YAML::EndSeq;
  out << YAML::EndMap;
  out << YAML::Key << "renderer" << YAML::Value << renderer;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

void runRender(const RenderOptions& opt) {
  const harness::SceneConfig scene = harness::loadScene(opt.scene);
  planner::Pose4 pose = scene.start;
  if (!opt.pose.empty()) {
    const std::vector<double> v = parseNumbers(opt.pose, 4, "--pose", "x,y,z,yaw (metres, radians)");
    pose.p_WB = Eigen::Vector3d(v[0], v[1], v[2]);
    pose.yaw_rad = v[3];
  } else if (scene.source == scene.mjcf) {
    throw InputError("--pose: required when --scene is an MJCF file (" + opt.scene + ")");
  }
  harness::CameraConfig camera_config;
  if (!opt.camera_config.empty()) camera_config = harness::loadCameraConfig(opt.camera_config);
  if (opt.width_given) camera_config.width_px = opt.width_px;
  if (opt.height_given) camera_config.height_px = opt.height_px;
  try {
    camera_config.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--width/--height: ") + e.what());
  }

  harness::ModelPtr model = harness::loadModel(scene.mjcf);
  harness::DataPtr data = harness::makeData(model.get());
  const auto ids = harness::VehicleIds::find(model.get(), scene.mjcf.string());
  harness::setVehiclePose(model.get(), data.get(), ids, pose);

  harness::EglContext gl;
  harness::Camera camera(model.get(), gl, camera_config, opt.seed);
  const auto t0 = std::chrono::steady_clock::now();
  const harness::RgbdFrame frame = camera.render(data.get());
  const double render_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  cv::Mat depth_mm(frame.depth_m.size(), CV_16UC1);
  frame.depth_m.convertTo(depth_mm, CV_16UC1, 1000.0);  // saturates; 0 stays invalid
  cv::Mat too_far = frame.depth_m > 65.535f;
  depth_mm.setTo(0, too_far);

  const std::filesystem::path out(opt.out);
  harness::makeOutputDir(out);
  harness::writeImageAtomic(out / "rgb.png", frame.bgr);
  harness::writeImageAtomic(out / "depth.png", depth_mm);
  harness::writeFileAtomic(out / "intrinsics.yaml",
                           intrinsicsYaml(camera.intrinsics(), frame.X_WC, opt.scene, gl.renderer()));
  std::printf("tgnav render: %dx%d frame of %s in %.1f ms -> %s/{rgb.png,depth.png,intrinsics.yaml}\n",
              camera.intrinsics().width_px, camera.intrinsics().height_px, opt.scene.c_str(),
              render_ms, out.string().c_str());
}

}  // namespace

void addRenderCommand(CLI::App& app) {
  auto opt = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand("render", "Render one RGB-D frame of a scene from a vehicle pose");
  cmd->add_option("--scene", opt->scene, "Scene YAML (configs/scenes/*.yaml) or MJCF file")->required();
  cmd->add_option("--pose", opt->pose,
                  "Vehicle pose x,y,z,yaw in metres and radians (default: the scene's start)");
  cmd->add_option("--out", opt->out, "Output directory")->required();
  cmd->add_option("--camera-config", opt->camera_config, "Camera YAML (default: built-in, see configs/camera.yaml)");
  cmd->add_option("--width", opt->width_px, "Image width in pixels (overrides the camera config)");
  cmd->add_option("--height", opt->height_px, "Image height in pixels (overrides the camera config)");
  cmd->add_option("--seed", opt->seed, "Seed of the camera noise");
  cmd->callback([opt, cmd] {
    opt->width_given = cmd->count("--width") > 0;
    opt->height_given = cmd->count("--height") > 0;
    runRender(*opt);
  });
}

}  // namespace tgnav::cli
