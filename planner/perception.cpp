#include "planner/perception.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "planner/check.h"

namespace tgnav::planner {

void InformationConfig::validate() const {
  require(bearing_noise_rad > 0.0, "bearing_noise_rad", bearing_noise_rad, "must be > 0");
  require(epsilon > 0.0, "information_epsilon", epsilon, "must be > 0");
  require(max_incidence_rad > 0.0 && max_incidence_rad <= M_PI / 2.0, "max_incidence_rad", max_incidence_rad,
          "must be in (0, pi/2]");
  require(min_landmarks >= 0.0 && std::isfinite(min_landmarks), "min_landmarks", min_landmarks,
          "must be finite and >= 0");
  require(min_image_coverage >= 0.0 && min_image_coverage <= 1.0, "min_image_coverage", min_image_coverage,
          "must be in [0, 1]");
  require(min_detections >= 0.0 && std::isfinite(min_detections), "min_detections", min_detections,
          "must be finite and >= 0");
  require(min_track_probability > 0.0 && min_track_probability < 1.0, "min_track_probability", min_track_probability,
          "must be in (0, 1)");
}

double ViewSupport::coverage() const {
  return static_cast<double>(__builtin_popcountll(cells)) / (kImageCols * kImageRows);
}

double ViewSupport::columnSpan() const {
  std::uint64_t rows_or = 0;  // bit col: some row holds a cell in that column
  for (int r = 0; r < kImageRows; ++r) rows_or |= (cells >> (r * kImageCols)) & ((std::uint64_t{1} << kImageCols) - 1);
  return static_cast<double>(__builtin_popcountll(rows_or)) / kImageCols;
}

double ViewSupport::rowSpan() const {
  int rows = 0;
  for (int r = 0; r < kImageRows; ++r) {
    rows += ((cells >> (r * kImageCols)) & ((std::uint64_t{1} << kImageCols) - 1)) != 0;
  }
  return static_cast<double>(rows) / kImageRows;
}

double ViewSupport::meanRangeM() const { return detections > 0.0 ? range_detections / detections : 0.0; }

ImageCells::ImageCells(double yaw_rad, const VisibilityConfig& visibility)
    : cos_yaw_(std::cos(yaw_rad)),
      sin_yaw_(std::sin(yaw_rad)),
      tan_half_hfov_(std::tan(0.5 * visibility.hfov_rad)),
      tan_half_vfov_(std::tan(0.5 * visibility.vfov_rad)) {}

int ImageCells::operator()(const Eigen::Vector3d& p_W, const Eigen::Vector3d& l_W) const {
  const Eigen::Vector3d d = l_W - p_W;
  const double forward = cos_yaw_ * d.x() + sin_yaw_ * d.y();
  const double left = -sin_yaw_ * d.x() + cos_yaw_ * d.y();
  if (forward <= 0.0) return -1;
  const double u = -left / forward / tan_half_hfov_;   // -1 left edge, +1 right
  const double v = -d.z() / forward / tan_half_vfov_;  // -1 top, +1 bottom
  const int col = std::clamp(static_cast<int>(std::floor(0.5 * (u + 1.0) * kImageCols)), 0, kImageCols - 1);
  const int row = std::clamp(static_cast<int>(std::floor(0.5 * (v + 1.0) * kImageRows)), 0, kImageRows - 1);
  return row * kImageCols + col;
}

bool ImageCells::inner(const Eigen::Vector3d& p_W, const Eigen::Vector3d& l_W) const {
  const Eigen::Vector3d d = l_W - p_W;
  const double forward = cos_yaw_ * d.x() + sin_yaw_ * d.y();
  if (forward <= 0.0) return false;
  const double left = -sin_yaw_ * d.x() + cos_yaw_ * d.y();
  const double limit = (1.0 - kImageBorderShare) * forward;
  return std::abs(left) <= limit * tan_half_hfov_ && std::abs(d.z()) <= limit * tan_half_vfov_;
}

int imageCell(const Eigen::Vector3d& p_W, double yaw_rad, const Eigen::Vector3d& l_W,
              const VisibilityConfig& visibility) {
  return ImageCells(yaw_rad, visibility)(p_W, l_W);
}

bool withinIncidence(const Eigen::Vector3d& p_W, const WeightedPoint& point, const InformationConfig& config) {
  if (config.max_incidence_rad >= M_PI / 2.0 || point.normal_W.isZero()) return true;
  const Eigen::Vector3d to_camera = p_W - point.p_W;
  const double range = to_camera.norm();
  return range > 0.0 && point.normal_W.dot(to_camera) >= std::cos(config.max_incidence_rad) * range;
}

double scoreInformation(const Matrix6d& info, const ViewSupport& support, const InformationConfig& config) {
  if (config.model) {
    const bool blind = config.model->probability(support) < config.min_track_probability;
    return logDetInformation(blind ? Matrix6d::Zero() : info, config.epsilon);
  }
  const bool blind = support.landmarks < config.min_landmarks || support.detections < config.min_detections ||
                     (config.min_image_coverage > 0.0 && support.coverage() < config.min_image_coverage);
  return blind ? logDetInformation(Matrix6d::Zero(), config.epsilon) : logDetInformation(info, config.epsilon);
}

double gateShortfall(const ViewSupport& support, const InformationConfig& config) {
  if (config.model) {
    const double p = config.model->probability(support);
    return p < config.min_track_probability ? 1.0 - p / config.min_track_probability : 0.0;
  }
  double least = 1.0;  // the smallest share of a gate's threshold reached
  if (support.landmarks < config.min_landmarks) least = std::min(least, support.landmarks / config.min_landmarks);
  if (support.detections < config.min_detections) {
    least = std::min(least, support.detections / config.min_detections);
  }
  if (config.min_image_coverage > 0.0 && support.coverage() < config.min_image_coverage) {
    least = std::min(least, support.coverage() / config.min_image_coverage);
  }
  return 1.0 - std::max(0.0, least);
}

double rankedScore(double score, const ViewSupport& support, const InformationConfig& config) {
  const double blind = logDetInformation(Matrix6d::Zero(), config.epsilon);
  return score - std::max(1.0, std::abs(blind)) * gateShortfall(support, config);
}

std::vector<WeightedPoint> aggregateByVoxel(const VoxelMap& voxels, const std::vector<int>& ids) {
  std::vector<std::pair<int, int>> keyed;  // (slot, id), grouped by slot below in ids' order
  keyed.reserve(ids.size());
  for (int id : ids) {
    const int slot = voxels.landmarkSlot(id);
    if (slot >= 0) keyed.emplace_back(slot, id);
  }
  std::stable_sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<WeightedPoint> points;
  for (std::size_t i = 0; i < keyed.size();) {
    const int slot = keyed[i].first;
    int n = 0;
    double detections = 0.0;
    for (; i < keyed.size() && keyed[i].first == slot; ++i) {
      ++n;
      detections += voxels.detectability(keyed[i].second);
    }
    const LandmarkVoxel& v = voxels.landmarkVoxels()[static_cast<std::size_t>(slot)];
    points.push_back({v.mean_W, static_cast<double>(n), v.normal_W, detections});
  }
  return points;
}

std::vector<WeightedPoint> aggregateSlots(const VoxelMap& voxels, const std::vector<int>& slots) {
  std::vector<WeightedPoint> points;
  points.reserve(slots.size());
  for (int slot : slots) {
    const LandmarkVoxel& v = voxels.landmarkVoxels().at(static_cast<std::size_t>(slot));
    points.push_back({v.mean_W, static_cast<double>(v.ids.size()), v.normal_W, v.detections});
  }
  return points;
}

namespace {

// The horizontal test of inFieldOfView(): the bearing of d off yaw_rad within half the FoV.
bool bearingWithin(const Eigen::Vector3d& d, double yaw_rad, const VisibilityConfig& visibility) {
  const double bearing = std::remainder(std::atan2(d.y(), d.x()) - yaw_rad, 2.0 * M_PI);
  return std::abs(bearing) <= 0.5 * visibility.hfov_rad;
}

}  // namespace

bool inFieldOfView(const Eigen::Vector3d& p_W, double yaw_rad, const Eigen::Vector3d& l_W,
                   const VisibilityConfig& visibility) {
  const Eigen::Vector3d d = l_W - p_W;
  const double range = d.norm();
  if (range < visibility.min_range_m || range > visibility.max_range_m) return false;
  const double horizontal = d.head<2>().norm();
  if (std::atan2(std::abs(d.z()), horizontal) > 0.5 * visibility.vfov_rad) return false;
  return bearingWithin(d, yaw_rad, visibility);
}

FieldOfView::FieldOfView(double yaw_rad, const VisibilityConfig& visibility)
    : yaw_rad_(yaw_rad),
      visibility_(&visibility),
      cos_yaw_(std::cos(yaw_rad)),
      sin_yaw_(std::sin(yaw_rad)),
      tan_half_hfov_(std::tan(0.5 * visibility.hfov_rad)),
      tan_half_vfov_(std::tan(0.5 * visibility.vfov_rad)),
      shortcuts_(visibility.vfov_rad > 0.0 && visibility.vfov_rad < M_PI && visibility.hfov_rad > 0.0 &&
                 visibility.hfov_rad < M_PI) {}

bool FieldOfView::operator()(const Eigen::Vector3d& p_W, const Eigen::Vector3d& l_W) const {
  const VisibilityConfig& visibility = *visibility_;
  const Eigen::Vector3d d = l_W - p_W;
  const double range = d.norm();
  if (range < visibility.min_range_m || range > visibility.max_range_m) return false;
  const double horizontal = d.head<2>().norm();
  if (!shortcuts_) return inFieldOfView(p_W, yaw_rad_, l_W, visibility);
  if (!withinHalfAngle(std::abs(d.z()), horizontal, 0.5 * visibility.vfov_rad, tan_half_vfov_)) return false;
  // |left| <= tan(hfov / 2) forward is the bearing test in the yaw's frame; it is off the
  // arctangent's answer only within a rounding error of the edge, which the margin holds.
  const double forward = cos_yaw_ * d.x() + sin_yaw_ * d.y();
  const double left = std::abs(cos_yaw_ * d.y() - sin_yaw_ * d.x());
  const double edge = tan_half_hfov_ * forward;
  const double margin = 1e-9 * horizontal;
  if (left < edge - margin) return true;
  if (left > edge + margin) return false;
  return bearingWithin(d, yaw_rad_, visibility);
}

Matrix6d poseInformation(const Eigen::Vector3d& p_W, double yaw_rad, const std::vector<WeightedPoint>& points,
                         const VisibilityConfig& visibility, const InformationConfig& config, ViewSupport* support) {
  Matrix6d info = Matrix6d::Zero();
  ViewSupport view;
  const ImageCells cell(yaw_rad, visibility);
  const FieldOfView in_view(yaw_rad, visibility);
  for (const WeightedPoint& pt : points) {
    if (in_view(p_W, pt.p_W) && withinIncidence(p_W, pt, config)) {
      addCentredInformation(p_W, pt.p_W, pt.weight, config.bearing_noise_rad, &info);
      view.add(pt, (pt.p_W - p_W).norm(), cell(p_W, pt.p_W), cell.inner(p_W, pt.p_W));
    }
  }
  if (support != nullptr) *support = view;
  return info;
}

double poseScore(const Eigen::Vector3d& p_W, double yaw_rad, const std::vector<WeightedPoint>& points,
                 const VisibilityConfig& visibility, const InformationConfig& config) {
  ViewSupport support;
  const Matrix6d info = poseInformation(p_W, yaw_rad, points, visibility, config, &support);
  return scoreInformation(info, support, config);
}

}  // namespace tgnav::planner
