#include "planner/topological_planner.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <stdexcept>
#include <tuple>

#include "planner/check.h"

namespace tgnav::planner {

namespace {

double windingOfSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& z) {
  const double d = std::atan2(b.y() - z.y(), b.x() - z.x()) - std::atan2(a.y() - z.y(), a.x() - z.x());
  return std::remainder(d, 2.0 * M_PI);
}

// One point inside every connected component (8-connected) of occupied cells that does not
// touch the map's edge (those merge with the outside, which no path can wind around).
std::vector<Eigen::Vector2d> obstacleComponentPoints(const OccupancyGrid2D& grid) {
  std::vector<int> label(grid.occupied.size(), -1);
  std::vector<Eigen::Vector2d> points;
  std::vector<Eigen::Vector2i> stack;
  for (int y = 0; y < grid.height; ++y) {
    for (int x = 0; x < grid.width; ++x) {
      if (!grid.isOccupied(x, y) || label[grid.index(x, y)] >= 0) continue;
      bool touches_edge = false;
      stack.assign(1, Eigen::Vector2i(x, y));
      label[grid.index(x, y)] = 1;
      while (!stack.empty()) {
        const Eigen::Vector2i c = stack.back();
        stack.pop_back();
        touches_edge = touches_edge || c.x() == 0 || c.y() == 0 || c.x() == grid.width - 1 || c.y() == grid.height - 1;
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const int nx = c.x() + dx;
            const int ny = c.y() + dy;
            if (!grid.inside(nx, ny) || !grid.isOccupied(nx, ny) || label[grid.index(nx, ny)] >= 0) continue;
            label[grid.index(nx, ny)] = 1;
            stack.emplace_back(nx, ny);
          }
        }
      }
      if (!touches_edge) points.push_back(grid.centreOf(x, y));
    }
  }
  return points;
}

// Partial path of the best-first search, stored as a tree of parents.
struct SearchNode {
  double cost;
  int vertex;
  int edge;    // edge taken to reach `vertex` (-1 at the root)
  int parent;  // index into the node pool
};

const int kDx8[8] = {1, 0, -1, 0, 1, -1, -1, 1};
const int kDy8[8] = {0, 1, 0, -1, 1, 1, -1, -1};

// A step from (x, y) in direction k between free cells, diagonals only past two free side cells
// (no corner cutting).
template <typename Free>
bool canStep(const OccupancyGrid2D& g, const Free& free, int x, int y, int k) {
  const int nx = x + kDx8[k];
  const int ny = y + kDy8[k];
  if (!g.inside(nx, ny) || !free(nx, ny)) return false;
  return k < 4 || (free(x + kDx8[k], y) && free(x, y + kDy8[k]));
}

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(n) {
    for (int i = 0; i < n; ++i) parent[i] = i;
  }
  int find(int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  bool unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    parent[std::max(a, b)] = std::min(a, b);
    return true;
  }
};

// Labels the 8-connected components of the cells where `member` holds; -1 elsewhere.
template <typename Member, typename Step>
int labelComponents(const OccupancyGrid2D& g, const Member& member, const Step& step, std::vector<int>* label) {
  label->assign(static_cast<std::size_t>(g.width) * g.height, -1);
  int n = 0;
  std::vector<int> stack;
  for (int y = 0; y < g.height; ++y) {
    for (int x = 0; x < g.width; ++x) {
      if (!member(x, y) || (*label)[g.index(x, y)] >= 0) continue;
      (*label)[g.index(x, y)] = n;
      stack.assign(1, static_cast<int>(g.index(x, y)));
      while (!stack.empty()) {
        const int i = stack.back();
        stack.pop_back();
        const int cx = i % g.width;
        const int cy = i / g.width;
        for (int k = 0; k < 8; ++k) {
          if (!step(cx, cy, k)) continue;
          const std::size_t j = g.index(cx + kDx8[k], cy + kDy8[k]);
          if ((*label)[j] >= 0) continue;
          (*label)[j] = n;
          stack.push_back(static_cast<int>(j));
        }
      }
      ++n;
    }
  }
  return n;
}

