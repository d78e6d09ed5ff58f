// The PX4-like cascade flies the MuJoCo quadrotor: hover, steps, a figure-8, yaw tracking and
// disturbance rejection meet the acceptance figures.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "harness/config/config_io.h"
#include "harness/config/scene_config.h"
#include "harness/sim/flight_loop.h"
#include "harness/sim/vehicle_model.h"
#include "test_util.h"

namespace tgnav::harness {
namespace {

constexpr double kDeg = M_PI / 180.0;

// The disturbed start of the hover tests: 10 deg of roll and drifting (0.3, -0.2, 0.1) m/s.
void disturb(mjData* d, const VehicleIds& ids) {
  const Eigen::Quaterniond tilted(Eigen::AngleAxisd(10 * kDeg, Eigen::Vector3d::UnitX()));
  mjtNum* q = d->qpos + ids.qpos_adr;
  q[3] = tilted.w();
  q[4] = tilted.x();
  q[5] = tilted.y();
  q[6] = tilted.z();
  d->qvel[ids.qvel_adr] = 0.3;
  d->qvel[ids.qvel_adr + 1] = -0.2;
  d->qvel[ids.qvel_adr + 2] = 0.1;
}

class FlightTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = loadSceneConfig(test::sourceDir() / "configs/scenes/empty.yaml");
    VehicleModel vehicle = loadVehicleModel(scene_.mjcf);
    model_ = std::move(vehicle.model);
    data_ = makeData(model_.get());
    ids_ = vehicle.ids;
    config_ = loadCascadeConfig(test::sourceDir() / "configs/controller.yaml");
    loop_ = std::make_unique<FlightLoop>(model_.get(), data_.get(), ids_, config_);
  }
  // Hovering at `p` with the motors already spun up to hover thrust.
  void startHovering(const Eigen::Vector3d& p, double yaw = 0.0) {
    planner::Pose4 pose;
    pose.p_WB = p;
    pose.yaw_rad = yaw;
    setVehiclePose(model_.get(), data_.get(), ids_, pose);
    const double hover_n = vehicleMass(model_.get(), ids_) * 9.81 / 4.0;
    for (int i = 0; i < 4; ++i) {
      data_->ctrl[ids_.motors[i]] = hover_n;
      data_->act[ids_.motor_act[i]] = hover_n;
    }
  }
  control::TrajectorySetpoint at(const Eigen::Vector3d& p, double yaw = 0.0) {
    control::TrajectorySetpoint sp;
    sp.p_WB = p;
    sp.yaw_rad = yaw;
    return sp;
  }
  void fly(double seconds, const control::TrajectorySetpoint& sp) {
    const int steps = static_cast<int>(std::lround(seconds / model_->opt.timestep));
    for (int i = 0; i < steps; ++i) ASSERT_TRUE(loop_->step(sp)) << loop_->divergence();
  }
  double yaw() const {
    const Eigen::Vector3d nose = loop_->state().q_WB * Eigen::Vector3d::UnitX();
    return std::atan2(nose.y(), nose.x());
  }

  SceneConfig scene_;
  ModelPtr model_;
  DataPtr data_;
  VehicleIds ids_;
  control::CascadeConfig config_;
  std::unique_ptr<FlightLoop> loop_;
};

TEST_F(FlightTest, VehicleParamsComeFromTheModel) {
  const control::VehicleParams& v = loop_->vehicle();
  EXPECT_NEAR(v.mass_kg, 1.5, 1e-12);
  ASSERT_EQ(v.rotors.size(), 4u);
  EXPECT_EQ(v.rotors[0].spin, 1);
  EXPECT_EQ(v.rotors[2].spin, -1);
  EXPECT_NEAR(v.rotors[0].yaw_moment_ratio_m, 0.02, 1e-12);
  EXPECT_NEAR(v.rotors[0].max_thrust_n, 7.5, 1e-12);
  EXPECT_NEAR(v.rotors[1].p_B.x(), -0.177, 1e-12);
  EXPECT_NEAR(v.motor_time_constant_s, 0.03, 1e-12);
  EXPECT_NEAR(v.hoverThrust(), 1.5 * 9.81 / 30.0, 1e-12);
}

