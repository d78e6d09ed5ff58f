#include "harness/run/explore.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <queue>
#include <utility>

#include "harness/run/look_columns.h"
#include "planner/covisibility.h"

namespace tgnav::harness {

namespace {

constexpr double kRayStepRad = 2.0 * M_PI / 180.0;  // the rays a cell's views are counted on
// The last stretch of a line of sight to a landmark's voxel that may cross unknown columns (the
// surface's own voxel, and the one before it that depth seldom fills).
constexpr double kSurfaceEndM = 0.2;
constexpr float kRuledOut = 2.0F;  // a view the guard's trips rule out (shortfalls are at most 1)

double wrapAngle(double a) { return std::remainder(a, 2.0 * M_PI); }

// What the views from one cell observe: per ray (kRayStepRad apart from angle 0), the unknown
// columns it first reaches, of the way on and of any.
struct CellSight {
  std::vector<int> way;
  std::vector<int> near;  // ... within LookConfig::near_m of the way on (way included)
  std::vector<int> any;
};

// Which unknown columns a look counts: any, near the way on, or of the way on (the levels of
// LookSearch's on_way_).
enum class Tier : std::uint8_t { kAny = 0, kNear = 1, kWay = 2 };

// A view from a cell (LookSearch::ratings): its shortfall, and the detections it expects.
struct Rated {
  float shortfall, detections;
};

// The search of planLook() over (cell, yaw) states: state = cell * yaws + yaw index.
class LookSearch {
 public:
  LookSearch(const planner::VoxelMap& voxels, ViewRater& rater, const planner::Pose4& start, const LookMemory& memory,
             const LookConfig& config)
      : config_(config),
        columns_(voxels, config, memory),
        rater_(rater),
        tripped_(memory.tripped),
        lo_(voxels.origin().head<2>()),
        start_(start) {
    const Eigen::Vector2d extent = voxels.size().head<2>().cast<double>() * voxels.resolution();
    gx_ = std::max(1, static_cast<int>(std::floor(extent.x() / config.cell_m)));
    gy_ = std::max(1, static_cast<int>(std::floor(extent.y() / config.cell_m)));
    yaws_ = std::max(1, static_cast<int>(std::lround(2.0 * M_PI / config.yaw_step_rad)));
    step_ = 2.0 * M_PI / yaws_;
    const std::size_t cells = static_cast<std::size_t>(gx_) * gy_;
    clear_.assign(cells, -1);
    rated_.resize(cells);
    sight_.resize(cells);
    stamp_.assign(static_cast<std::size_t>(columns_.nx()) * columns_.ny(), -1);
    const Eigen::Vector2d s = start.p_WB.head<2>();
    const int si = std::clamp(static_cast<int>(std::floor((s.x() - lo_.x()) / config.cell_m)), 0, gx_ - 1);
    const int sj = std::clamp(static_cast<int>(std::floor((s.y() - lo_.y()) / config.cell_m)), 0, gy_ - 1);
    start_cell_ = sj * gx_ + si;
    const int k = static_cast<int>(std::lround(std::remainder(start.yaw_rad, 2.0 * M_PI) / step_ + yaws_)) % yaws_;
    start_state_ = start_cell_ * yaws_ + k;
  }

  // Dijkstra from the start (allowed as it is, whatever its view) up to config.max_cost_m: a move
  // keeps the yaw and goes to one of the 8 neighbouring cells, clear, with that yaw trackable; a
  // turn changes the yaw by one step, trackable, where it is.
  void run() {
    cost_.assign(static_cast<std::size_t>(gx_) * gy_ * yaws_, std::numeric_limits<double>::infinity());
    prev_.assign(cost_.size(), -1);
    std::vector<std::uint8_t> done(cost_.size(), 0);
    using Entry = std::pair<double, int>;
    std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
    const auto relax = [&](int from, int to, double c) {
      if (c > config_.max_cost_m || c >= cost_[at(to)]) return;
      cost_[at(to)] = c;
      prev_[at(to)] = from;
      open.emplace(c, to);
    };
    cost_[at(start_state_)] = 0.0;
    open.emplace(0.0, start_state_);
    const double turn_cost = step_ * config_.turn_m_per_rad;
    while (!open.empty()) {
      const auto [c, s] = open.top();
      open.pop();
      if (done[at(s)]) continue;
      done[at(s)] = 1;
      settled_.push_back(s);
      const int cell = s / yaws_;
      const int k = s % yaws_;
      for (int dk : {-1, 1}) {
        const int k2 = (k + dk + yaws_) % yaws_;
        if (trackable(cell, k2)) relax(s, cell * yaws_ + k2, c + turn_cost);
      }
      const int ci = cell % gx_;
      const int cj = cell / gx_;
      for (int dj = -1; dj <= 1; ++dj) {
        for (int di = -1; di <= 1; ++di) {
          if ((di == 0 && dj == 0) || ci + di < 0 || cj + dj < 0 || ci + di >= gx_ || cj + dj >= gy_) continue;
          const int next = (cj + dj) * gx_ + ci + di;
          if (!clear(next) || !trackable(next, k)) continue;
          relax(s, next * yaws_ + k, c + config_.cell_m * std::hypot(di, dj));
        }
      }
    }
  }

