// Setpoint trajectories interpolate linearly, unwrap yaw, hold their ends and reject bad input.
#include "control/trajectory.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tgnav::control {
namespace {

TrajectorySetpoint at(double x, double yaw) {
  TrajectorySetpoint s;
  s.p_WB = Eigen::Vector3d(x, 0, 1);
  s.v_WB = Eigen::Vector3d(1, 0, 0);
  s.yaw_rad = yaw;
  return s;
}

TEST(SetpointTrajectory, InterpolatesAndHoldsEnds) {
  const SetpointTrajectory traj({0.0, 2.0}, {at(0.0, 0.0), at(4.0, 1.0)});
  EXPECT_NEAR(traj.sample(0.5).p_WB.x(), 1.0, 1e-12);
  EXPECT_NEAR(traj.sample(1.0).yaw_rad, 0.5, 1e-12);
  EXPECT_NEAR(traj.sample(-1.0).p_WB.x(), 0.0, 1e-12);
  const TrajectorySetpoint end = traj.sample(10.0);
  EXPECT_NEAR(end.p_WB.x(), 4.0, 1e-12);
  EXPECT_EQ(end.v_WB.norm(), 0.0);  // no feed-forward once the trajectory is over
}

TEST(SetpointTrajectory, YawCrossesPiTheShortWay) {
  const SetpointTrajectory traj({0.0, 1.0}, {at(0.0, 3.0), at(0.0, -3.0)});
  // From 3.0 to -3.0 (= 3.283) is +0.283 rad, not -6 rad.
  EXPECT_NEAR(traj.sample(0.5).yaw_rad, 3.0 + 0.5 * (2 * M_PI - 6.0), 1e-12);
  EXPECT_NEAR(std::remainder(traj.sample(1.0).yaw_rad + 3.0, 2 * M_PI), 0.0, 1e-12);
}

TEST(SetpointTrajectory, RejectsBadInput) {
  EXPECT_THROW(SetpointTrajectory({}, {}), std::invalid_argument);
  EXPECT_THROW(SetpointTrajectory({0.0, 0.0}, {at(0, 0), at(1, 0)}), std::invalid_argument);
  EXPECT_THROW(SetpointTrajectory({0.0, 1.0}, {at(0, 0), at(NAN, 0)}), std::invalid_argument);
  EXPECT_THROW(SetpointTrajectory({0.0}, {at(0, 0), at(1, 0)}), std::invalid_argument);
}

}  // namespace
}  // namespace tgnav::control
