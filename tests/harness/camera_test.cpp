// The rendered camera is a metric pinhole camera: depth is true z, the intrinsics derived from
// the MJCF fovy back-project pixels onto the surfaces they show, and project world points onto
// the pixels where they appear.
#include "harness/sim/camera.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <sstream>

#include "harness/sim/mujoco_sim.h"
#include "test_util.h"

namespace tgnav::harness {
namespace {

constexpr double kDeg = M_PI / 180.0;
const Eigen::Vector3d kCameraPos(0.0, 0.0, 1.0);
const Eigen::Vector3d kMarker(2.3, 0.3, 1.5);  // well off the optical axis
constexpr double kWallX = 3.0;                 // front face of the wall

// Rotation of MuJoCo's camera frame in W for a camera looking along yaw/pitch.
Eigen::Matrix3d mujocoCameraAxes(double yaw, double pitch) {
  const Eigen::Vector3d forward(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw), std::sin(pitch));
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d up = right.cross(forward);
  Eigen::Matrix3d R;
  R << right, up, -forward;
  return R;
}

// A camera looking obliquely at a large grey wall, with a small self-lit red marker.
std::string testScene(double yaw, double pitch) {
  const Eigen::Matrix3d R = mujocoCameraAxes(yaw, pitch);
  std::ostringstream xml;
  xml.precision(17);
  xml << "<mujoco><visual><global offwidth='640' offheight='480'/></visual><worldbody>"
      << "<camera name='cam' pos='" << kCameraPos.transpose() << "' xyaxes='" << R.col(0).transpose() << " "
      << R.col(1).transpose() << "' fovy='60'/>"
      << "<geom type='box' pos='" << kWallX + 0.1 << " 0 0' size='0.1 40 40' rgba='0.5 0.5 0.5 1'/>"
      << "<geom type='sphere' pos='" << kMarker.transpose() << "' size='0.03' rgba='1 0 0 1'"
      << " material='glow'/>"
      << "</worldbody><asset><material name='glow' emission='1' specular='0'/></asset></mujoco>";
  return xml.str();
}

class CameraTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto dir = test::tempDir();
    model_ = loadModel(test::writeFile(dir / "wall.xml", testScene(25 * kDeg, -8 * kDeg)));
    data_ = makeData(model_.get());
    mj_forward(model_.get(), data_.get());
    config_.name = "cam";
  }
  ModelPtr model_;
  DataPtr data_;
  CameraConfig config_;
};

TEST_F(CameraTest, IntrinsicsFollowFovyAndResolution) {
  const Intrinsics k = intrinsicsFromFovy(60.0, 640, 480);
  EXPECT_NEAR(k.fy, 240.0 / std::tan(30.0 * kDeg), 1e-9);
  EXPECT_DOUBLE_EQ(k.fx, k.fy);
  EXPECT_DOUBLE_EQ(k.cx, 319.5);
  EXPECT_DOUBLE_EQ(k.cy, 239.5);
}

TEST_F(CameraTest, PoseIsComputerVisionConvention) {
  EglContext gl;
  Camera camera(model_.get(), gl, config_, 0);
  const Eigen::Isometry3d X_WC = camera.pose(data_.get());
  const Eigen::Vector3d forward = X_WC.linear().col(2);
  EXPECT_NEAR(forward.dot(Eigen::Vector3d(std::cos(-8 * kDeg) * std::cos(25 * kDeg),
                                          std::cos(-8 * kDeg) * std::sin(25 * kDeg), std::sin(-8 * kDeg))),
              1.0, 1e-9);
  EXPECT_LT(X_WC.linear().col(1).z(), 0.0);  // image y points down
  EXPECT_NEAR((X_WC.translation() - kCameraPos).norm(), 0.0, 1e-9);
}

