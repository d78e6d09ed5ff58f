#pragma once
// Phases and divergence limits of a flight (a scenario's trial.flight section); the flight loop
// that uses them is harness/sim/flight_loop.h.
#include <cmath>

namespace tgnav::harness {

struct FlightConfig {
  double takeoff_speed_m_s = 1.0;       // peak climb speed from the ground to the first setpoint
  double settle_s = 1.0;                // hover at the first setpoint before the trajectory starts
  double hold_s = 2.0;                  // keep holding the last setpoint after the trajectory ends
  double max_start_offset_m = 0.5;      // first setpoint vs. start pose, horizontally
  double diverged_tilt_rad = M_PI / 2;  // beyond these the flight stops as diverged
  double diverged_speed_m_s = 20.0;

  // The keys of a trial's `flight:` section (harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a("takeoff_speed_m_s", takeoff_speed_m_s);
    a("settle_s", settle_s);
    a("hold_s", hold_s);
    a("max_start_offset_m", max_start_offset_m);
    a("diverged_tilt_rad", diverged_tilt_rad);
    a("diverged_speed_m_s", diverged_speed_m_s);
  }

  void validate() const;
};

}  // namespace tgnav::harness
