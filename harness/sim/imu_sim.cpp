#include "harness/sim/imu_sim.h"

namespace tgnav::harness {

SimulatedImu::SimulatedImu(const ImuConfig& config, const VehicleIds& ids, std::uint64_t seed)
    : config_(config), ids_(ids), rng_(seed) {
  config_.validate();
  for (int i = 0; i < 3; ++i) accel_bias_[i] = config_.accel_bias_m_s2 * unit_(rng_);
  for (int i = 0; i < 3; ++i) gyro_bias_[i] = config_.gyro_bias_rad_s * unit_(rng_);
}

control::ImuSample SimulatedImu::sample(const mjData* d) {
  control::ImuSample s;
  s.t_s = d->time;
  for (int i = 0; i < 3; ++i) {
    s.f_B[i] = d->sensordata[ids_.accel_adr + i] + accel_bias_[i] + config_.accel_noise_m_s2 * unit_(rng_);
    s.w_B[i] = d->sensordata[ids_.gyro_adr + i] + gyro_bias_[i] + config_.gyro_noise_rad_s * unit_(rng_);
  }
  return s;
}

}  // namespace tgnav::harness
