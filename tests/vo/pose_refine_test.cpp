// refinePoseLm against cv::solvePnPRefineLM on the same correspondences: the same minimum of the
// reprojection error, from starts near and far, with noisy pixels; and its refusals.
#include "vo/pose_refine.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <random>

namespace tgnav::vo {
namespace {

const CameraIntrinsics kCamera{640, 480, 416.0, 416.0, 319.5, 239.5};

struct Scene {
  std::vector<cv::Point3d> p_W;
  std::vector<cv::Point2d> uv;
  Eigen::Isometry3d X_CW_true;
};

// `n` points 1.5-8 m in front of a camera at a random pose, their pixels with Gaussian noise.
Scene makeScene(int n, double pixel_sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> x(-3.0, 3.0), y(-2.0, 2.0), z(1.5, 8.0), a(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, pixel_sigma);
  Scene s;
  s.X_CW_true = Eigen::Isometry3d::Identity();
  s.X_CW_true.linear() =
      Eigen::AngleAxisd(0.8 * a(rng), Eigen::Vector3d(a(rng), a(rng), a(rng)).normalized()).toRotationMatrix();
  s.X_CW_true.translation() = Eigen::Vector3d(a(rng), a(rng), a(rng));
  const Eigen::Isometry3d X_WC = s.X_CW_true.inverse();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d q(x(rng), y(rng), z(rng));
    const Eigen::Vector3d p = X_WC * q;
    s.p_W.emplace_back(p.x(), p.y(), p.z());
    s.uv.emplace_back(kCamera.fx * q.x() / q.z() + kCamera.cx + noise(rng),
                      kCamera.fy * q.y() / q.z() + kCamera.cy + noise(rng));
  }
  return s;
}

double cost(const Scene& s, const Eigen::Isometry3d& X_CW) {
  double c = 0.0;
  for (std::size_t i = 0; i < s.p_W.size(); ++i) {
    const Eigen::Vector3d q = X_CW * Eigen::Vector3d(s.p_W[i].x, s.p_W[i].y, s.p_W[i].z);
    const double du = kCamera.fx * q.x() / q.z() + kCamera.cx - s.uv[i].x;
    const double dv = kCamera.fy * q.y() / q.z() + kCamera.cy - s.uv[i].y;
    c += du * du + dv * dv;
  }
  return c;
}

Eigen::Isometry3d perturbed(const Eigen::Isometry3d& X, double angle, double shift, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
  d.linear() = Eigen::AngleAxisd(angle, Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized()).toRotationMatrix();
  d.translation() = shift * Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
  return d * X;
}

Eigen::Isometry3d openCvRefine(const Scene& s, const Eigen::Isometry3d& start) {
  cv::Mat R, rvec, tvec;
  cv::eigen2cv(Eigen::Matrix3d(start.linear()), R);
  cv::Rodrigues(R, rvec);
  cv::eigen2cv(Eigen::Vector3d(start.translation()), tvec);
  const cv::Matx33d K(kCamera.fx, 0.0, kCamera.cx, 0.0, kCamera.fy, kCamera.cy, 0.0, 0.0, 1.0);
  cv::solvePnPRefineLM(s.p_W, s.uv, K, cv::noArray(), rvec, tvec);
  cv::Rodrigues(rvec, R);
  Eigen::Matrix3d R_CW;
  Eigen::Vector3d t_CW;
  cv::cv2eigen(R, R_CW);
  cv::cv2eigen(tvec, t_CW);
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = R_CW;
  X.translation() = t_CW;
  return X;
}

// Both reach the same pose; ours's cost is never above OpenCV's (it converges at least as far).
TEST(PoseRefine, ReachesOpenCvsMinimum) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Scene s = makeScene(seed % 2 == 0 ? 40 : 600, 0.7, seed);
    const double angle = seed % 4 < 2 ? 0.02 : 0.2, shift = seed % 4 < 2 ? 0.02 : 0.3;
    const Eigen::Isometry3d start = perturbed(s.X_CW_true, angle, shift, seed + 50);
    Eigen::Isometry3d ours = start;
    const PoseRefinement r = refinePoseLm(s.p_W, s.uv, kCamera, &ours);
    ASSERT_TRUE(r.ok) << "seed " << seed;
    const Eigen::Isometry3d theirs = openCvRefine(s, start);
    EXPECT_LE(cost(s, ours), cost(s, theirs) * (1.0 + 1e-9) + 1e-12) << "seed " << seed;
    EXPECT_NEAR(r.rms_px * r.rms_px * static_cast<double>(s.p_W.size()), cost(s, ours), 1e-9 * cost(s, ours));
    EXPECT_LT((ours.translation() - theirs.translation()).norm(), 1e-6) << "seed " << seed;
    EXPECT_LT(Eigen::AngleAxisd(ours.linear() * theirs.linear().transpose()).angle(), 1e-7) << "seed " << seed;
    EXPECT_GE(r.iterations, 1);
    EXPECT_LE(r.iterations, 20);
  }
}

