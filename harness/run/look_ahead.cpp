#include "harness/run/look_ahead.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

namespace tgnav::harness {

namespace {
constexpr double kYawWindowS = 1.0;                 // the smoothing window
constexpr double kRateEveryS = 0.2;                 // trajectory time between two rated positions
constexpr double kYawStepRad = 5.0 * M_PI / 180.0;  // between two rated yaws
// The way half the look-ahead ahead stays this far beyond the way ahead's own limit (half_fov_rad,
// 10 deg inside the image's edge): 5 deg inside the edge.
constexpr double kNearMarginRad = 5.0 * M_PI / 180.0;
}  // namespace

void ViewRater::moveTo(const Eigen::Vector3d& p_WB) {
  p_WB_ = p_WB;
  points_ = planner::aggregateSlots(*voxels_, voxels_->visibleSlots(p_WB, *visibility_));
}

double ViewRater::shortfall(double yaw_rad) const {
  planner::ViewSupport support;
  planner::poseInformation(planner::cameraPosition(p_WB_, yaw_rad, *visibility_), yaw_rad, points_, *visibility_,
                           *information_, &support);
  return planner::gateShortfall(support, *information_);
}

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
                                             bool always, double max_yaw_rate, ViewRater* rater) {
  const std::vector<double>& t = trajectory.times();
  std::vector<control::TrajectorySetpoint> sp = trajectory.setpoints();
  if (look_ahead_s <= 0.0 || t.size() < 3) return trajectory;
  bool changed = false;
  double rated_at = -std::numeric_limits<double>::infinity();
  double share = 1.0;  // of the turn toward the way ahead, as last rated
  // The first setpoint keeps its yaw: it is the vehicle's own where the trajectory starts (and the
  // yaw it takes off with); the turn toward the way ahead follows within the rate limit.
  for (std::size_t i = 1; i < sp.size(); ++i) {
    const Eigen::Vector3d far = trajectory.sample(t[i] + look_ahead_s).p_WB;
    const Eigen::Vector3d near = trajectory.sample(t[i] + 0.5 * look_ahead_s).p_WB;
    const Eigen::Vector2d way = (far - sp[i].p_WB).head<2>();
    if (way.norm() < 0.1 || (!always && map.isKnown(far) && map.isKnown(near))) continue;
    // The least turn from the planner's yaw that keeps the way ahead in the camera's field of view.
    const double heading = std::atan2(way.y(), way.x());
    const double planned = sp[i].yaw_rad;
    const double look =
        heading + std::clamp(std::remainder(planned - heading, 2.0 * M_PI), -half_fov_rad, half_fov_rad);
    if (rater != nullptr && t[i] >= rated_at + kRateEveryS - 1e-9) {
      rater->moveTo(sp[i].p_WB);
      const Eigen::Vector2d near_way = (near - sp[i].p_WB).head<2>();
      const double near_heading = near_way.norm() > 0.05 ? std::atan2(near_way.y(), near_way.x()) : heading;
      share = trackableShare(*rater, planned, look, near_heading, half_fov_rad + kNearMarginRad);
      rated_at = t[i];
    }
    sp[i].yaw_rad = rater != nullptr ? planned + share * std::remainder(look - planned, 2.0 * M_PI) : look;
    changed = true;
  }
  if (!changed) return trajectory;
  smoothYaw(t, max_yaw_rate, &sp);
  return control::SetpointTrajectory(t, std::move(sp));
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

}  // namespace tgnav::harness