  // The least-cost state it reached in the cell of p (-1: none).
  int reached(const Eigen::Vector2d& p) const {
    const int cell = cellAt(p);
    if (cell < 0) return -1;
    for (const int s : settled_) {
      if (s / yaws_ == cell) return s;  // settled in order of cost
    }
    return -1;
  }

  // The least-cost state in the cell farthest along `route` that the search reached, at least min_m
  // along it from its first point, and not within config.repeat_m of a place flown to before (at
  // any yaw: it advances, it does not look); -1: none.
  int advance(const std::vector<Eigen::Vector3d>& route, double min_m,
              const std::vector<planner::Pose4>& looked) const {
    std::vector<int> first(static_cast<std::size_t>(gx_) * gy_, -1);  // per cell
    for (const int s : settled_) {
      int& f = first[at(s / yaws_)];
      if (f >= 0 || s / yaws_ == start_cell_ || !holds(s)) continue;
      const Eigen::Vector2d p = place(s / yaws_);
      const bool flown = std::any_of(looked.begin(), looked.end(), [&](const planner::Pose4& l) {
        return (l.p_WB.head<2>() - p).norm() <= config_.repeat_m;
      });
      if (!flown) f = s;
    }
    const RouteStations along(route, 0.5 * config_.cell_m);
    for (auto it = along.stations().rbegin(); it != along.stations().rend() && it->first >= min_m; ++it) {
      const int cell = cellAt(it->second);
      if (cell >= 0 && first[at(cell)] >= 0) return first[at(cell)];
    }
    return -1;
  }

  // LookConfig::along: chooseLook() orders its looks by how far along `route` their cells lie.
  void orderAlong(const std::vector<Eigen::Vector3d>& route) { along_.emplace(route, 0.5 * config_.cell_m); }

  // The look pose among the states reached (planLook()) whose view observes at least min_seen
  // unknown columns of `tier` (out->seen); -1: none. markWay() first.
  int chooseLook(Tier tier, int min_seen, const std::vector<planner::Pose4>& looked, LookPlan* out) {
    std::vector<int> seen(settled_.size(), 0);
    int best = 0;
    for (std::size_t n = 0; n < settled_.size(); ++n) {
      const int s = settled_[n];
      // The view it has now, one flown to, or one too poor to hold (LookConfig::hold_margin).
      if (s == start_state_ || repeats(s, looked) || !holds(s)) continue;
      const CellSight& cs = sight(s / yaws_);
      seen[n] = seenAlong(tier == Tier::kWay ? cs.way : tier == Tier::kNear ? cs.near : cs.any, yawOf(s % yaws_));
      best = std::max(best, seen[n]);
    }
    if (best <= 0 || best < min_seen) return -1;
    // The nearest that sees at least half as much as the best (and min_seen); at equal cost, the one
    // that sees more. With LookConfig::along, the one farthest along the route first (in cells).
    int chosen = -1;
    long chosen_bin = 0;
    for (std::size_t n = 0; n < settled_.size(); ++n) {
      if (2 * seen[n] < best || seen[n] < min_seen) continue;
      const double c = cost_[at(settled_[n])];
      const long bin = along_ ? std::lround(std::floor(along_->along(place(settled_[n] / yaws_)) / config_.cell_m)) : 0;
      if (chosen >= 0 && bin <= chosen_bin) {
        const double c0 = cost_[at(settled_[at(chosen)])];
        if (bin < chosen_bin || c > c0 + 1e-9 || (c >= c0 - 1e-9 && seen[n] <= seen[at(chosen)])) continue;
      }
      chosen = static_cast<int>(n);
      chosen_bin = bin;
    }
    out->seen = seen[at(chosen)];
    return settled_[at(chosen)];
  }

