#include "control/attitude_control.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "control/check.h"

namespace tgnav::control {

namespace {
Eigen::Quaterniond canonical(const Eigen::Quaterniond& q) {
  return q.w() < 0.0 ? Eigen::Quaterniond(-q.w(), -q.x(), -q.y(), -q.z()) : q;
}
}  // namespace

void AttitudeControlConfig::validate() const {
  require(roll_p > 0.0, "roll_p", roll_p, "must be > 0");
  require(pitch_p > 0.0, "pitch_p", pitch_p, "must be > 0");
  require(yaw_p > 0.0, "yaw_p", yaw_p, "must be > 0");
  require(yaw_weight > 0.0 && yaw_weight <= 1.0, "yaw_weight", yaw_weight, "must be in (0, 1]");
  require(max_roll_rate_rad_s > 0.0, "max_roll_rate_rad_s", max_roll_rate_rad_s, "must be > 0");
  require(max_pitch_rate_rad_s > 0.0, "max_pitch_rate_rad_s", max_pitch_rate_rad_s, "must be > 0");
  require(max_yaw_rate_rad_s > 0.0, "max_yaw_rate_rad_s", max_yaw_rate_rad_s, "must be > 0");
}

AttitudeControl::AttitudeControl(const AttitudeControlConfig& config) : config_(config) {
  config_.validate();
  gain_ = Eigen::Vector3d(config_.roll_p, config_.pitch_p, config_.yaw_p / config_.yaw_weight);
}

Eigen::Vector3d AttitudeControl::update(const Eigen::Quaterniond& q_in, const AttitudeSetpoint& setpoint) const {
  const Eigen::Quaterniond q = q_in.normalized();
  Eigen::Quaterniond qd = setpoint.q_WB.normalized();

  // Reduced attitude: the shortest rotation taking the current thrust axis to the desired one,
  // applied to the current attitude (so it keeps the current yaw).
  const Eigen::Vector3d e_z = q * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d e_z_d = qd * Eigen::Vector3d::UnitZ();
  Eigen::Quaterniond qd_red = Eigen::Quaterniond::FromTwoVectors(e_z, e_z_d);
  if (std::abs(qd_red.x()) > 1.0 - 1e-5 || std::abs(qd_red.y()) > 1.0 - 1e-5) {
    qd_red = qd;  // axes opposite: the reduced rotation is undefined, use the full one
  } else {
    qd_red = qd_red * q;
  }
  // Blend in yaw with its weight: rotate from the reduced to the full setpoint about body z.
  Eigen::Quaterniond q_mix = canonical(qd_red.inverse() * qd);
  const double w = std::clamp(q_mix.w(), -1.0, 1.0);
  const double z = std::clamp(q_mix.z(), -1.0, 1.0);
  const double yw = config_.yaw_weight;
  qd = qd_red * Eigen::Quaterniond(std::cos(yw * std::acos(w)), 0.0, 0.0, std::sin(yw * std::asin(z)));

  // P on the attitude error (2 x imaginary part ~ rotation vector for small errors).
  const Eigen::Quaterniond qe = canonical(q.inverse() * qd);
  Eigen::Vector3d rate_sp = gain_.cwiseProduct(2.0 * qe.vec());

  // Yaw-rate feed-forward about world z, expressed in B.
  rate_sp += (q.inverse() * Eigen::Vector3d::UnitZ()) * setpoint.yaw_rate_ff_rad_s;

  rate_sp.x() = std::clamp(rate_sp.x(), -config_.max_roll_rate_rad_s, config_.max_roll_rate_rad_s);
  rate_sp.y() = std::clamp(rate_sp.y(), -config_.max_pitch_rate_rad_s, config_.max_pitch_rate_rad_s);
  rate_sp.z() = std::clamp(rate_sp.z(), -config_.max_yaw_rate_rad_s, config_.max_yaw_rate_rad_s);
  return rate_sp;
}

}  // namespace tgnav::control
