#pragma once
// TUM RGB-D trajectory text: "timestamp tx ty tz qx qy qz qw" per line, '#' comments, the pose
// of the camera in the world (the format evo and the TUM benchmark tools read).
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace tgnav::vo {

struct StampedPose {
  double t_s = 0.0;
  Eigen::Isometry3d X_WC = Eigen::Isometry3d::Identity();
};

std::string toTum(const std::vector<StampedPose>& poses);
// Throws std::invalid_argument naming the line for malformed input.
std::vector<StampedPose> parseTum(const std::string& text);

}  // namespace tgnav::vo
