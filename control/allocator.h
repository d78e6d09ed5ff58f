#pragma once
// Control allocation as PX4 does it (ActuatorEffectivenessRotors + pseudo-inverse + sequential
// desaturation with airmode disabled): normalised torque/thrust demand -> per-rotor commands.
#include <Eigen/Core>

#include "control/types.h"
#include "control/vehicle.h"

namespace tgnav::control {

class ControlAllocator {
 public:
  // The effectiveness matrix comes from the rotors' positions, axes, spins, yaw-moment ratios
  // and maximum thrusts; nothing about the airframe is assumed.
  explicit ControlAllocator(const VehicleParams& vehicle);

  // Per-rotor commands in [0, 1] (fraction of each rotor's maximum thrust). Roll and pitch are
  // kept over yaw, and thrust is only ever reduced to make room (PX4, airmode disabled).
  Eigen::VectorXd allocate(const ControlDemand& demand, Saturation* saturation = nullptr) const;

  // Thrust of each rotor in newtons for commands `u`.
  Eigen::VectorXd thrustsN(const Eigen::VectorXd& u) const;
  // Physical wrench [Mx, My, Mz in N m about B's axes, Fz in N] that commands `u` produce.
  Eigen::Vector4d wrench(const Eigen::VectorXd& u) const { return effectiveness_ * u; }
  // Physical wrench that a normalised demand stands for.
  Eigen::Vector4d wrenchOf(const ControlDemand& demand) const;
  // The normalised demand that commands `u` produce.
  ControlDemand achieved(const Eigen::VectorXd& u) const;

 private:
  void desaturate(Eigen::VectorXd& u, const Eigen::VectorXd& direction, double u_max, bool reduce_only) const;
  static double desaturationGain(const Eigen::VectorXd& u, const Eigen::VectorXd& direction, double u_max);

  Eigen::MatrixXd effectiveness_;  // 4 x n: wrench per unit command
  Eigen::MatrixXd mix_;            // n x 4: u = mix_ * [roll, pitch, yaw, thrust] (normalised)
  Eigen::Vector4d scale_;          // normalised demand = scale_ .* physical wrench
  Eigen::VectorXd max_thrust_n_;
};

}  // namespace tgnav::control