// Exact pixels: the true pose, to rounding.
TEST(PoseRefine, ExactPixelsGiveTheTruePose) {
  const Scene s = makeScene(100, 0.0, 7);
  Eigen::Isometry3d X = perturbed(s.X_CW_true, 0.1, 0.2, 8);
  ASSERT_TRUE(refinePoseLm(s.p_W, s.uv, kCamera, &X).ok);
  EXPECT_LT((X.translation() - s.X_CW_true.translation()).norm(), 1e-9);
  EXPECT_LT(Eigen::AngleAxisd(X.linear() * s.X_CW_true.linear().transpose()).angle(), 1e-10);
}

// Too few points, sizes that disagree, a non-finite point, a non-finite start: not ok,
// the pose untouched.
TEST(PoseRefine, RefusesWhatItCannotSolve) {
  const Scene s = makeScene(10, 0.5, 9);
  const Eigen::Isometry3d start = s.X_CW_true;
  Eigen::Isometry3d X = start;
  EXPECT_FALSE(refinePoseLm({s.p_W.begin(), s.p_W.begin() + 2}, {s.uv.begin(), s.uv.begin() + 2}, kCamera, &X).ok);
  EXPECT_FALSE(refinePoseLm(s.p_W, {s.uv.begin(), s.uv.begin() + 5}, kCamera, &X).ok);
  Scene broken = s;
  broken.p_W[3].y = std::nan("");
  EXPECT_FALSE(refinePoseLm(broken.p_W, broken.uv, kCamera, &X).ok);
  EXPECT_TRUE(X.matrix() == start.matrix());
  X.translation().x() = std::nan("");
  EXPECT_FALSE(refinePoseLm(s.p_W, s.uv, kCamera, &X).ok);
}

// Points on a wall patch 4 m ahead, 0.8 m across (83 px), pixels with 1 px noise: their
// reprojections leave the pose free to slide while it turns, and the noise moves it 0.3-0.8 m.
// With the points' measured depths (exact here) it holds the depth to 1 cm and half the error at
// least. Depths marked absent
// (0, NaN) count for nothing, and a depth list of the wrong size is refused.
TEST(PoseRefine, MeasuredDepthsHoldThePoseAlongTheOpticalAxis) {
  const PoseDepth kDepth{nullptr, kCamera.fx * 0.08, 0.1};
  double worst_pixels = 0.0, worst_depth = 0.0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> a(-0.4, 0.4);
    std::normal_distribution<double> noise(0.0, 1.0);
    Scene s;
    s.X_CW_true = Eigen::Isometry3d::Identity();
    std::vector<double> depth, none;
    for (int i = 0; i < 40; ++i) {
      const Eigen::Vector3d q(a(rng), a(rng), 4.0);
      s.p_W.emplace_back(q.x(), q.y(), q.z());
      s.uv.emplace_back(kCamera.fx * q.x() / q.z() + kCamera.cx + noise(rng),
                        kCamera.fy * q.y() / q.z() + kCamera.cy + noise(rng));
      depth.push_back(q.z());
      none.push_back(i % 2 == 0 ? 0.0 : std::nan(""));
    }
    Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
    start.translation().z() = 0.25;  // the camera 0.25 m nearer the wall
    Eigen::Isometry3d pixels_only = start, with_depth = start, absent = start;
    ASSERT_TRUE(refinePoseLm(s.p_W, s.uv, kCamera, &pixels_only).ok);
    PoseDepth d = kDepth;
    d.depth_m = &depth;
    ASSERT_TRUE(refinePoseLm(s.p_W, s.uv, kCamera, &with_depth, 20, d).ok);
    d.depth_m = &none;
    ASSERT_TRUE(refinePoseLm(s.p_W, s.uv, kCamera, &absent, 20, d).ok);
    EXPECT_TRUE(absent.matrix() == pixels_only.matrix()) << "seed " << seed;
    // The true camera is at the origin: the translation is the error.
    EXPECT_LT(with_depth.translation().norm(), 0.5 * pixels_only.translation().norm()) << "seed " << seed;
    worst_pixels = std::max(worst_pixels, pixels_only.translation().norm());
    worst_depth = std::max(worst_depth, std::abs(with_depth.translation().z()));
  }
  EXPECT_GT(worst_pixels, 0.3);
  EXPECT_LT(worst_depth, 0.01);
  const Scene s = makeScene(10, 0.5, 9);
  const std::vector<double> short_list(5, 3.0);
  PoseDepth d = kDepth;
  d.depth_m = &short_list;
  Eigen::Isometry3d X = s.X_CW_true;
  EXPECT_FALSE(refinePoseLm(s.p_W, s.uv, kCamera, &X, 20, d).ok);
}

}  // namespace
}  // namespace tgnav::vo
