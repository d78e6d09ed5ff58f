#include "harness/scenario.h"

#include <cmath>

#include "harness/errors.h"
#include "harness/yaml_util.h"

namespace tgnav::harness {

namespace {
std::filesystem::path relativeFile(const YamlDoc& doc, const std::string& key) {
  const std::string text = doc.string(doc.root(), key, "");
  const std::filesystem::path p = std::filesystem::absolute(doc.file().parent_path() / text).lexically_normal();
  if (!std::filesystem::is_regular_file(p)) {
    doc.fail(doc.root()[key], "key '" + key + "' has value '" + text + "': file " + p.string() + " not found");
  }
  return p;
}

void readPoseOverride(const YamlDoc& doc, const std::string& key, const SceneConfig& scene, planner::Pose4* pose) {
  if (!doc.root()[key]) return;
  const std::vector<double> v = doc.numbers(doc.root(), key, 4, "");
  const Eigen::Vector3d p(v[0], v[1], v[2]);
  if ((p.array() < scene.bounds_min_m.array()).any() || (p.array() > scene.bounds_max_m.array()).any()) {
    doc.fail(doc.root()[key], "key '" + key + "' lies outside the bounds of scene " + scene.source.string());
  }
  pose->p_WB = p;
  pose->yaw_rad = v[3];
}
}  // namespace

Scenario loadScenario(const std::filesystem::path& yaml) {
  const YamlDoc doc = YamlDoc::load(yaml);
  const YAML::Node& root = doc.root();
  doc.requireKeys(root, {"scene", "seed", "planner_config", "planner", "start", "goal"}, "");
  Scenario s;
  s.source = yaml;
  s.scene = loadSceneConfig(relativeFile(doc, "scene"));
  const double seed = doc.number(root, "seed", "");
  if (seed < 0 || seed != std::floor(seed) || seed > 9.0e15) {
    doc.fail(root["seed"], "key 'seed' has value '" + root["seed"].Scalar() + "', expected an integer >= 0");
  }
  s.seed = static_cast<std::uint64_t>(seed);
  readPoseOverride(doc, "start", s.scene, &s.scene.start);
  readPoseOverride(doc, "goal", s.scene, &s.scene.goal);
  if (root["planner_config"]) s.planner = loadPlannerSettings(relativeFile(doc, "planner_config"));
  if (root["planner"]) {
    readPlannerSettings(FieldReader(doc, root["planner"], "planner"), &s.planner);
    validatePlannerSettings(s.planner, yaml.string());
  }
  return s;
}

}  // namespace tgnav::harness
