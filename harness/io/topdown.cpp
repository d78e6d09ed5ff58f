#include "harness/io/topdown.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "harness/io/staged_output.h"

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

MapLayer Topdown::layer(const std::string& title) const {
  MapLayer l;
  l.image = image_;
  l.extent_m[0] = scene_.bounds_min_m.x();
  l.extent_m[1] = scene_.bounds_min_m.x() + image_.cols * m_per_px_;
  l.extent_m[2] = scene_.bounds_max_m.y() - image_.rows * m_per_px_;
  l.extent_m[3] = scene_.bounds_max_m.y();
  l.start_xy = scene_.start.p_WB.head<2>();
  l.goal_xy = scene_.goal.p_WB.head<2>();
  l.title = title;
  l.legend = {{"occupied", cv::Vec3b(60, 60, 60)},
              {"free (observed)", cv::Vec3b(225, 225, 225)},
              {"unknown", cv::Vec3b(255, 255, 255)},
              {"landmark density", cv::Vec3b(188, 55, 84)}};
  return l;
}

MapLayer sceneMapLayer(const SceneConfig& scene, const planner::FeatureMap& map, double band_m, double pixels_across) {
  Topdown topdown(scene, (scene.bounds_max_m.x() - scene.bounds_min_m.x()) / pixels_across);
  topdown.drawMap(map, band_m);
  return topdown.layer(scene.source.stem().string());
}

void writeMapLayer(const std::filesystem::path& dir, const MapLayer& layer) {
  auto xy = [](const std::optional<Eigen::Vector2d>& p) {
    return p ? nlohmann::json::array({p->x(), p->y()}) : nlohmann::json(nullptr);
  };
  nlohmann::ordered_json j;
  j["extent_m"] = {layer.extent_m[0], layer.extent_m[1], layer.extent_m[2], layer.extent_m[3]};
  j["start_xy"] = xy(layer.start_xy);
  j["goal_xy"] = xy(layer.goal_xy);
  j["title"] = layer.title;
  j["legend"] = nlohmann::json::array();
  for (const auto& [label, rgb] : layer.legend) {
    j["legend"].push_back({{"label", label}, {"rgb", {rgb[0], rgb[1], rgb[2]}}});
  }
  writeImageAtomic(dir / "map.png", layer.image);
  writeFileAtomic(dir / "map.json", j.dump(2) + "\n");
}

}  // namespace tgnav::harness