TEST_F(FlightTest, HoverHoldsWithin2cmFor20s) {
  // Start disturbed (10 deg roll, drifting, motors idle), recover for 5 s, then hold 20 s.
  const Eigen::Vector3d p(1.0, -2.0, 1.5);
  startHovering(p);
  disturb(data_.get(), ids_);
  for (int i = 0; i < 4; ++i) data_->act[ids_.motor_act[i]] = 0.0;
  mj_forward(model_.get(), data_.get());
  fly(5.0, at(p));
  double worst = 0.0;
  for (int i = 0; i < 10000; ++i) {
    ASSERT_TRUE(loop_->step(at(p)));
    worst = std::max(worst, (loop_->state().p_WB - p).norm());
  }
  std::cout << "[ figure   ] hover 20 s after a disturbed start: max deviation " << worst << " m\n";
  EXPECT_LT(worst, 0.02);
  EXPECT_GT(worst, 0.0);
  EXPECT_EQ(mujocoWarnings(data_.get()), "");
}

TEST_F(FlightTest, OneMetreStepSettlesWithin3sAndOvershootsLessThan15Percent) {
  for (int axis : {0, 1, 2}) {
    SetUp();
    const Eigen::Vector3d p0(0.0, 0.0, 1.5);
    startHovering(p0);
    Eigen::Vector3d target = p0;
    target[axis] += 1.0;
    double overshoot = 0.0;
    double last_outside = 0.0;  // last time the error exceeded 5 cm (5 % of the step)
    for (int i = 0; i < 3000; ++i) {
      ASSERT_TRUE(loop_->step(at(target)));
      const Eigen::Vector3d p = loop_->state().p_WB;
      overshoot = std::max(overshoot, p[axis] - target[axis]);
      if ((p - target).norm() > 0.05) last_outside = loop_->time();
    }
    std::cout << "[ figure   ] 1 m step on axis " << axis << ": overshoot " << overshoot << " m, within 5 cm after "
              << last_outside << " s\n";
    EXPECT_LT(overshoot, 0.15) << "axis " << axis;
    EXPECT_LT(last_outside, 3.0) << "axis " << axis;
  }
}

// Figure-8 (lemniscate of Gerono) p = c + (a sin th, b sin 2th) flown from rest to rest: the
// phase rate ramps up and down smoothly over `ramp_s` and peaks so that the speed at the
// crossing is 1 m/s. Sampled at 100 Hz with exact velocity and acceleration feed-forward.
control::SetpointTrajectory figureEight(const Eigen::Vector3d& centre, double laps, double ramp_s) {
  const double a = 2.0;
  const double b = 1.0;
  const double w = 1.0 / std::sqrt(a * a + 4 * b * b);   // peak phase rate
  const double cruise_s = laps * 2 * M_PI / w - ramp_s;  // each ramp covers half its phase
  const double total_s = cruise_s + 2 * ramp_s;
  auto smooth = [](double u) { return u * u * (3 - 2 * u); };
  auto rate = [&](double t) {  // phase rate and its derivative
    if (t < ramp_s)
      return std::pair<double, double>{w * smooth(t / ramp_s), w * 6 * (t / ramp_s) * (1 - t / ramp_s) / ramp_s};
    if (t > total_s - ramp_s) {
      const double u = (total_s - t) / ramp_s;
      return std::pair<double, double>{w * smooth(u), -w * 6 * u * (1 - u) / ramp_s};
    }
    return std::pair<double, double>{w, 0.0};
  };
  std::vector<double> times;
  std::vector<control::TrajectorySetpoint> sps;
  double th = 0.0;
  const double h = 0.001;
  for (int k = 0; k * 0.01 <= total_s + 1e-9; ++k) {
    const double t = k * 0.01;
    const auto [thd, thdd] = rate(t);
    control::TrajectorySetpoint sp;
    sp.p_WB = centre + Eigen::Vector3d(a * std::sin(th), b * std::sin(2 * th), 0.0);
    sp.v_WB = Eigen::Vector3d(a * std::cos(th) * thd, 2 * b * std::cos(2 * th) * thd, 0.0);
    sp.a_WB = Eigen::Vector3d(-a * std::sin(th) * thd * thd + a * std::cos(th) * thdd,
                              -4 * b * std::sin(2 * th) * thd * thd + 2 * b * std::cos(2 * th) * thdd, 0.0);
    times.push_back(t);
    sps.push_back(sp);
    for (int j = 0; j < 10; ++j) th += h * 0.5 * (rate(t + j * h).first + rate(t + (j + 1) * h).first);
  }
  return control::SetpointTrajectory(times, sps);
}

