#include "control/vehicle.h"

#include <Eigen/Geometry>
#include <Eigen/QR>
#include <cmath>
#include <stdexcept>
#include <string>

#include "control/check.h"

namespace tgnav::control {

void VehicleParams::validate() const {
  auto fail = [](const std::string& what) { throw std::invalid_argument(what); };
  require(mass_kg > 0.0, "mass_kg", mass_kg, "must be > 0");
  if (!(inertia_diag_kg_m2.array() > 0.0).all()) fail("inertia_diag_kg_m2: must be > 0 on every axis");
  if (rotors.size() < 4) fail("rotors: " + std::to_string(rotors.size()) + " rotors, need >= 4");
  for (std::size_t i = 0; i < rotors.size(); ++i) {
    const Rotor& r = rotors[i];
    const std::string name = "rotors[" + std::to_string(i) + "].";
    require(r.max_thrust_n > 0.0, name + "max_thrust_n", r.max_thrust_n, "must be > 0");
    require(r.spin == 1 || r.spin == -1, name + "spin", r.spin, "must be +1 or -1");
    if (!(r.yaw_moment_ratio_m >= 0.0)) fail(name + "yaw_moment_ratio_m: must be >= 0");
    if (std::abs(r.axis_B.norm() - 1.0) > 1e-6) fail(name + "axis_B: must be a unit vector");
  }
  if (!(motor_time_constant_s >= 0.0)) fail("motor_time_constant_s: must be >= 0");
  if (!(gravity_m_s2 > 0.0)) fail("gravity_m_s2: must be > 0");
  require(hoverThrust() < 0.9, "hover thrust (of maximum)", hoverThrust(), "vehicle too heavy to fly");
}

Eigen::MatrixXd VehicleParams::effectiveness() const {
  Eigen::MatrixXd e(4, static_cast<Eigen::Index>(rotors.size()));
  for (std::size_t i = 0; i < rotors.size(); ++i) {
    const Rotor& r = rotors[i];
    const Eigen::Vector3d force = r.axis_B * r.max_thrust_n;
    // Thrust moment p x F, plus the rotor drag reaction (-spin along the axis).
    const Eigen::Vector3d moment = r.p_B.cross(force) - r.spin * r.yaw_moment_ratio_m * force;
    e.col(static_cast<Eigen::Index>(i)) << moment, force.z();
  }
  return e;
}

void VehicleParams::checkControllable() const {
  for (std::size_t i = 0; i < rotors.size(); ++i) {
    if (!(rotors[i].axis_B.z() > 0.0)) {
      throw std::invalid_argument("rotors[" + std::to_string(i) + "].axis_B: thrust must point upward (z > 0)");
    }
  }
  const Eigen::MatrixXd e = effectiveness();
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(e);
  qr.setThreshold(1e-6);
  if (qr.rank() < 4) {
    throw std::invalid_argument(
        "rotors: the rotor geometry cannot command roll, pitch, yaw and thrust "
        "independently (effectiveness matrix rank " +
        std::to_string(qr.rank()) + " < 4: check the rotor sites and the spin signs of the gears)");
  }
}

double VehicleParams::totalMaxThrustN() const {
  double sum = 0.0;
  for (const Rotor& r : rotors) sum += r.max_thrust_n * r.axis_B.z();
  return sum;
}

double VehicleParams::hoverThrust() const { return mass_kg * gravity_m_s2 / totalMaxThrustN(); }

}  // namespace tgnav::control
