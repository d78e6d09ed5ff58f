#pragma once
// PX4's body-rate controller (RateControl.cpp): PID with feed-forward on the rate setpoint, D on
// the measured angular acceleration, integrators limited, reduced for large errors and frozen
// in the direction allocation reports saturated.
#include "control/types.h"

namespace tgnav::control {

struct RateControlConfig {
  Eigen::Vector3d p = Eigen::Vector3d(0.15, 0.15, 0.2);               // MC_{ROLL,PITCH,YAW}RATE_P
  Eigen::Vector3d i = Eigen::Vector3d(0.2, 0.2, 0.1);                 // MC_*RATE_I
  Eigen::Vector3d d = Eigen::Vector3d(0.003, 0.003, 0.0);             // MC_*RATE_D
  Eigen::Vector3d ff = Eigen::Vector3d(0.0, 0.0, 0.0);                // MC_*RATE_FF
  Eigen::Vector3d integrator_limit = Eigen::Vector3d(0.3, 0.3, 0.3);  // MC_*R_INT_LIM
  double dterm_cutoff_hz = 30.0;  // IMU_DGYRO_CUTOFF: low-pass of the angular acceleration

  // Names every field once, for the harness's config files (a(key, field); harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a("p", p);
    a("i", i);
    a("d", d);
    a("ff", ff);
    a("integrator_limit", integrator_limit);
    a("dterm_cutoff_hz", dterm_cutoff_hz);
  }

  void validate() const;
};

class RateControl {
 public:
  explicit RateControl(const RateControlConfig& config);
  // Normalised torque demand for rate setpoint `rate_sp_B`, measured rates `w_B`.
  Eigen::Vector3d update(const Eigen::Vector3d& rate_sp_B, const Eigen::Vector3d& w_B, double dt_s);
  // Saturation reported by allocation for the next integrator update.
  void setSaturation(const Saturation& saturation) { saturation_ = saturation; }
  void reset();
  const Eigen::Vector3d& integral() const { return integral_; }

 private:
  RateControlConfig config_;
  Eigen::Vector3d integral_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d w_dot_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d w_prev_ = Eigen::Vector3d::Zero();
  bool has_prev_ = false;
  Saturation saturation_;
};

}  // namespace tgnav::control
