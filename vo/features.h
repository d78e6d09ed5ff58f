#pragma once
// ORB features spread over the image on a grid (ORB-SLAM2's bucketing idea): a textured patch
// in one corner must not starve the rest of the image of features.
// The feature maps are built with this detector and cached by their settings: a change to what
// it detects must bump kMapBuilderVersion (harness/run/map_cache.cpp).
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <vector>

namespace tgnav::vo {

struct FeatureConfig {
  int max_features = 1000;
  int grid_cols = 8;
  int grid_rows = 6;
  int fast_threshold = 20;  // FAST intensity threshold (8-bit units), ORB-SLAM2's iniThFAST
  double scale_factor = 1.2;
  int pyramid_levels = 8;
  int edge_threshold_px = 19;

  // Names every field once, for the harness's config files (a(key, field); harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a("max_features", max_features);
    a("grid_cols", grid_cols);
    a("grid_rows", grid_rows);
    a("fast_threshold", fast_threshold);
    a("scale_factor", scale_factor);
    a("pyramid_levels", pyramid_levels);
    a("edge_threshold_px", edge_threshold_px);
  }

  // Throws std::invalid_argument naming the field and value.
  void validate() const;
};

struct Features {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;  // one 32-byte ORB row per keypoint
};

class FeatureDetector {
 public:
  explicit FeatureDetector(const FeatureConfig& config);
  // `gray` is CV_8UC1. Each grid cell keeps its strongest keypoints up to an equal share of
  // max_features; budget a cell cannot use goes to the strongest keypoints left anywhere.
  Features detect(const cv::Mat& gray) const;

 private:
  FeatureConfig config_;
  cv::Ptr<cv::ORB> orb_;
};

}  // namespace tgnav::vo
