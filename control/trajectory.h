#pragma once
// A time-stamped sequence of trajectory setpoints, sampled by linear interpolation (yaw is
// stored unwrapped, so interpolation never takes the long way round).
#include <vector>

#include "control/types.h"

namespace tgnav::control {

class SetpointTrajectory {
 public:
  // Times must be strictly increasing and every value finite (std::invalid_argument otherwise).
  // Yaw is unwrapped here: consecutive yaws differ by less than pi.
  SetpointTrajectory(std::vector<double> t_s, std::vector<TrajectorySetpoint> setpoints);

  // Holds the first/last setpoint outside the time range (with zero feed-forward after the end).
  TrajectorySetpoint sample(double t_s) const;
  double startTime() const { return t_.front(); }
  double endTime() const { return t_.back(); }
  const std::vector<double>& times() const { return t_; }
  const std::vector<TrajectorySetpoint>& setpoints() const { return sp_; }

 private:
  std::vector<double> t_;
  std::vector<TrajectorySetpoint> sp_;
};

// `next` (in its own time base) taking over from `current` at time `t_switch` of current's time
// base: current's setpoints before t_switch, then next's shifted to start at t_switch, blended
// from current's into next's over `blend_s` by a quintic smoothstep s(t), so that position,
// velocity, acceleration, yaw and yaw rate stay continuous (the blend of p0 and p1 is
// (1 - s) p0 + s p1, its derivatives by the product rule; yaw blends along the shorter turn).
// With blend_s 0, next simply replaces current from t_switch.
SetpointTrajectory spliceTrajectory(const SetpointTrajectory& current, const SetpointTrajectory& next, double t_switch,
                                    double blend_s);

}  // namespace tgnav::control
