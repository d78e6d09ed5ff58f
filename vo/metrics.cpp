#include "vo/metrics.h"

#include <Eigen/SVD>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <string>

namespace tgnav::vo {
namespace {

// The point sets count as collinear (or coincident) when the cross-covariance's second singular
// value is below this fraction of its first: the rotation about the line is then undetermined.
constexpr double kDegenerateRatio = 1e-9;

// Shortest text that reads back to v (std::to_string would print 1e-9 as 0.000000).
std::string str(double v) {
  char buf[32];
  return std::string(buf, std::to_chars(buf, buf + sizeof(buf), v).ptr);
}

// Finite, strictly increasing timestamps; the message names the sequence and the index.
void checkTimes(const std::vector<StampedPose>& poses, const char* name) {
  auto at = [&](std::size_t i) { return std::string(name) + "[" + std::to_string(i) + "]"; };
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const double t = poses[i].t_s;
    if (!std::isfinite(t)) throw std::invalid_argument("associate: " + at(i) + " has a non-finite timestamp");
    if (i > 0 && !(t > poses[i - 1].t_s)) {
      throw std::invalid_argument("associate: " + at(i) + " timestamp " + str(t) + " is not after " + at(i - 1) + " (" +
                                  str(poses[i - 1].t_s) + "); timestamps must increase");
    }
  }
}

Eigen::Isometry3d translationOnly(const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = t;
  return T;
}

// Anchored at the first pair: the estimate's first pose mapped onto the ground truth's.
Eigen::Isometry3d anchor(const std::vector<PosePair>& pairs) {
  return pairs.front().X_WC_gt * pairs.front().X_WC_est.inverse();
}

}  // namespace

std::vector<PosePair> associate(const std::vector<StampedPose>& est, const std::vector<StampedPose>& gt,
                                double max_dt_s) {
  if (!(max_dt_s >= 0.0) || !std::isfinite(max_dt_s)) {
    throw std::invalid_argument("associate: max_dt_s must be finite and >= 0, not " + str(max_dt_s));
  }
  checkTimes(est, "est");
  checkTimes(gt, "gt");
  std::vector<PosePair> pairs;
  for (const StampedPose& e : est) {
    // First gt at or after e; the nearest is it or the one before (a tie goes to the earlier).
    const auto after =
        std::lower_bound(gt.begin(), gt.end(), e.t_s, [](const StampedPose& g, double t) { return g.t_s < t; });
    auto best = gt.end();
    if (after != gt.end()) best = after;
    if (after != gt.begin()) {
      const auto before = std::prev(after);
      if (best == gt.end() || e.t_s - before->t_s <= best->t_s - e.t_s) best = before;
    }
    if (best == gt.end() || std::abs(best->t_s - e.t_s) > max_dt_s) continue;
    pairs.push_back(PosePair{e.t_s, e.X_WC, best->X_WC});
  }
  return pairs;
}

Eigen::Isometry3d umeyamaAlignment(const std::vector<Eigen::Vector3d>& est, const std::vector<Eigen::Vector3d>& gt) {
  if (est.size() != gt.size()) {
    throw std::invalid_argument("umeyamaAlignment: " + std::to_string(est.size()) + " estimated points but " +
                                std::to_string(gt.size()) + " ground-truth points");
  }
  const auto n = static_cast<Eigen::Index>(est.size());
  if (n == 0) return Eigen::Isometry3d::Identity();
  Eigen::Matrix3Xd src(3, n), dst(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    src.col(i) = est[i];
    dst.col(i) = gt[i];
  }
  if (!src.allFinite() || !dst.allFinite()) throw std::invalid_argument("umeyamaAlignment: non-finite point");
  const Eigen::Vector3d mu_src = src.rowwise().mean();
  const Eigen::Vector3d mu_dst = dst.rowwise().mean();
  // Rank of the cross-covariance (Umeyama's Sigma): below 2 (fewer than 3 points, or all on one
  // line in either set) leaves the rotation about the line free; Eigen::umeyama would pick an
  // arbitrary one. Then: the best translation-only transform, the difference of the centroids.
  const Eigen::Matrix3d sigma = (dst.colwise() - mu_dst) * (src.colwise() - mu_src).transpose() / double(n);
  const Eigen::Vector3d s = Eigen::JacobiSVD<Eigen::Matrix3d>(sigma).singularValues();
  if (n < 3 || !(s(1) > kDegenerateRatio * s(0))) return translationOnly(mu_dst - mu_src);
  return Eigen::Isometry3d(Eigen::umeyama(src, dst, /*with_scaling=*/false));
}

