#include "vo/metrics.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "vo/text_fields.h"

namespace tgnav::vo {
namespace {

// The point sets count as collinear (or coincident) when the cross-covariance's second singular
// value is below this fraction of its first: the rotation about the line is then undetermined.
constexpr double kDegenerateRatio = 1e-9;

// Shortest text that reads back to v (std::to_string would print 1e-9 as 0.000000).
using text::str;

// Finite timestamps; the message names the sequence and the index.
void checkTimes(const std::vector<StampedPose>& poses, const char* name) {
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (!std::isfinite(poses[i].t_s)) {
      throw std::invalid_argument("associate: " + std::string(name) + "[" + std::to_string(i) +
                                  "] has a non-finite timestamp");
    }
  }
}

// The index of the pose nearest in time to t, the first in file order among equally near ones:
// numpy's argmin over |t_i - t|, which evo takes, in O(log n) per query (plus the ties).
class NearestTime {
 public:
  explicit NearestTime(const std::vector<StampedPose>& poses) : order_(poses.size()) {
    for (std::size_t i = 0; i < order_.size(); ++i) order_[i] = static_cast<int>(i);
    // Stable: equal timestamps keep their file order.
    std::stable_sort(order_.begin(), order_.end(), [&](int a, int b) {
      return poses[static_cast<std::size_t>(a)].t_s < poses[static_cast<std::size_t>(b)].t_s;
    });
    times_.reserve(order_.size());
    for (int i : order_) times_.push_back(poses[static_cast<std::size_t>(i)].t_s);
  }

  // -1 when there are no poses.
  int operator()(double t) const {
    if (times_.empty()) return -1;
    const auto n = static_cast<std::ptrdiff_t>(times_.size());
    const std::ptrdiff_t after = std::lower_bound(times_.begin(), times_.end(), t) - times_.begin();
    double best = std::numeric_limits<double>::infinity();
    if (after < n) best = std::abs(times_[static_cast<std::size_t>(after)] - t);
    if (after > 0) best = std::min(best, std::abs(times_[static_cast<std::size_t>(after - 1)] - t));
    // |t_i - t| only grows away from t on either side (as computed, too), so every pose at the
    // smallest difference is next to `after`: take the first of them in file order.
    int first = std::numeric_limits<int>::max();
    for (std::ptrdiff_t k = after; k < n && std::abs(times_[static_cast<std::size_t>(k)] - t) == best; ++k) {
      first = std::min(first, order_[static_cast<std::size_t>(k)]);
    }
    for (std::ptrdiff_t k = after - 1; k >= 0 && std::abs(times_[static_cast<std::size_t>(k)] - t) == best; --k) {
      first = std::min(first, order_[static_cast<std::size_t>(k)]);
    }
    return first;
  }

