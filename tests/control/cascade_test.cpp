// The cascade's laws, without a simulator: thrust follows acceleration, limits hold exactly at
// saturation, attitude control converges from a grid of attitudes, integrators behave.
#include <gtest/gtest.h>

#include <cmath>

#include "control/attitude_control.h"
#include "control/position_control.h"
#include "control/rate_control.h"

namespace tgnav::control {
namespace {

constexpr double kG = 9.81;
constexpr double kHover = 0.49;
constexpr double kDeg = M_PI / 180.0;

PositionControl makePositionControl(const PositionControlConfig& c = {}) { return PositionControl(c, kHover, kG); }

double tiltOf(const Eigen::Vector3d& v) { return std::acos(v.normalized().z()); }

TEST(PositionControl, HoverAtSetpointGivesHoverThrustUp) {
  PositionControl pc = makePositionControl();
  VehicleState s;
  s.p_WB = Eigen::Vector3d(1, 2, 3);
  TrajectorySetpoint sp;
  sp.p_WB = s.p_WB;
  const ThrustSetpoint t = pc.update(s, sp, 0.01);
  EXPECT_NEAR((t.thrust_W - Eigen::Vector3d(0, 0, kHover)).norm(), 0.0, 1e-12);
}

TEST(PositionControl, ThrustFollowsAccelerationSign) {
  PositionControl pc = makePositionControl();
  for (int axis = 0; axis < 2; ++axis) {
    for (double sign : {-1.0, 1.0}) {
      Eigen::Vector3d acc = Eigen::Vector3d::Zero();
      acc[axis] = 2.0 * sign;
      const Eigen::Vector3d t = pc.accelerationToThrust(acc);
      EXPECT_GT(t[axis] * sign, 0.0);
      EXPECT_NEAR(t[1 - axis], 0.0, 1e-12);
    }
  }
  EXPECT_GT(pc.accelerationToThrust({0, 0, 2}).z(), kHover);
  EXPECT_LT(pc.accelerationToThrust({0, 0, -2}).z(), kHover);
  // Level flight while accelerating: the vertical thrust component still balances gravity.
  EXPECT_NEAR(pc.accelerationToThrust({3, 0, 0}).z(), kHover, 1e-12);
}

TEST(PositionControl, PositionErrorPushesTowardsSetpoint) {
  PositionControl pc = makePositionControl();
  VehicleState s;
  TrajectorySetpoint sp;
  sp.p_WB = Eigen::Vector3d(-1.0, 0.5, 0.2);
  const ThrustSetpoint t = pc.update(s, sp, 0.01);
  EXPECT_LT(t.thrust_W.x(), 0.0);
  EXPECT_GT(t.thrust_W.y(), 0.0);
  EXPECT_GT(t.thrust_W.z(), kHover);
}

TEST(PositionControl, TiltLimitHoldsExactlyAtSaturation) {
  PositionControlConfig c;
  c.tilt_max_rad = 30 * kDeg;
  PositionControl pc = makePositionControl(c);
  for (double ax : {5.0, 50.0, -500.0}) {
    const Eigen::Vector3d t = pc.accelerationToThrust({ax, 0.7 * ax, 0});
    EXPECT_NEAR(tiltOf(t), 30 * kDeg, 1e-9);
  }
  EXPECT_NEAR(tiltOf(pc.accelerationToThrust({1.0, 0, 0})), std::atan(1.0 / kG), 1e-12);
  EXPECT_NEAR(tiltOf(limitTilt(-Eigen::Vector3d::UnitZ(), 30 * kDeg)), 30 * kDeg, 1e-12);
}

TEST(PositionControl, ThrustLimitsHoldExactlyAtSaturation) {
  PositionControlConfig c;
  PositionControl pc = makePositionControl(c);
  VehicleState s;
  TrajectorySetpoint sp;
  // Far below the setpoint and far to the side: vertical priority with horizontal margin.
  sp.p_WB = Eigen::Vector3d(100, 0, 100);
  sp.a_WB = Eigen::Vector3d(0, 0, 50);
  ThrustSetpoint t = pc.update(s, sp, 0.01);
  EXPECT_NEAR(t.thrust_W.norm(), c.thrust_max, 1e-12);
  EXPECT_NEAR(t.thrust_W.head<2>().norm(), c.thrust_xy_margin, 1e-12);
  // Straight up only: all of it vertical, never more than the maximum.
  pc.reset();
  sp.p_WB = Eigen::Vector3d(0, 0, 100);
  t = pc.update(s, sp, 0.01);
  EXPECT_NEAR(t.thrust_W.z(), c.thrust_max, 1e-12);
  // Far above: collective at its minimum, never below.
  pc.reset();
  sp = TrajectorySetpoint{};
  sp.p_WB = Eigen::Vector3d(0, 0, -100);
  sp.a_WB = Eigen::Vector3d(0, 0, -50);
  t = pc.update(s, sp, 0.01);
  EXPECT_NEAR(t.thrust_W.norm(), c.thrust_min, 1e-12);
}

TEST(PositionControl, VelocityLimitsHold) {
  PositionControlConfig c;
  c.max_vel_xy_m_s = 2.0;
  PositionControl pc = makePositionControl(c);
  VehicleState s;
  TrajectorySetpoint sp;
  sp.p_WB = Eigen::Vector3d(30, 40, 50);
  pc.update(s, sp, 0.01);
  EXPECT_NEAR(pc.velocitySetpoint().head<2>().norm(), 2.0, 1e-12);
  EXPECT_NEAR(pc.velocitySetpoint().z(), c.max_vel_up_m_s, 1e-12);
  sp.p_WB.z() = -50;
  pc.update(s, sp, 0.01);
  EXPECT_NEAR(pc.velocitySetpoint().z(), -c.max_vel_down_m_s, 1e-12);
}

TEST(PositionControl, VerticalIntegratorDoesNotWindUpIntoSaturation) {
  PositionControl pc = makePositionControl();
  VehicleState s;
  TrajectorySetpoint sp;
  sp.p_WB = Eigen::Vector3d(0, 0, 100);
  sp.a_WB = Eigen::Vector3d(0, 0, 100);  // saturates the collective
  for (int i = 0; i < 1000; ++i) pc.update(s, sp, 0.01);
  EXPECT_NEAR(pc.velocityIntegral().z(), 0.0, 1e-12);
  // Unsaturated, the same error integrates.
  pc.reset();
  sp.a_WB.setZero();
  sp.p_WB = Eigen::Vector3d(0, 0, 0.1);
  for (int i = 0; i < 100; ++i) pc.update(s, sp, 0.01);
  EXPECT_GT(pc.velocityIntegral().z(), 0.0);
}

TEST(ThrustToAttitude, BodyZAlongThrustAndHeadingFromYaw) {
  for (double yaw : {-3.0, -1.0, 0.0, 0.5, 2.0, 3.1}) {
    ThrustSetpoint t;
    t.thrust_W = Eigen::Vector3d(0.1, -0.2, 0.5);
    t.yaw_rad = yaw;
    const AttitudeSetpoint a = thrustToAttitude(t);
    EXPECT_NEAR(a.thrust, t.thrust_W.norm(), 1e-12);
    EXPECT_NEAR(((a.q_WB * Eigen::Vector3d::UnitZ()) - t.thrust_W.normalized()).norm(), 0.0, 1e-9);
    // Body x is perpendicular to the horizontal yaw-left direction: its heading is the yaw.
    const Eigen::Vector3d x = a.q_WB * Eigen::Vector3d::UnitX();
    EXPECT_NEAR(std::remainder(std::atan2(x.y(), x.x()) - yaw, 2 * M_PI), 0.0, 1e-9);
  }
}

Eigen::Quaterniond rpy(double roll, double pitch, double yaw) {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
}

TEST(AttitudeControl, ConvergesFromAGridOfAttitudes) {
  const AttitudeControlConfig c;
  const AttitudeControl ac(c);
  const double dt = 0.004;
  int cases = 0;
  for (double r0 : {-60.0, 0.0, 60.0}) {
    for (double p0 : {-60.0, 0.0, 45.0}) {
      for (double y0 : {-170.0, 0.0, 90.0}) {
        for (double yd : {-90.0, 0.0, 179.0}) {
          Eigen::Quaterniond q = rpy(r0 * kDeg, p0 * kDeg, y0 * kDeg);
          AttitudeSetpoint sp;
          sp.q_WB = rpy(10 * kDeg, -15 * kDeg, yd * kDeg);
          double max_rate_xy = 0.0;
          // Perfect rate tracking: integrate q_dot = q (0, w) / 2 for 8 s.
          for (int k = 0; k < 2000; ++k) {
            const Eigen::Vector3d w = ac.update(q, sp);
            max_rate_xy = std::max(max_rate_xy, std::max(std::abs(w.x()), std::abs(w.y())));
            ASSERT_LE(std::abs(w.z()), c.max_yaw_rate_rad_s + 1e-12);
            const Eigen::Vector3d dtheta = w * dt;
            const double angle = dtheta.norm();
            if (angle > 0) q = (q * Eigen::Quaterniond(Eigen::AngleAxisd(angle, dtheta / angle))).normalized();
          }
          EXPECT_LE(max_rate_xy, c.max_roll_rate_rad_s + 1e-12);
          EXPECT_LT(q.angularDistance(sp.q_WB), 0.5 * kDeg)
              << "from rpy " << r0 << "," << p0 << "," << y0 << " to yaw " << yd;
          ++cases;
        }
      }
    }
  }
  EXPECT_EQ(cases, 81);
}

TEST(AttitudeControl, TiltIsCorrectedBeforeYaw) {
  const AttitudeControl ac{AttitudeControlConfig{}};
  AttitudeSetpoint sp;
  sp.q_WB = rpy(0, 0, 90 * kDeg);
  // Tilted 20 deg and 90 deg off in yaw: tilt is corrected at a higher rate per radian of
  // error than yaw (yaw weight 0.4), and it is not slowed by the yaw error.
  const Eigen::Vector3d w = ac.update(rpy(20 * kDeg, 0, 0), sp);
  EXPECT_LT(w.x(), 0.0);
  EXPECT_GT(std::abs(w.x()) / (20 * kDeg), std::abs(w.z()) / (90 * kDeg));
  const Eigen::Vector3d w_tilt_only = ac.update(rpy(20 * kDeg, 0, 0), AttitudeSetpoint{rpy(0, 0, 0), 0.5, 0.0});
  EXPECT_NEAR(std::hypot(w.x(), w.y()), std::abs(w_tilt_only.x()), 1e-9);
  // Small yaw error only: yaw rate = MC_YAW_P x error (the weight is compensated).
  const Eigen::Vector3d wy = ac.update(rpy(0, 0, 0), AttitudeSetpoint{rpy(0, 0, 2 * kDeg), 0.5, 0.0});
  EXPECT_NEAR(wy.z(), 2.8 * 2 * kDeg, 0.01 * 2.8 * 2 * kDeg);
  EXPECT_NEAR(wy.x(), 0.0, 1e-12);
  // Yaw-rate feed-forward passes through when level.
  const Eigen::Vector3d wf = ac.update(rpy(0, 0, 0), AttitudeSetpoint{rpy(0, 0, 0), 0.5, 0.3});
  EXPECT_NEAR(wf.z(), 0.3, 1e-12);
}

TEST(RateControl, SignsAndIntegratorLimit) {
  RateControlConfig c;
  RateControl rc(c);
  const Eigen::Vector3d out = rc.update({1.0, -1.0, 0.5}, Eigen::Vector3d::Zero(), 0.002);
  EXPECT_GT(out.x(), 0.0);
  EXPECT_LT(out.y(), 0.0);
  EXPECT_GT(out.z(), 0.0);
  for (int i = 0; i < 100000; ++i) rc.update({1.0, -1.0, 0.5}, Eigen::Vector3d::Zero(), 0.002);
  EXPECT_NEAR(rc.integral().x(), c.integrator_limit.x(), 1e-12);
  EXPECT_NEAR(rc.integral().y(), -c.integrator_limit.y(), 1e-12);
}

TEST(RateControl, IntegratorFrozenInSaturatedDirection) {
  RateControl rc{RateControlConfig{}};
  Saturation sat;
  sat.positive[0] = true;
  rc.setSaturation(sat);
  for (int i = 0; i < 100; ++i) rc.update({1.0, 1.0, 0.0}, Eigen::Vector3d::Zero(), 0.002);
  EXPECT_EQ(rc.integral().x(), 0.0);  // positive error, positive saturation: frozen
  EXPECT_GT(rc.integral().y(), 0.0);  // the other axis integrates
  for (int i = 0; i < 100; ++i) rc.update({-1.0, 0.0, 0.0}, Eigen::Vector3d::Zero(), 0.002);
  EXPECT_LT(rc.integral().x(), 0.0);  // unwinding away from saturation is allowed
}

TEST(RateControl, DampsOnMeasuredAngularAcceleration) {
  RateControlConfig c;
  c.p.setZero();
  c.i.setZero();
  RateControl rc(c);
  rc.update(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 0.002);
  Eigen::Vector3d out;
  for (int k = 1; k <= 50; ++k) out = rc.update(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.01 * k, 0, 0), 0.002);
  EXPECT_LT(out.x(), 0.0);  // spinning up about +x: the D term pushes back
}

}  // namespace
}  // namespace tgnav::control
