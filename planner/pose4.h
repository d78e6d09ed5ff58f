#pragma once
// 4-DoF pose of the MAV: position of body B in world W (z up) and yaw about z_W.
#include <Eigen/Core>

namespace tgnav::planner {

struct Pose4 {
  Eigen::Vector3d p_WB = Eigen::Vector3d::Zero();
  double yaw_rad = 0.0;
};

}  // namespace tgnav::planner
