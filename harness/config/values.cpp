#include "harness/config/values.h"

#include <cmath>
#include <sstream>

#include "harness/base/errors.h"

namespace tgnav::harness {

std::vector<double> parseNumbers(const std::string& text, std::size_t count, const std::string& option,
                                 const std::string& form) {
  std::vector<double> values;
  std::stringstream ss(text);
  std::string item;
  bool ok = true;
  while (ok && std::getline(ss, item, ',')) {
    std::size_t used = 0;
    try {
      const double v = std::stod(item, &used);
      ok = used == item.size() && std::isfinite(v);
      values.push_back(v);
    } catch (const std::exception&) {
      ok = false;
    }
  }
  if (!ok || values.size() != count || (!text.empty() && text.back() == ',')) {
    throw InputError(option + ": '" + text + "' is not " + form);
  }
  return values;
}

namespace {
nlohmann::ordered_json scalarToJson(const std::string& text) {
  if (text == "true" || text == "false") return text == "true";
  std::size_t used = 0;
  try {
    const long long i = std::stoll(text, &used);
    if (used == text.size()) return i;
    const double d = std::stod(text, &used);
    if (used == text.size()) return d;
  } catch (const std::exception&) {
  }
  return text;
}
}  // namespace

nlohmann::ordered_json toJson(const YAML::Node& node) {
  if (node.IsMap()) {
    nlohmann::ordered_json j = nlohmann::ordered_json::object();
    for (const auto& kv : node) j[kv.first.as<std::string>()] = toJson(kv.second);
    return j;
  }
  if (node.IsSequence()) {
    nlohmann::ordered_json j = nlohmann::ordered_json::array();
    for (const auto& item : node) j.push_back(toJson(item));
    return j;
  }
  if (node.IsScalar()) return scalarToJson(node.Scalar());
  return nullptr;
}

}  // namespace tgnav::harness
