#pragma once
// Settings of a closed-loop trial: a scenario's `trial:` section. Its keys are TrialConfig::visit's;
// configs/trial.yaml lists them all with their defaults and what they mean.
#include <string>
#include <utility>
#include <vector>

#include "control/state_estimator.h"
#include "harness/config/flight_config.h"

namespace tgnav::harness {

enum class StateSource { kGroundTruth, kVo };
// Every source with its name in configs: {"gt", kGroundTruth}, {"vo", kVo}.
const std::vector<std::pair<std::string, StateSource>>& stateSourceNames();
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

  // The keys of a trial's `imu:` section (harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a("accel_noise_m_s2", accel_noise_m_s2);
    a("accel_bias_m_s2", accel_bias_m_s2);
    a("gyro_noise_rad_s", gyro_noise_rad_s);
    a("gyro_bias_rad_s", gyro_bias_rad_s);
  }

  void validate() const;  // std::invalid_argument naming the field and value
};

struct TrialConfig {
  StateSource state_source = StateSource::kGroundTruth;
  double camera_rate_hz = 20.0;
  double goal_radius_m = 0.5;
  // A trial whose VO tracked to the end but whose goal error exceeds this fraction of the
  // distance flown is `drifted`, not `success` (harness/run/trial_status.h).
  double max_drift_ratio = 0.01;
  bool pipeline = true;
  FlightConfig flight;
  ImuConfig imu;
  control::EstimatorConfig estimator;

  // The keys of configs/trial.yaml (harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a.choice("state_source", state_source, stateSourceNames());
    a("camera_rate_hz", camera_rate_hz);
    a("goal_radius_m", goal_radius_m);
    a("max_drift_ratio", max_drift_ratio);
    a("pipeline", pipeline);
    a("flight", flight);
    a("imu", imu);
    a("estimator", estimator);
  }

  void validate() const;  // std::invalid_argument naming the field (dotted within trial) and value
};

}  // namespace tgnav::harness