  // LookConfig::probe: among the cells reached, the view of at least min_seen unknown columns of the
  // way on, not ruled out by the guard, not flown to before and not the start's own, that the model
  // rates least short (at a tie, the nearer). Returns that (cell, yaw) state, sets *from to the
  // least-cost state reached in its cell and out->seen; -1: none. markWay() first.
  int probe(int min_seen, const std::vector<planner::Pose4>& looked, int* from, LookPlan* out) {
    std::vector<std::uint8_t> asked(static_cast<std::size_t>(gx_) * gy_, 0);
    int chosen = -1;
    float least = kRuledOut;
    for (const int s : settled_) {  // in order of cost: the first state in a cell is its nearest
      const int cell = s / yaws_;
      if (asked[at(cell)]) continue;
      asked[at(cell)] = 1;
      const std::vector<Rated>& rated = ratings(cell);
      const CellSight& cs = sight(cell);
      for (int k = 0; k < yaws_; ++k) {
        const int view = cell * yaws_ + k;
        if (rated[at(k)].shortfall >= least || view == start_state_ || repeats(view, looked)) continue;
        const int seen = seenAlong(cs.way, yawOf(k));
        if (seen < min_seen) continue;
        chosen = view;
        least = rated[at(k)].shortfall;
        *from = s;
        out->seen = seen;
      }
    }
    return chosen;
  }

  // The path to `from` (pathTo()), then a turn where it ends to the yaw of `view` (in its cell).
  std::vector<planner::Pose4> pathTurningTo(int from, int view) const {
    std::vector<planner::Pose4> path = pathTo(from);
    planner::Pose4 turned = path.back();
    turned.yaw_rad += wrapAngle(yawOf(view % yaws_) - turned.yaw_rad);
    path.push_back(turned);
    return path;
  }

  // The centres of the columns of `tier` the view of `state` counts (sight()).
  std::vector<Eigen::Vector2d> watched(int state, Tier tier) const {
    const int cell = state / yaws_;
    const Eigen::Vector2d from = place(cell);
    const int rays = static_cast<int>(std::lround(2.0 * M_PI / kRayStepRad));
    const int half = static_cast<int>(std::floor(config_.half_hfov_rad / kRayStepRad));
    const int mid = static_cast<int>(std::lround(yawOf(state % yaws_) / kRayStepRad));
    const auto needed = static_cast<std::uint8_t>(tier);
    std::vector<std::size_t> columns;
    for (int r = mid - half; r <= mid + half; ++r) {
      const double a = ((r % rays + rays) % rays) * kRayStepRad;
      columns_.march(from, Eigen::Vector2d(std::cos(a), std::sin(a)), config_.observe_range_m, [&](std::size_t c) {
        if (columns_.toObserve(c) && on_way_[c] >= needed) columns.push_back(c);
      });
    }
    std::sort(columns.begin(), columns.end());
    columns.erase(std::unique(columns.begin(), columns.end()), columns.end());
    std::vector<Eigen::Vector2d> centres;
    centres.reserve(columns.size());
    for (const std::size_t c : columns) {
      centres.push_back(columns_.centre(static_cast<int>(c % columns_.nx()), static_cast<int>(c / columns_.nx())));
    }
    return centres;
  }

  // The unknown columns within config.way_clear_m of the way on (2), or within config.near_m (1).
  void markWay(const std::vector<Eigen::Vector3d>& way_on) {
    on_way_.assign(static_cast<std::size_t>(columns_.nx()) * columns_.ny(), 0);
    const double near_m = std::max(config_.near_m, config_.way_clear_m);
    const int reach = static_cast<int>(std::ceil(near_m / columns_.res()));
    for (const Eigen::Vector3d& p : way_on) {
      const auto [ci, cj] = columns_.cellOf(p.head<2>());
      for (int j = cj - reach; j <= cj + reach; ++j) {
        for (int i = ci - reach; i <= ci + reach; ++i) {
          if (!columns_.inside(i, j)) continue;
          const double d = (columns_.centre(i, j) - p.head<2>()).norm();
          const std::size_t c = columns_.index(i, j);
          if (d > near_m || columns_.known(c) || columns_.occupied(c)) continue;
          const Tier tier = d <= config_.way_clear_m ? Tier::kWay : Tier::kNear;
          on_way_[c] = std::max(on_way_[c], static_cast<std::uint8_t>(tier));
        }
      }
    }
  }

