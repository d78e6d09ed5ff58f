#include "harness/scene_config.h"

#include <cmath>

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
  doc.requireKeys(root, {"mjcf", "flight_height_m", "start", "goal", "bounds", "survey"}, "");
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
  const YAML::Node survey = doc.child(root, "survey", "");
  doc.requireKeys(survey, {"spacing_m", "heights_m", "yaw_count", "clearance_m"}, "survey");
  SurveyPlan& plan = scene.survey;
  plan.spacing_m = doc.number(survey, "spacing_m", "survey");
  plan.clearance_m = doc.number(survey, "clearance_m", "survey");
  const double yaws = doc.number(survey, "yaw_count", "survey");
  const YAML::Node heights = doc.child(survey, "heights_m", "survey");
  if (!heights.IsSequence() || heights.size() == 0) {
    doc.fail(heights, "key 'survey.heights_m' must be a non-empty list of heights in metres");
  }
  plan.heights_m = doc.numbers(survey, "heights_m", heights.size(), "survey");
  if (!(plan.spacing_m >= 0.1)) doc.fail(survey["spacing_m"], "key 'survey.spacing_m' must be >= 0.1 m");
  if (!(plan.clearance_m >= 0.0)) doc.fail(survey["clearance_m"], "key 'survey.clearance_m' must be >= 0");
  if (yaws != std::floor(yaws) || yaws < 1 || yaws > 64) {
    doc.fail(survey["yaw_count"], "key 'survey.yaw_count' has value '" + survey["yaw_count"].Scalar() +
                                      "', expected an integer in [1, 64]");
  }
  plan.yaw_count = static_cast<int>(yaws);
  for (std::size_t i = 0; i < plan.heights_m.size(); ++i) {
    if (plan.heights_m[i] <= scene.bounds_min_m.z() || plan.heights_m[i] >= scene.bounds_max_m.z()) {
      doc.fail(heights[i], "key 'survey.heights_m' has value '" + heights[i].Scalar() +
                               "' outside the bounds' z range");
    }
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