// The GVD breaks where the working grid cannot resolve a passage (and the clearance filter or
// spur pruning can cut it): joins the skeleton's pieces within each connected free region by
// shortest chains of free cells (a spanning tree over the pieces, so no cycle and hence no
// homology class is invented), and gives a region with no skeleton its clearest cell. Returns
// the number of cells added.
int joinSkeleton(const DistanceField& field, const std::vector<std::uint8_t>& free_mask,
                 std::vector<std::uint8_t>* sk) {
  const OccupancyGrid2D& g = field.grid();
  auto free = [&](int x, int y) { return free_mask[g.index(x, y)] != 0; };
  auto step = [&](int x, int y, int k) { return canStep(g, free, x, y, k); };
  std::vector<int> region;
  const int n_regions = labelComponents(g, free, step, &region);
  int added = 0;
  std::vector<int> best(n_regions, -1);
  std::vector<std::uint8_t> has_skeleton(n_regions, 0);
  for (std::size_t i = 0; i < sk->size(); ++i) {
    if (region[i] < 0) continue;
    if ((*sk)[i]) has_skeleton[region[i]] = 1;
    const int x = static_cast<int>(i) % g.width;
    const int y = static_cast<int>(i) / g.width;
    const int b = best[region[i]];
    if (b < 0 || field.centreDistance(x, y) > field.centreDistance(b % g.width, b / g.width)) {
      best[region[i]] = static_cast<int>(i);
    }
  }
  for (int r = 0; r < n_regions; ++r) {
    if (!has_skeleton[r]) {
      (*sk)[best[r]] = 1;
      ++added;
    }
  }
  // Pieces: 8-connected skeleton components (as the graph tracer follows them).
  std::vector<int> piece;
  auto on_skeleton = [&](int x, int y) { return (*sk)[g.index(x, y)] != 0; };
  const int n_pieces = labelComponents(
      g, on_skeleton,
      [&](int x, int y, int k) {
        const int nx = x + kDx8[k];
        const int ny = y + kDy8[k];
        return g.inside(nx, ny) && on_skeleton(nx, ny);
      },
      &piece);
  if (n_pieces <= n_regions) return added;  // one piece per region at most: nothing to join
  // Breadth-first from every piece at once; where two pieces' fronts meet is a candidate chain.
  std::vector<int> parent(sk->size(), -1);
  std::vector<int> dist(sk->size(), -1);
  std::vector<int> queue;
  for (std::size_t i = 0; i < sk->size(); ++i) {
    if ((*sk)[i]) {
      dist[i] = 0;
      queue.push_back(static_cast<int>(i));
    }
  }
  for (std::size_t q = 0; q < queue.size(); ++q) {
    const int i = queue[q];
    const int x = i % g.width;
    const int y = i / g.width;
    for (int k = 0; k < 8; ++k) {
      if (!step(x, y, k)) continue;
      const std::size_t j = g.index(x + kDx8[k], y + kDy8[k]);
      if (dist[j] >= 0) continue;
      dist[j] = dist[i] + 1;
      parent[j] = i;
      piece[j] = piece[i];
      queue.push_back(static_cast<int>(j));
    }
  }
  struct Chain {
    int cost, a, b;
  };
  std::vector<Chain> chains;
  for (int i : queue) {
    const int x = i % g.width;
    const int y = i / g.width;
    for (int k = 0; k < 8; ++k) {
      if (!step(x, y, k)) continue;
      const int j = static_cast<int>(g.index(x + kDx8[k], y + kDy8[k]));
      if (piece[j] > piece[i]) chains.push_back({dist[i] + dist[j] + 1, i, j});
    }
  }
  std::sort(chains.begin(), chains.end(),
            [](const Chain& u, const Chain& v) { return std::tie(u.cost, u.a, u.b) < std::tie(v.cost, v.a, v.b); });
  UnionFind pieces(n_pieces);
  for (const Chain& c : chains) {
    if (!pieces.unite(piece[c.a], piece[c.b])) continue;
    for (int end : {c.a, c.b}) {
      for (int i = end; i >= 0 && !(*sk)[i]; i = parent[i]) {
        (*sk)[i] = 1;
        ++added;
      }
    }
  }
  return added;
}

// Where the working grid is coarse for the clearance (a point robot), the GVD can link two cells
// diagonally across the corner where two obstacle squares touch: a passage of zero width. Both
// cells leave the skeleton; joinSkeleton() reconnects what is connected without the pinch.
void cutPinches(const OccupancyGrid2D& g, const std::vector<std::uint8_t>& free_mask, std::vector<std::uint8_t>* sk) {
  auto free = [&](int x, int y) { return g.inside(x, y) && free_mask[g.index(x, y)] != 0; };
  std::vector<std::size_t> cut;
  for (int y = 0; y < g.height; ++y) {
    for (int x = 0; x < g.width; ++x) {
      if (!(*sk)[g.index(x, y)]) continue;
      for (int k = 4; k < 8; ++k) {
        const int nx = x + kDx8[k];
        const int ny = y + kDy8[k];
        if (!g.inside(nx, ny) || !(*sk)[g.index(nx, ny)] || free(nx, y) || free(x, ny)) continue;
        cut.push_back(g.index(x, y));
        cut.push_back(g.index(nx, ny));
      }
    }
  }
  for (std::size_t i : cut) (*sk)[i] = 0;
}

// Shortening stops once a pass gains less than this fraction of the length (or a millimetre):
// a hundredth of the 1 % within which paths are compared with grid optima.
constexpr double kRelativeGain = 1e-4;

