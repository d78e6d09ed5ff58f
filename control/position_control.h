#pragma once
// PX4's multicopter position controller (PositionControl.cpp), in ENU/FLU:
// position P -> velocity PID (D on the measured acceleration, anti-windup) plus feed-forward
// -> acceleration -> thrust vector with tilt limit, hover-thrust scaling and vertical priority
// with a horizontal margin.
#include "control/types.h"

namespace tgnav::control {

struct PositionControlConfig {
  double pos_p_xy = 0.95;                    // MPC_XY_P [1/s]
  double pos_p_z = 1.0;                      // MPC_Z_P [1/s]
  double vel_p_xy = 3.0;                     // MPC_XY_VEL_P_ACC [1/s] (PX4 default 1.8, see controller.yaml)
  double vel_i_xy = 0.4;                     // MPC_XY_VEL_I_ACC [1/s^2]
  double vel_d_xy = 0.2;                     // MPC_XY_VEL_D_ACC [-]
  double vel_p_z = 4.0;                      // MPC_Z_VEL_P_ACC
  double vel_i_z = 2.0;                      // MPC_Z_VEL_I_ACC
  double vel_d_z = 0.0;                      // MPC_Z_VEL_D_ACC
  double max_vel_xy_m_s = 12.0;              // MPC_XY_VEL_MAX
  double max_vel_up_m_s = 3.0;               // MPC_Z_VEL_MAX_UP
  double max_vel_down_m_s = 1.5;             // MPC_Z_VEL_MAX_DN
  double tilt_max_rad = 0.7853981633974483;  // MPC_TILTMAX_AIR 45 deg
  double thrust_min = 0.12;                  // MPC_THR_MIN
  double thrust_max = 1.0;                   // MPC_THR_MAX
  double thrust_xy_margin = 0.3;             // MPC_THR_XY_MARG
  double vel_deriv_cutoff_hz = 5.0;          // MPC_VELD_LP: low-pass of the velocity derivative

  // Names every field once, for the harness's config files (a(key, field); harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a("pos_p_xy", pos_p_xy);
    a("pos_p_z", pos_p_z);
    a("vel_p_xy", vel_p_xy);
    a("vel_i_xy", vel_i_xy);
    a("vel_d_xy", vel_d_xy);
    a("vel_p_z", vel_p_z);
    a("vel_i_z", vel_i_z);
    a("vel_d_z", vel_d_z);
    a("max_vel_xy_m_s", max_vel_xy_m_s);
    a("max_vel_up_m_s", max_vel_up_m_s);
    a("max_vel_down_m_s", max_vel_down_m_s);
    a("tilt_max_rad", tilt_max_rad);
    a("thrust_min", thrust_min);
    a("thrust_max", thrust_max);
    a("thrust_xy_margin", thrust_xy_margin);
    a("vel_deriv_cutoff_hz", vel_deriv_cutoff_hz);
  }

  void validate() const;
};

class PositionControl {
 public:
  // `hover_thrust`: normalised thrust that balances gravity (PX4 estimates it in flight; the
  // harness takes it from the vehicle model).
  PositionControl(const PositionControlConfig& config, double hover_thrust, double gravity_m_s2);

  ThrustSetpoint update(const VehicleState& state, const TrajectorySetpoint& setpoint, double dt_s);
  void reset();

  // Introspection for tests and logs.
  const Eigen::Vector3d& velocitySetpoint() const { return vel_sp_; }
  const Eigen::Vector3d& accelerationSetpoint() const { return acc_sp_; }
  const Eigen::Vector3d& velocityIntegral() const { return vel_int_; }

  // Thrust vector for an acceleration setpoint (tilt limit, hover scaling, minimum thrust);
  // without vertical priority, which needs the velocity error. Exposed for tests.
  Eigen::Vector3d accelerationToThrust(const Eigen::Vector3d& acc_sp_W) const;

 private:
  PositionControlConfig config_;
  double hover_thrust_;
  double gravity_;
  Eigen::Vector3d vel_int_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d vel_dot_ = Eigen::Vector3d::Zero();  // filtered derivative of velocity
  Eigen::Vector3d vel_prev_ = Eigen::Vector3d::Zero();
  bool has_prev_ = false;
  Eigen::Vector3d vel_sp_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d acc_sp_ = Eigen::Vector3d::Zero();
};

// Limits the tilt of unit vector `body_z` from the world z axis to `max_tilt_rad`.
Eigen::Vector3d limitTilt(const Eigen::Vector3d& body_z, double max_tilt_rad);

// Attitude whose body z is along `thrust_W` and whose heading is `yaw_rad` (PX4's
// ControlMath::bodyzToAttitude), with the collective thrust |thrust_W|.
AttitudeSetpoint thrustToAttitude(const ThrustSetpoint& thrust);

}  // namespace tgnav::control
