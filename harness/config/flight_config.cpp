#include "harness/config/flight_config.h"

#include <stdexcept>
#include <string>

namespace tgnav::harness {

void FlightConfig::validate() const {
  auto positive = [](double v, const char* name) {
    if (!(v > 0.0)) throw std::invalid_argument(std::string(name) + " = " + std::to_string(v) + ": must be > 0");
  };
  positive(takeoff_speed_m_s, "takeoff_speed_m_s");
  if (!(settle_s >= 0.0)) throw std::invalid_argument("settle_s: must be >= 0");
  if (!(hold_s >= 0.0)) throw std::invalid_argument("hold_s: must be >= 0");
  positive(max_start_offset_m, "max_start_offset_m");
  positive(diverged_tilt_rad, "diverged_tilt_rad");
  positive(diverged_speed_m_s, "diverged_speed_m_s");
}

}  // namespace tgnav::harness
