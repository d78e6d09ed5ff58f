// The map built frame by frame (harness/run/incremental_map.h): a snapshot taken between frames
// changes nothing that a later snapshot holds, though it counts only the frames new to a landmark
// that no frame has observed since.
#include "harness/run/incremental_map.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <iostream>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "harness/config/map_build_config.h"
#include "harness/sim/camera.h"

namespace tgnav::harness {
namespace {

constexpr double kWallM = 3.0;  // the textured plane z = 3 m in the world, the camera looking along +z

// A frame at camera position (x, 0, 0), its image a window of `texture` (the wall) shifted by the
// position, its depth the wall's.
RgbdFrame frameAt(const cv::Mat& texture, const Intrinsics& k, double x_m) {
  RgbdFrame f;
  const int shift_px = static_cast<int>(std::lround(k.fx * x_m / kWallM));
  f.bgr = texture(cv::Rect(shift_px, 0, k.width_px, k.height_px)).clone();
  f.depth_m = cv::Mat(k.height_px, k.width_px, CV_32FC1, cv::Scalar(static_cast<float>(kWallM)));
  f.X_WC.translation() = Eigen::Vector3d(x_m, 0.0, 0.0);
  return f;
}

TEST(IncrementalMapper, SnapshotsBetweenFramesLeaveTheLandmarksAndTheirCountsAsOneSnapshotAtTheEnd) {
  const Intrinsics k = intrinsicsFromFovy(60.0, 320, 240);
  cv::Mat noise(240, 1600, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 1.5);
  cv::Mat texture;
  cv::cvtColor(noise, texture, cv::COLOR_GRAY2BGR);
  // Out along the wall and back: landmarks leave the view (counted on from where they were) and
  // come back into it (observed again, their means move: counted again from the first frame).
  std::vector<double> xs;
  for (int i = 0; i <= 20; ++i) xs.push_back(0.12 * i);
  for (int i = 19; i >= 0; --i) xs.push_back(0.12 * i + 0.05);

  MapBuildConfig config;
  IncrementalMapper once(config, k);
  IncrementalMapper often(config, k);
  int snapshots = 0;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    const RgbdFrame f = frameAt(texture, k, xs[i]);
    for (IncrementalMapper* m : {&once, &often}) {
      m->insertDepth(f, 4);
      m->observeFeatures(f);
    }
    if (i % 3 == 2) {
      often.snapshot();
      ++snapshots;
    }
  }
  const std::vector<planner::Landmark> a = once.snapshot().map.landmarks();
  const std::vector<planner::Landmark> b = often.snapshot().map.landmarks();
  ASSERT_GT(snapshots, 10);
  ASSERT_GT(a.size(), 100U);
  ASSERT_EQ(a.size(), b.size());
  int more_chances = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].p_W, b[i].p_W) << i;
    ASSERT_EQ(a[i].observations, b[i].observations) << i;
    ASSERT_EQ(a[i].opportunities, b[i].opportunities) << i;
    more_chances += a[i].opportunities > a[i].observations ? 1 : 0;
  }
  // The counts are not trivial: most landmarks were in view in frames that missed them.
  EXPECT_GT(more_chances, static_cast<int>(a.size()) / 2);
}

// The depth of the wall x = kFaceX (solid beyond it) seen from the camera pose X_WC; 0 where a
// ray misses it.
constexpr double kFaceX = 2.01;  // 0.01 m into the voxels [2.0, 2.1]: 90 % of each inside the wall

RgbdFrame wallFrame(const Intrinsics& k, const Eigen::Isometry3d& X_WC) {
  RgbdFrame f;
  f.X_WC = X_WC;
  f.bgr = cv::Mat(k.height_px, k.width_px, CV_8UC3, cv::Scalar(128, 128, 128));
  f.depth_m = cv::Mat(k.height_px, k.width_px, CV_32FC1, cv::Scalar(0.0F));
  for (int v = 0; v < k.height_px; ++v) {
    for (int u = 0; u < k.width_px; ++u) {
      const Eigen::Vector3d dir_W = X_WC.linear() * Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
      const double z = (kFaceX - X_WC.translation().x()) / dir_W.x();  // the depth: dir_C has z = 1
      if (dir_W.x() > 1e-9 && z < 20.0) f.depth_m.at<float>(v, u) = static_cast<float>(z);
    }
  }
  return f;
}

// A camera at p looking along `forward` (horizontal), the image's x to its right, y down.
Eigen::Isometry3d lookingAlong(const Eigen::Vector3d& p, const Eigen::Vector3d& forward) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d f = forward.normalized();
  const Eigen::Vector3d down(0.0, 0.0, -1.0);
  X.linear().col(0) = down.cross(f);  // right: y x z = x
  X.linear().col(1) = down;
  X.linear().col(2) = f;
  X.translation() = p;
  return X;
}

