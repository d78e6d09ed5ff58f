// Texture decides features: in the rendered smoke scene the textured crates give the VO plenty
// of ORB keypoints while the plain floor and the plain pillar give almost none.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "harness/config/scene_config.h"
#include "harness/sim/camera.h"
#include "harness/sim/mujoco_sim.h"
#include "harness/sim/vehicle_model.h"
#include "test_util.h"
#include "vo/features.h"

namespace tgnav::harness {
namespace {

class SceneTextureTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const SceneConfig scene = loadSceneConfig(test::sourceDir() / "configs/scenes/smoke.yaml");
    VehicleModel vehicle = loadVehicleModel(scene.mjcf);
    model_ = std::move(vehicle.model);
    data_ = makeData(model_.get());
    ids_ = vehicle.ids;
    camera_ = std::make_unique<Camera>(model_.get(), gl_, CameraConfig{}.on(vehicle.vehicle.camera), 0);
  }
  // Keypoints seen from the vehicle at (x, y, z, yaw), pitched by `pitch_rad` (nose down > 0).
  int keypointsFrom(double x, double y, double z, double yaw_rad, double pitch_rad = 0.0) {
    planner::Pose4 pose;
    pose.p_WB = Eigen::Vector3d(x, y, z);
    setVehiclePose(model_.get(), data_.get(), ids_, pose);
    const Eigen::Quaterniond q =
        Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitY());
    mjtNum* qpos = data_->qpos + ids_.qpos_adr + 3;
    qpos[0] = q.w();
    qpos[1] = q.x();
    qpos[2] = q.y();
    qpos[3] = q.z();
    mj_forward(model_.get(), data_.get());
    const RgbdFrame frame = camera_->render(data_.get());
    cv::Mat gray;
    cv::cvtColor(frame.bgr, gray, cv::COLOR_BGR2GRAY);
    return static_cast<int>(detector_.detect(gray).keypoints.size());
  }

  ModelPtr model_;
  DataPtr data_;
  VehicleIds ids_;
  EglContext gl_;
  std::unique_ptr<Camera> camera_;
  vo::FeatureDetector detector_{vo::FeatureConfig{}};
};

TEST_F(SceneTextureTest, TexturedCratesGiveManyKeypoints) {
  // Facing the crates by the east wall from 2 m.
  EXPECT_GT(keypointsFrom(1.2, 0.2, 1.0, 0.0), 300);
  // Facing the crates by the north wall.
  EXPECT_GT(keypointsFrom(0.0, 0.3, 1.0, M_PI / 2), 300);
}

TEST_F(SceneTextureTest, PlainFloorGivesAlmostNone) { EXPECT_LT(keypointsFrom(-2.0, -1.0, 1.2, 0.0, M_PI / 2), 30); }

TEST_F(SceneTextureTest, PlainPillarGivesAlmostNone) {
  // 0.4 m in front of the pillar's west face: it fills the view.
  EXPECT_LT(keypointsFrom(-0.95, 0.0, 1.5, 0.0), 30);
}

}  // namespace
}  // namespace tgnav::harness