AteResult absoluteTrajectoryError(const std::vector<PosePair>& pairs, bool align) {
  AteResult r;
  if (pairs.empty()) return r;
  if (align) {
    std::vector<Eigen::Vector3d> est, gt;
    est.reserve(pairs.size());
    gt.reserve(pairs.size());
    for (const PosePair& p : pairs) {
      est.push_back(p.X_WC_est.translation());
      gt.push_back(p.X_WC_gt.translation());
    }
    r.alignment = umeyamaAlignment(est, gt);
  } else {
    r.alignment = anchor(pairs);
  }
  double sum = 0.0, sum_sq = 0.0;
  for (const PosePair& p : pairs) {
    const double e = (r.alignment * p.X_WC_est.translation() - p.X_WC_gt.translation()).norm();
    sum += e;
    sum_sq += e * e;
    r.max_m = std::max(r.max_m, e);
  }
  r.pairs = static_cast<int>(pairs.size());
  r.rmse_m = std::sqrt(sum_sq / r.pairs);
  r.mean_m = sum / r.pairs;
  return r;
}

RpeResult relativePoseError(const std::vector<PosePair>& pairs, double delta_m) {
  if (!(delta_m > 0.0) || !std::isfinite(delta_m)) {
    throw std::invalid_argument("relativePoseError: delta_m must be finite and > 0, not " + str(delta_m));
  }
  RpeResult r;
  r.delta_m = delta_m;
  // Path length along ground truth up to each pose.
  std::vector<double> s(pairs.size(), 0.0);
  for (std::size_t k = 1; k < pairs.size(); ++k) {
    s[k] = s[k - 1] + (pairs[k].X_WC_gt.translation() - pairs[k - 1].X_WC_gt.translation()).norm();
  }
  double sum = 0.0, sum_sq = 0.0, rot_sq = 0.0;
  std::size_t j = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    // Every i starts a pair (overlapping pairs, as evo's all_pairs); j only moves forward.
    j = std::max(j, i + 1);
    while (j < pairs.size() && s[j] - s[i] < delta_m) ++j;
    if (j >= pairs.size()) break;  // no pose delta_m further on, for this i or any later one
    const Eigen::Isometry3d d_gt = pairs[i].X_WC_gt.inverse() * pairs[j].X_WC_gt;
    const Eigen::Isometry3d d_est = pairs[i].X_WC_est.inverse() * pairs[j].X_WC_est;
    const Eigen::Isometry3d E = d_gt.inverse() * d_est;
    const double e = E.translation().norm();
    const double angle = Eigen::AngleAxisd(Eigen::Quaterniond(E.linear())).angle();  // in [0, pi]
    sum += e;
    sum_sq += e * e;
    rot_sq += angle * angle;
    ++r.pairs;
  }
  if (r.pairs == 0) return r;
  r.trans_rmse_m = std::sqrt(sum_sq / r.pairs);
  r.trans_mean_m = sum / r.pairs;
  r.trans_rmse_percent = r.trans_rmse_m / delta_m * 100.0;
  r.rot_rmse_rad = std::sqrt(rot_sq / r.pairs);
  return r;
}

double distanceTravelled(const std::vector<PosePair>& pairs) {
  double d = 0.0;
  for (std::size_t k = 1; k < pairs.size(); ++k) {
    d += (pairs[k].X_WC_gt.translation() - pairs[k - 1].X_WC_gt.translation()).norm();
  }
  return d;
}

double goalError(const std::vector<PosePair>& pairs) {
  if (pairs.empty()) return 0.0;
  return (anchor(pairs) * pairs.back().X_WC_est.translation() - pairs.back().X_WC_gt.translation()).norm();
}

}  // namespace tgnav::vo
