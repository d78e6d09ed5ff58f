#pragma once
// Physical description of a multirotor, as control allocation and the controller need it.
#include <Eigen/Core>
#include <vector>

namespace tgnav::control {

struct Rotor {
  Eigen::Vector3d p_B = Eigen::Vector3d::Zero();      // thrust point relative to the centre of mass
  Eigen::Vector3d axis_B = Eigen::Vector3d::UnitZ();  // thrust direction
  int spin = 1;                                       // +1 counter-clockwise seen from above, -1 clockwise
  double yaw_moment_ratio_m = 0.0;                    // drag moment / thrust
  double max_thrust_n = 0.0;
};

struct VehicleParams {
  double mass_kg = 0.0;
  Eigen::Vector3d inertia_diag_kg_m2 = Eigen::Vector3d::Zero();
  std::vector<Rotor> rotors;
  double motor_time_constant_s = 0.0;
  double gravity_m_s2 = 9.81;

  // Throws std::invalid_argument naming the field and value.
  void validate() const;
  // Throws std::invalid_argument unless the rotors can command roll, pitch and yaw moments and
  // collective thrust independently (the effectiveness matrix has rank 4) and every rotor lifts.
  void checkControllable() const;
  // The 4 x n effectiveness matrix: the wrench [Mx, My, Mz in N m about B's axes, Fz in N] of
  // each rotor at its maximum thrust (what the allocation inverts).
  Eigen::MatrixXd effectiveness() const;
  double totalMaxThrustN() const;
  // Normalised collective thrust that balances gravity when level.
  double hoverThrust() const;
};

}  // namespace tgnav::control
