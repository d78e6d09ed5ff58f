// The vehicle model is physically consistent: equal thrusts of weight/4 hold it still, and
// differential thrust turns it the way PX4's quad-X geometry says it must.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "harness/config/scene_config.h"
#include "harness/sim/mujoco_sim.h"
#include "harness/sim/vehicle_model.h"
#include "test_util.h"

namespace tgnav::harness {
namespace {

class VehicleTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = loadSceneConfig(test::sourceDir() / "configs/scenes/smoke.yaml");
    VehicleModel vehicle = loadVehicleModel(scene_.mjcf);
    model_ = std::move(vehicle.model);
    data_ = makeData(model_.get());
    ids_ = vehicle.ids;
    setVehiclePose(model_.get(), data_.get(), ids_, scene_.start);
  }
  // Commands per-rotor thrust, with the motor filter already settled at that value.
  void setThrusts(const Eigen::Vector4d& thrust_n) {
    for (int i = 0; i < 4; ++i) {
      data_->ctrl[ids_.motors[i]] = thrust_n[i];
      data_->act[ids_.motor_act[i]] = thrust_n[i];
    }
  }
  void simulate(double seconds) {
    const int steps = static_cast<int>(seconds / model_->opt.timestep + 0.5);
    for (int i = 0; i < steps; ++i) mj_step(model_.get(), data_.get());
  }
  Eigen::Vector3d position() const { return Eigen::Vector3d(data_->qpos + ids_.qpos_adr); }
  Eigen::Quaterniond attitude() const {
    const mjtNum* q = data_->qpos + ids_.qpos_adr + 3;
    return Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
  }
  double hoverThrust() const { return vehicleMass(model_.get(), ids_) * -model_->opt.gravity[2] / 4.0; }

  SceneConfig scene_;
  ModelPtr model_;
  DataPtr data_;
  VehicleIds ids_;
};

TEST_F(VehicleTest, ModelMatchesTheSpecifiedVehicle) {
  EXPECT_NEAR(vehicleMass(model_.get(), ids_), 1.5, 1e-9);
  EXPECT_DOUBLE_EQ(model_->opt.timestep, 0.002);
  for (int i = 0; i < 4; ++i) {
    const int a = ids_.motors[i];
    EXPECT_EQ(model_->actuator_dyntype[a], mjDYN_FILTER);
    EXPECT_NEAR(model_->actuator_dynprm[a * mjNDYN], 0.03, 1e-12);  // tau 30 ms
    const mjtNum* site = model_->site_pos + 3 * model_->actuator_trnid[2 * a];
    EXPECT_NEAR(std::hypot(site[0], site[1]), 0.25, 0.005);  // S500 arm
  }
}

TEST_F(VehicleTest, EqualThrustOfWeightOverFourHovers) {
  const Eigen::Vector3d p0 = position();
  setThrusts(Eigen::Vector4d::Constant(hoverThrust()));
  simulate(5.0);
  EXPECT_LT((position() - p0).norm(), 0.01);
  EXPECT_LT(attitude().angularDistance(Eigen::Quaterniond::Identity()), 1e-3);
  EXPECT_EQ(mujocoWarnings(data_.get()), "");
}

TEST_F(VehicleTest, LessThanWeightSinksMoreClimbs) {
  const double z0 = position().z();
  setThrusts(Eigen::Vector4d::Constant(0.9 * hoverThrust()));
  simulate(0.5);
  EXPECT_LT(position().z(), z0 - 0.05);
  setVehiclePose(model_.get(), data_.get(), ids_, scene_.start);
  setThrusts(Eigen::Vector4d::Constant(1.1 * hoverThrust()));
  simulate(0.5);
  EXPECT_GT(position().z(), z0 + 0.05);
}

TEST_F(VehicleTest, FrontRotorsPitchNoseUp) {
  // Rotors 0 (front-right) and 2 (front-left) push harder: the nose rises.
  const double h = hoverThrust();
  setThrusts(Eigen::Vector4d(h + 0.1, h - 0.1, h + 0.1, h - 0.1));
  simulate(0.3);
  const Eigen::Vector3d nose = attitude() * Eigen::Vector3d::UnitX();
  EXPECT_GT(nose.z(), 0.02);
}

TEST_F(VehicleTest, LeftRotorsRollRight) {
  // Rotors 1 (rear-left) and 2 (front-left) push harder: the vehicle rolls right (left side up).
  const double h = hoverThrust();
  setThrusts(Eigen::Vector4d(h - 0.1, h + 0.1, h + 0.1, h - 0.1));
  simulate(0.3);
  const Eigen::Vector3d left = attitude() * Eigen::Vector3d::UnitY();
  EXPECT_GT(left.z(), 0.02);
}

TEST_F(VehicleTest, CounterClockwiseRotorsYawClockwise) {
  // Rotors 0 and 1 spin counter-clockwise; their drag turns the body clockwise (negative yaw)
  // while the total thrust stays equal to the weight.
  const double h = hoverThrust();
  setThrusts(Eigen::Vector4d(h + 0.5, h + 0.5, h - 0.5, h - 0.5));
  simulate(0.5);
  const Eigen::Vector3d nose = attitude() * Eigen::Vector3d::UnitX();
  EXPECT_LT(std::atan2(nose.y(), nose.x()), -0.01);
  EXPECT_NEAR(position().z(), scene_.start.p_WB.z(), 0.01);
}

}  // namespace
}  // namespace tgnav::harness
