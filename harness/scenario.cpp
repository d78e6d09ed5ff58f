#include "harness/scenario.h"

#include <cmath>
#include <stdexcept>

#include "harness/config_io.h"
#include "harness/errors.h"

namespace tgnav::harness {

namespace fs = std::filesystem;

namespace {
struct Section {
  const char* key;
  const char* file_key;
};
constexpr Section kSections[] = {{"planner", "planner_config"},
                                 {"controller", "controller_config"},
                                 {"camera", "camera_config"},
                                 {"vo", "vo_config"},
                                 {"trial", "trial_config"}};

fs::path existingFile(const YamlDoc& doc, const std::string& key, const fs::path& base) {
  const std::string text = doc.string(doc.root(), key, "");
  const fs::path p = fs::absolute(base / text).lexically_normal();
  if (!fs::is_regular_file(p)) {
    doc.failKey(doc.root()[key], key, "key '" + key + "' has value '" + text + "': file " + p.string() + " not found");
  }
  return p;
}

// Paths in a scenario file are relative to it; on the command line, to the current directory.
fs::path relativeFile(const YamlDoc& doc, const std::string& key) {
  return existingFile(doc, key, doc.isOverrides() ? fs::path() : doc.file().parent_path());
}

std::uint64_t readSeed(const YamlDoc& doc) {
  const YAML::Node& root = doc.root();
  const double seed = doc.number(root, "seed", "");
  if (seed < 0 || seed != std::floor(seed) || seed > 9.0e15) {
    doc.failKey(root["seed"], "seed", "key 'seed' has value '" + root["seed"].Scalar() + "', expected an integer >= 0");
  }
  return static_cast<std::uint64_t>(seed);
}

void readPoseOverride(const YamlDoc& doc, const std::string& key, const SceneConfig& scene, planner::Pose4* pose) {
  if (!doc.root()[key]) return;
  const std::vector<double> v = doc.numbers(doc.root(), key, 4, "");
  const Eigen::Vector3d p(v[0], v[1], v[2]);
  if ((p.array() < scene.bounds_min_m.array()).any() || (p.array() > scene.bounds_max_m.array()).any()) {
    doc.failKey(doc.root()[key], key, "key '" + key + "' lies outside the bounds of scene " + scene.source.string());
  }
  pose->p_WB = p;
  pose->yaw_rad = v[3];
}

// The document that sets top-level `key`: the overrides when they do, else the scenario file.
const YamlDoc& sourceOf(const YamlDoc& doc, const YamlDoc* overrides, const char* key) {
  return overrides && overrides->root()[key] ? *overrides : doc;
}

bool isWithin(const std::string& prefix, const std::string& key) {
  return key == prefix ||
         (key.size() > prefix.size() && key.compare(0, prefix.size(), prefix) == 0 && key[prefix.size()] == '.');
}

// The --set assignment that gave the field a validate() message ("field = value: rule") is
// about: one setting `section.field` or a mapping holding it, else the only one under `section`
// that sets a key of that name (nested configs name their fields without the nesting).
std::string offendingAssignment(const YamlDoc& overrides, const std::string& section, const std::string& message) {
  const std::string field = message.substr(0, std::min(message.find(" = "), message.find(':')));
  const std::string full = joinKey(section, field);
  const std::string leaf = field.substr(field.rfind('.') == std::string::npos ? 0 : field.rfind('.') + 1);
  std::string only;
  int same_name = 0;
  for (const std::string& key : overrides.assignedKeys()) {
    if (isWithin(key, full)) return overrides.assignmentFor(key);
    const std::size_t dot = key.rfind('.');
    if (isWithin(section, key) && key.substr(dot == std::string::npos ? 0 : dot + 1) == leaf) {
      ++same_name;
      only = overrides.assignmentFor(key);
    }
  }
  return same_name == 1 ? only : std::string();
}

// One section through its layers; `read` is its read*Config, `load` its load*Config.
template <typename Config, typename Read, typename Load>
void readSection(const YamlDoc& doc, const YamlDoc* overrides, const Section& section, Read read, Load load,
                 Config* c) {
  const YAML::Node& root = doc.root();
  if (root[section.file_key]) *c = load(relativeFile(doc, section.file_key), Config{});
  if (root[section.key]) read(FieldReader(doc, root[section.key], section.key), c);
  const bool overridden = overrides && overrides->root()[section.key];
  if (overridden) read(FieldReader(*overrides, overrides->root()[section.key], section.key), c);
  if (!root[section.key] && !overridden) return;
  try {
    c->validate();
  } catch (const std::invalid_argument& e) {
    std::string where = doc.file().string();
    if (overridden) {
      const std::string assignment = offendingAssignment(*overrides, section.key, e.what());
      where = assignment.empty() ? where + " (with --set overrides)" : "--set " + assignment;
    }
    throw InputError(where + ": " + e.what());
  }
}

YAML::Node poseYaml(const planner::Pose4& pose) {
  const double v[4] = {pose.p_WB.x(), pose.p_WB.y(), pose.p_WB.z(), pose.yaw_rad};
  return exactSequence(v, 4);
}
}  // namespace

Scenario loadScenario(const fs::path& yaml, const YamlDoc* overrides) {
  const YamlDoc doc = YamlDoc::load(yaml);
  std::vector<std::string> keys = {"scene", "seed", "start", "goal"};
  std::vector<std::string> override_keys = keys;
  for (const Section& section : kSections) {
    keys.insert(keys.end(), {section.file_key, section.key});
    override_keys.push_back(section.key);
  }
  doc.requireKeys(doc.root(), keys, "");
  if (overrides) {
    for (const Section& section : kSections) {
      if (overrides->root()[section.file_key]) {
        overrides->failKey(overrides->root()[section.file_key], section.file_key,
                           std::string("key '") + section.file_key + "' names a file and cannot be set with --set; " +
                               "set the keys of '" + section.key + "' instead (--set " + section.key + ".KEY=VALUE)");
      }
    }
    overrides->requireKeys(overrides->root(), override_keys, "");
  }

  Scenario s;
  s.source = yaml;
  s.scene = loadSceneConfig(relativeFile(sourceOf(doc, overrides, "scene"), "scene"));
  s.seed = readSeed(sourceOf(doc, overrides, "seed"));
  readPoseOverride(sourceOf(doc, overrides, "start"), "start", s.scene, &s.scene.start);
  readPoseOverride(sourceOf(doc, overrides, "goal"), "goal", s.scene, &s.scene.goal);

  readSection(doc, overrides, kSections[0], readPlannerSettings,
              [](const fs::path& f, PlannerSettings base) { return loadPlannerSettings(f, base); }, &s.planner);
  readSection(doc, overrides, kSections[1], readCascadeConfig,
              [](const fs::path& f, control::CascadeConfig base) { return loadCascadeConfig(f, base); },
              &s.controller);
  readSection(doc, overrides, kSections[2], readCameraConfig,
              [](const fs::path& f, CameraConfig base) { return loadCameraConfig(f, base); }, &s.camera);
  readSection(doc, overrides, kSections[3], readOdometryConfig,
              [](const fs::path& f, vo::OdometryConfig base) { return loadOdometryConfig(f, base); }, &s.vo);
  readSection(doc, overrides, kSections[4], readTrialConfig,
              [](const fs::path& f, TrialConfig base) { return loadTrialConfig(f, base); }, &s.trial);
  return s;
}

std::string resolvedScenarioYaml(const Scenario& s) {
  YAML::Node root(YAML::NodeType::Map);
  root["scene"] = fs::absolute(s.scene.source).lexically_normal().string();
  root["seed"] = std::to_string(s.seed);
  root["start"] = poseYaml(s.scene.start);
  root["goal"] = poseYaml(s.scene.goal);
  root["planner"] = toYaml(s.planner);
  root["controller"] = toYaml(s.controller);
  root["camera"] = toYaml(s.camera);
  root["vo"] = toYaml(s.vo);
  root["trial"] = toYaml(s.trial);
  YAML::Emitter out;
  out << root;
  return std::string(
             "# A resolved scenario (harness/scenario.h): every setting in force after the defaults, the\n"
             "# *_config files, the scenario's sections and the --set overrides were layered. It loads\n"
             "# back as a scenario and reproduces the run.\n") +
         out.c_str() + "\n";
}

}  // namespace tgnav::harness
