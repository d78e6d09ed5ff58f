#pragma once
// Settings of a closed-loop trial: a scenario's `trial:` section.
//
//   trial:
//     state_source: gt        # gt: the controller flies on ground truth (the paper's motion
//                             # capture); vo: on the VO poses fused with the simulated IMU
//     camera_rate_hz: 20      # camera + VO; must divide the physics rate
//     goal_radius_m: 0.5      # success needs the true final position this close to the goal
//     pipeline: true          # render and VO on two threads; results equal the sequential run
//     flight: {takeoff_speed_m_s, settle_s, hold_s, max_start_offset_m, diverged_tilt_rad,
//              diverged_speed_m_s}
//     imu: {accel_noise_m_s2, accel_bias_m_s2, gyro_noise_rad_s, gyro_bias_rad_s}
//     estimator: {accel_noise_m_s2, position_sigma_m, attitude_gain, gyro_bias_gain,
//                 max_position_innovation_m, history_s}
#include <string>

#include "control/state_estimator.h"
#include "harness/flight_loop.h"

namespace tgnav::harness {

enum class StateSource { kGroundTruth, kVo };
const char* toString(StateSource source);  // "gt" | "vo"
// False when `text` names no source.
bool parseStateSource(const std::string& text, StateSource* source);

// The simulated IMU: the true specific force and body rates, sampled every physics step, with
// white noise and a constant bias per axis drawn from the trial's seed.
struct ImuConfig {
  double accel_noise_m_s2 = 0.05;  // white noise sigma per sample (about 2.2e-3 m/s^2/sqrt(Hz) at 500 Hz)
  double accel_bias_m_s2 = 0.02;   // sigma of the constant bias per axis
  double gyro_noise_rad_s = 0.005;
  double gyro_bias_rad_s = 0.001;

  void validate() const;  // std::invalid_argument naming the field and value
};

struct TrialConfig {
  StateSource state_source = StateSource::kGroundTruth;
  double camera_rate_hz = 20.0;
  double goal_radius_m = 0.5;
  bool pipeline = true;
  FlightConfig flight;
  ImuConfig imu;
  control::EstimatorConfig estimator;

  void validate() const;  // std::invalid_argument naming the field (dotted within trial) and value
};

}  // namespace tgnav::harness
