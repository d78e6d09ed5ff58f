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

// Straight along x at 1 m/s facing yaw 3.0, sampled at 100 Hz over [0, 10] s.
SetpointTrajectory cruise() {
  std::vector<double> t;
  std::vector<TrajectorySetpoint> sp;
  for (int i = 0; i <= 1000; ++i) {
    t.push_back(0.01 * i);
    TrajectorySetpoint s = at(0.01 * i, 3.0);
    sp.push_back(s);
  }
  return SetpointTrajectory(t, sp);
}

// From rest at (5, 0) to (5, 2) by minimum jerk over [0, 4] s, facing yaw -3.0 (across pi from 3.0).
SetpointTrajectory sideways() {
  std::vector<double> t;
  std::vector<TrajectorySetpoint> sp;
  for (int i = 0; i <= 400; ++i) {
    const double x = i / 400.0;
    TrajectorySetpoint s;
    s.p_WB = Eigen::Vector3d(5.0, 2.0 * x * x * x * (10 - 15 * x + 6 * x * x), 1.0);
    s.v_WB = Eigen::Vector3d(0.0, 2.0 * 30 * x * x * (1 - x) * (1 - x) / 4.0, 0.0);
    s.a_WB = Eigen::Vector3d(0.0, 2.0 * 60 * x * (1 - x) * (1 - 2 * x) / 16.0, 0.0);
    s.yaw_rad = -3.0;
    t.push_back(4.0 * x);
    sp.push_back(s);
  }
  return SetpointTrajectory(t, sp);
}

TEST(SpliceTrajectory, KeepsTheCurrentBeforeTheSwitchAndTheNextAfterTheBlend) {
  const SetpointTrajectory cur = cruise();
  const SetpointTrajectory next = sideways();
  const SetpointTrajectory spliced = spliceTrajectory(cur, next, 5.0, 1.0);
  for (double t : {0.0, 2.5, 4.99}) EXPECT_TRUE(spliced.sample(t).p_WB.isApprox(cur.sample(t).p_WB, 1e-12)) << t;
  for (double t : {6.0, 7.5, 9.0}) {
    EXPECT_TRUE(spliced.sample(t).p_WB.isApprox(next.sample(t - 5.0).p_WB, 1e-9)) << t;
    EXPECT_NEAR(std::remainder(spliced.sample(t).yaw_rad - next.sample(t - 5.0).yaw_rad, 2 * M_PI), 0.0, 1e-9);
  }
  EXPECT_DOUBLE_EQ(spliced.endTime(), 9.0);
  // Without a blend the next trajectory takes over at once.
  const SetpointTrajectory at_once = spliceTrajectory(cur, next, 5.0, 0.0);
  EXPECT_TRUE(at_once.sample(5.0).p_WB.isApprox(next.sample(0.0).p_WB, 1e-12));
}

TEST(SpliceTrajectory, PositionVelocityAndYawStayContinuousThroughTheBlend) {
  const SetpointTrajectory spliced = spliceTrajectory(cruise(), sideways(), 5.0, 1.0);
  // At the switch: the current trajectory's state, moving at 1 m/s along x.
  EXPECT_TRUE(spliced.sample(5.0).p_WB.isApprox(Eigen::Vector3d(5, 0, 1), 1e-9));
  EXPECT_TRUE(spliced.sample(5.0).v_WB.isApprox(Eigen::Vector3d(1, 0, 0), 1e-9));
  // The velocity is the derivative of the position, the acceleration that of the velocity, and the
  // yaw rate that of the yaw, everywhere around and through the blend.
  const double h = 0.005;
  double worst_v = 0.0;
  double worst_a = 0.0;
  double worst_yaw = 0.0;
  for (double t = 4.9; t <= 6.1; t += 0.01) {
    const TrajectorySetpoint lo = spliced.sample(t - h);
    const TrajectorySetpoint hi = spliced.sample(t + h);
    const TrajectorySetpoint mid = spliced.sample(t);
    worst_v = std::max(worst_v, ((hi.p_WB - lo.p_WB) / (2 * h) - mid.v_WB).norm());
    worst_a = std::max(worst_a, ((hi.v_WB - lo.v_WB) / (2 * h) - mid.a_WB).norm());
    worst_yaw = std::max(worst_yaw, std::abs((hi.yaw_rad - lo.yaw_rad) / (2 * h) - mid.yaw_rate_rad_s));
    // The heading turns the short way, across pi, never through 0.
    EXPECT_LT(std::cos(mid.yaw_rad), -0.95) << t;
  }
  EXPECT_LT(worst_v, 0.02);
  EXPECT_LT(worst_a, 0.2);
  EXPECT_LT(worst_yaw, 0.02);
}

}  // namespace
}  // namespace tgnav::control
