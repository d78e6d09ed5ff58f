#include "harness/config/vehicle_config.h"

#include <cctype>
#include <cmath>
#include <set>

#include "harness/base/errors.h"
#include "harness/base/files.h"
#include "harness/config/yaml_util.h"

namespace tgnav::harness {

namespace fs = std::filesystem;

bool supportedRotorCount(std::size_t n) { return n == 4 || n == 6 || n == 8; }

namespace {

std::string name(const YamlDoc& doc, const YAML::Node& map, const std::string& key, const std::string& context) {
  std::string value = doc.string(map, key, context);
  if (value.empty()) doc.failKey(map[key], joinKey(context, key), "key '" + joinKey(context, key) + "' is empty");
  return value;
}

double positive(const YamlDoc& doc, const YAML::Node& map, const std::string& key, const std::string& context,
                bool zero_allowed) {
  const double v = doc.number(map, key, context);
  if (!std::isfinite(v) || v < 0.0 || (!zero_allowed && v == 0.0)) {
    doc.failKey(map[key], joinKey(context, key),
                "key '" + joinKey(context, key) + "' has value '" + map[key].Scalar() + "', expected a number " +
                    (zero_allowed ? ">= 0" : "> 0"));
  }
  return v;
}

fs::path existing(const YamlDoc& doc, const YAML::Node& map, const std::string& key) {
  const std::string text = name(doc, map, key, "");
  fs::path p = fs::absolute(doc.file().parent_path() / text).lexically_normal();
  if (!isRegularFile(p)) {
    doc.failKey(map[key], key, "key '" + key + "' has value '" + text + "': file " + p.string() + " not found");
  }
  return p;
}

}  // namespace

VehicleDescription loadVehicleDescription(const fs::path& yaml) {
  const YamlDoc doc = YamlDoc::load(yaml);
  const YAML::Node& root = doc.root();
  doc.requireKeys(root,
                  {"mjcf", "body", "root_joint", "rotors", "gyro", "accelerometer", "camera", "motor", "timestep_s",
                   "controller_config"},
                  "");
  VehicleDescription v;
  v.source = yaml;
  v.mjcf = existing(doc, root, "mjcf");
  v.body = name(doc, root, "body", "");
  if (root["root_joint"]) v.root_joint = name(doc, root, "root_joint", "");
  const YAML::Node rotors = doc.child(root, "rotors", "");
  if (!rotors.IsSequence()) doc.failKey(rotors, "rotors", "key 'rotors' must be a list of actuator names");
  std::set<std::string> seen;
  for (std::size_t i = 0; i < rotors.size(); ++i) {
    const YAML::Node item = rotors[i];
    if (!item.IsScalar() || item.Scalar().empty()) {
      doc.failKey(item, "rotors", "key 'rotors' item " + std::to_string(i) + " must be an actuator name");
    }
    if (!seen.insert(item.Scalar()).second) {
      doc.failKey(item, "rotors", "key 'rotors' names actuator '" + item.Scalar() + "' twice");
    }
    v.rotors.push_back(item.Scalar());
  }
  if (!supportedRotorCount(v.rotors.size())) {
    doc.failKey(
        rotors, "rotors",
        "key 'rotors' names " + std::to_string(v.rotors.size()) + " actuators; supported rotor counts are 4, 6 and 8");
  }
  v.gyro = name(doc, root, "gyro", "");
  v.accelerometer = name(doc, root, "accelerometer", "");
  v.camera = name(doc, root, "camera", "");
  if (root["motor"]) {
    const YAML::Node motor = root["motor"];
    if (!motor.IsMap()) doc.failKey(motor, "motor", "key 'motor' must be a mapping");
    doc.requireKeys(motor, {"time_constant_s", "max_thrust_n"}, "motor");
    if (motor["time_constant_s"]) v.motor_time_constant_s = positive(doc, motor, "time_constant_s", "motor", true);
    if (motor["max_thrust_n"]) v.max_thrust_n = positive(doc, motor, "max_thrust_n", "motor", false);
  }
  if (root["timestep_s"]) v.timestep_s = positive(doc, root, "timestep_s", "", false);
  if (root["controller_config"]) v.controller_config = existing(doc, root, "controller_config");
  return v;
}

std::vector<IncludeRef> findIncludes(const std::string& text) {
  std::vector<IncludeRef> out;
  std::size_t i = 0;
  while ((i = text.find('<', i)) != std::string::npos) {
    if (text.compare(i, 4, "<!--") == 0) {
      const std::size_t end = text.find("-->", i + 4);
      if (end == std::string::npos) break;
      i = end + 3;
      continue;
    }
    const std::size_t tag_end = text.find('>', i);
    if (tag_end == std::string::npos) break;
    if (text.compare(i, 8, "<include") == 0 && (std::isspace(static_cast<unsigned char>(text[i + 8])) != 0)) {
      std::size_t a = text.find("file", i + 8);
      while (a != std::string::npos && a < tag_end) {
        std::size_t k = a + 4;
        while (k < tag_end && std::isspace(static_cast<unsigned char>(text[k])) != 0) ++k;
        const bool is_attribute = std::isspace(static_cast<unsigned char>(text[a - 1])) != 0;
        if (is_attribute && k < tag_end && text[k] == '=') {
          ++k;
          while (k < tag_end && std::isspace(static_cast<unsigned char>(text[k])) != 0) ++k;
          const char quote = text[k];
          const std::size_t close = (quote == '"' || quote == '\'') ? text.find(quote, k + 1) : std::string::npos;
          if (close != std::string::npos && close < tag_end) {
            out.push_back(IncludeRef{k + 1, close, text.substr(k + 1, close - k - 1)});
          }
          break;
        }
        a = text.find("file", a + 4);
      }
    }
    i = tag_end + 1;
  }
  return out;
}

std::optional<IncludeRef> vehicleInclude(const fs::path& mjcf, const std::string& text, fs::path* description) {
  std::optional<IncludeRef> found;
  for (const IncludeRef& inc : findIncludes(text)) {
    const fs::path file = (mjcf.parent_path() / inc.file).lexically_normal();
    const fs::path yaml = descriptionBeside(file);
    if (yaml.empty()) continue;
    if (found) {
      throw InputError(mjcf.string() + ": includes two vehicles ('" + found->file + "' and '" + inc.file +
                       "'); a scene includes one");
    }
    found = inc;
    *description = yaml;
  }
  return found;
}

fs::path includedVehicle(const fs::path& mjcf) {
  fs::path own = descriptionBeside(mjcf);
  if (!own.empty()) return own;
  fs::path description;
  vehicleInclude(mjcf, readTextFile(mjcf), &description);
  return description;
}

fs::path resolveVehicle(const fs::path& mjcf, const fs::path& vehicle_yaml) {
  if (!vehicle_yaml.empty()) return vehicle_yaml;
  fs::path included = includedVehicle(mjcf);
  if (included.empty()) {
    throw InputError(mjcf.string() +
                     ": includes no vehicle (an MJCF with a vehicle description .yaml beside it, such as "
                     "models/quadrotor.xml); include one, or name one with the scene's or scenario's 'vehicle' key");
  }
  return included;
}

fs::path descriptionBeside(const fs::path& mjcf) {
  fs::path yaml = mjcf;
  yaml.replace_extension(".yaml");
  return isRegularFile(yaml) ? yaml : fs::path();
}

}  // namespace tgnav::harness
