#pragma once
// Trajectory error metrics (pure functions), as the TUM RGB-D benchmark and evo compute them:
// association by timestamp, SE(3) Umeyama alignment, ATE (aligned, or anchored at the first
// pose), RPE per distance travelled, goal error.
#include <Eigen/Geometry>
#include <vector>

#include "vo/tum.h"

namespace tgnav::vo {

struct PosePair {
  double t_s = 0.0;
  Eigen::Isometry3d X_WC_est = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d X_WC_gt = Eigen::Isometry3d::Identity();
};

// For each estimate, the ground-truth pose nearest in time within max_dt_s (estimates without
// one are skipped); time order. std::invalid_argument for non-finite or non-increasing times.
// Notes: t_s is the estimate's time; an exact tie between two ground-truth poses goes to the
// earlier; a ground-truth pose may serve several estimates (when they are denser than it). The
// error message names the sequence and index ("associate: gt[12] ..."); a negative or non-finite
// max_dt_s is std::invalid_argument too.
std::vector<PosePair> associate(const std::vector<StampedPose>& est, const std::vector<StampedPose>& gt,
                                double max_dt_s = 0.02);

// The rigid transform T (rotation and translation, no scale) minimising sum |T est_i - gt_i|^2
// (Umeyama 1991). At least 3 non-collinear points for a unique rotation; with fewer, or
// degenerate ones, the best translation-only solution. std::invalid_argument on size mismatch.
// Notes: the rotation comes from Eigen::umeyama (with_scaling = false). Degenerate means the
// cross-covariance has rank < 2 (second singular value <= 1e-9 x the first: fewer than 3 points,
// or either set on one line or one point); the result is then the identity rotation with the
// difference of the centroids (no points: identity). Non-finite points: std::invalid_argument.
Eigen::Isometry3d umeyamaAlignment(const std::vector<Eigen::Vector3d>& est, const std::vector<Eigen::Vector3d>& gt);

struct AteResult {
  int pairs = 0;
  double rmse_m = 0.0;
  double mean_m = 0.0;
  double max_m = 0.0;
  Eigen::Isometry3d alignment = Eigen::Isometry3d::Identity();  // applied to the estimate
};
// Position error after aligning the estimate to ground truth: SE(3) Umeyama (align = true) or
// anchored at the first pair (T = X_gt0 X_est0^-1, align = false). Zero pairs -> pairs = 0.
AteResult absoluteTrajectoryError(const std::vector<PosePair>& pairs, bool align);

struct RpeResult {
  double delta_m = 0.0;
  int pairs = 0;              // (i, j) pose pairs, j the first pose delta_m along gt after i
  double trans_rmse_m = 0.0;  // translational error of the relative motion
  double trans_mean_m = 0.0;
  double trans_rmse_percent = 0.0;  // trans_rmse_m / delta_m * 100
  double rot_rmse_rad = 0.0;
};
// Every i with such a j counts (overlapping pairs, evo's all_pairs); relative motions
// E = (X_gt_i^-1 X_gt_j)^-1 (X_est_i^-1 X_est_j), errors |t(E)| and the rotation angle of E.
// No such pair: pairs = 0 and zero errors. std::invalid_argument unless delta_m > 0 and finite.
RpeResult relativePoseError(const std::vector<PosePair>& pairs, double delta_m);

// Length of the ground-truth path (sum of position steps).
double distanceTravelled(const std::vector<PosePair>& pairs);
// |final estimated position - final true position| with the estimate anchored at the first pair
// (T = X_gt0 X_est0^-1, as absoluteTrajectoryError with align = false). No pairs: 0.
double goalError(const std::vector<PosePair>& pairs);

}  // namespace tgnav::vo