// Seen face on, the wall's voxels are occupied. Then twenty views along it, 0.7 m off it (a flight
// past it) and turned 10 deg toward it: their rays meet it at grazing angles. OctoMap's insertion clears the wall's
// voxels on the way to points farther along it (the storage shelves' faces in online flights:
// docs/results/grazing); short of the surface it leaves them occupied.
TEST(IncrementalMapper, RaysThatGrazeAWallClearItsVoxelsUnlessTheyStopShortOfTheSurface) {
  const Intrinsics k = intrinsicsFromFovy(60.0, 320, 240);
  const double a = 10.0 * M_PI / 180.0;
  int occupied_before = 0;
  std::array<int, 2> kept{};
  for (const bool short_of_surface : {false, true}) {
    MapBuildConfig config;
    config.free_short_of_surface = short_of_surface;
    IncrementalMapper m(config, k);
    m.insertDepth(wallFrame(k, lookingAlong(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX())), 2);
    std::vector<Eigen::Vector3d> face;  // the wall's voxels at x 2.05 that the face-on view made occupied
    for (double y = -1.45; y < -0.6; y += 0.1) {
      for (double z = -0.25; z < 0.3; z += 0.1) {
        const Eigen::Vector3d c(2.05, y, z);
        const octomap::OcTreeNode* n = m.occupancy().search(c.x(), c.y(), c.z());
        if (n != nullptr && m.occupancy().isNodeOccupied(n)) face.push_back(c);
      }
    }
    occupied_before = static_cast<int>(face.size());
    for (int i = 0; i < 20; ++i) {  // from y = -6 to -4.1: the face's voxels lie 3-5 m ahead
      const Eigen::Vector3d p(kFaceX - 0.7, -6.0 + 0.1 * i, 0.0);
      m.insertDepth(wallFrame(k, lookingAlong(p, Eigen::Vector3d(std::sin(a), std::cos(a), 0.0))), 4);
    }
    for (const Eigen::Vector3d& c : face) {
      const octomap::OcTreeNode* n = m.occupancy().search(c.x(), c.y(), c.z());
      kept[short_of_surface ? 1 : 0] += n != nullptr && m.occupancy().isNodeOccupied(n) ? 1 : 0;
    }
    // In front of the face, the views along it cleared free space either way.
    const octomap::OcTreeNode* front = m.occupancy().search(1.75, -1.05, 0.05);
    ASSERT_NE(front, nullptr);
    EXPECT_FALSE(m.occupancy().isNodeOccupied(front));
  }
  std::cout << "[ figure   ] a grazed wall's voxels kept occupied: " << kept[0] << " of " << occupied_before
            << " by OctoMap's insertion, " << kept[1] << " short of the surface\n";
  ASSERT_GT(occupied_before, 40);  // 9 x 6 voxels
  EXPECT_LT(kept[0], occupied_before * 9 / 10) << "OctoMap's insertion no longer clears a grazed wall";
  EXPECT_EQ(kept[1], occupied_before);
}

// A camera's depth has no return beyond its range. Looking along the wall (at x 2.01, to the
// camera's right), the pixels to its left see nothing within 8 m: with no_return_depth_m their rays
// mark the space they cross free, within max_range_m; without it that space stays unobserved. A
// voxel observed occupied stays so, though later views without any return cross it.
TEST(IncrementalMapper, PixelsWithoutDepthClearOnlyUnobservedSpaceWithinRangeWhenAsked) {
  const Intrinsics k = intrinsicsFromFovy(60.0, 320, 240);
  const auto beyondRange = [](RgbdFrame f) {
    cv::Mat far = f.depth_m > 8.0F;
    f.depth_m.setTo(0.0F, far);
    return f;
  };
  const auto state = [](const IncrementalMapper& m, const Eigen::Vector3d& c) {
    const octomap::OcTreeNode* n = m.occupancy().search(c.x(), c.y(), c.z());
    return n == nullptr ? 'u' : m.occupancy().isNodeOccupied(n) ? 'o' : 'f';
  };
  const Eigen::Vector3d left_near(-1.0, 5.0, 0.0);  // 5 m ahead, 1 m left: no surface behind it
  const Eigen::Vector3d left_far(-1.0, 7.5, 0.0);   // ... beyond max_range_m
  const Eigen::Vector3d wall(2.05, 0.05, 0.05);     // the wall's voxel in front of the camera
  for (const double no_return_m : {0.0, 8.0}) {
    MapBuildConfig config;
    config.max_range_m = 6.0;
    config.no_return_depth_m = no_return_m;
    IncrementalMapper m(config, k);
    m.insertDepth(wallFrame(k, lookingAlong(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX())), 2);
    ASSERT_EQ(state(m, wall), 'o');
    m.insertDepth(beyondRange(wallFrame(k, lookingAlong(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY()))), 2);
    EXPECT_EQ(state(m, left_near), no_return_m > 0.0 ? 'f' : 'u') << "no_return_depth_m " << no_return_m;
    EXPECT_EQ(state(m, left_far), 'u') << "no_return_depth_m " << no_return_m;
    RgbdFrame blank = wallFrame(k, lookingAlong(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX()));
    blank.depth_m.setTo(0.0F);
    for (int i = 0; i < 5; ++i) m.insertDepth(blank, 2);  // five misses would clear a hit
    EXPECT_EQ(state(m, wall), 'o') << "no_return_depth_m " << no_return_m;
  }
}

}  // namespace
}  // namespace tgnav::harness
