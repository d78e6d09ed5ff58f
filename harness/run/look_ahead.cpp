#include "harness/run/look_ahead.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>

namespace tgnav::harness {

namespace {
constexpr double kYawWindowS = 1.0;                 // the smoothing window
constexpr double kRateEveryS = 0.2;                 // trajectory time between two rated positions
constexpr double kYawStepRad = 5.0 * M_PI / 180.0;  // between two rated yaws
// The way half the look-ahead ahead stays this far beyond the way ahead's own limit (half_fov_rad,
// 10 deg inside the image's edge): 5 deg inside the edge.
constexpr double kNearMarginRad = 5.0 * M_PI / 180.0;
// How far along the plan (in its time) the nearest point to a setpoint of the current trajectory is
// looked for when a plan's yaw is carried over to it (renewedViews).
constexpr double kRenewWindowS = 5.0;
}  // namespace

void ViewRater::moveTo(const Eigen::Vector3d& p_WB, const std::function<bool(const planner::LandmarkVoxel&)>& keep) {
  p_WB_ = p_WB;
  points_ = planner::aggregateSlots(*voxels_, voxels_->visibleSlots(p_WB, *visibility_, keep));
}

ViewRating ViewRater::rate(double yaw_rad) const {
  planner::ViewSupport support;
  planner::poseInformation(planner::cameraPosition(p_WB_, yaw_rad, *visibility_), yaw_rad, points_, *visibility_,
                           *information_, &support);
  ViewRating r;
  r.detections = support.detections;
  r.shortfall = planner::gateShortfall(support, *information_);
  if (support.detections < detection_floor_) {
    r.shortfall = std::max(r.shortfall, 1.0 - support.detections / detection_floor_);
  }
  return r;
}

double ViewRater::shortfall(double yaw_rad) const { return rate(yaw_rad).shortfall; }

double ViewRater::detections(double yaw_rad) const { return rate(yaw_rad).detections; }

double trackableShare(const ViewRater& rater, double planned, double look, double near, double near_limit) {
  const double turn = std::remainder(look - planned, 2.0 * M_PI);
  const int steps = std::max(1, static_cast<int>(std::ceil(std::abs(turn) / kYawStepRad)));
  double best_share = 1.0;
  double best = std::numeric_limits<double>::infinity();
  for (int k = steps; k >= 0; --k) {
    const double share = static_cast<double>(k) / steps;
    const double yaw = planned + share * turn;
    if (k < steps && std::abs(std::remainder(yaw - near, 2.0 * M_PI)) > near_limit) continue;
    const double shortfall = rater.shortfall(yaw);
    if (shortfall < best) {
      best = shortfall;
      best_share = share;
    }
    if (shortfall <= 0.0) break;
  }
  return best_share;
}

double bestViewOffset(const ViewRater& rater, double planned, double heading, double half_fov) {
  // The least turn first (the plain look-ahead's yaw), then the others from the least turn on.
  std::vector<double> offsets = {std::clamp(std::remainder(planned - heading, 2.0 * M_PI), -half_fov, half_fov)};
  const int n = std::max(1, static_cast<int>(std::ceil(2.0 * half_fov / kYawStepRad)));
  for (int k = 0; k <= n; ++k) offsets.push_back(-half_fov + 2.0 * half_fov * k / n);
  const auto turn = [&](double offset) { return std::abs(std::remainder(heading + offset - planned, 2.0 * M_PI)); };
  std::stable_sort(offsets.begin() + 1, offsets.end(), [&](double a, double b) { return turn(a) < turn(b); });
  double best_offset = offsets.front();
  double best = std::numeric_limits<double>::infinity();
  for (double offset : offsets) {
    const double shortfall = rater.shortfall(heading + offset);
    if (shortfall < best) {
      best = shortfall;
      best_offset = offset;
    }
    if (shortfall <= 0.0) break;
  }
  return best_offset;
}

void smoothYaw(const std::vector<double>& t, double max_rate, std::vector<control::TrajectorySetpoint>* sp) {
  std::vector<control::TrajectorySetpoint>& s = *sp;
  const double dt = (t.back() - t.front()) / static_cast<double>(t.size() - 1);
  const auto half = static_cast<std::ptrdiff_t>(std::lround(0.5 * kYawWindowS / dt));
  const auto n = static_cast<std::ptrdiff_t>(s.size());
  std::vector<double> yaw(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) yaw[i] = s[i].yaw_rad;
  std::vector<double> y(s.size());  // smoothed, unwrapped
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (std::ptrdiff_t j = std::max<std::ptrdiff_t>(0, i - half); j <= std::min(n - 1, i + half); ++j) {
      sum += Eigen::Vector2d(std::cos(yaw[static_cast<std::size_t>(j)]), std::sin(yaw[static_cast<std::size_t>(j)]));
    }
    const auto k = static_cast<std::size_t>(i);
    const double smoothed = sum.norm() > 1e-6 ? std::atan2(sum.y(), sum.x()) : yaw[k];
    y[k] = k == 0 ? smoothed : y[k - 1] + std::remainder(smoothed - y[k - 1], 2.0 * M_PI);
  }
  for (std::size_t i = s.size() - 1; i-- > 0;) {
    const double step = max_rate * (t[i + 1] - t[i]);
    y[i] = std::clamp(y[i], y[i + 1] - step, y[i + 1] + step);
  }
  const double shift = std::remainder(yaw[0] - y[0], 2.0 * M_PI);
  y[0] += shift;
  for (std::size_t i = 1; i < s.size(); ++i) {
    const double step = max_rate * (t[i] - t[i - 1]);
    y[i] = std::clamp(y[i], y[i - 1] - step, y[i - 1] + step);
  }
  for (std::size_t i = 0; i < s.size(); ++i) s[i].yaw_rad = y[i];
  for (std::size_t i = 0; i < s.size(); ++i) {
    const std::size_t lo = i == 0 ? 0 : i - 1;
    const std::size_t hi = std::min(s.size() - 1, i + 1);
    s[i].yaw_rate_rad_s = (y[hi] - y[lo]) / (t[hi] - t[lo]);
  }
}

