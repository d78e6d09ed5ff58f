#include "control/trajectory.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace tgnav::control {

namespace {
bool finite(const TrajectorySetpoint& s) {
  return s.p_WB.allFinite() && s.v_WB.allFinite() && s.a_WB.allFinite() && std::isfinite(s.yaw_rad) &&
         std::isfinite(s.yaw_rate_rad_s);
}
}  // namespace

SetpointTrajectory::SetpointTrajectory(std::vector<double> t_s, std::vector<TrajectorySetpoint> sp)
    : t_(std::move(t_s)), sp_(std::move(sp)) {
  if (t_.empty() || t_.size() != sp_.size()) {
    throw std::invalid_argument("trajectory: needs at least one setpoint and one time per setpoint");
  }
  for (std::size_t i = 0; i < t_.size(); ++i) {
    if (!std::isfinite(t_[i]) || !finite(sp_[i])) {
      throw std::invalid_argument("setpoint " + std::to_string(i) + ": non-finite value");
    }
    if (i > 0 && !(t_[i] > t_[i - 1])) {
      throw std::invalid_argument("setpoint " + std::to_string(i) + ": time " + std::to_string(t_[i]) +
                                  " does not increase");
    }
    if (i > 0) {
      sp_[i].yaw_rad = sp_[i - 1].yaw_rad + std::remainder(sp_[i].yaw_rad - sp_[i - 1].yaw_rad, 2.0 * M_PI);
    }
  }
}

TrajectorySetpoint SetpointTrajectory::sample(double t) const {
  if (t <= t_.front()) return sp_.front();
  if (t >= t_.back()) {
    TrajectorySetpoint end = sp_.back();
    end.v_WB.setZero();
    end.a_WB.setZero();
    end.yaw_rate_rad_s = 0.0;
    return end;
  }
  const auto it = std::upper_bound(t_.begin(), t_.end(), t);
  const std::size_t i = static_cast<std::size_t>(it - t_.begin());
  const double s = (t - t_[i - 1]) / (t_[i] - t_[i - 1]);
  const TrajectorySetpoint& a = sp_[i - 1];
  const TrajectorySetpoint& b = sp_[i];
  TrajectorySetpoint out;
  out.p_WB = a.p_WB + s * (b.p_WB - a.p_WB);
  out.v_WB = a.v_WB + s * (b.v_WB - a.v_WB);
  out.a_WB = a.a_WB + s * (b.a_WB - a.a_WB);
  out.yaw_rad = a.yaw_rad + s * (b.yaw_rad - a.yaw_rad);
  out.yaw_rate_rad_s = a.yaw_rate_rad_s + s * (b.yaw_rate_rad_s - a.yaw_rate_rad_s);
  return out;
}

}  // namespace tgnav::control

namespace tgnav::control {

SetpointTrajectory spliceTrajectory(const SetpointTrajectory& current, const SetpointTrajectory& next, double t_switch,
                                    double blend_s) {
  std::vector<double> t;
  std::vector<TrajectorySetpoint> sp;
  for (std::size_t i = 0; i < current.times().size() && current.times()[i] < t_switch - 1e-9; ++i) {
    t.push_back(current.times()[i]);
    sp.push_back(current.setpoints()[i]);
  }
  const double shift = t_switch - next.startTime();
  const double blend = std::min(std::max(blend_s, 0.0), next.endTime() - next.startTime());
  for (std::size_t i = 0; i < next.times().size(); ++i) {
    const double tt = next.times()[i] + shift;
    TrajectorySetpoint b = next.setpoints()[i];
    const double x = blend > 0.0 ? (tt - t_switch) / blend : 1.0;
    if (x < 1.0) {
      // Quintic smoothstep: s, s' and s'' are 0 at x = 0 and s = 1, s' = s'' = 0 at x = 1.
      const double s = x * x * x * (10.0 + x * (-15.0 + 6.0 * x));
      const double ds = 30.0 * x * x * (1.0 - x) * (1.0 - x) / blend;
      const double dds = 60.0 * x * (1.0 - x) * (1.0 - 2.0 * x) / (blend * blend);
      const TrajectorySetpoint a = current.sample(tt);
      const Eigen::Vector3d dp = b.p_WB - a.p_WB;
      const Eigen::Vector3d dv = b.v_WB - a.v_WB;
      const double dyaw = std::remainder(b.yaw_rad - a.yaw_rad, 2.0 * M_PI);
      TrajectorySetpoint m;
      m.p_WB = a.p_WB + s * dp;
      m.v_WB = a.v_WB + s * dv + ds * dp;
      m.a_WB = a.a_WB + s * (b.a_WB - a.a_WB) + 2.0 * ds * dv + dds * dp;
      m.yaw_rad = a.yaw_rad + s * dyaw;
      m.yaw_rate_rad_s = a.yaw_rate_rad_s + s * (b.yaw_rate_rad_s - a.yaw_rate_rad_s) + ds * dyaw;
      b = m;
    }
    t.push_back(tt);
    sp.push_back(b);
  }
  return SetpointTrajectory(std::move(t), std::move(sp));
}

}  // namespace tgnav::control
