#include "harness/sim/flight_loop.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "harness/base/errors.h"

namespace tgnav::harness {

int stepsPerTick(const mjModel* m, double rate_hz, const std::string& what) {
  const double physics_hz = 1.0 / m->opt.timestep;
  const double ratio = physics_hz / rate_hz;
  const int n = std::isfinite(ratio) ? static_cast<int>(std::lround(ratio)) : 0;
  if (n < 1 || std::abs(ratio - n) > 1e-6) {
    std::ostringstream msg;
    msg << what << " " << rate_hz << " Hz does not divide the physics rate of " << physics_hz
        << " Hz (e.g. 10, 20, 25, 50)";
    throw InputError(msg.str());
  }
  return n;
}

FlightLoop::FlightLoop(mjModel* m, mjData* d, const VehicleIds& ids, const control::CascadeConfig& config)
    : m_(m), d_(d), ids_(ids), vehicle_(vehicleParamsFromModel(m, ids)), cascade_(config, vehicle_) {
  per_rate_ = stepsPerTick(m, config.rate_rate_hz, "controller rates_hz.rate =");
  per_attitude_ = stepsPerTick(m, config.attitude_rate_hz, "controller rates_hz.attitude =");
  per_position_ = stepsPerTick(m, config.position_rate_hz, "controller rates_hz.position =");
  const double dt = m->opt.timestep;
  direct_alpha_ = ids.direct_lag_s > 0.0 ? 1.0 - std::exp(-dt / ids.direct_lag_s) : 1.0;
  command_n_ = Eigen::VectorXd::Zero(ids.rotorCount());
  thrust_n_ = Eigen::VectorXd::Zero(ids.rotorCount());
  for (int i = 0; i < ids.rotorCount(); ++i) {
    // Start from what the model holds (a test may have set the motors spinning).
    command_n_[i] = d->ctrl[ids.motors[i]] / ids.ctrl_per_n[i];
    thrust_n_[i] = ids.motor_act[i] >= 0 ? d->act[ids.motor_act[i]] / ids.ctrl_per_n[i] : command_n_[i];
  }
}

void FlightLoop::setMotorThrusts(const Eigen::VectorXd& thrust_n) {
  command_n_ = thrust_n;
  thrust_n_ = thrust_n;
  for (int i = 0; i < ids_.rotorCount(); ++i) {
    d_->ctrl[ids_.motors[i]] = thrust_n[i] * ids_.ctrl_per_n[i];
    if (ids_.motor_act[i] >= 0) d_->act[ids_.motor_act[i]] = thrust_n[i] * ids_.ctrl_per_n[i];
  }
}

void FlightLoop::applyMotors() {
  for (int i = 0; i < ids_.rotorCount(); ++i) {
    if (ids_.motor_act[i] >= 0) {  // MuJoCo's filter is the motor lag
      d_->ctrl[ids_.motors[i]] = command_n_[i] * ids_.ctrl_per_n[i];
    } else {  // direct thrust: the lag of the vehicle description, here
      thrust_n_[i] += direct_alpha_ * (command_n_[i] - thrust_n_[i]);
      d_->ctrl[ids_.motors[i]] = thrust_n_[i] * ids_.ctrl_per_n[i];
    }
  }
}

void FlightLoop::setDivergenceLimits(double tilt_rad, double speed_m_s) {
  max_tilt_rad_ = tilt_rad;
  max_speed_m_s_ = speed_m_s;
}

bool FlightLoop::checkDiverged() {
  const control::VehicleState s = state();
  if (!s.p_WB.allFinite() || !s.v_WB.allFinite() || !s.w_B.allFinite() || !s.q_WB.coeffs().allFinite()) {
    divergence_ = "non-finite state";
  } else if (std::acos(std::clamp((s.q_WB * Eigen::Vector3d::UnitZ()).z(), -1.0, 1.0)) > max_tilt_rad_) {
    divergence_ = "tilt beyond " + std::to_string(max_tilt_rad_ * 180.0 / M_PI) + " deg";
  } else if (s.v_WB.norm() > max_speed_m_s_) {
    divergence_ = "speed " + std::to_string(s.v_WB.norm()) + " m/s beyond " + std::to_string(max_speed_m_s_);
  }
  return !divergence_.empty();
}

bool FlightLoop::step(const control::TrajectorySetpoint& setpoint) { return step(setpoint, state()); }

bool FlightLoop::step(const control::TrajectorySetpoint& setpoint, const control::VehicleState& s) {
  if (!divergence_.empty()) return false;
  using Clock = std::chrono::steady_clock;
  const Clock::time_point t0 = Clock::now();
  const double dt = m_->opt.timestep;
  if (steps_ % per_position_ == 0) cascade_.updatePosition(s, setpoint, per_position_ * dt);
  if (steps_ % per_attitude_ == 0) cascade_.updateAttitude(s.q_WB);
  if (steps_ % per_rate_ == 0) {
    const Eigen::VectorXd thrust_n = cascade_.updateRate(s.w_B, per_rate_ * dt);
    if (!thrust_n.allFinite()) {
      divergence_ = "non-finite motor command";
      return false;
    }
    command_n_ = thrust_n;
  }
  applyMotors();
  const Clock::time_point t1 = Clock::now();
  mj_step(m_, d_);
  physics_wall_s_ += std::chrono::duration<double>(Clock::now() - t1).count();
  control_wall_s_ += std::chrono::duration<double>(t1 - t0).count();
  ++steps_;
  return !checkDiverged();
}

FlightTimeline flightTimeline(const FlightLoop& loop, const control::SetpointTrajectory& trajectory,
                              const FlightConfig& config) {
  const double climb_m = trajectory.setpoints().front().p_WB.z() - loop.state().p_WB.z();
  // Smoothstep climb (zero speed at both ends) whose peak speed is takeoff_speed_m_s.
  const double climb_s = 1.5 * std::abs(climb_m) / config.takeoff_speed_m_s;
  FlightTimeline timeline;
  timeline.takeoff_s = loop.time();
  timeline.climb_end_s = timeline.takeoff_s + climb_s;
  timeline.trajectory_start_s = timeline.climb_end_s + config.settle_s;
  timeline.end_s = timeline.trajectory_start_s + (trajectory.endTime() - trajectory.startTime()) + config.hold_s;
  return timeline;
}

FlightResult flyTrajectory(FlightLoop& loop, const control::SetpointTrajectory& trajectory, const FlightConfig& config,
                           const FlightHooks& hooks) {
  config.validate();
  loop.setDivergenceLimits(config.diverged_tilt_rad, config.diverged_speed_m_s);
  FlightResult result;
  const control::TrajectorySetpoint first = trajectory.sample(trajectory.startTime());
  const control::VehicleState start = loop.state();
  const double climb_m = first.p_WB.z() - start.p_WB.z();
  const FlightTimeline timeline = flightTimeline(loop, trajectory, config);
  const double t0 = timeline.takeoff_s;
  const double climb_s = timeline.climb_end_s - t0;
  result.trajectory_start_s = timeline.trajectory_start_s;
  double t_end = timeline.end_s;

  while (loop.time() < t_end - 1e-9) {
    const double t = loop.time();
    const control::SetpointTrajectory& flown = hooks.trajectory ? hooks.trajectory() : trajectory;
    if (hooks.trajectory) {
      t_end = result.trajectory_start_s + (flown.endTime() - trajectory.startTime()) + config.hold_s;
    }
    control::TrajectorySetpoint sp;
    bool on_trajectory = false;
    if (t < timeline.climb_end_s) {
      const double s = (t - t0) / climb_s;
      sp.p_WB = Eigen::Vector3d(first.p_WB.x(), first.p_WB.y(), start.p_WB.z() + climb_m * s * s * (3 - 2 * s));
      sp.v_WB = Eigen::Vector3d(0.0, 0.0, climb_m * 6 * s * (1 - s) / climb_s);
      sp.a_WB = Eigen::Vector3d(0.0, 0.0, climb_m * (6 - 12 * s) / (climb_s * climb_s));
      sp.yaw_rad = first.yaw_rad;
    } else if (t < result.trajectory_start_s) {
      sp = first;
      sp.v_WB.setZero();
      sp.a_WB.setZero();
      sp.yaw_rate_rad_s = 0.0;
    } else {
      const double tt = trajectory.startTime() + (t - result.trajectory_start_s);
      sp = flown.sample(tt);
      on_trajectory = tt <= flown.endTime();
    }
    const control::VehicleState truth = loop.state();
    const control::VehicleState flown_on = hooks.control_state ? hooks.control_state(loop) : truth;
    if (loop.positionUpdateDue()) result.log.push_back(FlightSample{t, on_trajectory, sp, truth, flown_on});
    if (!loop.step(sp, flown_on)) {
      result.status = FlightStatus::kDiverged;
      result.reason = loop.divergence();
      break;
    }
    if (hooks.after_step) {
      std::string stop = hooks.after_step(loop);
      if (!stop.empty()) {
        result.status = FlightStatus::kStopped;
        result.reason = std::move(stop);
        break;
      }
    }
  }
  return result;
}

TrackingSummary summarizeTracking(const FlightResult& result) {
  TrackingSummary s;
  double sum_sq = 0.0;
  double yaw_sq = 0.0;
  double first_t = 0.0;
  double last_t = 0.0;
  for (const FlightSample& f : result.log) {
    if (!f.on_trajectory) continue;
    const double e = (f.state.p_WB - f.setpoint.p_WB).norm();
    const Eigen::Vector3d nose = f.state.q_WB * Eigen::Vector3d::UnitX();
    const double yaw_err = std::remainder(std::atan2(nose.y(), nose.x()) - f.setpoint.yaw_rad, 2.0 * M_PI);
    if (s.samples == 0) first_t = f.t_s;
    last_t = f.t_s;
    sum_sq += e * e;
    yaw_sq += yaw_err * yaw_err;
    s.position_max_m = std::max(s.position_max_m, e);
    ++s.samples;
  }
  if (s.samples > 0) {
    s.position_rmse_m = std::sqrt(sum_sq / s.samples);
    s.yaw_rmse_rad = std::sqrt(yaw_sq / s.samples);
    s.duration_s = last_t - first_t;
  }
  if (!result.log.empty()) {
    const FlightSample& last = result.log.back();
    s.final_error_m = (last.state.p_WB - last.setpoint.p_WB).norm();
  }
  return s;
}

}  // namespace tgnav::harness
