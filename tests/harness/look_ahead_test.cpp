// The camera's yaw in an online trial (harness/run/look_ahead.h): smoothing within a yaw-rate
// limit that keeps the first yaw, and the rate limit applied to a spliced trajectory.
#include "harness/run/look_ahead.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tgnav::harness {
namespace {

// Setpoints every 0.01 s over `duration_s`, at rest at the origin, yaw(t).
template <typename Yaw>
control::SetpointTrajectory spinning(double duration_s, const Yaw& yaw) {
  std::vector<double> t;
  std::vector<control::TrajectorySetpoint> sp;
  for (int i = 0; i * 0.01 <= duration_s + 1e-9; ++i) {
    t.push_back(i * 0.01);
    control::TrajectorySetpoint s;
    s.yaw_rad = yaw(i * 0.01);
    sp.push_back(s);
  }
  return control::SetpointTrajectory(t, sp);
}

double maxRate(const control::SetpointTrajectory& traj) {
  double m = 0.0;
  const auto& t = traj.times();
  const auto& sp = traj.setpoints();
  for (std::size_t i = 1; i < sp.size(); ++i) {
    m = std::max(m, std::abs(sp[i].yaw_rad - sp[i - 1].yaw_rad) / (t[i] - t[i - 1]));
    m = std::max(m, std::abs(sp[i].yaw_rate_rad_s));
  }
  return m;
}

TEST(LookAhead, SmoothYawKeepsTheFirstYawAndTheRateLimitAndTurnsEarly) {
  // A step of 2 rad at t = 3 s: smoothed and rate-limited, the turn starts before 3 s (the
  // backward pass) and ends at the new yaw; the first yaw stays as it was.
  const control::SetpointTrajectory step = spinning(8.0, [](double t) { return t < 3.0 ? 0.5 : 2.5; });
  std::vector<control::TrajectorySetpoint> sp = step.setpoints();
  smoothYaw(step.times(), 0.6, &sp);
  const control::SetpointTrajectory out(step.times(), sp);
  EXPECT_DOUBLE_EQ(out.sample(0.0).yaw_rad, 0.5);
  EXPECT_LE(maxRate(out), 0.6 + 1e-9);
  EXPECT_NEAR(out.sample(8.0).yaw_rad, 2.5, 1e-6);
  EXPECT_GT(out.sample(2.5).yaw_rad, 0.6);  // already turning half a second before the step
}

TEST(LimitYawRate, HoldsTheLimitFromTheSwitchOnAndRejoinsTheYaw) {
  // A swing of 3 rad/s for 1 s from t = 2 s, across +-pi: limited to 0.6 rad/s from t = 1.5 s on,
  // the yaw lags, then rejoins the trajectory's (pi - 0.2 + 3 = -pi + 2.8 after wrapping).
  const auto yaw = [](double t) {
    return std::remainder(M_PI - 0.2 + 3.0 * std::clamp(t - 2.0, 0.0, 1.0), 2.0 * M_PI);
  };
  const control::SetpointTrajectory swing = spinning(10.0, yaw);
  const control::SetpointTrajectory out = limitYawRate(swing, 1.5, 0.6);
  EXPECT_LE(maxRate(out), 0.6 + 1e-9);
  EXPECT_NEAR(std::remainder(out.sample(10.0).yaw_rad - yaw(10.0), 2.0 * M_PI), 0.0, 1e-9);
  EXPECT_NEAR(std::remainder(out.sample(3.0).yaw_rad - (M_PI - 0.2 + 0.6), 2.0 * M_PI), 0.0, 1e-9);
  // Before the switch nothing changes, even where it is too fast.
  const control::SetpointTrajectory late = limitYawRate(swing, 2.5, 0.6);
  EXPECT_DOUBLE_EQ(late.sample(2.5).yaw_rad, swing.sample(2.5).yaw_rad);
  // Within the limit, nothing changes at all.
  const control::SetpointTrajectory slow = spinning(5.0, [](double t) { return 0.5 * t; });
  EXPECT_EQ(limitYawRate(slow, 0.0, 0.6).setpoints().back().yaw_rad, slow.setpoints().back().yaw_rad);
}

}  // namespace
}  // namespace tgnav::harness
