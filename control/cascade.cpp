#include "control/cascade.h"

#include <stdexcept>
#include <string>

namespace tgnav::control {

void CascadeConfig::validate() const {
  position.validate();
  attitude.validate();
  rate.validate();
  auto positive = [](double v, const char* name) {
    if (!(v > 0.0)) throw std::invalid_argument(std::string(name) + " = " + std::to_string(v) + ": must be > 0");
  };
  positive(position_rate_hz, "position_rate_hz");
  positive(attitude_rate_hz, "attitude_rate_hz");
  positive(rate_rate_hz, "rate_rate_hz");
  if (position_rate_hz > attitude_rate_hz || attitude_rate_hz > rate_rate_hz) {
    throw std::invalid_argument("rates: position_rate_hz <= attitude_rate_hz <= rate_rate_hz required");
  }
}

Cascade::Cascade(const CascadeConfig& config, const VehicleParams& vehicle)
    : position_(config.position, vehicle.hoverThrust(), vehicle.gravity_m_s2),
      attitude_(config.attitude),
      rate_(config.rate),
      allocator_(vehicle),
      hover_thrust_(vehicle.hoverThrust()) {
  config.validate();
  reset();
}

void Cascade::reset() {
  position_.reset();
  rate_.reset();
  attitude_sp_ = AttitudeSetpoint{};
  attitude_sp_.thrust = hover_thrust_;
  rate_sp_.setZero();
}

void Cascade::updatePosition(const VehicleState& state, const TrajectorySetpoint& setpoint, double dt_s) {
  attitude_sp_ = thrustToAttitude(position_.update(state, setpoint, dt_s));
}

void Cascade::updateAttitude(const Eigen::Quaterniond& q_WB) {
  rate_sp_ = attitude_.update(q_WB, attitude_sp_);
}

Eigen::VectorXd Cascade::updateRate(const Eigen::Vector3d& w_B, double dt_s) {
  ControlDemand demand;
  demand.torque = rate_.update(rate_sp_, w_B, dt_s);
  demand.thrust = attitude_sp_.thrust;
  Saturation saturation;
  const Eigen::VectorXd u = allocator_.allocate(demand, &saturation);
  rate_.setSaturation(saturation);
  return allocator_.thrustsN(u);
}

}  // namespace tgnav::control
