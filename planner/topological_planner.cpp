#include "planner/topological_planner.h"

#include <algorithm>
#include <cmath>
#include <queue>
#include <stdexcept>

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

}  // namespace

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
}

double polylineLength(const std::vector<Eigen::Vector2d>& path) {
  double len = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) len += (path[i] - path[i - 1]).norm();
  return len;
}

TopologicalPlanner::TopologicalPlanner(const OccupancyGrid2D& grid, const TopoPlannerConfig& config)
    : config_(config), field_(grid) {
  config_.validate();
  skeleton_ = computeGvd(field_, GvdConfig{config_.robot_radius_m, config_.min_spur_length_m});
  obstacle_points_ = obstacleComponentPoints(grid);
}

std::vector<double> windingAngles(const std::vector<Eigen::Vector2d>& path,
                                  const std::vector<Eigen::Vector2d>& obstacle_points) {
  std::vector<double> w(obstacle_points.size(), 0.0);
  for (std::size_t k = 0; k < obstacle_points.size(); ++k) {
    for (std::size_t i = 1; i < path.size(); ++i) w[k] += windingOfSegment(path[i - 1], path[i], obstacle_points[k]);
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
  for (const Eigen::Vector2d& p : obstacle_points_) {
    const double d1 = cross(b - a, p - a);
    const double d2 = cross(c - b, p - b);
    const double d3 = cross(a - c, p - c);
    const bool neg = d1 < 0 || d2 < 0 || d3 < 0;
    const bool pos = d1 > 0 || d2 > 0 || d3 > 0;
    if (!(neg && pos)) return true;
  }
  return false;
}

std::vector<Eigen::Vector2d> TopologicalPlanner::shorten(std::vector<Eigen::Vector2d> pts) const {
  // String pulling that never crosses an obstacle: a vertex is dropped, or moved towards the
  // chord of its neighbours, only if the new segments keep the clearance and the triangle
  // swept holds no obstacle (so the path stays in its homology class).
  const double r = config_.robot_radius_m;
  // Relaxation converges geometrically; stop once a sweep gains less than a centimetre.
  double length = polylineLength(pts);
  for (int sweep = 0; sweep < 50; ++sweep) {
    bool changed = false;
    for (std::size_t i = 1; i + 1 < pts.size();) {
      const Eigen::Vector2d a = pts[i - 1];
      const Eigen::Vector2d b = pts[i];
      const Eigen::Vector2d c = pts[i + 1];
      if (field_.segmentClear(a, c, r) && !obstacleInTriangle(a, b, c)) {
        pts.erase(pts.begin() + static_cast<long>(i));
        changed = true;
        continue;
      }
      const Eigen::Vector2d ac = c - a;
      const double t_proj = std::clamp((b - a).dot(ac) / std::max(ac.squaredNorm(), 1e-12), 0.0, 1.0);
      const Eigen::Vector2d target = a + t_proj * ac;
      auto movable = [&](double t) {
        const Eigen::Vector2d m = b + t * (target - b);
        return field_.segmentClear(a, m, r) && field_.segmentClear(m, c, r) && !obstacleInTriangle(a, b, m) &&
               !obstacleInTriangle(b, c, m);
      };
      double lo = 0.0;
      double hi = 1.0;
      for (int it = 0; it < 8; ++it) {
        const double mid = 0.5 * (lo + hi);
        (movable(mid) ? lo : hi) = mid;
      }
      if (lo * (target - b).norm() > 1e-3) {
        pts[i] = b + lo * (target - b);
        changed = true;
      }
      ++i;
    }
    const double new_length = polylineLength(pts);
    if (!changed || length - new_length < 1e-2) break;
    length = new_length;
  }
  return pts;
}

TopoPlan TopologicalPlanner::solve(const Eigen::Vector2d& start, const Eigen::Vector2d& goal) const {
  TopoPlan plan;
  plan.gvd = skeleton_;
  plan.obstacle_points = obstacle_points_;
  const OccupancyGrid2D& grid = field_.grid();
  const double r = config_.robot_radius_m;
  if (field_.clearance(start) < r) {
    plan.status = PlanStatus::kInvalidStart;
    return plan;
  }
  if (field_.clearance(goal) < r) {
    plan.status = PlanStatus::kInvalidGoal;
    return plan;
  }

  // Attach start and goal to the nearest skeleton cell they see with clearance.
  std::vector<Eigen::Vector2i> cells;
  for (int y = 0; y < grid.height; ++y) {
    for (int x = 0; x < grid.width; ++x) {
      if (skeleton_[grid.index(x, y)]) cells.emplace_back(x, y);
    }
  }
  auto attach = [&](const Eigen::Vector2d& p) -> Eigen::Vector2i {
    std::vector<std::pair<double, Eigen::Vector2i>> by_distance;
    for (const auto& c : cells) by_distance.emplace_back((grid.centreOf(c.x(), c.y()) - p).squaredNorm(), c);
    std::sort(by_distance.begin(), by_distance.end(), [](const auto& u, const auto& v) { return u.first < v.first; });
    for (const auto& [d2, c] : by_distance) {
      if (field_.segmentClear(p, grid.centreOf(c.x(), c.y()), r)) return c;
    }
    return Eigen::Vector2i(-1, -1);
  };
  const Eigen::Vector2i start_cell = attach(start);
  const Eigen::Vector2i goal_cell = attach(goal);
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
  // Start and goal become vertices joined to their attachment cells by straight edges.
  auto addEndpoint = [&](const Eigen::Vector2d& p, const Eigen::Vector2i& cell) {
    const int v = static_cast<int>(g.vertices.size());
    g.vertices.push_back(TopoVertex{grid.cellOf(p), p});
    g.incident.emplace_back();
    const int target = cell.x() >= 0 ? g.vertexAt(cell) : -1;
    if (target >= 0) {
      TopoEdge e;
      e.a = v;
      e.b = target;
      e.points_m = {p, g.vertices[target].p_m};
      e.length_m = (e.points_m[1] - e.points_m[0]).norm();
      e.min_clearance_m = r;
      g.incident[v].push_back(static_cast<int>(g.edges.size()));
      g.incident[target].push_back(static_cast<int>(g.edges.size()));
      g.edges.push_back(std::move(e));
    }
    return v;
  };
  const int vs = addEndpoint(start, start_cell);
  const int vg = addEndpoint(goal, goal_cell);
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
  std::vector<std::vector<double>> edge_winding(g.edges.size(), std::vector<double>(k_obs, 0.0));
  for (std::size_t e = 0; e < g.edges.size(); ++e) edge_winding[e] = hSignature(g.edges[e].points_m);

  // Best-first search over simple paths, shortest first.
  std::vector<SearchNode> pool{{0.0, vs, -1, -1}};
  auto cmp = [&](int x, int y) { return pool[x].cost > pool[y].cost; };
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
    if (first_length > 0.0 && node.cost > config_.max_length_ratio * first_length) break;
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
        for (std::size_t k = 0; k < k_obs; ++k) sig[k] += sign * edge_winding[edges[i]][k];
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
      if (on_path) continue;
      pool.push_back(SearchNode{node.cost + edge.length_m, next, e, node_id});
      open.push(static_cast<int>(pool.size()) - 1);
    }
  }

  for (std::size_t i = 0; i < graph_paths.size(); ++i) {
    HomologyClass c;
    c.graph_path = graph_paths[i];
    c.path = shorten(graph_paths[i]);
    c.h_signature = hSignature(c.path);
    c.length_m = polylineLength(c.path);
    plan.classes.push_back(std::move(c));
  }
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
