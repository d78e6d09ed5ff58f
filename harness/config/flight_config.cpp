#include "harness/config/flight_config.h"

#include "harness/config/check.h"

namespace tgnav::harness {

void FlightConfig::validate() const {
  require(takeoff_speed_m_s > 0.0, "takeoff_speed_m_s", takeoff_speed_m_s, "must be > 0");
  require(settle_s >= 0.0, "settle_s", settle_s, "must be >= 0");
  require(hold_s >= 0.0, "hold_s", hold_s, "must be >= 0");
  require(max_start_offset_m > 0.0, "max_start_offset_m", max_start_offset_m, "must be > 0");
  require(diverged_tilt_rad > 0.0, "diverged_tilt_rad", diverged_tilt_rad, "must be > 0");
  require(diverged_speed_m_s > 0.0, "diverged_speed_m_s", diverged_speed_m_s, "must be > 0");
}

}  // namespace tgnav::harness
