#include "harness/topdown.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace tgnav::harness {

Topdown::Topdown(const SceneConfig& scene, double metres_per_px) : scene_(scene), m_per_px_(metres_per_px) {
  const Eigen::Vector3d extent = scene.bounds_max_m - scene.bounds_min_m;
  image_ = cv::Mat(static_cast<int>(std::ceil(extent.y() / m_per_px_)),
                   static_cast<int>(std::ceil(extent.x() / m_per_px_)), CV_8UC3, cv::Scalar(255, 255, 255));
}

cv::Point Topdown::toPixel(const Eigen::Vector2d& p) const {
  // North (+y) up.
  return cv::Point(static_cast<int>((p.x() - scene_.bounds_min_m.x()) / m_per_px_),
                   static_cast<int>((scene_.bounds_max_m.y() - p.y()) / m_per_px_));
}

void Topdown::drawMap(const planner::FeatureMap& map, double band_m) {
  const octomap::OcTree& tree = map.occupancy();
  const double z_lo = scene_.flight_height_m - band_m;
  const double z_hi = scene_.flight_height_m + band_m;
  cv::Mat occupied(image_.size(), CV_8UC1, cv::Scalar(0));
  cv::Mat free(image_.size(), CV_8UC1, cv::Scalar(0));
  const octomap::point3d lo(scene_.bounds_min_m.x(), scene_.bounds_min_m.y(), z_lo);
  const octomap::point3d hi(scene_.bounds_max_m.x(), scene_.bounds_max_m.y(), z_hi);
  for (auto it = tree.begin_leafs_bbx(lo, hi), end = tree.end_leafs_bbx(); it != end; ++it) {
    const double half = 0.5 * it.getSize();
    const cv::Point a = toPixel({it.getX() - half, it.getY() + half});
    const cv::Point b = toPixel({it.getX() + half, it.getY() - half});
    cv::rectangle(tree.isNodeOccupied(*it) ? occupied : free, a, b - cv::Point(1, 1), cv::Scalar(255), cv::FILLED);
  }
  image_.setTo(cv::Scalar(225, 225, 225), free);
  image_.setTo(cv::Scalar(60, 60, 60), occupied);

  // Landmark density: count per pixel, blurred over 5 cm, log-scaled, drawn where there are any.
  cv::Mat counts(image_.size(), CV_32FC1, cv::Scalar(0));
  for (int i = 0; i < static_cast<int>(map.landmarks().size()); ++i) {
    const cv::Point p = toPixel(map.landmarkVoxel(i).head<2>());
    if (p.x >= 0 && p.y >= 0 && p.x < counts.cols && p.y < counts.rows) counts.at<float>(p) += 1.0f;
  }
  cv::Mat density;
  cv::GaussianBlur(counts, density, cv::Size(0, 0), std::max(1.0, 0.05 / m_per_px_));
  double max_density = 0.0;
  cv::minMaxLoc(density, nullptr, &max_density);
  if (max_density <= 0.0) return;
  cv::Mat scaled;
  cv::log(density + 1.0f, scaled);
  scaled.convertTo(scaled, CV_8UC1, 255.0 / std::log(max_density + 1.0));
  cv::Mat colours;
  cv::applyColorMap(scaled, colours, cv::COLORMAP_INFERNO);
  colours.copyTo(image_, density > 0.05f);
}

void Topdown::drawStartGoal() {
  const int r = std::max(3, static_cast<int>(0.2 / m_per_px_));
  cv::circle(image_, toPixel(scene_.start.p_WB.head<2>()), r, cv::Scalar(0, 170, 0), cv::FILLED);
  cv::circle(image_, toPixel(scene_.goal.p_WB.head<2>()), r, cv::Scalar(0, 0, 220), cv::FILLED);
}

}  // namespace tgnav::harness
