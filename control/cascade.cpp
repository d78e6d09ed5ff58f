#include "control/cascade.h"

#include <stdexcept>
#include <string>

#include "control/check.h"

namespace tgnav::control {

void CascadeConfig::validate() const {
  position.validate();
  attitude.validate();
  rate.validate();
  require(position_rate_hz > 0.0 && position_rate_hz <= attitude_rate_hz, "rates_hz.position", position_rate_hz,
          "must be > 0 and <= rates_hz.attitude");
  require(attitude_rate_hz <= rate_rate_hz, "rates_hz.attitude", attitude_rate_hz, "must be <= rates_hz.rate");
  require(rate_rate_hz > 0.0, "rates_hz.rate", rate_rate_hz, "must be > 0");
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

void Cascade::updateAttitude(const Eigen::Quaterniond& q_WB) { rate_sp_ = attitude_.update(q_WB, attitude_sp_); }

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
