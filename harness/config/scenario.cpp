#include "harness/config/scenario.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <tuple>

#include "harness/base/errors.h"
#include "harness/base/files.h"
#include "harness/config/config_io.h"
#include "harness/config/map_build_config.h"
#include "harness/config/track_model_file.h"
#include "harness/config/vehicle_config.h"

namespace tgnav::harness {

namespace fs = std::filesystem;

namespace {
// The top-level key of a section's file: "camera" -> "camera_config".
std::string fileKey(const std::string& section) { return section + "_config"; }

// The keys of the sections (Scenario::visitSections), in order.
std::vector<std::string> sectionKeys() {
  Scenario s;
  KeyLister keys;
  s.visitSections(keys);
  return keys.keys();
}

fs::path existingFile(const YamlDoc& doc, const std::string& key, const fs::path& base) {
  const std::string text = doc.string(doc.root(), key, "");
  fs::path p = fs::absolute(base / text).lexically_normal();
  if (!isRegularFile(p)) {
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

// One section through its layers: its file, its inline section, the overrides.
template <typename Config>
void readSection(const YamlDoc& doc, const YamlDoc* overrides, const std::string& key, Config* c) {
  const YAML::Node& root = doc.root();
  const std::string file_key = fileKey(key);
  // The file goes over what the section holds already: the built-in defaults, or for the
  // controller the vehicle's gains.
  if (root[file_key]) *c = loadConfigFile(relativeFile(doc, file_key), *c);
  if (root[key]) readConfig(YamlArchive(doc, root[key], key), c);
  const bool overridden = overrides && overrides->root()[key];
  if (overridden) readConfig(YamlArchive(*overrides, overrides->root()[key], key), c);
  if (!root[key] && !overridden) return;
  try {
    c->validate();
  } catch (const std::invalid_argument& e) {
    std::string where = doc.file().string();
    if (overridden) {
      const std::string assignment = offendingAssignment(*overrides, key, e.what());
      where = assignment.empty() ? where + " (with --set overrides)" : "--set " + assignment;
    }
    throw InputError(where + ": " + e.what());
  }
}

// An archive over Scenario::visitSections that reads each section through its layers.
class SectionReader {
 public:
  SectionReader(const YamlDoc& doc, const YamlDoc* overrides) : doc_(doc), overrides_(overrides) {}
  template <typename Config>
  SectionReader& operator()(const std::string& key, Config& config) {
    readSection(doc_, overrides_, key, &config);
    return *this;
  }

 private:
  const YamlDoc& doc_;
  const YamlDoc* overrides_;
};

// A model fitted on features counted with other view settings than the planner's: InputError
// naming the setting, both values and the fix.
void checkViewSettings(const planner::TrackModel& model, const planner::PerceptionPlannerConfig& perception,
                       const std::string& where) {
  if (!model.has_view_settings) return;
  const planner::TrackModel::ViewSettings& fitted = model.view_settings;
  const std::tuple<const char*, double, double> pairs[] = {
      {"planner.visibility.hfov_rad", fitted.hfov_rad, perception.visibility.hfov_rad},
      {"planner.visibility.vfov_rad", fitted.vfov_rad, perception.visibility.vfov_rad},
      {"planner.visibility.min_range_m", fitted.min_range_m, perception.visibility.min_range_m},
      {"planner.visibility.max_range_m", fitted.max_range_m, perception.visibility.max_range_m},
      {"planner.information.max_incidence_rad", fitted.max_incidence_rad, perception.information.max_incidence_rad},
      {"planner.visibility.sight_to_face", fitted.sight_to_face, perception.visibility.sight_to_face ? 1.0 : 0.0}};
  for (const auto& [key, model_value, config_value] : pairs) {
    if (std::abs(model_value - config_value) <= 1e-9 * std::max(1.0, std::abs(model_value))) continue;
    std::ostringstream msg;
    msg << where << ": key 'planner.information.track_model' has value '" << model.source << "': it was fitted with "
        << key << " = " << model_value << ", this config has " << config_value
        << " (fit a model for these settings: scripts/fit_track_model.py --views)";
    throw InputError(msg.str());
  }
}

// Reads the learned perception model that planner.information.track_model names (relative to the
// current directory when --set gives it, else to the scenario file) into the planners' settings,
// and records its absolute path there (config.yaml); no model when the key is "none"; "default"
// (the default) is configs/track_model.json of the build's source tree, or $TGNAV_CONFIGS_DIR's.
void readTrackModel(const YamlDoc& doc, const YamlDoc* overrides, PlannerSettings* planner) {
  planner::InformationConfig& info = planner->perception.information;
  info.model.reset();
  const bool overridden = overrides && overrides->root()["planner"] && overrides->root()["planner"]["information"] &&
                          overrides->root()["planner"]["information"]["track_model"];
  const std::string where = overridden ? std::string("--set") : doc.file().string();
  if (info.track_model != "none") {
    fs::path file;
    std::string hint;
    if (info.track_model == "default") {
      const char* env = std::getenv("TGNAV_CONFIGS_DIR");
      file =
          (env != nullptr && *env != '\0' ? fs::path(env) : fs::path(TGNAV_SOURCE_DIR "/configs")) / "track_model.json";
      hint = " (set TGNAV_CONFIGS_DIR, or track_model: none for the gates)";
    } else {
      const fs::path base = overridden ? fs::path() : doc.file().parent_path();
      file = fs::absolute(base / info.track_model).lexically_normal();
    }
    if (!isRegularFile(file)) {
      throw InputError(where + ": key 'planner.information.track_model' has value '" + info.track_model + "': file " +
                       file.string() + " not found" + hint);
    }
    info.model = std::make_shared<const planner::TrackModel>(loadTrackModel(file));
    info.track_model = file.string();
    checkViewSettings(*info.model, planner->perception, where);
  }
  planner->shareFromPerception();
}

// With an external planner configured, makes planner.external.dir absolute: relative to the
// current directory when --set gives the dir or the command, else to the scenario file; InputError
// when the folder does not exist.
void resolveExternalDir(const YamlDoc& doc, const YamlDoc* overrides, PlannerSettings* planner) {
  ExternalPlannerConfig& ext = planner->external;
  if (!ext.configured()) return;
  const YAML::Node set = overrides ? overrides->root()["planner"] : YAML::Node();
  const bool overridden = set && set["external"] && (set["external"]["dir"] || set["external"]["command"]);
  const fs::path base = overridden ? fs::path() : doc.file().parent_path();
  const fs::path dir = fs::absolute(base / ext.dir).lexically_normal();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw InputError((overridden ? std::string("--set") : doc.file().string()) +
                     ": key 'planner.external.dir' has value '" + ext.dir + "': folder " + dir.string() + " not found");
  }
  ext.dir = dir.string();
}

// trial.map_clear_no_return needs depth left to clear: InputError naming the camera's settings.
void checkNoReturnDepth(const YamlDoc& doc, const YamlDoc* overrides, const Scenario& s) {
  if (!s.trial.online.map_clear_no_return) return;
  const double depth = noReturnDepth(s.camera);
  if (depth > kMinNoReturnDepthM) return;
  std::ostringstream msg;
  const bool overridden = overrides && (overrides->root()["trial"] || overrides->root()["camera"]);
  msg << doc.file().string() << (overridden ? " (with --set overrides)" : "")
      << ": key 'trial.map_clear_no_return' is true, but camera.max_depth_m " << s.camera.max_depth_m
      << " less three sigmas of its depth noise (camera.depth_noise_sigma_per_m2 " << s.camera.depth_noise_sigma_per_m2
      << ") leaves " << depth << " m to clear (needs > " << kMinNoReturnDepthM << ")";
  throw InputError(msg.str());
}

// trial.look_fov_margin_deg must leave a field of view: InputError naming both settings.
void checkLookFovMargin(const YamlDoc& doc, const YamlDoc* overrides, const Scenario& s) {
  const double margin_rad = s.trial.online.look_fov_margin_deg * M_PI / 180.0;
  const double hfov_rad = s.planner.perception.visibility.hfov_rad;
  if (2.0 * margin_rad < hfov_rad) return;
  std::ostringstream msg;
  const bool overridden = overrides && (overrides->root()["trial"] || overrides->root()["planner"]);
  msg << doc.file().string() << (overridden ? " (with --set overrides)" : "") << ": key 'trial.look_fov_margin_deg' is "
      << s.trial.online.look_fov_margin_deg << ", which on each side leaves nothing of planner.visibility.hfov_rad "
      << hfov_rad << " (needs less than half of it)";
  throw InputError(msg.str());
}

YAML::Node poseYaml(const planner::Pose4& pose) {
  const double v[4] = {pose.p_WB.x(), pose.p_WB.y(), pose.p_WB.z(), pose.yaw_rad};
  return exactSequence(v, 4);
}
}  // namespace

Scenario loadScenario(const fs::path& yaml, const YamlDoc* overrides) {
  const YamlDoc doc = YamlDoc::load(yaml);
  std::vector<std::string> keys = {"scene", "vehicle", "seed", "start", "goal"};
  std::vector<std::string> override_keys = keys;
  for (const std::string& section : sectionKeys()) {
    keys.insert(keys.end(), {fileKey(section), section});
    override_keys.push_back(section);
  }
  doc.requireKeys(doc.root(), keys, "");
  if (overrides) {
    for (const std::string& section : sectionKeys()) {
      const std::string file_key = fileKey(section);
      if (overrides->root()[file_key]) {
        overrides->failKey(overrides->root()[file_key], file_key,
                           "key '" + file_key + "' names a file and cannot be set with --set; " + "set the keys of '" +
                               section + "' instead (--set " + section + ".KEY=VALUE)");
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
  const YamlDoc& vehicle_doc = sourceOf(doc, overrides, "vehicle");
  const fs::path named = vehicle_doc.root()["vehicle"] ? relativeFile(vehicle_doc, "vehicle") : s.scene.vehicle;
  s.vehicle = resolveVehicle(s.scene.mjcf, named);
  const VehicleDescription vehicle = loadVehicleDescription(s.vehicle);
  if (!vehicle.controller_config.empty()) s.controller = loadCascadeConfig(vehicle.controller_config);

  SectionReader sections(doc, overrides);
  s.visitSections(sections);
  readTrackModel(doc, overrides, &s.planner);
  resolveExternalDir(doc, overrides, &s.planner);
  checkNoReturnDepth(doc, overrides, s);
  checkLookFovMargin(doc, overrides, s);
  return s;
}

std::string resolvedScenarioYaml(const Scenario& s) {
  YAML::Node root(YAML::NodeType::Map);
  root["scene"] = fs::absolute(s.scene.source).lexically_normal().string();
  root["vehicle"] = fs::absolute(s.vehicle).lexically_normal().string();
  root["seed"] = std::to_string(s.seed);
  root["start"] = poseYaml(s.scene.start);
  root["goal"] = poseYaml(s.scene.goal);
  Scenario sections = s;  // visitSections() is not const
  YamlArchive writer = YamlArchive::writer(root);
  sections.visitSections(writer);
  YAML::Emitter out;
  out << root;
  return std::string(
             "# A resolved scenario (harness/scenario.h): every setting in force after the defaults, the\n"
             "# *_config files, the scenario's sections and the --set overrides were layered. It loads\n"
             "# back as a scenario and reproduces the run.\n") +
         out.c_str() + "\n";
}

std::string defaultSectionsYaml() {
  YAML::Node root(YAML::NodeType::Map);
  Scenario defaults;
  YamlArchive writer = YamlArchive::writer(root);
  defaults.visitSections(writer);
  YAML::Emitter out;
  out << root;
  return std::string(
             "# The built-in defaults of every section of a scenario (harness/config/scenario.h), every key\n"
             "# with its value, in the form of a resolved config.yaml's sections.\n") +
         out.c_str() + "\n";
}

}  // namespace tgnav::harness
