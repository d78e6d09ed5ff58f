// Grid-bucketed ORB: features spread over textured cells, the budget holds, blank images give
// none, and the result is deterministic.
#include "vo/features.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

namespace tgnav::vo {
namespace {

// Random black/white blocks of `block` px inside `roi`, mid-grey elsewhere.
cv::Mat blocks(cv::Size size, cv::Rect roi, int block, unsigned seed) {
  cv::Mat img(size, CV_8UC1, cv::Scalar(128));
  std::mt19937 rng(seed);
  for (int y = roi.y; y < roi.y + roi.height; y += block) {
    for (int x = roi.x; x < roi.x + roi.width; x += block) {
      const cv::Rect cell = cv::Rect(x, y, block, block) & roi;
      img(cell).setTo(rng() % 2 ? 230 : 25);
    }
  }
  return img;
}

TEST(FeatureDetector, BlankImageHasNoFeatures) {
  const FeatureDetector det{FeatureConfig{}};
  EXPECT_TRUE(det.detect(cv::Mat(480, 640, CV_8UC1, cv::Scalar(100))).keypoints.empty());
}

TEST(FeatureDetector, BudgetHoldsAndDescriptorsMatchKeypoints) {
  FeatureConfig config;
  config.max_features = 200;
  const FeatureDetector det(config);
  const Features f = det.detect(blocks({640, 480}, {0, 0, 640, 480}, 6, 1));
  EXPECT_LE(static_cast<int>(f.keypoints.size()), 200);
  EXPECT_GT(static_cast<int>(f.keypoints.size()), 150);
  EXPECT_EQ(f.descriptors.rows, static_cast<int>(f.keypoints.size()));
  EXPECT_EQ(f.descriptors.cols, 32);
}

TEST(FeatureDetector, FeaturesSpreadOverEveryTexturedCell) {
  // Fine, strong texture on the left half; coarse texture on the right half. Without bucketing
  // the strong half would take the budget; with it every textured grid cell gets features.
  cv::Mat img = blocks({640, 480}, {0, 0, 320, 480}, 4, 2);
  blocks({640, 480}, {320, 0, 320, 480}, 16, 3)(cv::Rect(320, 0, 320, 480)).copyTo(img(cv::Rect(320, 0, 320, 480)));
  FeatureConfig config;
  config.max_features = 300;
  const Features f = FeatureDetector(config).detect(img);
  std::vector<int> per_cell(config.grid_cols * config.grid_rows, 0);
  for (const auto& kp : f.keypoints) {
    const int cx = static_cast<int>(kp.pt.x * config.grid_cols / 640);
    const int cy = static_cast<int>(kp.pt.y * config.grid_rows / 480);
    ++per_cell[cy * config.grid_cols + cx];
  }
  for (std::size_t c = 0; c < per_cell.size(); ++c) EXPECT_GT(per_cell[c], 0) << "cell " << c;
  int right = 0;
  for (const auto& kp : f.keypoints) right += kp.pt.x >= 320;
  EXPECT_GT(right, 100);
}

TEST(FeatureDetector, Deterministic) {
  const FeatureDetector det{FeatureConfig{}};
  const cv::Mat img = blocks({320, 240}, {0, 0, 320, 240}, 5, 4);
  const Features a = det.detect(img);
  const Features b = det.detect(img);
  ASSERT_EQ(a.keypoints.size(), b.keypoints.size());
  EXPECT_EQ(cv::norm(a.descriptors, b.descriptors, cv::NORM_HAMMING), 0.0);
}

TEST(FeatureConfig, ValidateRejectsBadValues) {
  FeatureConfig c;
  c.grid_cols = 0;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = FeatureConfig{};
  c.scale_factor = 1.0;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  EXPECT_NO_THROW(FeatureConfig{}.validate());
}

}  // namespace
}  // namespace tgnav::vo
