#pragma once
// The voxel columns at the flight height, as the look search (explore.h) sees them: occupied
// within the robot radius of the flight height, observed at it, and what the flight adds (visited
// places count as observed near them; columns given up no longer count as unknown to observe).
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "harness/run/explore.h"
#include "planner/voxel_map.h"

namespace tgnav::harness {

class LookColumns {
 public:
  LookColumns(const planner::VoxelMap& voxels, const LookConfig& config, const LookMemory& memory)
      : res_(voxels.resolution()),
        origin_(voxels.origin().head<2>()),
        nx_(voxels.size().x()),
        ny_(voxels.size().y()),
        occupied_(static_cast<std::size_t>(nx_) * ny_, 0),
        known_(occupied_.size(), 0),
        seen_(occupied_.size(), 0),
        given_up_(occupied_.size(), 0) {
    for (const Eigen::Vector2d& p : memory.given_up) {
      const auto [i, j] = cellOf(p);
      if (inside(i, j)) given_up_[index(i, j)] = 1;
    }
    const double h = config.flight_height_m;
    const int layers = static_cast<int>(std::ceil(config.robot_radius_m / res_));
    for (int j = 0; j < ny_; ++j) {
      for (int i = 0; i < nx_; ++i) {
        const Eigen::Vector2d c = centre(i, j);
        const std::size_t at = index(i, j);
        for (int dz = -layers; dz <= layers; ++dz) {
          if (voxels.state(Eigen::Vector3d(c.x(), c.y(), h + dz * res_)) == planner::VoxelState::kOccupied) {
            occupied_[at] = 1;
          }
        }
        const bool observed = voxels.observed(Eigen::Vector3d(c.x(), c.y(), h));
        double nearest = std::numeric_limits<double>::infinity();  // to a visited place
        if (!observed) {
          for (const Eigen::Vector3d& v : memory.visited) nearest = std::min(nearest, (v.head<2>() - c).norm());
        }
        known_[at] = observed || nearest <= config.visited_clear_m ? 1 : 0;
        seen_[at] = observed || nearest <= config.robot_radius_m ? 1 : 0;
      }
    }
  }
  double res() const { return res_; }
  int nx() const { return nx_; }
  int ny() const { return ny_; }
  Eigen::Vector2d centre(int i, int j) const { return origin_ + res_ * Eigen::Vector2d(i + 0.5, j + 0.5); }
  bool inside(int i, int j) const { return i >= 0 && j >= 0 && i < nx_ && j < ny_; }
  std::size_t index(int i, int j) const { return static_cast<std::size_t>(j) * nx_ + i; }
  std::pair<int, int> cellOf(const Eigen::Vector2d& p) const {
    return {static_cast<int>(std::floor((p.x() - origin_.x()) / res_)),
            static_cast<int>(std::floor((p.y() - origin_.y()) / res_))};
  }
  bool occupied(std::size_t at) const { return occupied_[at] != 0; }
  bool known(std::size_t at) const { return known_[at] != 0; }
  // Unknown, and not given up on: what a view counts as observing.
  bool toObserve(std::size_t at) const { return known_[at] == 0 && given_up_[at] == 0; }
  // Whether the segment from p to q crosses only observed columns (occupied or free; of visited
  // places, only the disc of the robot radius) before its last `end_m`: what lies across unknown
  // space may be hidden by what is not mapped yet.
  bool knownLine(const Eigen::Vector2d& p, const Eigen::Vector2d& q, double end_m) const {
    const double length = (q - p).norm();
    const double dr = 0.5 * res_;
    for (double d = 0.0; d < length - end_m; d += dr) {
      const auto [i, j] = cellOf(p + (d / length) * (q - p));
      if (!inside(i, j) || seen_[index(i, j)] == 0) return false;
    }
    return true;
  }
  // Calls visit(column index) for the columns a ray from p along the unit vector dir reaches within
  // range_m, in steps of half a column, up to the first occupied one (not visited) or the map's edge.
  template <typename Visit>
  void march(const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double range_m, Visit visit) const {
    const double dr = 0.5 * res_;
    for (double d = dr; d <= range_m; d += dr) {
      const auto [i, j] = cellOf(p + d * dir);
      if (!inside(i, j) || occupied(index(i, j))) return;
      visit(index(i, j));
    }
  }
  // No column within `radius` of p occupied, and every one within `known_m` of it observed.
  bool clear(const Eigen::Vector2d& p, double radius, double known_m) const {
    const int reach = static_cast<int>(std::ceil(std::max(radius, known_m) / res_)) + 1;
    const auto [ci, cj] = cellOf(p);
    for (int j = cj - reach; j <= cj + reach; ++j) {
      for (int i = ci - reach; i <= ci + reach; ++i) {
        if (!inside(i, j)) return false;
        // The nearest point of the column's square to p.
        const Eigen::Vector2d lo = origin_ + res_ * Eigen::Vector2d(i, j);
        const double d = (p.cwiseMax(lo).cwiseMin(lo + Eigen::Vector2d::Constant(res_)) - p).norm();
        const std::size_t at = index(i, j);
        if ((d <= radius && occupied(at)) || (d <= known_m && !known(at))) return false;
      }
    }
    return true;
  }