// Shortest distance along the graph from every vertex to `target` (Dijkstra; infinity where unreachable).
std::vector<double> distancesTo(const TopoGraph& g, int target) {
  std::vector<double> d(g.vertices.size(), std::numeric_limits<double>::infinity());
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  d[target] = 0.0;
  open.emplace(0.0, target);
  while (!open.empty()) {
    const auto [dv, v] = open.top();
    open.pop();
    if (dv > d[v]) continue;
    for (int e : g.incident[v]) {
      const TopoEdge& edge = g.edges[e];
      const int w = edge.a == v ? edge.b : edge.a;
      if (dv + edge.length_m < d[w]) {
        d[w] = dv + edge.length_m;
        open.emplace(d[w], w);
      }
    }
  }
  return d;
}

}  // namespace

int workingGridFactor(int width, int height, double resolution_m, double robot_radius_m) {
  const double cell_m = robot_radius_m > 0.0 ? robot_radius_m / 1.5 : resolution_m / 3.0;
  int k = std::max(1, static_cast<int>(std::ceil(resolution_m / cell_m - 1e-9)));
  if (k % 2 == 0) ++k;
  const double cells = static_cast<double>(width) * height;
  while (k > 1 && cells * k * k > static_cast<double>(kMaxWorkingCells)) k -= 2;
  return k;
}

OccupancyGrid2D refineGrid(const OccupancyGrid2D& grid, int k) {
  OccupancyGrid2D fine(grid.width * k, grid.height * k, grid.resolution_m / k, grid.origin_m);
  for (int y = 0; y < fine.height; ++y) {
    for (int x = 0; x < fine.width; ++x) fine.set(x, y, grid.isOccupied(x / k, y / k));
  }
  return fine;
}

const char* toString(PlanStatus status) {
  switch (status) {
    case PlanStatus::kSolved:
      return "solved";
    case PlanStatus::kNoPath:
      return "no_path";
    case PlanStatus::kInvalidStart:
      return "invalid_start";
    case PlanStatus::kInvalidGoal:
      return "invalid_goal";
    case PlanStatus::kTimeout:
      return "timeout";
  }
  return "unknown";
}

void TopoPlannerConfig::validate() const {
  require(robot_radius_m >= 0.0, "robot_radius_m", robot_radius_m, "must be >= 0");
  require(min_spur_length_m >= 0.0, "min_spur_length_m", min_spur_length_m, "must be >= 0");
  require(max_classes >= 1, "max_classes", max_classes, "must be >= 1");
  require(max_expansions >= 1, "max_expansions", max_expansions, "must be >= 1");
  require(max_length_ratio >= 1.0, "max_length_ratio", max_length_ratio, "must be >= 1");
  require(path_margin_m >= 0.0, "path_margin_m", path_margin_m, "must be >= 0");
}

double polylineLength(const std::vector<Eigen::Vector2d>& path) {
  double len = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) len += (path[i] - path[i - 1]).norm();
  return len;
}

namespace {
const TopoPlannerConfig& validated(const TopoPlannerConfig& config) {
  config.validate();
  return config;
}
}  // namespace

TopologicalPlanner::TopologicalPlanner(const OccupancyGrid2D& grid, const TopoPlannerConfig& config)
    : config_(validated(config)),
      working_factor_(workingGridFactor(grid.width, grid.height, grid.resolution_m, config.robot_radius_m)),
      field_(working_factor_ == 1 ? grid : refineGrid(grid, working_factor_)),
      clearance_m_(std::max(config.robot_radius_m, kPointRobotClearance * grid.resolution_m)),
      native_(grid) {
  const OccupancyGrid2D& work = field_.grid();
  skeleton_ = computeGvd(field_, GvdConfig{clearance_m_, config_.min_spur_length_m});
  free_.assign(skeleton_.size(), 0);
  for (int y = 0; y < work.height; ++y) {
    for (int x = 0; x < work.width; ++x) {
      // The centre's clearance lies between the centre distance less 0.71 and less 0.5 cells.
      const double d = field_.centreDistance(x, y);
      const std::size_t i = work.index(x, y);
      if (work.isOccupied(x, y) || d - 0.5 * work.resolution_m < clearance_m_) {
        free_[i] = 0;
      } else {
        free_[i] =
            d - 0.7072 * work.resolution_m >= clearance_m_ || field_.clearance(work.centreOf(x, y)) >= clearance_m_;
      }
    }
  }
  cutPinches(work, free_, &skeleton_);
  repair_cells_ = joinSkeleton(field_, free_, &skeleton_);
  for (int y = 0; y < work.height; ++y) {
    for (int x = 0; x < work.width; ++x) {
      if (skeleton_[work.index(x, y)]) skeleton_cells_.emplace_back(x, y);
    }
  }
  obstacle_points_ = obstacleComponentPoints(grid);
  obstacle_point_at_.assign(grid.occupied.size(), -1);
  for (std::size_t i = 0; i < obstacle_points_.size(); ++i) {
    const Eigen::Vector2i c = grid.cellOf(obstacle_points_[i]);
    obstacle_point_at_[grid.index(c.x(), c.y())] = static_cast<int>(i);
  }
}

