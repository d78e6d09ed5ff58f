#pragma once
// The whole PX4-like cascade for one vehicle. The stages run at their own rates: the caller
// (harness FlightLoop) decides when each update is due, so this class holds no clock.
#include <Eigen/Core>

#include "control/allocator.h"
#include "control/attitude_control.h"
#include "control/position_control.h"
#include "control/rate_control.h"

namespace tgnav::control {

struct CascadeConfig {
  PositionControlConfig position;
  AttitudeControlConfig attitude;
  RateControlConfig rate;
  double position_rate_hz = 100.0;
  double attitude_rate_hz = 250.0;
  double rate_rate_hz = 500.0;

  // Names every field once, for the harness's config files (a(key, field), nested structs and
  // groups as mappings; harness/config/yaml_util.h): configs/controller.yaml.
  template <typename Archive>
  void visit(Archive& a) {
    a.group("rates_hz", [&](auto& g) {
      g("position", position_rate_hz);
      g("attitude", attitude_rate_hz);
      g("rate", rate_rate_hz);
    });
    a("position", position);
    a("attitude", attitude);
    a("rate", rate);
  }

  void validate() const;
};

class Cascade {
 public:
  Cascade(const CascadeConfig& config, const VehicleParams& vehicle);

  // Position/velocity stage: trajectory setpoint -> attitude and thrust setpoint.
  void updatePosition(const VehicleState& state, const TrajectorySetpoint& setpoint, double dt_s);
  // Attitude stage: attitude setpoint -> body-rate setpoint.
  void updateAttitude(const Eigen::Quaterniond& q_WB);
  // Rate stage and allocation: body-rate setpoint -> rotor thrusts in newtons.
  Eigen::VectorXd updateRate(const Eigen::Vector3d& w_B, double dt_s);
  void reset();

  const PositionControl& positionControl() const { return position_; }

 private:
  PositionControl position_;
  AttitudeControl attitude_;
  RateControl rate_;
  ControlAllocator allocator_;
  double hover_thrust_;
  AttitudeSetpoint attitude_sp_;
  Eigen::Vector3d rate_sp_ = Eigen::Vector3d::Zero();
};

}  // namespace tgnav::control
