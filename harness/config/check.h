#pragma once
// Config validation: std::invalid_argument naming the field and its value ("width_px = 3: must be
// in [16, 4096]"); validateConfig re-raises it as an InputError naming the file.
#include <sstream>
#include <stdexcept>
#include <string>

namespace tgnav::harness {

inline void require(bool ok, const std::string& field, double value, const std::string& rule) {
  if (ok) return;
  std::ostringstream msg;
  msg << field << " = " << value << ": " << rule;
  throw std::invalid_argument(msg.str());
}

}  // namespace tgnav::harness