TEST_F(CameraTest, DepthIsMetricAndBackProjectsOntoTheWall) {
  EglContext gl;
  Camera camera(model_.get(), gl, config_, 0);
  const RgbdFrame frame = camera.render(data_.get());
  const Intrinsics& k = camera.intrinsics();
  ASSERT_EQ(frame.depth_m.cols, 640);
  ASSERT_EQ(frame.depth_m.rows, 480);

  // Image centre: the optical axis hits the wall plane x = kWallX.
  const Eigen::Vector3d axis = frame.X_WC.linear().col(2);
  const double expected_z = (kWallX - kCameraPos.x()) / axis.x();
  const float centre = 0.25f * (frame.depth_m.at<float>(239, 319) + frame.depth_m.at<float>(239, 320) +
                                frame.depth_m.at<float>(240, 319) + frame.depth_m.at<float>(240, 320));
  EXPECT_NEAR(centre, expected_z, 0.01);

  // Every pixel of the oblique wall back-projects onto the wall plane.
  int checked = 0;
  double worst = 0.0;
  for (int v = 0; v < k.height_px; v += 7) {
    for (int u = 0; u < k.width_px; u += 7) {
      const double z = frame.depth_m.at<float>(v, u);
      const cv::Vec3b bgr = frame.bgr.at<cv::Vec3b>(v, u);
      if (z <= 0.0 || bgr[2] > 2 * bgr[1] + 40) continue;  // invalid or the red marker
      const Eigen::Vector3d p_C((u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z);
      const Eigen::Vector3d p_W = frame.X_WC * p_C;
      worst = std::max(worst, std::abs(p_W.x() - kWallX));
      ++checked;
    }
  }
  EXPECT_GT(checked, 5000);
  EXPECT_LT(worst, 0.01);
}

TEST_F(CameraTest, MarkerAppearsWhereTheIntrinsicsProjectIt) {
  EglContext gl;
  Camera camera(model_.get(), gl, config_, 0);
  const RgbdFrame frame = camera.render(data_.get());
  const Intrinsics& k = camera.intrinsics();

  const Eigen::Vector3d p_C = frame.X_WC.inverse() * kMarker;
  ASSERT_GT(p_C.z(), 0.0);
  const double u_expected = k.fx * p_C.x() / p_C.z() + k.cx;
  const double v_expected = k.fy * p_C.y() / p_C.z() + k.cy;
  ASSERT_GT(std::hypot(u_expected - k.cx, v_expected - k.cy), 80.0) << "marker must be off-axis";

  double su = 0.0, sv = 0.0;
  int n = 0;
  for (int v = 0; v < k.height_px; ++v) {
    for (int u = 0; u < k.width_px; ++u) {
      const cv::Vec3b bgr = frame.bgr.at<cv::Vec3b>(v, u);
      if (bgr[2] > 200 && bgr[1] < 60 && bgr[0] < 60) {
        su += u;
        sv += v;
        ++n;
      }
    }
  }
  ASSERT_GT(n, 10) << "marker not visible";
  EXPECT_NEAR(su / n, u_expected, 1.0);
  EXPECT_NEAR(sv / n, v_expected, 1.0);
}

// camera.offscreen_samples: with multisampling the marker's silhouette blends red into the grey
// wall; with one sample per pixel every pixel is either the marker's or the wall's.
TEST_F(CameraTest, OffscreenSamplesBlendSilhouettesOnlyWhenMultisampled) {
  auto blended = [&](int samples) {
    EglContext gl;
    CameraConfig config = config_;
    config.offscreen_samples = samples;
    Camera camera(model_.get(), gl, config, 0);
    const RgbdFrame frame = camera.renderNoiseless(data_.get());
    int n = 0;
    for (int v = 0; v < frame.bgr.rows; ++v) {
      for (int u = 0; u < frame.bgr.cols; ++u) {
        const cv::Vec3b bgr = frame.bgr.at<cv::Vec3b>(v, u);
        const int redness = static_cast<int>(bgr[2]) - static_cast<int>(bgr[1]);
        if (redness > 40 && redness < 200) ++n;  // partly marker, partly wall
      }
    }
    return n;
  };
  EXPECT_GT(blended(4), 5);
  EXPECT_EQ(blended(0), 0);
}

TEST_F(CameraTest, NoiseIsSeededAndBounded) {
  config_.rgb_noise_sigma = 3.0;
  config_.depth_noise_sigma_per_m2 = 0.002;
  EglContext gl;
  Camera a(model_.get(), gl, config_, 42);
  Camera b(model_.get(), gl, config_, 42);
  Camera c(model_.get(), gl, config_, 43);
  const RgbdFrame fa = a.render(data_.get());
  const RgbdFrame fb = b.render(data_.get());
  const RgbdFrame fc = c.render(data_.get());
  EXPECT_EQ(cv::norm(fa.bgr, fb.bgr, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(fa.depth_m, fb.depth_m, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(fa.depth_m, fc.depth_m, cv::NORM_INF), 0.0);

  config_.rgb_noise_sigma = 0.0;
  config_.depth_noise_sigma_per_m2 = 0.0;
  Camera clean(model_.get(), gl, config_, 0);
  const RgbdFrame f0 = clean.render(data_.get());
  cv::Mat diff;
  cv::absdiff(fa.depth_m, f0.depth_m, diff);
  cv::Mat rel = diff / (f0.depth_m.mul(f0.depth_m) + 1e-9);
  // sigma = 0.002 z^2: residual / z^2 is a unit-free sample of N(0, 0.002).
  cv::Scalar mean, stddev;
  cv::meanStdDev(rel, mean, stddev, (f0.depth_m > 0) & (fa.depth_m > 0));
  EXPECT_NEAR(mean[0], 0.002 * std::sqrt(2.0 / M_PI), 0.0002)  // E|N(0, s)| = s sqrt(2/pi)
      << "std " << stddev[0];
}

// The table the noise is drawn from: the normal quantiles at (i + 0.5) / 65536, increasing and
// symmetric, each where the normal CDF puts it (to float precision).
TEST(CameraNoiseTest, QuantilesAreTheStandardNormals) {
  const std::vector<float>& z = normalQuantiles();
  ASSERT_EQ(z.size(), 65536u);
  double mean = 0.0, var = 0.0;
  for (std::size_t i = 0; i < z.size(); ++i) {
    if (i > 0) {
      ASSERT_LT(z[i - 1], z[i]) << i;
    }
    ASSERT_EQ(z[i], -z[z.size() - 1 - i]);
    const double p = (static_cast<double>(i) + 0.5) / 65536.0;
    ASSERT_NEAR(0.5 * std::erfc(-z[i] / std::sqrt(2.0)), p, 1e-7 + 1e-6 * p) << i;
    mean += z[i];
    var += static_cast<double>(z[i]) * z[i];
  }
  EXPECT_NEAR(mean / 65536.0, 0.0, 1e-9);
  EXPECT_NEAR(var / 65536.0, 1.0, 1e-3);  // the tails beyond 4.32 sigma are cut
  EXPECT_NEAR(z.back(), 4.325, 0.001);    // p = 1 - 0.5 / 65536
  EXPECT_NEAR(z[55137], 1.0, 1e-4);       // Phi(1) = 0.841345 = (55137.4 + 0.5) / 65536
}

// Colour noise on a mid-grey frame: zero mean, the standard deviation of a rounded Gaussian
// (sqrt(sigma^2 + 1/12)), the Gaussian's share beyond 1.75 sigma; repeatable per seed, new in
// every frame. Depth noise keeps invalid pixels invalid.
TEST(CameraNoiseTest, ColourNoiseIsARoundedGaussian) {
  CameraConfig config;
  config.rgb_noise_sigma = 2.0;
  config.depth_noise_sigma_per_m2 = 0.002;
  auto grey = [] {
    RgbdFrame f;
    f.bgr = cv::Mat(480, 640, CV_8UC3, cv::Scalar(128, 128, 128));
    f.depth_m = cv::Mat(480, 640, CV_32FC1, cv::Scalar(2.0));
    f.depth_m(cv::Rect(0, 0, 64, 48)).setTo(0.0f);
    return f;
  };
  CameraNoise noise(config, 7);
  RgbdFrame a = grey();
  noise.apply(&a);
  cv::Mat values;
  a.bgr.reshape(1).convertTo(values, CV_64F);
  cv::Scalar mean, stddev;
  cv::meanStdDev(values, mean, stddev);
  EXPECT_NEAR(mean[0], 128.0, 0.01);
  EXPECT_NEAR(stddev[0], std::sqrt(4.0 + 1.0 / 12.0), 0.01);
  const double beyond = cv::countNonZero(cv::abs(values - 128.0) >= 4.0) / static_cast<double>(values.total());
  EXPECT_NEAR(beyond, std::erfc(1.75 / std::sqrt(2.0)), 0.002);  // |round(2 z)| >= 4 <=> |z| >= 1.75
  EXPECT_EQ(cv::countNonZero(a.depth_m(cv::Rect(0, 0, 64, 48))), 0);
  cv::Mat depth_rel = (a.depth_m(cv::Rect(64, 48, 576, 432)) - 2.0) / (0.002 * 4.0);
  cv::meanStdDev(depth_rel, mean, stddev);
  EXPECT_NEAR(mean[0], 0.0, 0.01);
  EXPECT_NEAR(stddev[0], 1.0, 0.01);

  RgbdFrame b = grey();
  noise.apply(&b);
  EXPECT_GT(cv::norm(a.bgr, b.bgr, cv::NORM_L1), 0.0);  // a new draw for every frame
  CameraNoise same(config, 7), other(config, 8);
  RgbdFrame a2 = grey(), c = grey();
  same.apply(&a2);
  other.apply(&c);
  EXPECT_EQ(cv::norm(a.bgr, a2.bgr, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.depth_m, a2.depth_m, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a.bgr, c.bgr, cv::NORM_L1), 0.0);
}

TEST(CameraConfigTest, ValidateNamesTheOffendingValue) {
  CameraConfig c;
  c.width_px = 3;
  try {
    c.validate();
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("width_px = 3"), std::string::npos) << e.what();
  }
  c = CameraConfig{};
  c.max_depth_m = 100.0;
  EXPECT_THROW(c.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace tgnav::harness