 private:
  std::vector<int> order_;     // pose indices by time, ties in file order
  std::vector<double> times_;  // their timestamps
};

Eigen::Isometry3d translationOnly(const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = t;
  return T;
}

// Anchored at the first pair: the estimate's first pose mapped onto the ground truth's.
Eigen::Isometry3d anchor(const std::vector<PosePair>& pairs) {
  return pairs.front().X_WC_gt * pairs.front().X_WC_est.inverse();
}

// Point sets of one size, finite; `who` names the caller in errors.
void checkPoints(const std::vector<Eigen::Vector3d>& est, const std::vector<Eigen::Vector3d>& gt, const char* who) {
  if (est.size() != gt.size()) {
    throw std::invalid_argument(std::string(who) + ": " + std::to_string(est.size()) + " estimated points but " +
                                std::to_string(gt.size()) + " ground-truth points");
  }
  for (std::size_t i = 0; i < est.size(); ++i) {
    if (!est[i].allFinite() || !gt[i].allFinite()) throw std::invalid_argument(std::string(who) + ": non-finite point");
  }
}

// Eigen::umeyama's [s R | t] mapping est onto gt (s = 1 without scaling); for degenerate inputs
// the translation between the centroids.
Eigen::Matrix4d umeyamaFit(const std::vector<Eigen::Vector3d>& est, const std::vector<Eigen::Vector3d>& gt,
                           bool with_scaling, const char* who) {
  checkPoints(est, gt, who);
  const auto n = static_cast<Eigen::Index>(est.size());
  if (n == 0) return Eigen::Matrix4d::Identity();
  Eigen::Matrix3Xd src(3, n), dst(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    src.col(i) = est[i];
    dst.col(i) = gt[i];
  }
  const Eigen::Vector3d mu_src = src.rowwise().mean();
  const Eigen::Vector3d mu_dst = dst.rowwise().mean();
  // Rank of the cross-covariance (Umeyama's Sigma): below 2 (fewer than 3 points, or all on one
  // line in either set) leaves the rotation about the line free; Eigen::umeyama would pick an
  // arbitrary one. Then: the best translation-only transform, the difference of the centroids.
  const Eigen::Matrix3d sigma = (dst.colwise() - mu_dst) * (src.colwise() - mu_src).transpose() / double(n);
  const Eigen::Vector3d s = Eigen::JacobiSVD<Eigen::Matrix3d>(sigma).singularValues();
  if (n < 3 || !(s(1) > kDegenerateRatio * s(0))) return translationOnly(mu_dst - mu_src).matrix();
  return Eigen::umeyama(src, dst, with_scaling);
}

Similarity3 similarity(const Eigen::Isometry3d& X) {
  Similarity3 S;
  S.R = X.linear();
  S.t = X.translation();
  return S;
}

void positionsOf(const std::vector<PosePair>& pairs, std::vector<Eigen::Vector3d>* est,
                 std::vector<Eigen::Vector3d>* gt) {
  for (const PosePair& p : pairs) {
    est->push_back(p.X_WC_est.translation());
    gt->push_back(p.X_WC_gt.translation());
  }
}

using IndexPairs = std::vector<std::pair<std::size_t, std::size_t>>;

// (i, j) with j the first pose at least delta_m further along the ground truth than i.
IndexPairs pairsByDistance(const std::vector<PosePair>& pairs, double delta_m) {
  // Path length along ground truth up to each pose.
  std::vector<double> s(pairs.size(), 0.0);
  for (std::size_t k = 1; k < pairs.size(); ++k) {
    s[k] = s[k - 1] + (pairs[k].X_WC_gt.translation() - pairs[k - 1].X_WC_gt.translation()).norm();
  }
  IndexPairs ids;
  std::size_t j = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    // Every i starts a pair (overlapping pairs, as evo's all_pairs); j only moves forward.
    j = std::max(j, i + 1);
    while (j < pairs.size() && s[j] - s[i] < delta_m) ++j;
    if (j >= pairs.size()) break;  // no pose delta_m further on, for this i or any later one
    ids.emplace_back(i, j);
  }
  return ids;
}

IndexPairs pairsByFrames(std::size_t n, std::size_t delta) {
  IndexPairs ids;
  for (std::size_t i = 0; i + delta < n; ++i) ids.emplace_back(i, i + delta);
  return ids;
}

// The translation and rotation errors of E = (X_gt_i^-1 X_gt_j)^-1 (X_est_i^-1 X_est_j) per (i, j).
void relativeErrors(const std::vector<PosePair>& pairs, const IndexPairs& ids, std::vector<double>* trans_m,
                    std::vector<double>* rot_rad) {
  for (const auto& [i, j] : ids) {
    const Eigen::Isometry3d d_gt = pairs[i].X_WC_gt.inverse() * pairs[j].X_WC_gt;
    const Eigen::Isometry3d d_est = pairs[i].X_WC_est.inverse() * pairs[j].X_WC_est;
    const Eigen::Isometry3d E = d_gt.inverse() * d_est;
    trans_m->push_back(E.translation().norm());
    rot_rad->push_back(Eigen::AngleAxisd(Eigen::Quaterniond(E.linear())).angle());  // in [0, pi]
  }
}

void checkDeltaM(double delta_m, const char* who) {
  if (!(delta_m > 0.0) || !std::isfinite(delta_m)) {
    throw std::invalid_argument(std::string(who) + ": delta_m must be finite and > 0, not " + str(delta_m));
  }
}

}  // namespace