std::vector<double> windingAngles(const std::vector<Eigen::Vector2d>& path,
                                  const std::vector<Eigen::Vector2d>& obstacle_points) {
  std::vector<double> w(obstacle_points.size(), 0.0);
  if (path.size() < 2) return w;
  // A point outside the path's bounding box is separated from the whole path by a line, so the
  // path winds less than half a turn around it: its winding is the wrapped angle between the ends.
  Eigen::Vector2d lo = path.front();
  Eigen::Vector2d hi = path.front();
  for (const auto& p : path) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  for (std::size_t k = 0; k < obstacle_points.size(); ++k) {
    const Eigen::Vector2d& z = obstacle_points[k];
    if ((z.array() < lo.array()).any() || (z.array() > hi.array()).any()) {
      w[k] = windingOfSegment(path.front(), path.back(), z);
      continue;
    }
    for (std::size_t i = 1; i < path.size(); ++i) w[k] += windingOfSegment(path[i - 1], path[i], z);
  }
  return w;
}

std::vector<double> TopologicalPlanner::hSignature(const std::vector<Eigen::Vector2d>& path) const {
  return windingAngles(path, obstacle_points_);
}

bool TopologicalPlanner::sameClass(const std::vector<double>& a, const std::vector<double>& b) {
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (std::abs(a[k] - b[k]) > M_PI) return false;
  }
  return true;
}

bool TopologicalPlanner::obstacleInTriangle(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                                            const Eigen::Vector2d& c) const {
  auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) { return u.x() * v.y() - u.y() * v.x(); };
  auto inside = [&](const Eigen::Vector2d& p) {
    const double d1 = cross(b - a, p - a);
    const double d2 = cross(c - b, p - b);
    const double d3 = cross(a - c, p - c);
    const bool neg = d1 < 0 || d2 < 0 || d3 < 0;
    const bool pos = d1 > 0 || d2 > 0 || d3 > 0;
    return !(neg && pos);
  };
  // Hundreds of obstacles: look only at the cells under the triangle's box when that is cheaper.
  const Eigen::Vector2i lo = native_.cellOf(a.cwiseMin(b).cwiseMin(c)).cwiseMax(Eigen::Vector2i::Zero());
  const Eigen::Vector2i hi =
      native_.cellOf(a.cwiseMax(b).cwiseMax(c)).cwiseMin(Eigen::Vector2i(native_.width - 1, native_.height - 1));
  const double box_cells = static_cast<double>(std::max(0, hi.x() - lo.x() + 1)) * std::max(0, hi.y() - lo.y() + 1);
  if (box_cells < static_cast<double>(obstacle_points_.size())) {
    for (int y = lo.y(); y <= hi.y(); ++y) {
      for (int x = lo.x(); x <= hi.x(); ++x) {
        const int i = obstacle_point_at_[native_.index(x, y)];
        if (i >= 0 && inside(obstacle_points_[i])) return true;
      }
    }
    return false;
  }
  for (const Eigen::Vector2d& p : obstacle_points_) {
    if (inside(p)) return true;
  }
  return false;
}

std::vector<Eigen::Vector2d> TopologicalPlanner::shortcut(const std::vector<Eigen::Vector2d>& pts) const {
  // From each kept point, the farthest later point reached by a clear chord whose fan of
  // triangles (kept point, p_k, p_k+1) holds no obstacle: the loop of path and chord then winds
  // around no obstacle, so the chord stays in the class.
  const double r = clearance_m_ + config_.path_margin_m;
  std::vector<Eigen::Vector2d> out{pts.front()};
  std::size_t i = 0;
  while (i + 1 < pts.size()) {
    std::size_t j = i + 1;
    while (j + 1 < pts.size() && !obstacleInTriangle(pts[i], pts[j], pts[j + 1]) &&
           field_.segmentClear(pts[i], pts[j + 1], r)) {
      ++j;
    }
    out.push_back(pts[j]);
    i = j;
  }
  return out;
}

