#include "harness/config/trial_config.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "harness/config/check.h"

namespace tgnav::harness {

const std::vector<std::pair<std::string, StateSource>>& stateSourceNames() {
  static const std::vector<std::pair<std::string, StateSource>> names = {{"gt", StateSource::kGroundTruth},
                                                                         {"vo", StateSource::kVo}};
  return names;
}

const char* toString(StateSource source) {
  for (const auto& [name, s] : stateSourceNames()) {
    if (s == source) return name.c_str();
  }
  return "?";
}

bool parseStateSource(const std::string& text, StateSource* source) {
  for (const auto& [name, s] : stateSourceNames()) {
    if (text == name) {
      *source = s;
      return true;
    }
  }
  return false;
}

namespace {

void nonNegative(double value, const char* field) {
  require(std::isfinite(value) && value >= 0.0, field, value, "must be >= 0");
}

// Runs a member's validate(), its field names prefixed with the member's key.
template <typename Config>
void validateMember(const Config& config, const std::string& key) {
  try {
    config.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(key + "." + e.what());
  }
}
}  // namespace

void ImuConfig::validate() const {
  nonNegative(accel_noise_m_s2, "accel_noise_m_s2");
  nonNegative(accel_bias_m_s2, "accel_bias_m_s2");
  nonNegative(gyro_noise_rad_s, "gyro_noise_rad_s");
  nonNegative(gyro_bias_rad_s, "gyro_bias_rad_s");
}

void TrialConfig::validate() const {
  require(std::isfinite(camera_rate_hz) && camera_rate_hz > 0.0, "camera_rate_hz", camera_rate_hz, "must be > 0");
  require(std::isfinite(goal_radius_m) && goal_radius_m > 0.0, "goal_radius_m", goal_radius_m, "must be > 0");
  require(std::isfinite(max_drift_ratio) && max_drift_ratio > 0.0, "max_drift_ratio", max_drift_ratio, "must be > 0");
  validateMember(flight, "flight");
  validateMember(imu, "imu");
  validateMember(estimator, "estimator");
}

}  // namespace tgnav::harness
