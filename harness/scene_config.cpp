#include "harness/scene_config.h"

#include "harness/errors.h"
#include "harness/yaml_util.h"

namespace tgnav::harness {

namespace {
planner::Pose4 readPose(const YamlDoc& doc, const std::string& key) {
  const std::vector<double> v = doc.numbers(doc.root(), key, 4, "");
  planner::Pose4 pose;
  pose.p_WB = Eigen::Vector3d(v[0], v[1], v[2]);
  pose.yaw_rad = v[3];
  return pose;
}
}  // namespace

SceneConfig loadSceneConfig(const std::filesystem::path& yaml) {
  const YamlDoc doc = YamlDoc::load(yaml);
  const YAML::Node& root = doc.root();
  doc.requireKeys(root, {"mjcf", "flight_height_m", "start", "goal", "bounds"}, "");
  SceneConfig scene;
  scene.source = yaml;
  const std::string mjcf = doc.string(root, "mjcf", "");
  scene.mjcf = std::filesystem::absolute(yaml.parent_path() / mjcf).lexically_normal();
  if (!std::filesystem::is_regular_file(scene.mjcf)) {
    doc.fail(root["mjcf"], "key 'mjcf' has value '" + mjcf + "': file " + scene.mjcf.string() +
                               " not found");
  }
  scene.flight_height_m = doc.number(root, "flight_height_m", "");
  scene.start = readPose(doc, "start");
  scene.goal = readPose(doc, "goal");
  const YAML::Node bounds = doc.child(root, "bounds", "");
  doc.requireKeys(bounds, {"min", "max"}, "bounds");
  const std::vector<double> lo = doc.numbers(bounds, "min", 3, "bounds");
  const std::vector<double> hi = doc.numbers(bounds, "max", 3, "bounds");
  scene.bounds_min_m = Eigen::Vector3d(lo[0], lo[1], lo[2]);
  scene.bounds_max_m = Eigen::Vector3d(hi[0], hi[1], hi[2]);
  if ((scene.bounds_max_m.array() <= scene.bounds_min_m.array()).any()) {
    doc.fail(bounds, "key 'bounds.max' must exceed 'bounds.min' on every axis");
  }
  auto inside = [&](const Eigen::Vector3d& p) {
    return (p.array() >= scene.bounds_min_m.array()).all() &&
           (p.array() <= scene.bounds_max_m.array()).all();
  };
  if (!inside(scene.start.p_WB)) doc.fail(root["start"], "key 'start' lies outside 'bounds'");
  if (!inside(scene.goal.p_WB)) doc.fail(root["goal"], "key 'goal' lies outside 'bounds'");
  if (scene.flight_height_m <= scene.bounds_min_m.z() ||
      scene.flight_height_m >= scene.bounds_max_m.z()) {
    doc.fail(root["flight_height_m"], "key 'flight_height_m' = " +
                                          std::to_string(scene.flight_height_m) +
                                          " lies outside the bounds' z range");
  }
  return scene;
}

SceneConfig loadScene(const std::filesystem::path& path) {
  const std::string ext = path.extension().string();
  if (ext == ".xml" || ext == ".mjcf") {
    if (!std::filesystem::is_regular_file(path)) throw InputError(path.string() + ": file not found");
    SceneConfig scene;
    scene.source = path;
    scene.mjcf = std::filesystem::absolute(path).lexically_normal();
    return scene;
  }
  if (ext == ".yaml" || ext == ".yml") return loadSceneConfig(path);
  throw InputError(path.string() + ": unknown scene file type '" + ext +
                   "' (expected a scene .yaml or an MJCF .xml)");
}

}  // namespace tgnav::harness