  // The poses from the start to `target`: the start as given, cell centres at the flight height,
  // yaws unwrapped from the start's; straight moves at one yaw merged.
  std::vector<planner::Pose4> pathTo(int target) const {
    std::vector<int> chain;
    for (int s = target; s >= 0; s = prev_[at(s)]) chain.push_back(s);
    std::reverse(chain.begin(), chain.end());
    std::vector<planner::Pose4> poses{start_};
    poses.front().p_WB.z() = config_.flight_height_m;
    for (std::size_t n = 1; n < chain.size(); ++n) {
      const Eigen::Vector2d c = place(chain[n] / yaws_);
      const double yaw = poses.back().yaw_rad + wrapAngle(yawOf(chain[n] % yaws_) - poses.back().yaw_rad);
      poses.push_back(planner::Pose4{Eigen::Vector3d(c.x(), c.y(), config_.flight_height_m), yaw});
    }
    std::vector<planner::Pose4> path;
    for (const planner::Pose4& p : poses) {
      if (path.size() >= 2 && straight(path[path.size() - 2], path.back(), p)) path.pop_back();
      path.push_back(p);
    }
    return path;
  }

  // LookConfig::tracked_inliers: lowers the rater's floor to what the current view calibrates;
  // returns the floor in force.
  double calibrateFloor() {
    const double floor = rater_.detectionFloor();
    if (config_.tracked_inliers <= 0 || floor <= 0.0) return floor;
    rateFrom(start_.p_WB.head<2>());
    const double expected = rater_.detections(start_.yaw_rad);
    const double calibrated = config_.floor_inliers * expected / config_.tracked_inliers;
    if (calibrated < floor) rater_.setDetectionFloor(calibrated);
    return rater_.detectionFloor();
  }

  double cost(int state) const { return cost_[at(state)]; }
  int states() const { return static_cast<int>(settled_.size()); }
  int cellsRated() const { return cells_rated_; }

 private:
  static std::size_t at(int i) { return static_cast<std::size_t>(i); }
  // The cell of p; -1 outside the grid.
  int cellAt(const Eigen::Vector2d& p) const {
    const int i = static_cast<int>(std::floor((p.x() - lo_.x()) / config_.cell_m));
    const int j = static_cast<int>(std::floor((p.y() - lo_.y()) / config_.cell_m));
    return i < 0 || j < 0 || i >= gx_ || j >= gy_ ? -1 : j * gx_ + i;
  }
  double yawOf(int k) const { return wrapAngle(k * step_); }
  Eigen::Vector2d centre(int cell) const {
    const int i = cell % gx_;
    const int j = cell / gx_;  // the row
    return lo_ + config_.cell_m * Eigen::Vector2d(i + 0.5, j + 0.5);
  }
  // Where the vehicle is in a cell: its centre, or, in the start's, the start itself.
  Eigen::Vector2d place(int cell) const {
    return cell == start_cell_ ? Eigen::Vector2d(start_.p_WB.head<2>()) : centre(cell);
  }

  bool clear(int cell) {
    std::int8_t& c = clear_[at(cell)];
    if (c < 0) c = columns_.clear(centre(cell), config_.robot_radius_m + columns_.res(), config_.known_m) ? 1 : 0;
    return c == 1;
  }

  // The rater moved to c: a landmark counts only where the way to it runs through observed space
  // (the voxel map's line of sight passes through unknown space, where a surface not yet mapped may
  // hide it).
  void rateFrom(const Eigen::Vector2d& c) {
    rater_.moveTo(Eigen::Vector3d(c.x(), c.y(), config_.flight_height_m), [&](const planner::LandmarkVoxel& v) {
      return columns_.knownLine(c, v.centre_W.head<2>(), kSurfaceEndM);
    });
  }