std::vector<Eigen::Vector2d> TopologicalPlanner::relax(std::vector<Eigen::Vector2d> pts) const {
  // Each vertex moved towards the chord of its neighbours as far as the new segments keep the
  // clearance and the triangle swept holds no obstacle (so the path stays in its homology class).
  // Vertices stay (shortcut() drops those left on a chord): a midpoint inserted on a straight
  // stretch is what lets its neighbour move. Converges geometrically: stops once a sweep gains
  // little (kRelativeGain).
  const double r = clearance_m_ + config_.path_margin_m;
  double length = polylineLength(pts);
  for (int sweep = 0; sweep < 100; ++sweep) {
    bool changed = false;
    for (std::size_t i = 1; i + 1 < pts.size(); ++i) {
      const Eigen::Vector2d a = pts[i - 1];
      const Eigen::Vector2d b = pts[i];
      const Eigen::Vector2d c = pts[i + 1];
      // Towards the chord, or along either segment (sliding along a side that already touches an
      // obstacle corner while the other side swings free): each only shortens the two segments.
      const Eigen::Vector2d ac = c - a;
      const double t_proj = std::clamp((b - a).dot(ac) / std::max(ac.squaredNorm(), 1e-12), 0.0, 1.0);
      Eigen::Vector2d best = b;
      double best_length = (b - a).norm() + (c - b).norm();
      for (const Eigen::Vector2d& target : {Eigen::Vector2d(a + t_proj * ac), a, c}) {
        if ((best - b).norm() > 1e-4) break;  // the chord direction moved it: slide only when it cannot
        auto movable = [&](double t) {
          const Eigen::Vector2d m = b + t * (target - b);
          return field_.segmentClear(a, m, r) && field_.segmentClear(m, c, r) && !obstacleInTriangle(a, b, m) &&
                 !obstacleInTriangle(b, c, m);
        };
        // All the way when it can (most moves in open space), else the farthest by bisection.
        double lo = movable(1.0) ? 1.0 : 0.0;
        double hi = 1.0;
        for (int it = 0; it < 8 && lo < 1.0; ++it) {
          const double mid = 0.5 * (lo + hi);
          (movable(mid) ? lo : hi) = mid;
        }
        const Eigen::Vector2d m = b + lo * (target - b);
        const double length = (m - a).norm() + (c - m).norm();
        if (length < best_length - 1e-6) {
          best = m;
          best_length = length;
        }
      }
      if ((best - b).norm() > 1e-4) {
        pts[i] = best;
        changed = true;
      }
    }
    const double new_length = polylineLength(pts);
    if (!changed || length - new_length < std::max(1e-3, kRelativeGain * length)) break;
    length = new_length;
  }
  return pts;
}

std::vector<Eigen::Vector2d> TopologicalPlanner::shorten(std::vector<Eigen::Vector2d> pts) const {
  // String pulling that never leaves the class: shortcuts, then relaxation. A vertex held by an
  // obstacle corner on one side cannot move, while the taut path bends at that corner: so the
  // segments are split at their midpoints, which gives relaxation a vertex there, until a round
  // gains little (kRelativeGain).
  pts = relax(shortcut(pts));
  double length = polylineLength(pts);
  const double min_split_m = field_.grid().resolution_m;
  for (int round = 0; round < 8; ++round) {
    std::vector<Eigen::Vector2d> split{pts.front()};
    for (std::size_t i = 1; i < pts.size(); ++i) {
      if ((pts[i] - pts[i - 1]).norm() > 2.0 * min_split_m) split.push_back(0.5 * (pts[i - 1] + pts[i]));
      split.push_back(pts[i]);
    }
    if (split.size() == pts.size()) break;
    pts = shortcut(relax(split));
    const double new_length = polylineLength(pts);
    if (length - new_length < std::max(1e-3, kRelativeGain * length)) break;
    length = new_length;
  }
  return pts;
}

bool TopologicalPlanner::attach(const Eigen::Vector2d& p, Eigen::Vector2i* cell,
                                std::vector<Eigen::Vector2d>* points) const {
  const OccupancyGrid2D& grid = field_.grid();
  const double r = clearance_m_;
  // The nearest skeleton cells seen along a clear segment (a few: beyond them, walking is cheaper).
  constexpr std::size_t kStraightTries = 64;
  std::vector<std::pair<double, int>> by_distance;
  by_distance.reserve(skeleton_cells_.size());
  for (std::size_t i = 0; i < skeleton_cells_.size(); ++i) {
    const Eigen::Vector2i& c = skeleton_cells_[i];
    by_distance.emplace_back((grid.centreOf(c.x(), c.y()) - p).squaredNorm(), static_cast<int>(i));
  }
  const std::size_t tries = std::min(kStraightTries, by_distance.size());
  std::partial_sort(by_distance.begin(), by_distance.begin() + static_cast<long>(tries), by_distance.end());
  for (std::size_t t = 0; t < tries; ++t) {
    const Eigen::Vector2i& c = skeleton_cells_[by_distance[t].second];
    if (field_.segmentClear(p, grid.centreOf(c.x(), c.y()), r)) {
      *cell = c;
      *points = {p, grid.centreOf(c.x(), c.y())};
      return true;
    }
  }
  // Through free cells (Dijkstra, octile steps) from the cells around p that it sees.
  const Eigen::Vector2i pc = grid.cellOf(p);
  std::vector<double> cost(skeleton_.size(), std::numeric_limits<double>::infinity());
  std::vector<int> parent(skeleton_.size(), -1);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const int x = pc.x() + dx;
      const int y = pc.y() + dy;
      if (!grid.inside(x, y) || !freeCell(x, y) || !field_.segmentClear(p, grid.centreOf(x, y), r)) continue;
      const int i = static_cast<int>(grid.index(x, y));
      cost[i] = (grid.centreOf(x, y) - p).norm();
      open.emplace(cost[i], i);
    }
  }
  auto free = [&](int x, int y) { return freeCell(x, y); };
  while (!open.empty()) {
    const auto [c, i] = open.top();
    open.pop();
    if (c > cost[i]) continue;
    const int x = i % grid.width;
    const int y = i / grid.width;
    if (skeleton_[i]) {
      *cell = Eigen::Vector2i(x, y);
      points->clear();
      for (int j = i; j >= 0; j = parent[j]) points->push_back(grid.centreOf(j % grid.width, j / grid.width));
      points->push_back(p);
      std::reverse(points->begin(), points->end());
      return true;
    }
    for (int k = 0; k < 8; ++k) {
      if (!canStep(grid, free, x, y, k)) continue;
      const int j = static_cast<int>(grid.index(x + kDx8[k], y + kDy8[k]));
      const double nc = c + grid.resolution_m * (k < 4 ? 1.0 : std::sqrt(2.0));
      if (nc < cost[j]) {
        cost[j] = nc;
        parent[j] = i;
        open.emplace(nc, j);
      }
    }
  }
  return false;
}