std::vector<PosePair> associate(const std::vector<StampedPose>& est, const std::vector<StampedPose>& gt,
                                double max_dt_s) {
  if (!(max_dt_s >= 0.0) || !std::isfinite(max_dt_s)) {
    throw std::invalid_argument("associate: max_dt_s must be finite and >= 0, not " + str(max_dt_s));
  }
  checkTimes(est, "est");
  checkTimes(gt, "gt");
  // evo: the estimate is the shorter unless it has strictly more poses.
  const bool est_longer = est.size() > gt.size();
  const std::vector<StampedPose>& shorter = est_longer ? gt : est;
  const std::vector<StampedPose>& longer = est_longer ? est : gt;
  const NearestTime nearest(longer);
  std::vector<PosePair> pairs;
  for (const StampedPose& s : shorter) {
    const int j = nearest(s.t_s);
    if (j < 0) break;
    const StampedPose& l = longer[static_cast<std::size_t>(j)];
    if (!(std::abs(l.t_s - s.t_s) <= max_dt_s)) continue;
    const StampedPose& e = est_longer ? l : s;
    const StampedPose& g = est_longer ? s : l;
    pairs.push_back(PosePair{e.t_s, e.X_WC, g.X_WC});
  }
  return pairs;
}

int nonIncreasingTimes(const std::vector<StampedPose>& poses) {
  int n = 0;
  for (std::size_t i = 1; i < poses.size(); ++i) n += poses[i].t_s > poses[i - 1].t_s ? 0 : 1;
  return n;
}

Eigen::Isometry3d umeyamaAlignment(const std::vector<Eigen::Vector3d>& est, const std::vector<Eigen::Vector3d>& gt) {
  return Eigen::Isometry3d(umeyamaFit(est, gt, /*with_scaling=*/false, "umeyamaAlignment"));
}

AteResult absoluteTrajectoryError(const std::vector<PosePair>& pairs, bool align) {
  AteResult r;
  if (pairs.empty()) return r;
  const ApeResult ape = absolutePoseError(pairs, align ? Alignment::kSe3 : Alignment::kOrigin);
  r.alignment.linear() = ape.alignment.R;
  r.alignment.translation() = ape.alignment.t;
  r.pairs = ape.stats_m.n;
  r.rmse_m = ape.stats_m.rmse;
  r.mean_m = ape.stats_m.mean;
  r.max_m = ape.stats_m.max;
  return r;
}

