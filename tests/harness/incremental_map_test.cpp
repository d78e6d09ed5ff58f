// The map built frame by frame (harness/run/incremental_map.h): a snapshot taken between frames
// changes nothing that a later snapshot holds, though it counts only the frames new to a landmark
// that no frame has observed since.
#include "harness/run/incremental_map.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace tgnav::harness
