#pragma once
// The pose of a calibrated pinhole camera from 3D-2D correspondences: Levenberg-Marquardt on the
// reprojection error, from a start. The same least-squares problem as cv::solvePnPRefineLM
// (tests/vo/pose_refine_test.cpp compares the two), with analytic Jacobians, fixed-size blocks and
// no allocation per iteration: the VO refines each frame's pose twice, and OpenCV's version, which
// projects the points through cv::projectPoints at every iteration, cost a tenth of a trial's CPU.
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <vector>

#include "vo/camera_intrinsics.h"

namespace tgnav::vo {

struct PoseRefinement {
  bool ok = false;      // a finite pose (false: fewer than 3 correspondences, or a failure)
  int iterations = 0;   // linearisations
  double rms_px = 0.0;  // reprojection error at the result (pixels only)
};

// The points' depths measured in the frame (an RGB-D camera's), for the disparity residual
// (bf / z - bf / z_obs) / depth_sigma_px of each point with one: the bundle adjustment's
// (vo/bundle_adjustment.h), and ORB-SLAM2's motion-only BA for RGB-D (its virtual right
// coordinate). Reprojection alone leaves a pose of points spread over little of the image free to
// slide along the optical axis; the depths hold it.
struct PoseDepth {
  const std::vector<double>* depth_m = nullptr;  // per point, metres; <= 0 or not finite: none
  double bf_px = 0.0;                            // fx times the virtual baseline
  double depth_sigma_px = 1.0;
};

// Minimises sum |pi(X_CW p_W) - uv|^2 over X_CW, from *X_CW; pi projects with `camera`'s fx, fy,
// cx, cy (no distortion); with `depth`, plus the disparity residuals squared. Stops when a step
// changes the pose by less than 1e-10 (relative), the cost by less than 1e-14 of itself, or after
// max_iterations. Leaves *X_CW as it was when !ok.
PoseRefinement refinePoseLm(const std::vector<cv::Point3d>& p_W, const std::vector<cv::Point2d>& uv,
                            const CameraIntrinsics& camera, Eigen::Isometry3d* X_CW, int max_iterations = 20,
                            const PoseDepth& depth = {});

}  // namespace tgnav::vo
