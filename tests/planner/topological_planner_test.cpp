// Topological planning on 2D grids: GVD properties, graph extraction, distinct homology
// classes (counted exactly on pillar rows), H-signatures, clearance, and near-optimal length
// against an independent grid search.
#include "planner/topological_planner.h"

#include <gtest/gtest.h>

#include <iostream>
#include <queue>
#include <random>

namespace tgnav::planner {
namespace {

constexpr double kRes = 0.1;

OccupancyGrid2D room(double w_m, double h_m) {
  return OccupancyGrid2D(static_cast<int>(w_m / kRes), static_cast<int>(h_m / kRes), kRes, Eigen::Vector2d::Zero());
}

void block(OccupancyGrid2D& g, double x0, double y0, double x1, double y1, bool occ = true) {
  for (int y = 0; y < g.height; ++y) {
    for (int x = 0; x < g.width; ++x) {
      const Eigen::Vector2d c = g.centreOf(x, y);
      if (c.x() > x0 && c.x() < x1 && c.y() > y0 && c.y() < y1) g.set(x, y, occ);
    }
  }
}

// k pillars of 1 x 1 m in a row along the middle of a (4k + 4) x 6 m room.
OccupancyGrid2D pillarRow(int k) {
  OccupancyGrid2D g = room(4.0 * k + 4.0, 6.0);
  for (int i = 0; i < k; ++i) block(g, 3.5 + 4.0 * i, 2.5, 4.5 + 4.0 * i, 3.5);
  return g;
}

void expectClear(const TopologicalPlanner& planner, const std::vector<Eigen::Vector2d>& path, double r) {
  for (std::size_t i = 1; i < path.size(); ++i) {
    ASSERT_TRUE(planner.field().segmentClear(path[i - 1], path[i], r)) << "segment " << i;
  }
}

TEST(TopologicalPlanner, PillarRowsGiveAllTwoToTheKClassesUpToTheCap) {
  for (int k = 1; k <= 4; ++k) {
    TopoPlannerConfig config;
    config.max_classes = 20;
    const OccupancyGrid2D grid = pillarRow(k);
    const TopologicalPlanner planner(grid, config);
    const TopoPlan plan = planner.solve({1.0, 3.0}, {4.0 * k + 3.0, 3.0});
    ASSERT_EQ(plan.status, PlanStatus::kSolved) << "k = " << k;
    EXPECT_EQ(static_cast<int>(plan.classes.size()), 1 << k) << "k = " << k;
    for (std::size_t i = 0; i < plan.classes.size(); ++i) {
      expectClear(planner, plan.classes[i].path, config.robot_radius_m);
      for (std::size_t j = 0; j < i; ++j) {
        EXPECT_FALSE(TopologicalPlanner::sameClass(plan.classes[i].h_signature, plan.classes[j].h_signature));
      }
    }
  }
  TopoPlannerConfig capped;
  capped.max_classes = 10;
  const TopoPlan plan = TopologicalPlanner(pillarRow(4), capped).solve({1.0, 3.0}, {19.0, 3.0});
  EXPECT_EQ(plan.classes.size(), 10u);
}

TEST(TopologicalPlanner, ShorteningKeepsTheClassAndTheSignatureSurvivesDeformation) {
  const OccupancyGrid2D grid = pillarRow(2);
  const TopologicalPlanner planner(grid, TopoPlannerConfig{});
  const TopoPlan plan = planner.solve({1.0, 3.0}, {11.0, 3.0});
  ASSERT_EQ(plan.classes.size(), 4u);
  std::mt19937 rng(5);
  std::normal_distribution<double> wiggle(0.0, 0.15);
  for (const HomologyClass& c : plan.classes) {
    EXPECT_TRUE(TopologicalPlanner::sameClass(planner.hSignature(c.graph_path), c.h_signature));
    std::vector<Eigen::Vector2d> deformed = c.graph_path;
    for (std::size_t i = 1; i + 1 < deformed.size(); ++i) deformed[i] += Eigen::Vector2d(wiggle(rng), wiggle(rng));
    EXPECT_TRUE(TopologicalPlanner::sameClass(planner.hSignature(deformed), c.h_signature));
    EXPECT_LE(c.length_m, polylineLength(c.graph_path) + 1e-9);
  }
  // The straight line through the row crosses both pillars: it matches no class going around them.
  const auto straight = planner.hSignature({{1.0, 3.0}, {11.0, 3.0}});
  EXPECT_EQ(straight.size(), 2u);
}

TEST(Gvd, CellsAreEquidistantToTwoObstaclesWithinOneCell) {
  OccupancyGrid2D grid = room(6.0, 4.0);
  block(grid, 1.0, 1.0, 2.0, 3.0);
  block(grid, 3.5, 0.5, 4.5, 1.5);
  const DistanceField field(grid);
  GvdConfig config;
  config.robot_radius_m = 0.2;
  const std::vector<std::uint8_t> gvd = computeGvd(field, config);
  int checked = 0;
  for (int y = 0; y < grid.height; ++y) {
    for (int x = 0; x < grid.width; ++x) {
      if (!gvd[grid.index(x, y)]) continue;
      const Eigen::Vector2i site = field.nearestObstacle(x, y);
      const double d = (site - Eigen::Vector2i(x, y)).cast<double>().norm();
      double other = 1e9;
      for (int oy = -1; oy <= grid.height; ++oy) {
        for (int ox = -1; ox <= grid.width; ++ox) {
          if (!grid.isOccupied(ox, oy) || (Eigen::Vector2i(ox, oy) - site).cwiseAbs().maxCoeff() <= 1) continue;
          other = std::min(other, std::hypot(ox - x, oy - y));
        }
      }
      EXPECT_LE(other - d, 1.5) << "cell " << x << "," << y;  // within one cell (diagonal)
      EXPECT_GE(field.clearance(grid.centreOf(x, y)), config.robot_radius_m);
      ++checked;
    }
  }
  EXPECT_GT(checked, 50);
}

TEST(TopoGraph, PlusShapedCorridorsHaveOneJunctionAndFourEnds) {
  OccupancyGrid2D grid = room(10.0, 10.0);
  block(grid, -1, -1, 11, 11);                     // all solid
  block(grid, 0.5, 4.5, 9.5, 5.5, /*occ=*/false);  // horizontal corridor
  block(grid, 4.5, 0.5, 5.5, 9.5, /*occ=*/false);  // vertical corridor
  const DistanceField field(grid);
  GvdConfig config;
  config.robot_radius_m = 0.2;
  const TopoGraph g = buildTopoGraph(field, computeGvd(field, config), {});
  int junctions = 0;
  int ends = 0;
  for (std::size_t v = 0; v < g.vertices.size(); ++v) {
    junctions += g.incident[v].size() == 4;
    ends += g.incident[v].size() == 1;
  }
  EXPECT_EQ(junctions, 1);
  EXPECT_EQ(ends, 4);
  EXPECT_EQ(g.edges.size(), 4u);
  for (const TopoEdge& e : g.edges) EXPECT_GT(e.length_m, 3.0);
}

TEST(TopologicalPlanner, StartAndGoalAttachAndBadEndsAreReported) {
  OccupancyGrid2D grid = room(8.0, 6.0);
  block(grid, 3.5, 2.5, 4.5, 3.5);
  const TopologicalPlanner planner(grid, TopoPlannerConfig{});
  // Start tucked in a corner: it attaches with a clear straight connection.
  const TopoPlan plan = planner.solve({0.5, 0.5}, {7.5, 5.5});
  ASSERT_EQ(plan.status, PlanStatus::kSolved);
  EXPECT_EQ(plan.classes.size(), 2u);
  EXPECT_TRUE((plan.classes[0].path.front() - Eigen::Vector2d(0.5, 0.5)).norm() < 1e-9);
  EXPECT_TRUE((plan.classes[0].path.back() - Eigen::Vector2d(7.5, 5.5)).norm() < 1e-9);
  EXPECT_EQ(planner.solve({4.0, 3.0}, {7.5, 5.5}).status, PlanStatus::kInvalidStart);  // in the pillar
  EXPECT_EQ(planner.solve({0.5, 0.5}, {9.0, 5.5}).status, PlanStatus::kInvalidGoal);   // off the map
  EXPECT_EQ(planner.solve({0.5, 0.5}, {4.0, 3.7}).status, PlanStatus::kInvalidGoal);   // too close
  // A wall across the room: nothing connects.
  OccupancyGrid2D split = room(8.0, 6.0);
  block(split, 3.9, -1.0, 4.1, 7.0);
  EXPECT_EQ(TopologicalPlanner(split, TopoPlannerConfig{}).solve({1.0, 3.0}, {7.0, 3.0}).status, PlanStatus::kNoPath);
  // No free space at all.
  OccupancyGrid2D solid = room(4.0, 4.0);
  block(solid, -1, -1, 5, 5);
  EXPECT_EQ(TopologicalPlanner(solid, TopoPlannerConfig{}).solve({1.0, 1.0}, {3.0, 3.0}).status,
            PlanStatus::kInvalidStart);
}

TEST(TopologicalPlanner, EffortCapEndsTheSearch) {
  TopoPlannerConfig config;
  config.max_expansions = 3;
  const TopoPlan plan = TopologicalPlanner(pillarRow(4), config).solve({1.0, 3.0}, {19.0, 3.0});
  EXPECT_EQ(plan.status, PlanStatus::kTimeout);
  EXPECT_LE(plan.expansions, 3);
}

// Independent reference: 8-connected Dijkstra over cells whose centres keep the clearance.
// It is never shorter than the true optimum and at most 8.24 % longer.
double gridShortest(const TopologicalPlanner& planner, const Eigen::Vector2d& s, const Eigen::Vector2d& t, double r) {
  const OccupancyGrid2D& g = planner.field().grid();
  std::vector<double> dist(g.occupied.size(), 1e18);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  const Eigen::Vector2i sc = g.cellOf(s);
  const Eigen::Vector2i tc = g.cellOf(t);
  dist[g.index(sc.x(), sc.y())] = 0.0;
  open.push({0.0, static_cast<int>(g.index(sc.x(), sc.y()))});
  while (!open.empty()) {
    const auto [d, i] = open.top();
    open.pop();
    if (d > dist[i]) continue;
    const int x = i % g.width;
    const int y = i / g.width;
    if (x == tc.x() && y == tc.y()) return d;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if ((dx == 0 && dy == 0) || !g.inside(x + dx, y + dy)) continue;
        if (planner.field().clearance(g.centreOf(x + dx, y + dy)) < r) continue;
        const std::size_t j = g.index(x + dx, y + dy);
        const double nd = d + g.resolution_m * std::hypot(dx, dy);
        if (nd < dist[j]) {
          dist[j] = nd;
          open.push({nd, static_cast<int>(j)});
        }
      }
    }
  }
  return -1.0;
}

