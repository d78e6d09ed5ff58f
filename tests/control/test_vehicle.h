#pragma once
// The S500-class quad of models/quadrotor.xml, written out for simulator-free tests.
#include "control/vehicle.h"

namespace tgnav::control::test {

inline VehicleParams quadX() {
  VehicleParams v;
  v.mass_kg = 1.5;
  v.inertia_diag_kg_m2 = Eigen::Vector3d(0.029125, 0.029125, 0.055225);
  const double a = 0.177;
  const double xs[4] = {a, -a, a, -a};
  const double ys[4] = {-a, a, a, -a};
  const int spins[4] = {1, 1, -1, -1};
  for (int i = 0; i < 4; ++i) {
    Rotor r;
    r.p_B = Eigen::Vector3d(xs[i], ys[i], 0.03);
    r.spin = spins[i];
    r.yaw_moment_ratio_m = 0.02;
    r.max_thrust_n = 7.5;
    v.rotors.push_back(r);
  }
  v.motor_time_constant_s = 0.03;
  return v;
}

}  // namespace tgnav::control::test
