#pragma once
// Plain data exchanged by the control library. Frames: world W z-up, body B FLU (README).
#include <Eigen/Geometry>
#include <array>

namespace tgnav::control {

// Estimated (or true) state of the vehicle.
struct VehicleState {
  Eigen::Vector3d p_WB = Eigen::Vector3d::Zero();  // position of B in W [m]
  Eigen::Vector3d v_WB = Eigen::Vector3d::Zero();  // velocity of B in W [m/s]
  Eigen::Quaterniond q_WB = Eigen::Quaterniond::Identity();
  Eigen::Vector3d w_B = Eigen::Vector3d::Zero();  // body rates in B [rad/s]
};

// One trajectory setpoint; velocity and acceleration are feed-forward terms.
struct TrajectorySetpoint {
  Eigen::Vector3d p_WB = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_WB = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_WB = Eigen::Vector3d::Zero();
  double yaw_rad = 0.0;
  double yaw_rate_rad_s = 0.0;
};

// Output of the position controller: normalised thrust vector in W (|T| in [0, 1] of the
// vehicle's total maximum thrust, along body z) and the yaw setpoint.
struct ThrustSetpoint {
  Eigen::Vector3d thrust_W = Eigen::Vector3d::Zero();
  double yaw_rad = 0.0;
  double yaw_rate_rad_s = 0.0;
};

struct AttitudeSetpoint {
  Eigen::Quaterniond q_WB = Eigen::Quaterniond::Identity();
  double thrust = 0.0;  // normalised collective thrust along body z, [0, 1]
  double yaw_rate_ff_rad_s = 0.0;
};

// Normalised torque in [-1, 1] per axis (roll, pitch, yaw about B's x, y, z) and collective
// thrust in [0, 1], as PX4's rate controller hands them to control allocation.
struct ControlDemand {
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();
  double thrust = 0.0;
};

// Per-axis saturation reported by allocation back to the rate controller (its integrators
// freeze in the direction that cannot be produced).
struct Saturation {
  std::array<bool, 3> positive{};
  std::array<bool, 3> negative{};
};

}  // namespace tgnav::control