TEST(TopologicalPlanner, ShortestClassIsNearOptimalOnRandomMaps) {
  std::mt19937 rng(2021);
  std::uniform_real_distribution<double> pos(1.0, 9.0);
  std::uniform_real_distribution<double> size(0.4, 1.6);
  int compared = 0;
  double worst = 0.0;
  for (int trial = 0; trial < 40 && compared < 20; ++trial) {
    OccupancyGrid2D grid = room(10.0, 10.0);
    for (int k = 0; k < 7; ++k) {
      const double x = pos(rng), y = pos(rng);
      block(grid, x, y, x + size(rng), y + size(rng));
    }
    block(grid, 0.0, 0.0, 1.5, 1.5, false);  // keep start and goal free
    block(grid, 8.5, 8.5, 10.0, 10.0, false);
    const TopologicalPlanner planner(grid, TopoPlannerConfig{});
    const Eigen::Vector2d s(0.7, 0.7), t(9.3, 9.3);
    const TopoPlan plan = planner.solve(s, t);
    const double ref = gridShortest(planner, s, t, 0.3);
    if (ref < 0.0) {
      EXPECT_NE(plan.status, PlanStatus::kSolved) << "trial " << trial;
      continue;
    }
    ASSERT_EQ(plan.status, PlanStatus::kSolved) << "trial " << trial;
    for (const HomologyClass& c : plan.classes) expectClear(planner, c.path, 0.3);
    const double ours = plan.classes[plan.chosen].length_m;
    worst = std::max(worst, ours / ref);
    EXPECT_LE(ours, 1.05 * ref) << "trial " << trial;
    ++compared;
  }
  std::cout << "[ figure   ] shortest class / 8-connected optimum: worst " << worst << " over " << compared
            << " maps\n";
  EXPECT_EQ(compared, 20);
}

}  // namespace
}  // namespace tgnav::planner
