#include "harness/config/scene_config.h"

#include "harness/base/errors.h"
#include "harness/base/files.h"
#include "harness/config/vehicle_config.h"
#include "harness/config/yaml_util.h"

namespace tgnav::harness {

SceneConfig loadSceneConfig(const std::filesystem::path& yaml) {
  const YamlDoc doc = YamlDoc::load(yaml);
  const YAML::Node& root = doc.root();
  SceneConfig scene;
  YamlArchive(doc, root, "").required().except({"vehicle"}).fields(scene);
  scene.source = yaml;
  const std::string mjcf = scene.mjcf.string();
  scene.mjcf = std::filesystem::absolute(yaml.parent_path() / mjcf).lexically_normal();
  if (!isRegularFile(scene.mjcf)) {
    doc.fail(root["mjcf"], "key 'mjcf' has value '" + mjcf + "': file " + scene.mjcf.string() + " not found");
  }
  if (!scene.vehicle.empty()) {
    const std::string text = scene.vehicle.string();
    scene.vehicle = std::filesystem::absolute(yaml.parent_path() / text).lexically_normal();
    if (!isRegularFile(scene.vehicle)) {
      doc.fail(root["vehicle"],
               "key 'vehicle' has value '" + text + "': file " + scene.vehicle.string() + " not found");
    }
    loadVehicleDescription(scene.vehicle);  // its own errors name its file
  }
  if ((scene.bounds_max_m.array() <= scene.bounds_min_m.array()).any()) {
    doc.fail(root["bounds"], "key 'bounds.max' must exceed 'bounds.min' on every axis");
  }
  auto inside = [&](const Eigen::Vector3d& p) {
    return (p.array() >= scene.bounds_min_m.array()).all() && (p.array() <= scene.bounds_max_m.array()).all();
  };
  if (!inside(scene.start.p_WB)) doc.fail(root["start"], "key 'start' lies outside 'bounds'");
  if (!inside(scene.goal.p_WB)) doc.fail(root["goal"], "key 'goal' lies outside 'bounds'");
  if (scene.flight_height_m <= scene.bounds_min_m.z() || scene.flight_height_m >= scene.bounds_max_m.z()) {
    doc.fail(root["flight_height_m"],
             "key 'flight_height_m' = " + std::to_string(scene.flight_height_m) + " lies outside the bounds' z range");
  }
  const YAML::Node survey = root["survey"];
  const SurveyPlan& plan = scene.survey;
  if (plan.heights_m.empty()) {
    doc.fail(survey["heights_m"], "key 'survey.heights_m' must be a non-empty list of heights in metres");
  }
  if (!(plan.spacing_m >= 0.1)) doc.fail(survey["spacing_m"], "key 'survey.spacing_m' must be >= 0.1 m");
  if (!(plan.clearance_m >= 0.0)) doc.fail(survey["clearance_m"], "key 'survey.clearance_m' must be >= 0");
  if (plan.yaw_count < 1 || plan.yaw_count > 64) {
    doc.fail(survey["yaw_count"],
             "key 'survey.yaw_count' has value '" + survey["yaw_count"].Scalar() + "', expected an integer in [1, 64]");
  }
  for (std::size_t i = 0; i < plan.heights_m.size(); ++i) {
    if (plan.heights_m[i] <= scene.bounds_min_m.z() || plan.heights_m[i] >= scene.bounds_max_m.z()) {
      doc.fail(survey["heights_m"][i], "key 'survey.heights_m' has value '" + survey["heights_m"][i].Scalar() +
                                           "' outside the bounds' z range");
    }
  }
  return scene;
}

SceneConfig loadScene(const std::filesystem::path& path) {
  const std::string ext = path.extension().string();
  if (ext == ".xml" || ext == ".mjcf") {
    if (!isRegularFile(path)) throw InputError(path.string() + ": file not found");
    SceneConfig scene;
    scene.source = path;
    scene.mjcf = std::filesystem::absolute(path).lexically_normal();
    return scene;
  }
  if (ext == ".yaml" || ext == ".yml") return loadSceneConfig(path);
  throw InputError(path.string() + ": unknown scene file type '" + ext + "' (expected a scene .yaml or an MJCF .xml)");
}

}  // namespace tgnav::harness
