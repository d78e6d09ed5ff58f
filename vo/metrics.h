#pragma once
// Trajectory error metrics (pure functions), as the TUM RGB-D benchmark and evo compute them:
// association by timestamp, SE(3) Umeyama alignment, ATE (aligned, or anchored at the first
// pose), RPE per distance travelled, goal error.
//
// The definitions are evo's (github.com/MichaelGrupp/evo), which papers quote, so that numbers
// compare across them:
//   ATE = evo_ape's translation part (its default, "-r trans_part"): |p_gt_i - S(p_est_i)| per
//     associated pair after the alignment S, with evo's statistics rmse, mean, median, std
//     (population, numpy's), min, max and sse (sum of squares). Alignments: se3 = evo's -a
//     (Umeyama without scale), sim3 = -as (Umeyama with scale), origin = --align_origin
//     (S = X_gt_0 X_est_0^-1), none; posyaw = rpg_trajectory_evaluation's 4-DoF alignment
//     (translation and a rotation about the world z axis only: right for VIO, where gravity is
//     observable).
//   RPE = evo_rpe with --all_pairs: for every i with a partner j, the relative-motion error
//     E = (X_gt_i^-1 X_gt_j)^-1 (X_est_i^-1 X_est_j), its translation |t(E)| and rotation angle;
//     j = i + delta (--delta_unit f), or the first pose at least delta metres further along the
//     ground truth (evo's --delta_unit m takes the pose whose path length from i is nearest to
//     delta, within 10 % of it; on densely sampled paths the two agree).
//   Association: each estimate with the ground-truth pose nearest in time within max_dt_s (evo's
//     --t_max_diff, default 0.01 s there, 0.02 s here); evo pairs each pose of the shorter
//     trajectory instead, which differs only when the estimate is the denser one.
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "vo/tum.h"

namespace tgnav::vo {

struct PosePair {
  double t_s = 0.0;
  Eigen::Isometry3d X_WC_est = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d X_WC_gt = Eigen::Isometry3d::Identity();
};

// Pairs by time as evo does (evo.core.sync.associate_trajectories): each pose of the shorter
// trajectory (the estimate when both are as long) with the pose of the other whose timestamp is
// nearest, if within max_dt_s; of poses equally near, the first in its file (numpy's argmin over
// |t_i - t|). Timestamps need not increase or differ (TUM's own ground truth repeats some): each
// file is taken in its own order. Pairs come in the shorter trajectory's order; t_s is the
// estimate's time; one pose of the longer may serve several. std::invalid_argument for a
// non-finite timestamp, naming the sequence and index ("associate: gt[12] ..."), and for a
// negative or non-finite max_dt_s.
std::vector<PosePair> associate(const std::vector<StampedPose>& est, const std::vector<StampedPose>& gt,
                                double max_dt_s = 0.02);

// The poses whose timestamp is not after the one before them in the file (repeated or going
// back): 0 for strictly increasing times. Readers warn with it; associate() does not need order.
int nonIncreasingTimes(const std::vector<StampedPose>& poses);

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

// --- Any trajectory pair, every alignment, evo's statistics (tgnav eval) ------------------------

enum class Alignment { kSe3, kSim3, kPosYaw, kOrigin, kNone };
// "se3" | "sim3" | "posyaw" | "origin" | "none"; std::invalid_argument otherwise.
Alignment parseAlignment(const std::string& name);
const char* toString(Alignment alignment);

// The similarity p -> scale R p + t that maps estimated positions onto ground truth; a pose
// X_est becomes (R R_est, scale R p_est + t). Rigid alignments have scale 1.
struct Similarity3 {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double scale = 1.0;

  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const { return scale * (R * p) + t; }
  Eigen::Isometry3d operator*(const Eigen::Isometry3d& X) const;
};

// Umeyama with scale (Sim(3), evo's -as): the s, R, t minimising sum |s R est_i + t - gt_i|^2.
// Degenerate inputs as umeyamaAlignment: the difference of the centroids, scale 1.
Similarity3 umeyamaSim3Alignment(const std::vector<Eigen::Vector3d>& est, const std::vector<Eigen::Vector3d>& gt);
// The yaw (rotation about z) and translation minimising sum |R_z est_i + t - gt_i|^2: yaw =
// atan2(sum (x_e y_g - y_e x_g), sum (x_e x_g + y_e y_g)) over the centred points, t = the
// centroids' difference after the rotation (rpg_trajectory_evaluation's align_posyaw over all
// points). No points, or all on one vertical line: yaw 0. std::invalid_argument on size mismatch
// or non-finite points.
Similarity3 posYawAlignment(const std::vector<Eigen::Vector3d>& est, const std::vector<Eigen::Vector3d>& gt);
// The transform `alignment` fits to the pairs' positions (origin: from their first poses); the
// identity for no pairs.
Similarity3 alignmentOf(const std::vector<PosePair>& pairs, Alignment alignment);
// The pairs with every estimated pose mapped by S (ground truth unchanged).
std::vector<PosePair> alignedPairs(const std::vector<PosePair>& pairs, const Similarity3& S);

// evo's statistics of a set of errors. n = 0: every field NaN except sse = 0.
struct ErrorStatistics {
  int n = 0;
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;  // the mean of the middle two for even n (numpy)
  double std = 0.0;     // population standard deviation (numpy's default, ddof = 0)
  double min = 0.0;
  double max = 0.0;
  double sse = 0.0;  // sum of squared errors
};
ErrorStatistics errorStatistics(std::vector<double> errors);

// ATE (evo_ape, translation part): the fitted alignment, the error of every pair in order, and
// their statistics in metres.
struct ApeResult {
  Similarity3 alignment;
  std::vector<double> errors_m;
  ErrorStatistics stats_m;
};
ApeResult absolutePoseError(const std::vector<PosePair>& pairs, Alignment alignment);

enum class RpeUnit { kMetres, kFrames };
// RPE over the pairs as given (align them first for sim3: the scale matters, a rigid alignment
// does not). kFrames needs a whole delta >= 1, kMetres a finite delta > 0 (std::invalid_argument
// otherwise). No pair delta apart: n = 0 in both statistics.
struct RpeStatistics {
  double delta = 0.0;
  RpeUnit unit = RpeUnit::kMetres;
  ErrorStatistics trans_m;  // |t(E)|
  ErrorStatistics rot_rad;  // rotation angle of E, in [0, pi]
};
RpeStatistics rpeStatistics(const std::vector<PosePair>& pairs, double delta, RpeUnit unit);

// Length of a trajectory (sum of position steps); 0 for fewer than two poses.
double pathLength(const std::vector<StampedPose>& poses);

}  // namespace tgnav::vo