RpeResult relativePoseError(const std::vector<PosePair>& pairs, double delta_m) {
  checkDeltaM(delta_m, "relativePoseError");
  RpeResult r;
  r.delta_m = delta_m;
  std::vector<double> trans, rot;
  relativeErrors(pairs, pairsByDistance(pairs, delta_m), &trans, &rot);
  r.pairs = static_cast<int>(trans.size());
  if (r.pairs == 0) return r;
  const ErrorStatistics t = errorStatistics(trans);
  r.trans_rmse_m = t.rmse;
  r.trans_mean_m = t.mean;
  r.trans_rmse_percent = r.trans_rmse_m / delta_m * 100.0;
  r.rot_rmse_rad = errorStatistics(rot).rmse;
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

Alignment parseAlignment(const std::string& name) {
  for (const Alignment a :
       {Alignment::kSe3, Alignment::kSim3, Alignment::kPosYaw, Alignment::kOrigin, Alignment::kNone}) {
    if (name == toString(a)) return a;
  }
  throw std::invalid_argument("'" + name + "' is not an alignment; expected se3, sim3, posyaw, origin or none");
}

const char* toString(Alignment alignment) {
  switch (alignment) {
    case Alignment::kSe3:
      return "se3";
    case Alignment::kSim3:
      return "sim3";
    case Alignment::kPosYaw:
      return "posyaw";
    case Alignment::kOrigin:
      return "origin";
    case Alignment::kNone:
      return "none";
  }
  return "?";
}

Eigen::Isometry3d Similarity3::operator*(const Eigen::Isometry3d& X) const {
  Eigen::Isometry3d Y = Eigen::Isometry3d::Identity();
  Y.linear() = R * X.linear();
  Y.translation() = *this * X.translation();
  return Y;
}

Similarity3 umeyamaSim3Alignment(const std::vector<Eigen::Vector3d>& est, const std::vector<Eigen::Vector3d>& gt) {
  const Eigen::Matrix4d M = umeyamaFit(est, gt, /*with_scaling=*/true, "umeyamaSim3Alignment");
  Similarity3 S;
  S.scale = std::cbrt(M.topLeftCorner<3, 3>().determinant());  // det(s R) = s^3
  S.R = M.topLeftCorner<3, 3>() / S.scale;
  S.t = M.topRightCorner<3, 1>();
  return S;
}

Similarity3 posYawAlignment(const std::vector<Eigen::Vector3d>& est, const std::vector<Eigen::Vector3d>& gt) {
  checkPoints(est, gt, "posYawAlignment");
  Similarity3 S;
  if (est.empty()) return S;
  Eigen::Vector3d mu_est = Eigen::Vector3d::Zero(), mu_gt = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < est.size(); ++i) {
    mu_est += est[i] / double(est.size());
    mu_gt += gt[i] / double(gt.size());
  }
  // The yaw maximising sum gt_i . R_z est_i over the centred points: atan2(sum of the cross
  // products' z, sum of the dot products in xy).
  double cross = 0.0, dot = 0.0;
  for (std::size_t i = 0; i < est.size(); ++i) {
    const Eigen::Vector3d e = est[i] - mu_est, g = gt[i] - mu_gt;
    cross += e.x() * g.y() - e.y() * g.x();
    dot += e.x() * g.x() + e.y() * g.y();
  }
  S.R = Eigen::AngleAxisd(std::atan2(cross, dot), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  S.t = mu_gt - S.R * mu_est;
  return S;
}

Similarity3 alignmentOf(const std::vector<PosePair>& pairs, Alignment alignment) {
  if (pairs.empty() || alignment == Alignment::kNone) return Similarity3{};
  if (alignment == Alignment::kOrigin) return similarity(anchor(pairs));
  std::vector<Eigen::Vector3d> est, gt;
  positionsOf(pairs, &est, &gt);
  if (alignment == Alignment::kSim3) return umeyamaSim3Alignment(est, gt);
  if (alignment == Alignment::kPosYaw) return posYawAlignment(est, gt);
  return similarity(umeyamaAlignment(est, gt));
}

std::vector<PosePair> alignedPairs(const std::vector<PosePair>& pairs, const Similarity3& S) {
  std::vector<PosePair> aligned = pairs;
  for (PosePair& p : aligned) p.X_WC_est = S * p.X_WC_est;
  return aligned;
}

ErrorStatistics errorStatistics(std::vector<double> errors) {
  ErrorStatistics r;
  r.n = static_cast<int>(errors.size());
  if (errors.empty()) {
    r.rmse = r.mean = r.median = r.std = r.min = r.max = std::nan("");
    return r;
  }
  double sum = 0.0;
  for (const double e : errors) {
    sum += e;
    r.sse += e * e;
  }
  r.rmse = std::sqrt(r.sse / r.n);
  r.mean = sum / r.n;
  double var = 0.0;
  for (const double e : errors) var += (e - r.mean) * (e - r.mean);
  r.std = std::sqrt(var / r.n);
  std::sort(errors.begin(), errors.end());
  const std::size_t mid = errors.size() / 2;
  r.median = errors.size() % 2 == 1 ? errors[mid] : 0.5 * (errors[mid - 1] + errors[mid]);
  r.min = errors.front();
  r.max = errors.back();
  return r;
}

ApeResult absolutePoseError(const std::vector<PosePair>& pairs, Alignment alignment) {
  ApeResult r;
  r.alignment = alignmentOf(pairs, alignment);
  for (const PosePair& p : pairs) {
    r.errors_m.push_back((r.alignment * p.X_WC_est.translation() - p.X_WC_gt.translation()).norm());
  }
  r.stats_m = errorStatistics(r.errors_m);
  return r;
}

RpeStatistics rpeStatistics(const std::vector<PosePair>& pairs, double delta, RpeUnit unit) {
  IndexPairs ids;
  if (unit == RpeUnit::kMetres) {
    checkDeltaM(delta, "rpeStatistics");
    ids = pairsByDistance(pairs, delta);
  } else {
    if (!(delta >= 1.0 && delta <= 1e9 && delta == std::floor(delta))) {
      throw std::invalid_argument("rpeStatistics: a delta in frames must be a whole number >= 1, not " + str(delta));
    }
    ids = pairsByFrames(pairs.size(), static_cast<std::size_t>(delta));
  }
  std::vector<double> trans, rot;
  relativeErrors(pairs, ids, &trans, &rot);
  RpeStatistics r;
  r.delta = delta;
  r.unit = unit;
  r.trans_m = errorStatistics(trans);
  r.rot_rad = errorStatistics(rot);
  return r;
}

double pathLength(const std::vector<StampedPose>& poses) {
  double d = 0.0;
  for (std::size_t k = 1; k < poses.size(); ++k) {
    d += (poses[k].X_WC.translation() - poses[k - 1].X_WC.translation()).norm();
  }
  return d;
}

}  // namespace tgnav::vo