bool TopologicalPlanner::keepClearance(std::vector<Eigen::Vector2d>* path) const {
  const double r = clearance_m_;  // the guarantee; path_margin_m is what shortening aims for
  // Pushed a little beyond r: points exactly at r around a corner leave the chord between them short of r.
  const double target = r + 1e-3 * field_.grid().resolution_m;
  std::vector<Eigen::Vector2d> out{path->front()};
  std::function<bool(const Eigen::Vector2d&, const Eigen::Vector2d&, int)> fix =
      [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b, int depth) {
        if (field_.segmentClear(a, b, r)) {
          out.push_back(b);
          return true;
        }
        if (depth == 0) return false;
        Eigen::Vector2d m = 0.5 * (a + b);
        for (int it = 0; it < 20; ++it) {
          Eigen::Vector2d gradient;
          const double c = field_.clearance(m, &gradient);
          if (c >= target || gradient.isZero()) break;
          m += (target - c) * gradient;
        }
        return fix(a, m, depth - 1) && fix(m, b, depth - 1);
      };
  for (std::size_t i = 1; i < path->size(); ++i) {
    if (!fix(out.back(), (*path)[i], 12)) return false;
  }
  *path = std::move(out);
  return true;
}

std::vector<Eigen::Vector2d> TopologicalPlanner::freeSpaceShortest(const Eigen::Vector2d& start,
                                                                   const Eigen::Vector2d& goal) const {
  const OccupancyGrid2D& grid = field_.grid();
  const Eigen::Vector2i s = grid.cellOf(start);
  const Eigen::Vector2i t = grid.cellOf(goal);
  auto free = [&](int x, int y) { return freeCell(x, y); };
  if (!grid.inside(s.x(), s.y()) || !grid.inside(t.x(), t.y()) || !free(s.x(), s.y()) || !free(t.x(), t.y())) {
    return {};
  }
  const double res = grid.resolution_m;
  const double r = clearance_m_;
  // A step is taken only where its segment keeps r: then the path found is clear as it stands.
  // Each step of an 8-connected path through native cell centres lies on such a path's segment,
  // so the optimum here is never longer than the native grid's.
  auto clearStep = [&](int x, int y, int nx, int ny) {
    const Eigen::Vector2d a = grid.centreOf(x, y);
    const Eigen::Vector2d b = grid.centreOf(nx, ny);
    const double half = 0.5 * (b - a).norm();
    // Clearance is 1-Lipschitz: no point of the segment is farther than `half` from an end.
    return std::min(field_.clearance(a), field_.clearance(b)) >= r + half || field_.segmentClear(a, b, r);
  };
  auto octile = [&](int i) {
    const double dx = std::abs(i % grid.width - t.x());
    const double dy = std::abs(i / grid.width - t.y());
    return res * (std::max(dx, dy) + (std::sqrt(2.0) - 1.0) * std::min(dx, dy));
  };
  std::vector<double> cost(grid.occupied.size(), std::numeric_limits<double>::infinity());
  std::vector<int> parent(grid.occupied.size(), -1);
  using Item = std::pair<double, int>;  // f, cell
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  const int si = static_cast<int>(grid.index(s.x(), s.y()));
  const int ti = static_cast<int>(grid.index(t.x(), t.y()));
  cost[si] = 0.0;
  open.emplace(octile(si), si);
  while (!open.empty()) {
    const auto [f, i] = open.top();
    open.pop();
    if (i == ti) break;
    if (f > cost[i] + octile(i) + 1e-12) continue;
    const int x = i % grid.width;
    const int y = i / grid.width;
    for (int k = 0; k < 8; ++k) {
      if (!canStep(grid, free, x, y, k)) continue;
      const int j = static_cast<int>(grid.index(x + kDx8[k], y + kDy8[k]));
      const double nc = cost[i] + res * (k < 4 ? 1.0 : std::sqrt(2.0));
      if (nc < cost[j] && clearStep(x, y, x + kDx8[k], y + kDy8[k])) {
        cost[j] = nc;
        parent[j] = i;
        open.emplace(nc + octile(j), j);
      }
    }
  }
  if (!std::isfinite(cost[ti])) return {};
  std::vector<Eigen::Vector2d> cells;
  for (int i = ti; i >= 0; i = parent[i]) cells.push_back(grid.centreOf(i % grid.width, i / grid.width));
  std::reverse(cells.begin(), cells.end());
  // The exact ends, where they are not the cell centres: kept clear like any path.
  cells.insert(cells.begin(), start);
  cells.push_back(goal);
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  if (cells.size() < 2) return {};  // start == goal: the enumeration's own path stands
  std::vector<Eigen::Vector2d> found = cells;
  const bool found_clear = keepClearance(&found);
  std::vector<Eigen::Vector2d> shortened = shorten(cells);
  const bool shortened_clear = keepClearance(&shortened);
  if (shortened_clear && (!found_clear || polylineLength(shortened) <= polylineLength(found))) return shortened;
  return found_clear ? found : std::vector<Eigen::Vector2d>{};
}

