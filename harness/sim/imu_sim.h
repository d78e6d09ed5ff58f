#pragma once
// The vehicle's IMU: MuJoCo's accelerometer and gyro at the `imu` site (the body origin), read
// after every physics step, with the white noise and per-axis constant bias of ImuConfig. The
// biases and the noise are drawn from the trial's seed.
#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <cstdint>
#include <random>

#include "control/state_estimator.h"
#include "harness/config/trial_config.h"
#include "harness/sim/mujoco_sim.h"

namespace tgnav::harness {

class SimulatedImu {
 public:
  SimulatedImu(const ImuConfig& config, const VehicleIds& ids, std::uint64_t seed);

  // The sample of the step just taken: MuJoCo computes sensors at the start of a step from that
  // step's acceleration, which is the acceleration held over [t - dt, t]; t_s is the step's end.
  control::ImuSample sample(const mjData* d);
  const Eigen::Vector3d& accelBias() const { return accel_bias_; }
  const Eigen::Vector3d& gyroBias() const { return gyro_bias_; }

 private:
  ImuConfig config_;
  VehicleIds ids_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> unit_{0.0, 1.0};
  Eigen::Vector3d accel_bias_;
  Eigen::Vector3d gyro_bias_;
};

}  // namespace tgnav::harness