control::SetpointTrajectory lookWhereUnknown(const control::SetpointTrajectory& trajectory,
                                             const planner::FeatureMap& map, double look_ahead_s, double half_fov_rad,
                                             bool always, double max_yaw_rate, ViewRater* rater, bool best_view) {
  const std::vector<double>& t = trajectory.times();
  std::vector<control::TrajectorySetpoint> sp = trajectory.setpoints();
  if (look_ahead_s <= 0.0 || t.size() < 3) return trajectory;
  bool changed = false;
  double rated_at = -std::numeric_limits<double>::infinity();
  double share = 1.0;   // of the turn toward the way ahead, as last rated
  double offset = 0.0;  // best_view: of the yaw from the way ahead, as last rated
  // The first setpoint keeps its yaw: it is the vehicle's own where the trajectory starts (and the
  // yaw it takes off with); the turn toward the way ahead follows within the rate limit.
  for (std::size_t i = 1; i < sp.size(); ++i) {
    const Eigen::Vector3d far = trajectory.sample(t[i] + look_ahead_s).p_WB;
    const Eigen::Vector3d near = trajectory.sample(t[i] + 0.5 * look_ahead_s).p_WB;
    const Eigen::Vector2d way = (far - sp[i].p_WB).head<2>();
    if (way.norm() < planner::kLookAheadMinWayM || (!always && map.isKnown(far) && map.isKnown(near))) continue;
    // The least turn from the planner's yaw that keeps the way ahead in the camera's field of view.
    const double heading = std::atan2(way.y(), way.x());
    const double planned = sp[i].yaw_rad;
    const double look =
        heading + std::clamp(std::remainder(planned - heading, 2.0 * M_PI), -half_fov_rad, half_fov_rad);
    if (rater != nullptr && t[i] >= rated_at + kRateEveryS - 1e-9) {
      rater->moveTo(sp[i].p_WB);
      if (best_view) {
        offset = bestViewOffset(*rater, planned, heading, half_fov_rad);
      } else {
        const Eigen::Vector2d near_way = (near - sp[i].p_WB).head<2>();
        const double near_heading = near_way.norm() > 0.05 ? std::atan2(near_way.y(), near_way.x()) : heading;
        share = trackableShare(*rater, planned, look, near_heading, half_fov_rad + kNearMarginRad);
      }
      rated_at = t[i];
    }
    if (rater == nullptr) {
      sp[i].yaw_rad = look;
    } else {
      sp[i].yaw_rad = best_view ? heading + offset : planned + share * std::remainder(look - planned, 2.0 * M_PI);
    }
    changed = true;
  }
  if (!changed) return trajectory;
  smoothYaw(t, max_yaw_rate, &sp);
  return control::SetpointTrajectory(t, std::move(sp));
}