  // Per yaw, how far the view from the cell falls short of trackable (ViewRater::shortfall; 0:
  // trackable), kRuledOut where the guard tripped on it, and the detections it expects.
  const std::vector<Rated>& ratings(int cell) {
    std::vector<Rated>& rated = rated_[at(cell)];
    if (!rated.empty()) return rated;
    const Eigen::Vector2d c = place(cell);
    rateFrom(c);
    rated.resize(at(yaws_));
    for (int k = 0; k < yaws_; ++k) {
      // A look guard's trip (GuardEvent::predicted) rules out views near the view ahead, not the held cell's.
      const bool ruled_out = std::any_of(tripped_.begin(), tripped_.end(), [&](const GuardEvent& e) {
        return !(e.predicted() && cell == start_cell_) &&
               trippedView(e, c, yawOf(k), config_.tripped_m, config_.half_hfov_rad);
      });
      const ViewRating r = rater_.rate(yawOf(k));
      rated[at(k)] = {ruled_out ? kRuledOut : static_cast<float>(r.shortfall), static_cast<float>(r.detections)};
    }
    ++cells_rated_;
    return rated;
  }
  bool trackable(int cell, int k) { return ratings(cell)[at(k)].shortfall <= 0.0F; }
  // A settled state's view is one to stop and hold (LookConfig::hold_margin); every state settled
  // but the start was rated trackable on the way to it, so its cell's views are rated.
  bool holds(int state) const {
    const std::vector<Rated>& rated = rated_[at(state / yaws_)];
    return config_.hold_margin <= 0.0 || (!rated.empty() && rated[at(state % yaws_)].detections >=
                                                                rater_.detectionFloor() * (1.0 + config_.hold_margin));
  }

  // What the cell's views observe: rays kRayStepRad apart to config.observe_range_m, through
  // unknown columns (optimistic), stopping at occupied ones.
  const CellSight& sight(int cell) {
    CellSight& s = sight_[at(cell)];
    if (!s.way.empty()) return s;
    const int rays = static_cast<int>(std::lround(2.0 * M_PI / kRayStepRad));
    s.way.assign(at(rays), 0);
    s.near.assign(at(rays), 0);
    s.any.assign(at(rays), 0);
    const Eigen::Vector2d from = place(cell);
    for (int r = 0; r < rays; ++r) {
      const Eigen::Vector2d dir(std::cos(r * kRayStepRad), std::sin(r * kRayStepRad));
      columns_.march(from, dir, config_.observe_range_m, [&](std::size_t c) {
        if (!columns_.toObserve(c) || stamp_[c] == cell) return;
        stamp_[c] = cell;
        ++s.any[at(r)];
        if (on_way_[c] >= static_cast<std::uint8_t>(Tier::kNear)) ++s.near[at(r)];
        if (on_way_[c] == static_cast<std::uint8_t>(Tier::kWay)) ++s.way[at(r)];
      });
    }
    return s;
  }

  // The unknown columns a view along yaw observes, of those per ray.
  int seenAlong(const std::vector<int>& per_ray, double yaw) const {
    const int rays = static_cast<int>(per_ray.size());
    const int half = static_cast<int>(std::floor(config_.half_hfov_rad / kRayStepRad));
    const int mid = static_cast<int>(std::lround(wrapAngle(yaw) / kRayStepRad));
    int n = 0;
    for (int r = mid - half; r <= mid + half; ++r) n += per_ray[at((r % rays + rays) % rays)];
    return n;
  }

  bool repeats(int state, const std::vector<planner::Pose4>& looked) const {
    const Eigen::Vector2d p = place(state / yaws_);
    return std::any_of(looked.begin(), looked.end(), [&](const planner::Pose4& l) {
      return (l.p_WB.head<2>() - p).norm() <= config_.repeat_m &&
             std::abs(wrapAngle(l.yaw_rad - yawOf(state % yaws_))) <= 1.01 * step_;
    });
  }

  // b lies on the straight line from a on to c, all three at one yaw.
  static bool straight(const planner::Pose4& a, const planner::Pose4& b, const planner::Pose4& c) {
    const Eigen::Vector2d ab = (b.p_WB - a.p_WB).head<2>();
    const Eigen::Vector2d bc = (c.p_WB - b.p_WB).head<2>();
    return ab.norm() > 1e-9 && bc.norm() > 1e-9 && std::abs(ab.x() * bc.y() - ab.y() * bc.x()) < 1e-9 &&
           ab.dot(bc) > 0.0 && a.yaw_rad == b.yaw_rad && b.yaw_rad == c.yaw_rad;
  }

