#include "harness/config_io.h"

#include <stdexcept>

#include "harness/errors.h"
#include "harness/yaml_util.h"

namespace tgnav::harness {

namespace {
void readOptional(const YamlDoc& doc, const YAML::Node& map, const std::string& key, double& out) {
  if (map[key]) out = doc.number(map, key, "");
}
void readOptional(const YamlDoc& doc, const YAML::Node& map, const std::string& key, int& out) {
  if (!map[key]) return;
  const double v = doc.number(map, key, "");
  if (v != static_cast<int>(v)) {
    doc.fail(map[key], "key '" + key + "' has value '" + map[key].Scalar() + "', expected an integer");
  }
  out = static_cast<int>(v);
}
void readOptional(const YamlDoc& doc, const YAML::Node& map, const std::string& key,
                  std::string& out) {
  if (map[key]) out = doc.string(map, key, "");
}

template <typename Config>
void validateFrom(const YamlDoc& doc, const Config& config) {
  try {
    config.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(doc.file().string() + ": " + e.what());
  }
}
}  // namespace

CameraConfig loadCameraConfig(const std::filesystem::path& yaml, CameraConfig base) {
  const YamlDoc doc = YamlDoc::load(yaml);
  const YAML::Node& root = doc.root();
  doc.requireKeys(root,
                  {"name", "width_px", "height_px", "near_clip_m", "far_clip_m", "min_depth_m",
                   "max_depth_m", "rgb_noise_sigma", "depth_noise_sigma_per_m2"},
                  "");
  readOptional(doc, root, "name", base.name);
  readOptional(doc, root, "width_px", base.width_px);
  readOptional(doc, root, "height_px", base.height_px);
  readOptional(doc, root, "near_clip_m", base.near_clip_m);
  readOptional(doc, root, "far_clip_m", base.far_clip_m);
  readOptional(doc, root, "min_depth_m", base.min_depth_m);
  readOptional(doc, root, "max_depth_m", base.max_depth_m);
  readOptional(doc, root, "rgb_noise_sigma", base.rgb_noise_sigma);
  readOptional(doc, root, "depth_noise_sigma_per_m2", base.depth_noise_sigma_per_m2);
  validateFrom(doc, base);
  return base;
}

}  // namespace tgnav::harness
