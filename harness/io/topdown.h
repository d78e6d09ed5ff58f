#pragma once
// Top-down picture of a feature map: occupancy in a height band around the flight height
// (dark: occupied, light: observed free, white: unknown) with landmark density on top.
#include <Eigen/Core>
#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "harness/config/scene_config.h"
#include "planner/feature_map.h"

namespace tgnav::harness {

// The background of the top-down figures (scripts/tgnav_plots.py): a raster, north up, whose
// outer pixel edges span extent_m = {x_min, x_max, y_min, y_max} in the world frame.
struct MapLayer {
  cv::Mat image;  // BGR
  double extent_m[4] = {0.0, 0.0, 0.0, 0.0};
  std::optional<Eigen::Vector2d> start_xy;
  std::optional<Eigen::Vector2d> goal_xy;
  std::string title;
  // What the raster's colours mean (RGB, 0-255), for the figure's legend.
  std::vector<std::pair<std::string, cv::Vec3b>> legend;
};
// The feature map of `scene` in a band of +-band_m about its flight height, `pixels_across` wide,
// titled with the scene's name: what the top-down figures of map, plan and trial lie on.
MapLayer sceneMapLayer(const SceneConfig& scene, const planner::FeatureMap& map, double band_m,
                       double pixels_across = 800.0);
// Writes map.png and map.json into `dir`.
void writeMapLayer(const std::filesystem::path& dir, const MapLayer& layer);

class Topdown {
 public:
  Topdown(const SceneConfig& scene, double metres_per_px);
  // Occupancy in [flight height - band, flight height + band], then landmark density.
  void drawMap(const planner::FeatureMap& map, double band_m);
  // The picture as a figure background, with the scene's start and goal.
  MapLayer layer(const std::string& title) const;
  cv::Point toPixel(const Eigen::Vector2d& p_W) const;
  const cv::Mat& image() const { return image_; }

 private:
  SceneConfig scene_;
  double m_per_px_;
  cv::Mat image_;  // BGR
};

}  // namespace tgnav::harness