TEST_F(FlightTest, FigureEightAt1mpsTrackedWithin5cmRmse) {
  const control::SetpointTrajectory traj = figureEight(Eigen::Vector3d(0, 0, 1.5), 2.0, 3.0);
  planner::Pose4 landed;
  landed.p_WB = Eigen::Vector3d(0, 0, 0.035);
  setVehiclePose(model_.get(), data_.get(), ids_, landed);
  const FlightResult result = flyTrajectory(*loop_, traj, FlightConfig{});
  ASSERT_EQ(result.status, FlightStatus::kCompleted) << result.reason;
  const TrackingSummary s = summarizeTracking(result);
  EXPECT_GT(s.duration_s, 2 * 2 * M_PI * std::sqrt(8.0));
  std::cout << "[ figure   ] figure-8 at 1 m/s: rmse " << s.position_rmse_m << " m, max " << s.position_max_m
            << " m, final " << s.final_error_m << " m\n";
  EXPECT_LT(s.position_rmse_m, 0.05);
  EXPECT_LT(s.final_error_m, 0.05);
  double peak_speed = 0.0;
  for (const auto& f : result.log) peak_speed = std::max(peak_speed, f.on_trajectory ? f.state.v_WB.norm() : 0.0);
  EXPECT_GT(peak_speed, 0.95);
  EXPECT_LT(peak_speed, 1.1);
}

// Every shipped airframe and the X2-like test model (direct-thrust motors, rotors at two heights,
// asymmetric arms) fly the same scene, each composed into it by reference and flown on its own
// gains (its description's gains file, else the built-in defaults).
class AirframeFlight : public ::testing::TestWithParam<const char*> {
 protected:
  void SetUp() override {
    const SceneConfig scene = loadSceneConfig(test::sourceDir() / "configs/scenes/empty.yaml");
    vehicle_ = loadVehicleModel(scene.mjcf, test::sourceDir() / GetParam());
    data_ = makeData(vehicle_.model.get());
    if (!vehicle_.vehicle.controller_config.empty()) {
      config_ = loadCascadeConfig(vehicle_.vehicle.controller_config);
    }
    loop_ = std::make_unique<FlightLoop>(vehicle_.model.get(), data_.get(), vehicle_.ids, config_);
  }
  void place(const Eigen::Vector3d& p) {
    planner::Pose4 pose;
    pose.p_WB = p;
    setVehiclePose(vehicle_.model.get(), data_.get(), vehicle_.ids, pose);
  }

  VehicleModel vehicle_;
  DataPtr data_;
  control::CascadeConfig config_;
  std::unique_ptr<FlightLoop> loop_;
};

TEST_P(AirframeFlight, HoverHoldsWithin2cmAfterADisturbedStart) {
  // As HoverHoldsWithin2cmFor20s: 10 deg roll, drifting, motors idle; recover 5 s, hold 20 s.
  const Eigen::Vector3d p(1.0, -2.0, 1.5);
  place(p);
  disturb(data_.get(), vehicle_.ids);
  const control::VehicleParams& v = loop_->vehicle();
  const auto n = static_cast<Eigen::Index>(v.rotors.size());
  loop_->setMotorThrusts(Eigen::VectorXd::Zero(n));
  mj_forward(vehicle_.model.get(), data_.get());
  control::TrajectorySetpoint sp;
  sp.p_WB = p;
  const int settle = static_cast<int>(std::lround(5.0 / vehicle_.model->opt.timestep));
  for (int i = 0; i < settle; ++i) ASSERT_TRUE(loop_->step(sp)) << loop_->divergence();
  double worst = 0.0;
  const int hold = static_cast<int>(std::lround(20.0 / vehicle_.model->opt.timestep));
  for (int i = 0; i < hold; ++i) {
    ASSERT_TRUE(loop_->step(sp)) << loop_->divergence();
    worst = std::max(worst, (loop_->state().p_WB - p).norm());
  }
  std::cout << "[ figure   ] " << GetParam() << ": " << n << " rotors, " << v.mass_kg << " kg, hover "
            << v.hoverThrust() << "; hover 20 s: max deviation " << worst << " m\n";
  EXPECT_LT(worst, 0.02);
  EXPECT_GT(worst, 0.0);
  EXPECT_EQ(mujocoWarnings(data_.get()), "");
}