  const LookConfig& config_;
  const LookColumns columns_;
  ViewRater& rater_;
  const std::vector<GuardEvent>& tripped_;
  Eigen::Vector2d lo_;
  planner::Pose4 start_;
  int gx_ = 1;
  int gy_ = 1;
  int yaws_ = 1;
  double step_ = 2.0 * M_PI;
  int start_cell_ = 0;
  int start_state_ = 0;
  std::vector<std::int8_t> clear_;         // per cell: -1 not asked yet
  std::vector<std::vector<Rated>> rated_;  // per cell, per yaw: ratings() (empty: not rated yet)
  std::vector<CellSight> sight_;           // per cell (empty: not cast yet)
  std::vector<int> stamp_;                 // per column: the cell whose rays reached it last
  std::vector<std::uint8_t> on_way_;       // per column: its Tier (kAny: neither near nor on)
  std::vector<double> cost_;               // per state
  std::vector<int> prev_;                  // per state
  std::vector<int> settled_;               // in order of cost
  std::optional<RouteStations> along_;     // LookConfig::along (none: the nearest look)
  int cells_rated_ = 0;
};

}  // namespace

LookPlan planLook(const planner::VoxelMap& voxels, ViewRater& rater, const planner::Pose4& start,
                  const Eigen::Vector3d& goal, const std::vector<Eigen::Vector3d>& route,
                  const std::vector<Eigen::Vector3d>& way_on, const LookMemory& memory, const LookConfig& config) {
  LookPlan out;
  // The goal counts as a visited place: the mission gives it free, as it gives the start (the
  // planners' snapshot marks both free). Else a goal within known_m of space never observed, a
  // strip the views toward it leave, is a cell the search never enters (detour-1014, -5007).
  LookMemory free_goal = memory;
  free_goal.visited.push_back(goal);
  LookSearch search(voxels, rater, start, free_goal, config);
  out.floor = search.calibrateFloor();
  search.run();
  out.states = search.states();
  int target = search.reached(goal.head<2>());
  out.goal = target >= 0;
  Tier tier = Tier::kWay;
  int probe_from = -1;  // LookConfig::probe: the state reached that turns to the probed view
  if (!out.goal) {
    search.markWay(way_on);
    if (config.along) search.orderAlong(route);
    // With advance, a look must observe at least the robot's footprint of unknown columns: less
    // opens no way for it.
    const double footprint = M_PI * config.robot_radius_m * config.robot_radius_m;
    const int min_seen =
        config.advance ? static_cast<int>(std::ceil(footprint / (voxels.resolution() * voxels.resolution()))) : 1;
    target = search.chooseLook(Tier::kWay, min_seen, memory.looked, &out);
    if (target < 0 && config.advance) {
      target = search.advance(route, config.advance_min_m, memory.looked);
      out.advance = target >= 0;
      if (target < 0 && config.probe && planner::polylineLength3(way_on) <= config.near_m) {
        target = search.probe(min_seen, memory.looked, &probe_from, &out);
      }
      out.probe = target >= 0 && !out.advance;
      if (!out.probe) tier = Tier::kNear;
      if (target < 0) target = search.chooseLook(tier, min_seen, memory.looked, &out);
    }
    if (target < 0 && !out.advance) {
      tier = Tier::kAny;
      target = search.chooseLook(tier, min_seen, memory.looked, &out);
    }
    out.way = target >= 0 && tier == Tier::kWay;
    out.near = target >= 0 && tier == Tier::kNear && !out.advance;
  }
  out.cells = search.cellsRated();
  if (target < 0) return out;
  out.cost_m = search.cost(out.probe ? probe_from : target);
  out.path = out.probe ? search.pathTurningTo(probe_from, target) : search.pathTo(target);
  if (!out.goal && !out.advance) out.watched = search.watched(target, tier);
  if (out.goal) {
    if (out.path.size() == 1) out.path.push_back(start);  // already in the goal's cell
    out.path.back().p_WB = Eigen::Vector3d(goal.x(), goal.y(), config.flight_height_m);
  }
  return out;
}

}  // namespace tgnav::harness
