#include "harness/config/track_model_file.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/base/errors.h"
#include "harness/base/files.h"

namespace tgnav::harness {

namespace {

using Json = nlohmann::json;

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
  throw InputError(file.string() + ": " + what);
}

const Json& member(const std::filesystem::path& file, const Json& doc, const char* key) {
  const auto it = doc.find(key);
  if (it == doc.end()) fail(file, std::string("key '") + key + "' is missing");
  return *it;
}

double number(const std::filesystem::path& file, const Json& value, const std::string& key) {
  if (!value.is_number()) fail(file, "key '" + key + "' has value '" + value.dump() + "', expected a number");
  const double v = value.get<double>();
  if (!std::isfinite(v)) fail(file, "key '" + key + "' has value '" + value.dump() + "', expected a finite number");
  return v;
}

std::vector<double> numbers(const std::filesystem::path& file, const Json& doc, const char* key, std::size_t n) {
  const Json& array = member(file, doc, key);
  if (!array.is_array() || array.size() != n) {
    fail(file, std::string("key '") + key + "' has value '" + array.dump().substr(0, 80) + "', expected an array of " +
                   std::to_string(n) + " numbers (one per feature)");
  }
  std::vector<double> out;
  for (std::size_t i = 0; i < n; ++i) {
    out.push_back(number(file, array[i], std::string(key) + "[" + std::to_string(i) + "]"));
  }
  return out;
}

// A term's entry of "ramps" (version 2): null, or [lo, hi] with lo < hi.
void readRamp(const std::filesystem::path& file, const Json& r, std::size_t i, planner::TrackModel::Term* term) {
  if (r.is_null()) return;
  const std::string rkey = "ramps[" + std::to_string(i) + "]";
  if (!r.is_array() || r.size() != 2) {
    fail(file, "key '" + rkey + "' has value '" + r.dump().substr(0, 80) + "', expected null or [lo, hi]");
  }
  term->ramp = true;
  term->ramp_lo = number(file, r[0], rkey + "[0]");
  term->ramp_hi = number(file, r[1], rkey + "[1]");
  if (!(term->ramp_hi > term->ramp_lo)) fail(file, "key '" + rkey + "' has value '" + r.dump() + "', expected lo < hi");
}

// The optional "view_settings" object: every key present and a finite number.
void readViewSettings(const std::filesystem::path& file, const Json& doc, planner::TrackModel* model) {
  const auto settings = doc.find("view_settings");
  if (settings != doc.end()) {
    if (!settings->is_object()) {
      fail(file, "key 'view_settings' has value '" + settings->dump().substr(0, 80) + "', expected an object");
    }
    planner::TrackModel::ViewSettings& v = model->view_settings;
    const std::pair<const char*, double*> keys[] = {{"hfov_rad", &v.hfov_rad},
                                                    {"vfov_rad", &v.vfov_rad},
                                                    {"min_range_m", &v.min_range_m},
                                                    {"max_range_m", &v.max_range_m},
                                                    {"max_incidence_rad", &v.max_incidence_rad}};
    for (const auto& [key, value] : keys) {
      const std::string name = std::string("view_settings.") + key;
      if (!settings->contains(key)) fail(file, "key '" + name + "' is missing");
      *value = number(file, (*settings)[key], name);
    }
    // Optional (files from before it counted to the voxel's centre: 0); 0 or 1.
    if (settings->contains("sight_to_face")) {
      const Json& face = (*settings)["sight_to_face"];
      v.sight_to_face = number(file, face, "view_settings.sight_to_face");
      if (v.sight_to_face != 0.0 && v.sight_to_face != 1.0) {
        fail(file, "key 'view_settings.sight_to_face' has value '" + face.dump() + "', expected 0 or 1");
      }
    }
    model->has_view_settings = true;
  }
}

}  // namespace

planner::TrackModel loadTrackModel(const std::filesystem::path& file) {
  const std::string text = readTextFile(file);  // InputError naming the file when it cannot be read
  Json doc;
  try {
    doc = Json::parse(text);
  } catch (const Json::exception& e) {  // parse_error, or out_of_range for a number like 1e999
    fail(file, std::string("not JSON (") + e.what() + ")");
  }
  if (!doc.is_object()) fail(file, "expected a JSON object, found '" + doc.dump().substr(0, 40) + "'");
  const Json& format = member(file, doc, "format");
  if (format != "tgnav-track-model") {
    fail(file, "key 'format' has value '" + format.dump() + "', expected \"tgnav-track-model\"");
  }
  const Json& version = member(file, doc, "version");
  if (version != 1 && version != 2) {
    fail(file, "key 'version' has value '" + version.dump() + "', expected 1 or 2 (this build reads versions 1-2)");
  }
  const Json& kind = member(file, doc, "kind");
  if (kind != "logistic") fail(file, "key 'kind' has value '" + kind.dump() + "', expected \"logistic\"");
  const Json& features = member(file, doc, "features");
  if (!features.is_array() || features.empty()) {
    fail(file, "key 'features' has value '" + features.dump().substr(0, 80) + "', expected a non-empty array of names");
  }
  planner::TrackModel model;
  model.source = file.string();
  const std::size_t n = features.size();
  const std::vector<double> mean = numbers(file, doc, "mean", n);
  const std::vector<double> scale = numbers(file, doc, "scale", n);
  const std::vector<double> weights = numbers(file, doc, "weights", n);
  // Version 2 may give a term a ramp of its feature; version 1 has none (an older reader would
  // take the feature itself, so a file with ramps must say version 2).
  const auto ramps = doc.find("ramps");
  if (ramps != doc.end()) {
    if (version != 2) fail(file, "key 'ramps' needs version 2, the file says " + version.dump());
    if (!ramps->is_array() || ramps->size() != n) {
      fail(file, "key 'ramps' has value '" + ramps->dump().substr(0, 80) + "', expected an array of " +
                     std::to_string(n) + " entries (null or [lo, hi], one per feature)");
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    planner::TrackModel::Term term;
    const std::string key = "features[" + std::to_string(i) + "]";
    if (!features[i].is_string() || !planner::parseTrackFeature(features[i].get<std::string>(), &term.feature)) {
      std::string known;
      for (const std::string& name : planner::trackFeatureNames()) known += (known.empty() ? "" : ", ") + name;
      fail(file, "key '" + key + "' has value '" + features[i].dump() + "', expected one of " + known);
    }
    if (!(scale[i] > 0.0)) {
      fail(file, "key 'scale[" + std::to_string(i) + "]' has value '" + std::to_string(scale[i]) + "', expected > 0");
    }
    term.mean = mean[i];
    term.scale = scale[i];
    term.weight = weights[i];
    if (ramps != doc.end()) readRamp(file, (*ramps)[i], i, &term);
    model.terms.push_back(term);
  }
  model.intercept = number(file, member(file, doc, "intercept"), "intercept");
  readViewSettings(file, doc, &model);
  return model;
}

}  // namespace tgnav::harness
