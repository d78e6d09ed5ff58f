#include "harness/experiments/report_trial.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "harness/base/errors.h"
#include "harness/base/files.h"
#include "vo/odometry.h"

namespace tgnav::harness {
namespace {

namespace fs = std::filesystem;

nlohmann::json readObject(const fs::path& file, const std::string& shown) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(readTextFile(file));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(shown + ": not valid JSON: " + e.what());
  }
  if (!j.is_object()) throw InputError(shown + ": not a JSON object");
  return j;
}

std::optional<double> numberField(const nlohmann::json& j, const char* key) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_number() || !std::isfinite(it->get<double>())) return std::nullopt;
  return it->get<double>();
}

// A non-negative integer field; none when missing, null or anything else.
std::optional<int> indexField(const nlohmann::json& j, const char* key) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_number_integer() || it->get<long long>() < 0) return std::nullopt;
  return static_cast<int>(it->get<long long>());
}

}  // namespace

void readTrialMetrics(const fs::path& file, const std::string& shown, IndexRow& row) {
  const nlohmann::json j = readObject(file, shown);
  const auto ok = j.find("vo_ok");
  const auto weak = j.find("vo_weak");
  if (ok != j.end() && weak != j.end() && ok->is_number() && weak->is_number()) {
    row.tracked_frames = ok->get<double>() + weak->get<double>() > 0;
  }
  const auto lost = j.find("vo_lost_position");
  if (lost != j.end() && lost->is_array() && lost->size() == 3 &&
      std::all_of(lost->begin(), lost->end(), [](const nlohmann::json& v) { return v.is_number(); })) {
    row.vo_lost_position = lost->get<std::vector<double>>();
  }
  row.oracle_class = indexField(j, "oracle_class");
  row.chosen_class = indexField(j, "chosen_class");
  row.classes = indexField(j, "classes");
  row.chosen_c_p_min = numberField(j, "c_p_min");
}

void readTrialPlan(const fs::path& file, const std::string& shown, IndexRow& row) {
  const nlohmann::json j = readObject(file, shown);
  row.c_p_threshold = numberField(j, "c_p_threshold");
  const std::optional<int> chosen = indexField(j, "chosen_class");
  const auto classes = j.find("classes");
  if (chosen && classes != j.end() && classes->is_array() && *chosen < static_cast<int>(classes->size())) {
    const nlohmann::json& c = (*classes)[static_cast<std::size_t>(*chosen)];
    if (c.is_object()) {
      const std::optional<double> c_p_min = numberField(c, "c_p_min");
      if (c_p_min || c.contains("c_p_min")) row.chosen_c_p_min = c_p_min;  // null there: no score
    }
  }
}

std::optional<int> trialMinInliers(const fs::path& trial_folder) {
  try {
    const YAML::Node config = YAML::LoadFile((trial_folder / "config.yaml").string());
    if (!config.IsMap()) return std::nullopt;
    const YAML::Node vo = config["vo"];  // invalid (false) when there is none
    if (vo && vo.IsMap() && vo["min_inliers"]) return vo["min_inliers"].as<int>();
    return vo::OdometryConfig{}.min_inliers;
  } catch (const YAML::Exception&) {
    return std::nullopt;
  }
}

bool voCsvHasColumn(const fs::path& trial_folder, const std::string& name) {
  std::ifstream in(trial_folder / "vo.csv");
  std::string header;
  if (!in || !std::getline(in, header)) return false;
  if (!header.empty() && header.back() == '\r') header.pop_back();
  std::string::size_type start = 0;
  while (true) {
    const auto end = header.find(',', start);
    if (header.compare(start, end == std::string::npos ? std::string::npos : end - start, name) == 0) return true;
    if (end == std::string::npos) return false;
    start = end + 1;
  }
}

}  // namespace tgnav::harness
