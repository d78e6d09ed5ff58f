#include "planner/perception.h"

#include <cmath>
#include <map>

#include "planner/check.h"

namespace tgnav::planner {

void InformationConfig::validate() const {
  require(bearing_noise_rad > 0.0, "bearing_noise_rad", bearing_noise_rad, "must be > 0");
  require(epsilon > 0.0, "information_epsilon", epsilon, "must be > 0");
  require(max_incidence_rad > 0.0 && max_incidence_rad <= M_PI / 2.0, "max_incidence_rad", max_incidence_rad,
          "must be in (0, pi/2]");
  require(min_landmarks >= 0.0 && std::isfinite(min_landmarks), "min_landmarks", min_landmarks,
          "must be finite and >= 0");
}

bool withinIncidence(const Eigen::Vector3d& p_W, const WeightedPoint& point, const InformationConfig& config) {
  if (config.max_incidence_rad >= M_PI / 2.0 || point.normal_W.isZero()) return true;
  const Eigen::Vector3d to_camera = p_W - point.p_W;
  const double range = to_camera.norm();
  return range > 0.0 && point.normal_W.dot(to_camera) >= std::cos(config.max_incidence_rad) * range;
}

double scoreInformation(const Matrix6d& info, double landmarks, const InformationConfig& config) {
  return landmarks < config.min_landmarks ? logDetInformation(Matrix6d::Zero(), config.epsilon)
                                          : logDetInformation(info, config.epsilon);
}

std::vector<WeightedPoint> aggregateByVoxel(const VoxelMap& voxels, const std::vector<int>& ids) {
  std::map<int, int> count;
  for (int id : ids) {
    const int slot = voxels.landmarkSlot(id);
    if (slot >= 0) ++count[slot];
  }
  std::vector<WeightedPoint> points;
  points.reserve(count.size());
  for (const auto& [slot, n] : count) {
    const LandmarkVoxel& v = voxels.landmarkVoxels()[static_cast<std::size_t>(slot)];
    points.push_back({v.mean_W, static_cast<double>(n), v.normal_W});
  }
  return points;
}

bool inFieldOfView(const Eigen::Vector3d& p_W, double yaw_rad, const Eigen::Vector3d& l_W,
                   const VisibilityConfig& visibility) {
  const Eigen::Vector3d d = l_W - p_W;
  const double range = d.norm();
  if (range < visibility.min_range_m || range > visibility.max_range_m) return false;
  const double horizontal = d.head<2>().norm();
  if (std::atan2(std::abs(d.z()), horizontal) > 0.5 * visibility.vfov_rad) return false;
  const double bearing = std::remainder(std::atan2(d.y(), d.x()) - yaw_rad, 2.0 * M_PI);
  return std::abs(bearing) <= 0.5 * visibility.hfov_rad;
}

Matrix6d poseInformation(const Eigen::Vector3d& p_W, double yaw_rad, const std::vector<WeightedPoint>& points,
                         const VisibilityConfig& visibility, const InformationConfig& config, double* landmarks) {
  Matrix6d info = Matrix6d::Zero();
  double count = 0.0;
  for (const WeightedPoint& pt : points) {
    if (inFieldOfView(p_W, yaw_rad, pt.p_W, visibility) && withinIncidence(p_W, pt, config)) {
      addCentredInformation(p_W, pt.p_W, pt.weight, config.bearing_noise_rad, &info);
      count += pt.weight;
    }
  }
  if (landmarks != nullptr) *landmarks = count;
  return info;
}

double poseScore(const Eigen::Vector3d& p_W, double yaw_rad, const std::vector<WeightedPoint>& points,
                 const VisibilityConfig& visibility, const InformationConfig& config) {
  double landmarks = 0.0;
  const Matrix6d info = poseInformation(p_W, yaw_rad, points, visibility, config, &landmarks);
  return scoreInformation(info, landmarks, config);
}

}  // namespace tgnav::planner