TEST_P(AirframeFlight, FigureEightAt1mpsTrackedWithin5cmRmse) {
  const control::SetpointTrajectory traj = figureEight(Eigen::Vector3d(0, 0, 1.5), 2.0, 3.0);
  place(Eigen::Vector3d(0, 0, vehicle_.ids.landed_height_m));
  const FlightResult result = flyTrajectory(*loop_, traj, FlightConfig{});
  ASSERT_EQ(result.status, FlightStatus::kCompleted) << result.reason;
  const TrackingSummary s = summarizeTracking(result);
  std::cout << "[ figure   ] " << GetParam() << ": figure-8 at 1 m/s: rmse " << s.position_rmse_m << " m, max "
            << s.position_max_m << " m, final " << s.final_error_m << " m\n";
  EXPECT_LT(s.position_rmse_m, 0.05);
  EXPECT_LT(s.final_error_m, 0.05);
  EXPECT_EQ(mujocoWarnings(data_.get()), "");
}

INSTANTIATE_TEST_SUITE_P(Airframes, AirframeFlight,
                         ::testing::Values("models/quadrotor.yaml", "models/vehicles/quad250.yaml",
                                           "models/vehicles/hexarotor.yaml", "tests/data/x2_like/x2_like.yaml"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           return std::filesystem::path(info.param).stem().string();
                         });

TEST_F(FlightTest, YawTrackedWithin3DegAt0p3RadPerSecondAcrossPi) {
  const Eigen::Vector3d p(0, 0, 1.5);
  startHovering(p, 2.5);
  double worst = 0.0;
  const double rate = 0.3;
  for (int i = 0; i < 7500; ++i) {  // 15 s: from 2.5 rad through +-pi to about 7 rad
    const double t = i * model_->opt.timestep;
    control::TrajectorySetpoint sp = at(p, std::remainder(2.5 + rate * t, 2 * M_PI));
    sp.yaw_rate_rad_s = rate;
    ASSERT_TRUE(loop_->step(sp));
    if (t > 1.0) worst = std::max(worst, std::abs(std::remainder(yaw() - sp.yaw_rad, 2 * M_PI)));
  }
  std::cout << "[ figure   ] yaw at 0.3 rad/s: max error " << worst / kDeg << " deg\n";
  EXPECT_LT(worst, 3 * kDeg);
  EXPECT_LT((loop_->state().p_WB - p).norm(), 0.02);
}

TEST_F(FlightTest, LateralPushOf1NRejectedWithin2s) {
  const Eigen::Vector3d p(0, 0, 1.5);
  startHovering(p);
  fly(1.0, at(p));
  // 1 N sideways for 1 s, then released.
  data_->xfrc_applied[6 * ids_.body + 1] = 1.0;
  double worst = 0.0;
  for (int i = 0; i < 500; ++i) {
    ASSERT_TRUE(loop_->step(at(p)));
    worst = std::max(worst, (loop_->state().p_WB - p).norm());
  }
  data_->xfrc_applied[6 * ids_.body + 1] = 0.0;
  double back_at = -1.0;
  for (int i = 0; i < 1500; ++i) {
    ASSERT_TRUE(loop_->step(at(p)));
    const double e = (loop_->state().p_WB - p).norm();
    if (e > 0.05)
      back_at = -1.0;
    else if (back_at < 0.0)
      back_at = i * model_->opt.timestep;
  }
  std::cout << "[ figure   ] 1 N push for 1 s: max deviation " << worst << " m, back within 5 cm " << back_at
            << " s after release\n";
  EXPECT_GT(worst, 0.02) << "the push must move the vehicle";
  EXPECT_LT(worst, 0.3);
  ASSERT_GE(back_at, 0.0) << "never back within 5 cm";
  EXPECT_LT(back_at, 2.0);
}

TEST_F(FlightTest, DivergenceStopsTheFlight) {
  startHovering(Eigen::Vector3d(0, 0, 5));
  // Upside down and spinning: beyond 90 deg of tilt the loop refuses to go on.
  data_->qpos[ids_.qpos_adr + 3] = 0.0;
  data_->qpos[ids_.qpos_adr + 4] = 1.0;
  mj_forward(model_.get(), data_.get());
  EXPECT_FALSE(loop_->step(at(Eigen::Vector3d(0, 0, 5))));
  EXPECT_NE(loop_->divergence().find("tilt"), std::string::npos);
  EXPECT_FALSE(loop_->step(at(Eigen::Vector3d(0, 0, 5))));
}

}  // namespace
}  // namespace tgnav::harness
