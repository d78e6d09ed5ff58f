#include "control/position_control.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "control/check.h"

namespace tgnav::control {

void PositionControlConfig::validate() const {
  require(pos_p_xy > 0.0, "pos_p_xy", pos_p_xy, "must be > 0");
  require(pos_p_z > 0.0, "pos_p_z", pos_p_z, "must be > 0");
  require(vel_p_xy > 0.0, "vel_p_xy", vel_p_xy, "must be > 0");
  require(vel_p_z > 0.0, "vel_p_z", vel_p_z, "must be > 0");
  require(vel_i_xy >= 0.0, "vel_i_xy", vel_i_xy, "must be >= 0");
  require(vel_i_z >= 0.0, "vel_i_z", vel_i_z, "must be >= 0");
  require(vel_d_xy >= 0.0, "vel_d_xy", vel_d_xy, "must be >= 0");
  require(vel_d_z >= 0.0, "vel_d_z", vel_d_z, "must be >= 0");
  require(max_vel_xy_m_s > 0.0, "max_vel_xy_m_s", max_vel_xy_m_s, "must be > 0");
  require(max_vel_up_m_s > 0.0, "max_vel_up_m_s", max_vel_up_m_s, "must be > 0");
  require(max_vel_down_m_s > 0.0, "max_vel_down_m_s", max_vel_down_m_s, "must be > 0");
  require(tilt_max_rad > 0.0 && tilt_max_rad < 1.5, "tilt_max_rad", tilt_max_rad, "must be in (0, 1.5)");
  require(thrust_min >= 0.0 && thrust_min < thrust_max, "thrust_min", thrust_min, "must be in [0, thrust_max)");
  require(thrust_max > 0.0 && thrust_max <= 1.0, "thrust_max", thrust_max, "must be in (0, 1]");
  require(thrust_xy_margin >= 0.0 && thrust_xy_margin < thrust_max, "thrust_xy_margin", thrust_xy_margin,
          "must be in [0, thrust_max)");
  require(vel_deriv_cutoff_hz > 0.0, "vel_deriv_cutoff_hz", vel_deriv_cutoff_hz, "must be > 0");
}

PositionControl::PositionControl(const PositionControlConfig& config, double hover_thrust, double gravity_m_s2)
    : config_(config), hover_thrust_(hover_thrust), gravity_(gravity_m_s2) {
  config_.validate();
  require(hover_thrust > config_.thrust_min && hover_thrust < config_.thrust_max, "hover_thrust", hover_thrust,
          "must lie between thrust_min and thrust_max");
}

void PositionControl::reset() {
  vel_int_.setZero();
  vel_dot_.setZero();
  vel_prev_.setZero();
  has_prev_ = false;
  vel_sp_.setZero();
  acc_sp_.setZero();
}

Eigen::Vector3d limitTilt(const Eigen::Vector3d& body_z, double max_tilt_rad) {
  const double tilt = std::acos(std::clamp(body_z.z(), -1.0, 1.0));
  if (tilt <= max_tilt_rad) return body_z;
  Eigen::Vector3d horizontal(body_z.x(), body_z.y(), 0.0);
  if (horizontal.norm() < 1e-12) horizontal = Eigen::Vector3d::UnitX();  // pointing down
  return std::cos(max_tilt_rad) * Eigen::Vector3d::UnitZ() + std::sin(max_tilt_rad) * horizontal.normalized();
}

Eigen::Vector3d PositionControl::accelerationToThrust(const Eigen::Vector3d& acc_sp) const {
  // Direction from the horizontal acceleration against gravity only (PX4 decouples vertical
  // acceleration from the tilt, MPC_ACC_DECOUPLE); collective from the vertical acceleration.
  const Eigen::Vector3d body_z =
      limitTilt(Eigen::Vector3d(acc_sp.x(), acc_sp.y(), gravity_).normalized(), config_.tilt_max_rad);
  double collective = (acc_sp.z() + gravity_) * (hover_thrust_ / gravity_) / body_z.z();
  collective = std::max(collective, config_.thrust_min);
  return body_z * collective;
}

ThrustSetpoint PositionControl::update(const VehicleState& state, const TrajectorySetpoint& sp, double dt_s) {
  // Position P plus velocity feed-forward; the horizontal limit applies to the sum but keeps
  // the feed-forward part first (ControlMath::constrainXY simplified to a norm clamp).
  vel_sp_ =
      sp.v_WB + Eigen::Vector3d(config_.pos_p_xy, config_.pos_p_xy, config_.pos_p_z).cwiseProduct(sp.p_WB - state.p_WB);
  const double vxy = vel_sp_.head<2>().norm();
  if (vxy > config_.max_vel_xy_m_s) vel_sp_.head<2>() *= config_.max_vel_xy_m_s / vxy;
  vel_sp_.z() = std::clamp(vel_sp_.z(), -config_.max_vel_down_m_s, config_.max_vel_up_m_s);

  // Derivative of the measured velocity, low-pass filtered (D acts on it, not on the error).
  if (has_prev_ && dt_s > 0.0) {
    const double alpha = dt_s / (dt_s + 1.0 / (2.0 * M_PI * config_.vel_deriv_cutoff_hz));
    vel_dot_ += alpha * ((state.v_WB - vel_prev_) / dt_s - vel_dot_);
  }
  vel_prev_ = state.v_WB;
  has_prev_ = true;

  const Eigen::Vector3d kp(config_.vel_p_xy, config_.vel_p_xy, config_.vel_p_z);
  const Eigen::Vector3d ki(config_.vel_i_xy, config_.vel_i_xy, config_.vel_i_z);
  const Eigen::Vector3d kd(config_.vel_d_xy, config_.vel_d_xy, config_.vel_d_z);
  Eigen::Vector3d vel_err = vel_sp_ - state.v_WB;
  acc_sp_ = kp.cwiseProduct(vel_err) + vel_int_ - kd.cwiseProduct(vel_dot_) + sp.a_WB;

  Eigen::Vector3d thrust = accelerationToThrust(acc_sp_);

  // Vertical anti-windup: stop integrating into a saturated collective thrust.
  if ((thrust.z() <= config_.thrust_min && vel_err.z() <= 0.0) ||
      (thrust.z() >= config_.thrust_max && vel_err.z() >= 0.0)) {
    vel_err.z() = 0.0;
  }

  // Vertical priority: the vertical thrust may use all but the horizontal margin.
  const double thrust_xy_norm = thrust.head<2>().norm();
  const double max_sq = config_.thrust_max * config_.thrust_max;
  const double allocated_xy = std::min(thrust_xy_norm, config_.thrust_xy_margin);
  thrust.z() = std::min(thrust.z(), std::sqrt(max_sq - allocated_xy * allocated_xy));
  const double max_xy = std::sqrt(std::max(0.0, max_sq - thrust.z() * thrust.z()));
  if (thrust_xy_norm > max_xy) thrust.head<2>() *= max_xy / thrust_xy_norm;

  // Horizontal tracking anti-windup: bleed the integrator by what the thrust could not produce.
  const Eigen::Vector2d acc_xy_produced = thrust.head<2>() * (gravity_ / hover_thrust_);
  if (acc_sp_.head<2>().squaredNorm() > acc_xy_produced.squaredNorm()) {
    const double arw_gain = 2.0 / config_.vel_p_xy;
    vel_err.head<2>() -= arw_gain * (acc_sp_.head<2>() - acc_xy_produced);
  }
  vel_int_ += ki.cwiseProduct(vel_err) * dt_s;
  vel_int_.z() = std::clamp(vel_int_.z(), -gravity_, gravity_);

  ThrustSetpoint out;
  out.thrust_W = thrust;
  out.yaw_rad = sp.yaw_rad;
  out.yaw_rate_rad_s = sp.yaw_rate_rad_s;
  return out;
}

AttitudeSetpoint thrustToAttitude(const ThrustSetpoint& t) {
  AttitudeSetpoint att;
  att.thrust = t.thrust_W.norm();
  att.yaw_rate_ff_rad_s = t.yaw_rate_rad_s;
  const Eigen::Vector3d body_z =
      att.thrust > 1e-9 ? Eigen::Vector3d(t.thrust_W / att.thrust) : Eigen::Vector3d::UnitZ();
  // Heading: body x lies in the plane spanned by body z and the yaw direction.
  const Eigen::Vector3d y_c(-std::sin(t.yaw_rad), std::cos(t.yaw_rad), 0.0);
  Eigen::Vector3d body_x = y_c.cross(body_z);
  if (body_z.z() < 0.0) body_x = -body_x;                       // keep the nose forward when inverted
  if (body_x.norm() < 1e-9) body_x = Eigen::Vector3d::UnitX();  // thrust horizontal along y_c
  body_x.normalize();
  const Eigen::Vector3d body_y = body_z.cross(body_x);
  Eigen::Matrix3d R;
  R << body_x, body_y, body_z;
  att.q_WB = Eigen::Quaterniond(R).normalized();
  return att;
}

}  // namespace tgnav::control
