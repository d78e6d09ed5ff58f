#include "control/allocator.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace tgnav::control {

namespace {
// PX4 lets yaw use 15 % beyond full thrust before it is cut, so some yaw authority remains at
// full collective thrust (ControlAllocationSequentialDesaturation::mixYaw).
constexpr double kYawHeadroom = 0.15;
constexpr double kEps = 1e-9;
}  // namespace

ControlAllocator::ControlAllocator(const VehicleParams& vehicle) {
  vehicle.validate();
  const int n = static_cast<int>(vehicle.rotors.size());
  effectiveness_ = vehicle.effectiveness();
  max_thrust_n_.resize(n);
  for (int i = 0; i < n; ++i) max_thrust_n_[i] = vehicle.rotors[i].max_thrust_n;
  const Eigen::MatrixXd pinv = effectiveness_.completeOrthogonalDecomposition().pseudoInverse();  // n x 4

  // PX4's normalisation: a full roll or pitch demand spans about +-1/sqrt(2) of the motor range
  // on a quad X, a full yaw demand saturates the most yaw-effective motor, full thrust makes
  // every motor full.
  const double rp = std::sqrt(std::max(pinv.col(0).squaredNorm(), pinv.col(1).squaredNorm()) / (0.5 * n));
  scale_ << rp, rp, pinv.col(2).cwiseAbs().maxCoeff(), pinv.col(3).maxCoeff();
  mix_ = pinv;
  for (int j = 0; j < 4; ++j) mix_.col(j) /= scale_[j];
}

Eigen::VectorXd ControlAllocator::thrustsN(const Eigen::VectorXd& u) const { return u.cwiseProduct(max_thrust_n_); }

Eigen::Vector4d ControlAllocator::wrenchOf(const ControlDemand& d) const {
  Eigen::Vector4d normalised;
  normalised << d.torque, d.thrust;
  return normalised.cwiseQuotient(scale_);
}

ControlDemand ControlAllocator::achieved(const Eigen::VectorXd& u) const {
  const Eigen::Vector4d normalised = scale_.cwiseProduct(wrench(u));
  ControlDemand d;
  d.torque = normalised.head<3>();
  d.thrust = normalised[3];
  return d;
}

double ControlAllocator::desaturationGain(const Eigen::VectorXd& u, const Eigen::VectorXd& dir, double u_max) {
  double k_min = 0.0;
  double k_max = 0.0;
  for (int i = 0; i < u.size(); ++i) {
    if (std::abs(dir[i]) < kEps) continue;
    double k = 0.0;
    if (u[i] < 0.0) {
      k = -u[i] / dir[i];
    } else if (u[i] > u_max) {
      k = (u_max - u[i]) / dir[i];
    } else {
      continue;
    }
    k_min = std::min(k_min, k);
    k_max = std::max(k_max, k);
  }
  // Moving by the sum unsaturates both ends as far as the direction allows.
  return k_min + k_max;
}

void ControlAllocator::desaturate(Eigen::VectorXd& u, const Eigen::VectorXd& dir, double u_max,
                                  bool reduce_only) const {
  double gain = desaturationGain(u, dir, u_max);
  if (reduce_only && gain > 0.0) return;
  u += gain * dir;
  // A second, half step balances the residual saturation between the two ends.
  gain = desaturationGain(u, dir, u_max);
  if (reduce_only && gain > 0.0) return;
  u += 0.5 * gain * dir;
}

Eigen::VectorXd ControlAllocator::allocate(const ControlDemand& demand, Saturation* saturation) const {
  const Eigen::VectorXd roll = mix_.col(0);
  const Eigen::VectorXd pitch = mix_.col(1);
  const Eigen::VectorXd yaw = mix_.col(2);
  const Eigen::VectorXd thrust = mix_.col(3);

  Eigen::VectorXd u = roll * demand.torque.x() + pitch * demand.torque.y() + thrust * demand.thrust;
  desaturate(u, thrust, 1.0, /*reduce_only=*/true);
  desaturate(u, roll, 1.0, false);
  desaturate(u, pitch, 1.0, false);
  u += yaw * demand.torque.z();
  desaturate(u, yaw, 1.0 + kYawHeadroom, false);
  desaturate(u, thrust, 1.0, /*reduce_only=*/true);
  u = u.cwiseMax(0.0).cwiseMin(1.0);

  if (saturation != nullptr) {
    const ControlDemand got = achieved(u);
    constexpr double kTol = 1e-4;
    for (int axis = 0; axis < 3; ++axis) {
      const double unallocated = demand.torque[axis] - got.torque[axis];
      saturation->positive[axis] = unallocated > kTol;
      saturation->negative[axis] = unallocated < -kTol;
    }
  }
  return u;
}

}  // namespace tgnav::control