void TopologicalPlanner::ensureShortestClass(const Eigen::Vector2d& start, const Eigen::Vector2d& goal,
                                             TopoPlan* plan) const {
  std::vector<Eigen::Vector2d> path = freeSpaceShortest(start, goal);
  if (path.empty()) return;
  HomologyClass shortest;
  shortest.h_signature = hSignature(path);
  shortest.length_m = polylineLength(path);
  shortest.graph_path = path;
  shortest.path = std::move(path);
  for (HomologyClass& c : plan->classes) {
    if (!sameClass(c.h_signature, shortest.h_signature)) continue;
    if (shortest.length_m < c.length_m) c = std::move(shortest);
    return;
  }
  if (static_cast<int>(plan->classes.size()) >= config_.max_classes) plan->classes.pop_back();
  plan->classes.push_back(std::move(shortest));
}

TopoPlan TopologicalPlanner::solve(const Eigen::Vector2d& start, const Eigen::Vector2d& goal) const {
  TopoPlan plan;
  plan.gvd = skeleton_;
  plan.working_factor = working_factor_;
  plan.obstacle_points = obstacle_points_;
  const OccupancyGrid2D& grid = field_.grid();
  const double r = clearance_m_;
  if (field_.clearance(start) < r) {
    plan.status = PlanStatus::kInvalidStart;
    return plan;
  }
  if (field_.clearance(goal) < r) {
    plan.status = PlanStatus::kInvalidGoal;
    return plan;
  }

  Eigen::Vector2i start_cell(-1, -1);
  Eigen::Vector2i goal_cell(-1, -1);
  std::vector<Eigen::Vector2d> start_link;
  std::vector<Eigen::Vector2d> goal_link;
  attach(start, &start_cell, &start_link);
  attach(goal, &goal_cell, &goal_link);
  const bool direct = field_.segmentClear(start, goal, r);
  if ((start_cell.x() < 0 || goal_cell.x() < 0) && !direct) {
    plan.status = PlanStatus::kNoPath;
    return plan;
  }
  std::vector<Eigen::Vector2i> forced;
  if (start_cell.x() >= 0) forced.push_back(start_cell);
  if (goal_cell.x() >= 0) forced.push_back(goal_cell);
  plan.graph = buildTopoGraph(field_, skeleton_, forced);
  TopoGraph& g = plan.graph;
  // Start and goal become vertices joined to their attachment cells.
  auto addEndpoint = [&](const Eigen::Vector2d& p, const Eigen::Vector2i& cell,
                         const std::vector<Eigen::Vector2d>& link) {
    const int v = static_cast<int>(g.vertices.size());
    g.vertices.push_back(TopoVertex{grid.cellOf(p), p});
    g.incident.emplace_back();
    const int target = cell.x() >= 0 ? g.vertexAt(cell) : -1;
    if (target >= 0) {
      TopoEdge e;
      e.a = v;
      e.b = target;
      e.points_m = link;
      e.points_m.back() = g.vertices[target].p_m;
      e.length_m = polylineLength(e.points_m);
      e.min_clearance_m = r;
      g.incident[v].push_back(static_cast<int>(g.edges.size()));
      g.incident[target].push_back(static_cast<int>(g.edges.size()));
      g.edges.push_back(std::move(e));
    }
    return v;
  };
  const int vs = addEndpoint(start, start_cell, start_link);
  const int vg = addEndpoint(goal, goal_cell, goal_link);
  if (direct) {
    TopoEdge e;
    e.a = vs;
    e.b = vg;
    e.points_m = {start, goal};
    e.length_m = (goal - start).norm();
    e.min_clearance_m = r;
    g.incident[vs].push_back(static_cast<int>(g.edges.size()));
    g.incident[vg].push_back(static_cast<int>(g.edges.size()));
    g.edges.push_back(std::move(e));
  }

  // Winding of every edge around every obstacle point, in the a -> b direction.
  const std::size_t k_obs = obstacle_points_.size();
  // Computed when a complete path first uses the edge: most edges are only ever expanded.
  std::vector<std::vector<double>> edge_winding(g.edges.size());
  auto windingOf = [&](int e) -> const std::vector<double>& {
    if (edge_winding[e].size() != k_obs) edge_winding[e] = hSignature(g.edges[e].points_m);
    return edge_winding[e];
  };

  // Best-first search over simple paths, shortest first: A* on the exact distance to the goal
  // along the graph, so that complete paths come out in order of length while partial paths that
  // cannot beat the next one are never expanded (with hundreds of obstacles the graph has as many
  // cycles, and plain best-first would expand every short partial path first).
  const std::vector<double> to_goal = distancesTo(g, vg);
  std::vector<SearchNode> pool{{0.0, vs, -1, -1}};
  auto f = [&](int x) { return pool[x].cost + to_goal[pool[x].vertex]; };
  auto cmp = [&](int x, int y) { return f(x) > f(y); };
  std::priority_queue<int, std::vector<int>, decltype(cmp)> open(cmp);
  open.push(0);
  double first_length = -1.0;
  std::vector<std::vector<Eigen::Vector2d>> graph_paths;
  std::vector<std::vector<double>> signatures;
  while (!open.empty() && static_cast<int>(signatures.size()) < config_.max_classes) {
    if (plan.expansions >= config_.max_expansions) break;
    const int node_id = open.top();
    open.pop();
    const SearchNode node = pool[node_id];
    if (first_length > 0.0 && f(node_id) > config_.max_length_ratio * first_length) break;
    ++plan.expansions;
    if (node.vertex == vg) {
      std::vector<double> sig(k_obs, 0.0);
      std::vector<int> edges;
      std::vector<int> froms;
      for (int n = node_id; pool[n].parent >= 0; n = pool[n].parent) {
        edges.push_back(pool[n].edge);
        froms.push_back(pool[pool[n].parent].vertex);
      }
      std::reverse(edges.begin(), edges.end());
      std::reverse(froms.begin(), froms.end());
      std::vector<Eigen::Vector2d> pts;
      for (std::size_t i = 0; i < edges.size(); ++i) {
        const TopoEdge& e = g.edges[edges[i]];
        const bool forward = e.a == froms[i];
        const double sign = forward ? 1.0 : -1.0;
        const std::vector<double>& w = windingOf(edges[i]);
        for (std::size_t k = 0; k < k_obs; ++k) sig[k] += sign * w[k];
        std::vector<Eigen::Vector2d> seg = e.points_m;
        if (!forward) std::reverse(seg.begin(), seg.end());
        pts.insert(pts.end(), seg.begin() + (pts.empty() ? 0 : 1), seg.end());
      }
      bool known = false;
      for (const auto& s : signatures) known = known || sameClass(s, sig);
      if (!known) {
        if (first_length < 0.0) first_length = node.cost;
        signatures.push_back(sig);
        graph_paths.push_back(pts);
      }
      continue;
    }
    for (int e : g.incident[node.vertex]) {
      const TopoEdge& edge = g.edges[e];
      const int next = edge.a == node.vertex ? edge.b : edge.a;
      bool on_path = false;
      for (int n = node_id; n >= 0 && !on_path; n = pool[n].parent) on_path = pool[n].vertex == next;
      if (on_path || !std::isfinite(to_goal[next])) continue;
      pool.push_back(SearchNode{node.cost + edge.length_m, next, e, node_id});
      open.push(static_cast<int>(pool.size()) - 1);
    }
  }

  for (std::size_t i = 0; i < graph_paths.size(); ++i) {
    HomologyClass c;
    c.graph_path = graph_paths[i];
    c.path = shorten(graph_paths[i]);
    if (!keepClearance(&c.path)) continue;  // never hand out a path closer than r to an obstacle
    c.h_signature = hSignature(c.path);
    c.length_m = polylineLength(c.path);
    plan.classes.push_back(std::move(c));
  }
  // The enumeration takes the first max_classes classes in order of their GVD length; with many
  // near-equal ones (warehouse aisles) the shortest class can be left out, or its shortened path
  // stop short of its own shortest. A search cut by max_expansions before any class stays cut.
  if (!plan.classes.empty()) ensureShortestClass(start, goal, &plan);
  std::sort(plan.classes.begin(), plan.classes.end(),
            [](const HomologyClass& a, const HomologyClass& b) { return a.length_m < b.length_m; });
  if (plan.classes.empty()) {
    plan.status = plan.expansions >= config_.max_expansions ? PlanStatus::kTimeout : PlanStatus::kNoPath;
    return plan;
  }
  plan.status = PlanStatus::kSolved;
  plan.chosen = 0;
  return plan;
}

}  // namespace tgnav::planner
