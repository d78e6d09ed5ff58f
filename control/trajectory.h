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

}  // namespace tgnav::control