 private:
  double res_;
  Eigen::Vector2d origin_;
  int nx_;
  int ny_;
  std::vector<std::uint8_t> occupied_;
  std::vector<std::uint8_t> known_;  // observed, or within visited_clear_m of a visited place
  std::vector<std::uint8_t> seen_;   // observed, or within the robot radius of one
  std::vector<std::uint8_t> given_up_;
};

// Points along a route's horizontal polyline, at most step_m apart, each with its distance along
// the route from its first point (LookConfig::advance and LookConfig::along).
class RouteStations {
 public:
  RouteStations(const std::vector<Eigen::Vector3d>& route, double step_m) {
    double d = 0.0;
    for (std::size_t i = 0; i < route.size(); ++i) {
      const Eigen::Vector2d p = route[i].head<2>();
      if (i == 0) {
        stations_.emplace_back(0.0, p);
        continue;
      }
      const Eigen::Vector2d q = route[i - 1].head<2>();
      const int n = std::max(1, static_cast<int>(std::ceil((p - q).norm() / step_m)));
      for (int k = 1; k <= n; ++k) stations_.emplace_back(d + (p - q).norm() * k / n, q + (p - q) * k / n);
      d += (p - q).norm();
    }
  }
  // (distance along the route, point), from the first point on.
  const std::vector<std::pair<double, Eigen::Vector2d>>& stations() const { return stations_; }
  // The distance along the route of the station nearest p (the first of equals; 0: no route).
  double along(const Eigen::Vector2d& p) const {
    double nearest = std::numeric_limits<double>::infinity();
    double d = 0.0;
    for (const auto& [at, q] : stations_) {
      const double r = (q - p).squaredNorm();
      if (r < nearest) {
        nearest = r;
        d = at;
      }
    }
    return d;
  }

 private:
  std::vector<std::pair<double, Eigen::Vector2d>> stations_;
};

// trial.look_give_up: per unknown column, how many adopted looks were to observe it
// (LookPlan::watched), and the columns counted often enough to give up (LookMemory::given_up).
class LookWatch {
 public:
  // Counts each centre's column on the map's grid (res_m; the voxel map's origin a multiple of it).
  void note(const std::vector<Eigen::Vector2d>& watched, double res_m) {
    for (const Eigen::Vector2d& c : watched) {
      const std::pair<long, long> key{std::lround(std::floor(c.x() / res_m)), std::lround(std::floor(c.y() / res_m))};
      ++count_.try_emplace(key, c, 0).first->second.second;  // the first centre seen stays
    }
  }
  // The centres of the columns counted at least `after` times (none where after <= 0).
  std::vector<Eigen::Vector2d> givenUp(int after) const {
    std::vector<Eigen::Vector2d> points;
    for (const auto& [key, watch] : count_) {
      if (after > 0 && watch.second >= after) points.push_back(watch.first);
    }
    return points;
  }

 private:
  std::map<std::pair<long, long>, std::pair<Eigen::Vector2d, int>> count_;  // per column: a centre, looks
};

// trial.look_stall_s: whether the looks still bring the vehicle closer to the goal. A plan makes
// progress where its route to the goal (from where it starts) is at least margin_m shorter than the
// shortest so far; the looks have stalled when none has for a while.
class RouteProgress {
 public:
  explicit RouteProgress(double margin_m) : margin_m_(margin_m) {}
  // Notes a plan's route length at t_s; returns the time since the last plan that made progress (0
  // at the first, and at progress).
  double note(double t_s, double route_m) {
    if (!since_s_ || route_m < best_m_ - margin_m_) {
      best_m_ = route_m;
      since_s_ = t_s;
    }
    return t_s - *since_s_;
  }

 private:
  double margin_m_;
  double best_m_ = 0.0;            // the route at the last progress
  std::optional<double> since_s_;  // ... and when (none: no plan yet)
};

}  // namespace tgnav::harness
