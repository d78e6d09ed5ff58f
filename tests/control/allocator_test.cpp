// Allocation reproduces the requested wrench when it is feasible, keeps roll/pitch over yaw and
// only ever reduces thrust when it is not, and never commands outside [0, 1].
#include "control/allocator.h"

#include <gtest/gtest.h>

#include <random>

#include "test_vehicle.h"

namespace tgnav::control {
namespace {

ControlDemand demand(double roll, double pitch, double yaw, double thrust) {
  ControlDemand d;
  d.torque = Eigen::Vector3d(roll, pitch, yaw);
  d.thrust = thrust;
  return d;
}

TEST(ControlAllocator, EffectivenessFollowsGeometry) {
  const ControlAllocator alloc(test::quadX());
  // Rotor 0 alone: front-right, counter-clockwise.
  Eigen::VectorXd u = Eigen::VectorXd::Zero(4);
  u[0] = 1.0;
  const Eigen::Vector4d w = alloc.wrench(u);
  EXPECT_NEAR(w[0], -0.177 * 7.5, 1e-12);  // y < 0: lifts the right side (negative Mx)
  EXPECT_NEAR(w[1], -0.177 * 7.5, 1e-12);  // x > 0: nose up (negative My)
  EXPECT_NEAR(w[2], -0.02 * 7.5, 1e-12);   // CCW rotor: reaction turns the body clockwise
  EXPECT_NEAR(w[3], 7.5, 1e-12);
}

TEST(ControlAllocator, HoverIsEqualThrust) {
  const VehicleParams v = test::quadX();
  const ControlAllocator alloc(v);
  const Eigen::VectorXd u = alloc.allocate(demand(0, 0, 0, v.hoverThrust()));
  const Eigen::VectorXd f = alloc.thrustsN(u);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(f[i], v.mass_kg * 9.81 / 4.0, 1e-9);
}

TEST(ControlAllocator, FeasibleDemandsAreReproducedExactly) {
  const ControlAllocator alloc(test::quadX());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> torque(-0.15, 0.15);
  std::uniform_real_distribution<double> thrust(0.35, 0.65);
  for (int k = 0; k < 500; ++k) {
    const ControlDemand d = demand(torque(rng), torque(rng), torque(rng), thrust(rng));
    Saturation sat;
    const Eigen::VectorXd u = alloc.allocate(d, &sat);
    ASSERT_TRUE((u.array() >= 0.0).all() && (u.array() <= 1.0).all());
    const Eigen::Vector4d err = alloc.wrench(u) - alloc.wrenchOf(d);
    EXPECT_LT(err.norm(), 1e-9) << "demand " << k;
    for (int a = 0; a < 3; ++a) EXPECT_FALSE(sat.positive[a] || sat.negative[a]);
  }
}

TEST(ControlAllocator, RollPitchKeptOverYaw) {
  const ControlAllocator alloc(test::quadX());
  Saturation sat;
  const ControlDemand d = demand(0.4, -0.3, 1.0, 0.5);
  const Eigen::VectorXd u = alloc.allocate(d, &sat);
  const ControlDemand got = alloc.achieved(u);
  EXPECT_NEAR(got.torque.x(), 0.4, 1e-9);
  EXPECT_NEAR(got.torque.y(), -0.3, 1e-9);
  EXPECT_GT(got.torque.z(), 0.0);
  EXPECT_LT(got.torque.z(), 1.0);
  EXPECT_TRUE(sat.positive[2]);
  EXPECT_FALSE(sat.positive[0] || sat.negative[0] || sat.positive[1] || sat.negative[1]);
}

TEST(ControlAllocator, ThrustIsOnlyReducedToMakeRoomForAttitude) {
  const ControlAllocator alloc(test::quadX());
  const Eigen::VectorXd u = alloc.allocate(demand(0.5, 0.0, 0.0, 1.0));
  const ControlDemand got = alloc.achieved(u);
  EXPECT_NEAR(got.torque.x(), 0.5, 1e-9);
  EXPECT_LT(got.thrust, 1.0);
  EXPECT_GT(got.thrust, 0.5);
  // At low thrust, roll is not bought by adding thrust: airmode disabled.
  const Eigen::VectorXd low = alloc.allocate(demand(1.0, 0.0, 0.0, 0.1));
  EXPECT_LE(alloc.achieved(low).thrust, 0.1 + 1e-9);
}

TEST(ControlAllocator, OutputsStayInRangeForAnyDemand) {
  const ControlAllocator alloc(test::quadX());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> any(-3.0, 3.0);
  for (int k = 0; k < 1000; ++k) {
    const Eigen::VectorXd u = alloc.allocate(demand(any(rng), any(rng), any(rng), any(rng)));
    ASSERT_TRUE((u.array() >= 0.0).all() && (u.array() <= 1.0).all()) << u.transpose();
  }
}

TEST(VehicleParams, ValidateRejectsNonsense) {
  VehicleParams v = test::quadX();
  v.rotors[2].spin = 0;
  EXPECT_THROW(v.validate(), std::invalid_argument);
  v = test::quadX();
  v.mass_kg = 3.0;  // hover would need 98 % of maximum thrust
  EXPECT_THROW(v.validate(), std::invalid_argument);
  v = test::quadX();
  v.rotors.pop_back();
  EXPECT_THROW(v.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace tgnav::control
