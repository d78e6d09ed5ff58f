#pragma once
// Local bundle adjustment over a window of keyframes: the keyframes' poses and the landmarks
// they observe are refined together, ORB-SLAM2's local BA for an RGB-D camera. Two solvers of the
// same least-squares problem (BundleAdjustmentConfig::solver): Levenberg-Marquardt on the Schur
// complement written for it (vo/ba_schur.cpp, the default), and Ceres's DENSE_SCHUR, the
// reference; the first follows Ceres's trust-region rules and takes the same steps to rounding
// (tests/vo/bundle_adjustment_test.cpp: SchurSolverAgreesWithCeres), at about a third of the CPU.
//
// Each observation of landmark p_W by keyframe k contributes the reprojection residual
//   ((u, v) - pi(X_CW_k p_W)) / sigma,   sigma = scale_factor^octave
// (a keypoint found on a coarser pyramid level is located less precisely) and, when the keypoint
// had a depth z_obs, a disparity residual
//   (bf / z - bf / z_obs) / depth_sigma_px,   bf = fx * virtual_baseline_m,
// with z the landmark's depth in keyframe k: ORB-SLAM2's virtual-stereo coordinate
// u_R = u - bf / z less its u part, so that depth noise and keypoint localisation have sigmas of
// their own. Depth noise sigma_z = k z^2 (structured light, stereo) is a constant disparity noise
// bf k; ORB-SLAM2 gives u_R the keypoint's sigma (depth_sigma_px = 1 at octave 0).
// The residuals pass through a Cauchy loss of scale sqrt(5.991) for 2 residuals, sqrt(7.815) for
// 3 (the chi-square 95 % points ORB-SLAM2 uses). ORB-SLAM2 uses Huber; a mismatch 40 px off still
// pulls its landmark with Huber's constant gradient far enough that the landmark's good
// observations fail the test too (BundleAdjustment.FlagsGrossOutliersAndIgnoresThem: 14 false
// alarms for 17 mismatches), Cauchy's redescending influence does not (none). Fixed keyframes
// are the gauge (with depth the scale is observable, so one fixed keyframe suffices).
//
// After the optimisation (robust_iterations) an observation whose weighted squared residual
// exceeds the chi-square point (or whose landmark lies behind the camera) is an outlier; the
// problem is solved again (max_iterations) without the outliers and without the robust loss, and
// the outliers are those of that final solution (an observation a mismatch had pulled off during
// the first pass comes back). Jacobians are analytic. A landmark observed once cannot inform a
// pose (it fits its observation exactly): it is left out of the solver and placed on its
// observation from the adjusted pose afterwards, which is where the solver would put it.
// Deterministic: one thread, a fixed ordering (landmarks eliminated first, Schur complement on
// the poses), with either solver.
#include <Eigen/Geometry>
#include <string>
#include <utility>
#include <vector>

#include "vo/camera_intrinsics.h"

namespace tgnav::vo {

// The solver: `schur`, Levenberg-Marquardt on the Schur complement written for this problem
// (landmarks of 3 parameters eliminated, the poses' reduced system solved dense, Eigen's
// fixed-size blocks), after Ceres's trust-region rules; `ceres`, Ceres's DENSE_SCHUR, the
// reference it is tested against (its eliminator runs with dynamic block sizes here: rows of 2
// and 3 residuals mixed, which none of its compiled specialisations covers).
enum class BaSolver { kSchur, kCeres };
inline std::vector<std::pair<std::string, BaSolver>> baSolverNames() {
  return {{"schur", BaSolver::kSchur}, {"ceres", BaSolver::kCeres}};
}

struct BundleAdjustmentConfig {
  bool enabled = true;  // false: no BA (frame-to-map PnP only), for ablations
  BaSolver solver = BaSolver::kSchur;
  double virtual_baseline_m = 0.08;  // bf = fx * this, for the depth residual (ORB-SLAM2's)
  double depth_sigma_px = 0.1;       // sigma of the disparity bf / z, pixels: bf k for depth
                                     // noise k z^2 (a RealSense D435, k = 0.002, at fx 416,
                                     // 640x480 with fovy 60 deg: 0.07)
  int robust_iterations = 5;         // Levenberg-Marquardt iterations of the robust pass and
  int max_iterations = 10;           // of the final pass (ORB-SLAM2's local BA: 5 and 10)
  int fixed_keyframes = 20;          // RgbdOdometry: the last keyframes that left the local map,
                                     // held fixed in the window (the gauge)
  int latency_frames = 0;            // RgbdOdometry: 0 adjusts at the keyframe; L > 0 solves on a
                                     // thread of its own and applies the result L frames later
  int every_keyframes = 3;           // RgbdOdometry: adjust at every N-th keyframe (with N up to
                                     // local_map_keyframes the window holds the N new ones)

  template <typename Archive>
  void visit(Archive& a) {
    a("enabled", enabled);
    a.choice("solver", solver, baSolverNames());
    a("virtual_baseline_m", virtual_baseline_m);
    a("depth_sigma_px", depth_sigma_px);
    a("robust_iterations", robust_iterations);
    a("max_iterations", max_iterations);
    a("fixed_keyframes", fixed_keyframes);
    a("latency_frames", latency_frames);
    a("every_keyframes", every_keyframes);
  }

  void validate() const;  // std::invalid_argument naming the field (within ba) and value
};

struct BaObservation {
  int keyframe = 0;  // index into BaProblem::X_CW
  int landmark = 0;  // index into BaProblem::p_W
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  double depth_m = 0.0;   // <= 0 or non-finite: no depth (reprojection only)
  double sigma_px = 1.0;  // the keypoint's scale (scale_factor^octave)
};

struct BaProblem {
  std::vector<Eigen::Isometry3d> X_CW;  // per keyframe, optimised in place
  std::vector<bool> fixed;              // per keyframe
  std::vector<Eigen::Vector3d> p_W;     // per landmark, optimised in place
  std::vector<BaObservation> observations;
};

struct BaReport {
  bool solved = false;  // false: nothing to optimise (no free keyframe or no observation)
  int observations = 0;
  std::vector<bool> outlier;  // per observation
  int outliers = 0;
  double initial_cost = 0.0;  // Ceres's cost (1/2 sum of robustified squared residuals)
  double final_cost = 0.0;
  int iterations = 0;  // both passes
};

// Optimises `problem` in place; std::invalid_argument for indices out of range or sizes that do
// not agree.
BaReport bundleAdjust(BaProblem* problem, const CameraIntrinsics& camera, const BundleAdjustmentConfig& config);

// One observation's weighted residuals, as the optimiser sees them: (u, v) and, with depth, the
// disparity (the returned count, 2 or 3, says how many rows are used), with their analytic
// Jacobians by the pose parameters (angle-axis of R_CW, then t_CW) and by p_W. For the tests,
// which check the Jacobians against finite differences.
int observationResiduals(const CameraIntrinsics& camera, const BaObservation& observation,
                         const BundleAdjustmentConfig& config, const Eigen::Matrix<double, 6, 1>& pose,
                         const Eigen::Vector3d& p_W, Eigen::Vector3d* residual, Eigen::Matrix<double, 3, 6>* J_pose,
                         Eigen::Matrix3d* J_point);

}  // namespace tgnav::vo
