#include "harness/run/view_guard.h"

#include <algorithm>
#include <cmath>

namespace tgnav::harness {

namespace {

double wrapAngle(double a) { return std::remainder(a, 2.0 * M_PI); }

// Calls fn(key, voxel centre) for every voxel of `tree`'s grid over the band whose centre lies
// within radius_m of `centre` horizontally, layer by layer from the band's bottom.
template <typename Fn>
void forEachKeyWithin(const octomap::OcTree& tree, const Eigen::Vector3d& centre, double radius_m,
                      const ClearanceBand& band, Fn fn) {
  const double res = tree.getResolution();
  const int n = static_cast<int>(std::ceil(radius_m / res)) + 1;
  for (double z = band.lo_m + 0.5 * res; z < band.hi_m; z += res) {
    const octomap::OcTreeKey key = tree.coordToKey(centre.x(), centre.y(), z);
    for (int i = -n; i <= n; ++i) {
      for (int j = -n; j <= n; ++j) {
        octomap::OcTreeKey k = key;
        k[0] = static_cast<octomap::key_type>(k[0] + i);
        k[1] = static_cast<octomap::key_type>(k[1] + j);
        const octomap::point3d c = tree.keyToCoord(k);
        const Eigen::Vector3d v(c.x(), c.y(), c.z());
        if ((v - centre).head<2>().norm() <= radius_m) fn(k, v);
      }
    }
  }
}

}  // namespace

bool inWedge(const BlindWedge& wedge, const Eigen::Vector3d& p) {
  const Eigen::Vector2d d = (p - wedge.apex).head<2>();
  const double r = d.norm();
  if (r > wedge.range_m) return false;
  if (r < 1e-9) return false;  // the apex itself: where the vehicle was
  double off = std::atan2(d.y(), d.x()) - wedge.from_rad;
  off = off - 2.0 * M_PI * std::floor(off / (2.0 * M_PI));  // in [0, 2 pi)
  return off <= wedge.width_rad;
}

int inliersAfterTurn(const std::array<int, vo::FrameResult::kColumnBins>& columns, const vo::CameraIntrinsics& camera,
                     double turn_rad, double edge_px) {
  const double lo = std::atan((edge_px - camera.cx) / camera.fx);
  const double hi = std::atan((camera.width_px - 1 - edge_px - camera.cx) / camera.fx);
  const double bin_px = static_cast<double>(camera.width_px) / vo::FrameResult::kColumnBins;
  int kept = 0;
  for (int b = 0; b < vo::FrameResult::kColumnBins; ++b) {
    const double bearing = std::atan(((b + 0.5) * bin_px - camera.cx) / camera.fx) + turn_rad;
    if (bearing >= lo && bearing <= hi) kept += columns[static_cast<std::size_t>(b)];
  }
  return kept;
}

std::optional<BlindWedge> ViewGuard::observe(double t_s, const Eigen::Vector3d& p, double yaw_rad, int inliers,
                                             const std::array<int, vo::FrameResult::kColumnBins>* columns,
                                             double planned_turn_rad) {
  recent_.emplace_back(t_s, yaw_rad);
  while (recent_.size() > 1 && recent_[1].first <= t_s - kTurnWindowS + 1e-9) recent_.pop_front();
  const double turning = wrapAngle(yaw_rad - recent_.front().second);
  // The turn the lead foresees, at the rate of the last kRateWindowS (a turn speeds up: the rate
  // over the whole window saw too little of it), and the inliers it would leave in view.
  const auto from = std::find_if(recent_.begin(), recent_.end(), [&](const std::pair<double, double>& s) {
    return s.first >= t_s - kRateWindowS - 1e-9;
  });
  const double span_s = t_s - from->first;
  const double rate = span_s > 0.0 ? wrapAngle(yaw_rad - from->second) / span_s : 0.0;
  const bool leads = lead_.lead_s > 0.0 && columns != nullptr;
  // The commanded turn, where it is the larger: a turn about to start has no rate yet.
  const bool planned = leads && std::abs(planned_turn_rad) > std::abs(rate * lead_.lead_s);
  const double lead_rad = !leads ? 0.0 : planned ? planned_turn_rad : rate * lead_.lead_s;
  if (lead_rad != 0.0) inliers = std::min(inliers, inliersAfterTurn(*columns, lead_.camera, lead_rad, lead_.edge_px));
  if (inliers >= min_inliers_) {
    has_good_ = true;
    good_yaw_rad_ = yaw_rad;
    if (rearm_) armed_ = true;
    rearm_ = false;
    return std::nullopt;
  }
  if (!armed_ || !has_good_) return std::nullopt;
  const bool turned = std::abs(turning) >= min_turn_rad_;
  const bool turned_enough = turned || (planned && std::abs(planned_turn_rad) >= min_turn_rad_);
  if (!turned_enough && !still_) return std::nullopt;
  armed_ = false;
  last_trip_turned_ = turned_enough;
  last_trip_planned_rad_ = planned && turned_enough ? planned_turn_rad : 0.0;
  BlindWedge w;
  w.apex = p;
  w.range_m = range_m_;
  if (!turned_enough) {  // the view lost as the vehicle moved: its field of view
    w.from_rad = wrapAngle(yaw_rad - half_fov_rad_);
    w.width_rad = 2.0 * half_fov_rad_;
    return w;
  }
  // The new part of the view: from the good view's edge on the side turned to, to the bad view's
  // far edge and kBeyondRad on.
  const double so_far = std::abs(wrapAngle(yaw_rad - good_yaw_rad_));
  const double width = std::min(M_PI, so_far + std::abs(lead_rad) + kBeyondRad);
  const double side = turned ? turning : lead_rad;  // a turn not yet started: the one commanded
  w.width_rad = width;
  w.from_rad = side > 0.0 ? wrapAngle(good_yaw_rad_ + half_fov_rad_) : wrapAngle(good_yaw_rad_ - half_fov_rad_ - width);
  return w;
}

int blockWedges(octomap::OcTree* tree, const std::vector<BlindWedge>& wedges, const ClearanceBand& band,
                const std::vector<Eigen::Vector3d>& keep_free, double keep_m) {
  int marked = 0;
  for (const BlindWedge& w : wedges) {
    forEachKeyWithin(*tree, w.apex, w.range_m, band, [&](const octomap::OcTreeKey& k, const Eigen::Vector3d& v) {
      if (!inWedge(w, v) || (v - w.apex).head<2>().norm() <= keep_m) return;
      if (tree->search(k) != nullptr) return;  // observed: planned as it is
      const bool kept = std::any_of(keep_free.begin(), keep_free.end(),
                                    [&](const Eigen::Vector3d& f) { return (v - f).head<2>().norm() <= keep_m; });
      if (kept) return;
      tree->updateNode(k, true, /*lazy_eval=*/true);
      ++marked;
    });
  }
  if (marked > 0) tree->updateInnerOccupancy();
  return marked;
}

void markFree(octomap::OcTree* tree, const std::vector<Eigen::Vector3d>& centres, double radius_m,
              const ClearanceBand& band) {
  for (const Eigen::Vector3d& c : centres) {
    forEachKeyWithin(*tree, c, radius_m, band, [&](const octomap::OcTreeKey& k, const Eigen::Vector3d&) {
      if (tree->search(k) == nullptr) tree->updateNode(k, false, /*lazy_eval=*/true);
    });
  }
  tree->updateInnerOccupancy();
}

bool trippedView(const GuardEvent& event, const Eigen::Vector2d& p, double yaw_rad, double within_m,
                 double beyond_rad) {
  if ((event.wedge.apex.head<2>() - p).norm() > within_m) return false;
  if (!event.turning) return std::abs(std::remainder(yaw_rad - event.yaw_rad, 2.0 * M_PI)) <= 0.5 * beyond_rad;
  const double turn = std::remainder(event.yaw_rad - event.good_yaw_rad, 2.0 * M_PI) + event.planned_rad;
  const double sign = turn >= 0.0 ? 1.0 : -1.0;
  const double along = sign * std::remainder(yaw_rad - event.good_yaw_rad, 2.0 * M_PI);  // in the turn's direction
  return along >= 0.5 * std::abs(turn) && along <= std::abs(turn) + beyond_rad;
}

}  // namespace tgnav::harness
