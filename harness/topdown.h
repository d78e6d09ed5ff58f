#pragma once
// Top-down picture of a feature map: occupancy in a height band around the flight height
// (dark: occupied, light: observed free, white: unknown) with landmark density on top.
#include <opencv2/core.hpp>

#include "harness/scene_config.h"
#include "planner/feature_map.h"

namespace tgnav::harness {

class Topdown {
 public:
  Topdown(const SceneConfig& scene, double metres_per_px);
  // Occupancy in [flight height - band, flight height + band], then landmark density.
  void drawMap(const planner::FeatureMap& map, double band_m);
  // Start (green) and goal (red) markers.
  void drawStartGoal();
  cv::Point toPixel(const Eigen::Vector2d& p_W) const;
  const cv::Mat& image() const { return image_; }

 private:
  SceneConfig scene_;
  double m_per_px_;
  cv::Mat image_;  // BGR
};

}  // namespace tgnav::harness