namespace {

// Whether p's voxel of `map`, and every one within clear_m of p (horizontally, at p's height), is
// observed or lies within visited_m of a place the vehicle has been.
bool observedAround(const Eigen::Vector3d& p, const planner::FeatureMap& map,
                    const std::vector<Eigen::Vector3d>& visited, double clear_m, double visited_m) {
  const double res = map.resolution();
  const int n = static_cast<int>(std::ceil(clear_m / res));
  const octomap::OcTree& tree = map.occupancy();
  const octomap::point3d c = tree.keyToCoord(tree.coordToKey(planner::toOcto(p)));
  const Eigen::Vector3d centre(c.x(), c.y(), c.z());
  for (int i = -n; i <= n; ++i) {
    for (int j = -n; j <= n; ++j) {
      const Eigen::Vector3d v = centre + res * Eigen::Vector3d(i, j, 0.0);
      if ((i != 0 || j != 0) && (v - p).head<2>().norm() > clear_m) continue;
      if (map.isKnown(v)) continue;
      const bool been = std::any_of(visited.begin(), visited.end(),
                                    [&](const Eigen::Vector3d& q) { return (v - q).head<2>().norm() <= visited_m; });
      if (!been) return false;
    }
  }
  return true;
}

}  // namespace

std::vector<planner::Pose4> stopBeforeUnknown(const std::vector<planner::Pose4>& path, const planner::FeatureMap& map,
                                              const std::vector<Eigen::Vector3d>& visited, const StopRule& rule) {
  std::vector<double> s(path.size(), 0.0);  // along the path
  for (std::size_t i = 1; i < path.size(); ++i) s[i] = s[i - 1] + (path[i].p_WB - path[i - 1].p_WB).norm();
  // The first point the vehicle may not fly to: its own voxel unobserved (and not where the vehicle
  // has been), or, beyond min_m along, any voxel within clear_m.
  std::size_t stop = path.size();
  for (std::size_t i = 1; i < path.size() && stop == path.size(); ++i) {
    const bool open = observedAround(path[i].p_WB, map, visited, 0.0, rule.clear_m);
    if (!open || (s[i] > rule.min_m && !observedAround(path[i].p_WB, map, visited, rule.clear_m, rule.clear_m))) {
      stop = i;
    }
  }
  if (stop == path.size()) return path;
  const std::size_t end = stop - 1;
  std::vector<planner::Pose4> out(path.begin(), path.begin() + static_cast<std::ptrdiff_t>(end) + 1);
  // The way on: the path's point look_m beyond the end (its last where it is shorter).
  std::size_t on = end + 1;
  while (on + 1 < path.size() && s[on] < s[end] + rule.look_m) ++on;
  const Eigen::Vector2d d = (path[on].p_WB - path[end].p_WB).head<2>();
  if (d.norm() > 1e-6) {
    const double heading = std::atan2(d.y(), d.x());
    double& yaw = out.back().yaw_rad;
    const double off = std::remainder(heading - yaw, 2.0 * M_PI);
    if (std::abs(off) > rule.half_fov_rad) yaw = heading - std::copysign(rule.half_fov_rad, off);
  }
  return out;
}

