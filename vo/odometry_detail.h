#pragma once
// Helpers shared by the odometry's source files (vo/odometry.cpp, vo/local_map.cpp); not an API.
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <cstring>
#include <future>
#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "vo/bundle_adjustment.h"
#include "vo/odometry.h"

namespace tgnav::vo {

// The local map's landmarks matched to a frame's keypoints, and the 2D-3D correspondences.
struct RgbdOdometry::LocalMapMatches {
  std::vector<int> landmark_of;     // keypoint -> landmark (-1: none)
  std::vector<bool> expected;       // landmark -> projects into the image from the prediction
  std::vector<cv::Point3d> object;  // landmark positions, in keypoint order
  std::vector<cv::Point2d> pixels;  // their keypoints' pixels
  std::vector<int> keypoint;        // correspondence -> keypoint
  std::vector<double> depth_m;      // its keypoint's measured depth (0: none)
};

struct RgbdOdometry::PoseEstimate {
  bool ransac_ok = false;  // PnP RANSAC found a pose with at least min_inliers inliers
  int ransac_inliers = 0;
  int inliers = -1;  // of the refined pose among all correspondences (-1: non-finite pose)
  Eigen::Isometry3d X_CW = Eigen::Isometry3d::Identity();
  std::vector<bool> is_inlier;  // per correspondence
};

// One try at the frame's pose: its matches and the pose they give.
struct RgbdOdometry::Attempt {
  LocalMapMatches matches;
  PoseEstimate pose;
  // Whether it tracks: enough matches, RANSAC's pose, and enough inliers of the refined one.
  bool tracks(int min_inliers) const {
    return static_cast<int>(matches.object.size()) >= min_inliers && pose.ransac_ok && pose.inliers >= min_inliers;
  }
};

// A local bundle adjustment: the window as it was copied, the problem solved on it, and where
// its parts came from, so that the solution can be applied to the map by ids later.
struct RgbdOdometry::BaJob {
  BaProblem problem;
  std::size_t fixed = 0;                    // the window's first `fixed` keyframes are the gauge
  std::vector<int> keyframe_ids;            // window keyframe -> Keyframe::id
  std::vector<int> landmark_index;          // problem landmark -> index into landmarks_ at the copy
  std::vector<long> landmark_ids;           // problem landmark -> Landmark::id
  std::vector<std::pair<int, int>> source;  // problem observation -> (window keyframe, its observation)
  Eigen::Isometry3d newest_before;          // the newest keyframe's pose at the copy
  long next_landmark_id = 0;                // landmarks from this id on were added after the copy
  long copied_at = 0;                       // the frame it was copied at
  long apply_at = 0;                        // the frame it is applied at, before tracking it
  BaReport report;
  double solve_cpu_s = 0.0;   // the solve's CPU seconds, on the thread that ran it
  std::future<void> solving;  // the solve on its own thread (declared last: waited for first)
};

namespace detail {

inline double rotationAngle(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle(); }

// Row `row` of an ORB descriptor matrix (32 bytes) as four 64-bit words.
inline std::array<std::uint64_t, 4> descriptorBits(const cv::Mat& descriptors, int row) {
  std::array<std::uint64_t, 4> bits{};
  std::memcpy(bits.data(), descriptors.ptr<std::uint8_t>(row), sizeof(bits));
  return bits;
}

}  // namespace detail
}  // namespace tgnav::vo
