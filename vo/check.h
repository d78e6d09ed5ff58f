#pragma once
// Config validation: std::invalid_argument naming the field and its value ("min_inliers = 3: ...").
#include <sstream>
#include <stdexcept>
#include <string>

namespace tgnav::vo {

inline void require(bool ok, const std::string& field, double value, const std::string& rule) {
  if (ok) return;
  std::ostringstream msg;
  msg << field << " = " << value << ": " << rule;
  throw std::invalid_argument(msg.str());
}

}  // namespace tgnav::vo
