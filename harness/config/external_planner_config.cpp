#include "harness/config/external_planner_config.h"

#include <stdexcept>

#include "harness/config/check.h"

namespace tgnav::harness {

bool isExternalPlannerName(const std::string& name) {
  if (name.empty() || name.size() > 40) return false;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
    if (!ok) return false;
  }
  for (const char* reserved : {"proposed", "agnostic", "rrtstar", "trajectory", "path"}) {
    if (name == reserved) return false;
  }
  return true;
}

void ExternalPlannerConfig::validate() const {
  if (command.empty()) throw std::invalid_argument("command = '': give a command, or none");
  if (!isExternalPlannerName(name)) {
    throw std::invalid_argument("name = '" + name +
                                "': 1-40 letters, digits, '_' or '-', and not proposed, agnostic, rrtstar, "
                                "trajectory or path");
  }
  if (dir.empty()) throw std::invalid_argument("dir = '': give a folder ('.' for the file's own)");
  require(timeout_s > 0.0 && timeout_s <= 3600.0, "timeout_s", timeout_s, "must be in (0, 3600] s");
}

}  // namespace tgnav::harness