std::optional<control::SetpointTrajectory> renewedViews(const control::SetpointTrajectory& current,
                                                        const control::SetpointTrajectory& plan, double tau_switch,
                                                        double max_rate) {
  const std::vector<double>& t = current.times();
  const std::vector<double>& from_t = plan.times();
  const std::vector<control::TrajectorySetpoint>& from = plan.setpoints();
  std::vector<double> tt;
  std::vector<control::TrajectorySetpoint> sp;
  std::size_t j = 0;  // the plan's point matched last: matches move forward along it
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t[i] < tau_switch - 1e-9) continue;
    control::TrajectorySetpoint s = current.setpoints()[i];
    double best = std::numeric_limits<double>::infinity();
    const std::size_t j0 = j;
    for (std::size_t k = j0; k < from.size() && from_t[k] < from_t[j0] + kRenewWindowS - 1e-9; ++k) {
      const double d = (from[k].p_WB - s.p_WB).squaredNorm();
      if (d < best) {
        best = d;
        j = k;
      }
    }
    if (!sp.empty()) s.yaw_rad = from[j].yaw_rad;  // the first keeps the vehicle's
    tt.push_back(t[i]);
    sp.push_back(s);
  }
  if (tt.size() < 3) return std::nullopt;
  smoothYaw(tt, max_rate, &sp);
  return control::SetpointTrajectory(tt, std::move(sp));
}

control::SetpointTrajectory limitYawRate(const control::SetpointTrajectory& trajectory, double from_s,
                                         double max_rate) {
  const std::vector<double>& t = trajectory.times();
  std::vector<control::TrajectorySetpoint> sp = trajectory.setpoints();
  std::vector<bool> changed(sp.size(), false);
  bool any = false;
  for (std::size_t i = 1; i < sp.size(); ++i) {
    if (t[i] <= from_s) continue;
    const double step = max_rate * (t[i] - t[i - 1]);
    const double wanted = sp[i - 1].yaw_rad + std::remainder(sp[i].yaw_rad - sp[i - 1].yaw_rad, 2.0 * M_PI);
    const double yaw = std::clamp(wanted, sp[i - 1].yaw_rad - step, sp[i - 1].yaw_rad + step);
    if (yaw != wanted) {
      changed[i] = true;
      any = true;
    }
    sp[i].yaw_rad = yaw;
  }
  if (!any) return trajectory;
  for (std::size_t i = 0; i < sp.size(); ++i) {
    const bool near = changed[i] || (i > 0 && changed[i - 1]) || (i + 1 < sp.size() && changed[i + 1]);
    if (!near) continue;
    const std::size_t lo = i == 0 ? 0 : i - 1;
    const std::size_t hi = std::min(sp.size() - 1, i + 1);
    sp[i].yaw_rate_rad_s = std::clamp((sp[hi].yaw_rad - sp[lo].yaw_rad) / (t[hi] - t[lo]), -max_rate, max_rate);
  }
  return control::SetpointTrajectory(t, std::move(sp));
}

double lookAheadHalfFov(const planner::PerceptionPlannerConfig& perception) {
  return planner::lookAheadHalfFov(perception.visibility);
}

control::SetpointTrajectory holdTrajectory(const planner::Pose4& pose, double duration_s, double rate_hz) {
  control::TrajectorySetpoint sp;
  sp.p_WB = pose.p_WB;
  sp.yaw_rad = pose.yaw_rad;
  const int n = std::max(1, static_cast<int>(std::ceil(duration_s * rate_hz - 1e-9)));
  std::vector<double> t;
  for (int i = 0; i <= n; ++i) t.push_back(duration_s * i / n);
  return control::SetpointTrajectory(t, std::vector<control::TrajectorySetpoint>(t.size(), sp));
}

}  // namespace tgnav::harness
