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
