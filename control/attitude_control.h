#pragma once
// PX4's quaternion attitude controller (AttitudeControl.cpp): roll/pitch are corrected first
// (reduced attitude), yaw only with weight yaw_weight; P on the quaternion error, yaw-rate
// feed-forward, body-rate limits.
#include "control/types.h"

namespace tgnav::control {

struct AttitudeControlConfig {
  double roll_p = 6.5;                              // MC_ROLL_P [1/s]
  double pitch_p = 6.5;                             // MC_PITCH_P
  double yaw_p = 2.8;                               // MC_YAW_P
  double yaw_weight = 0.4;                          // MC_YAW_WEIGHT: yaw priority relative to roll/pitch
  double max_roll_rate_rad_s = 3.839724354387525;   // MC_ROLLRATE_MAX 220 deg/s
  double max_pitch_rate_rad_s = 3.839724354387525;  // MC_PITCHRATE_MAX 220 deg/s
  double max_yaw_rate_rad_s = 3.490658503988659;    // MC_YAWRATE_MAX 200 deg/s

  // Names every field once, for the harness's config files (a(key, field); harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a("roll_p", roll_p);
    a("pitch_p", pitch_p);
    a("yaw_p", yaw_p);
    a("yaw_weight", yaw_weight);
    a("max_roll_rate_rad_s", max_roll_rate_rad_s);
    a("max_pitch_rate_rad_s", max_pitch_rate_rad_s);
    a("max_yaw_rate_rad_s", max_yaw_rate_rad_s);
  }

  void validate() const;
};

class AttitudeControl {
 public:
  explicit AttitudeControl(const AttitudeControlConfig& config);
  // Body-rate setpoint w_B [rad/s].
  Eigen::Vector3d update(const Eigen::Quaterniond& q_WB, const AttitudeSetpoint& setpoint) const;

 private:
  AttitudeControlConfig config_;
  Eigen::Vector3d gain_;  // yaw gain compensated for the yaw weight, as PX4 does
};

}  // namespace tgnav::control
