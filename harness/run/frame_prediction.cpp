#include "harness/run/frame_prediction.h"

#include <cmath>

namespace tgnav::harness {

FramePrediction predictFrame(const planner::VoxelMap& voxels, const Eigen::Isometry3d& X_WC,
                             const planner::VisibilityConfig& visibility,
                             const planner::InformationConfig& information) {
  const Eigen::Vector3d p = X_WC.translation();
  const Eigen::Vector3d forward = X_WC.linear().col(2);
  const double yaw = std::atan2(forward.y(), forward.x());
  const std::vector<planner::WeightedPoint> points =
      planner::aggregateByVoxel(voxels, voxels.visibleFrom(p, visibility));
  planner::ViewSupport support;
  const planner::Matrix6d info = planner::poseInformation(p, yaw, points, visibility, information, &support);
  FramePrediction out;
  out.score = planner::scoreInformation(info, support, information);
  out.landmarks = static_cast<int>(support.landmarks);
  out.detections = support.detections;
  out.coverage = support.coverage();
  return out;
}

}  // namespace tgnav::harness
