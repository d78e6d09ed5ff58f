// The topological planner on benchmark-like grid maps at 1 m per cell (MovingAI kinds, made here
// by tests/planner/grid_maps.h): wherever an 8-connected path exists on the map inflated by the
// robot radius, a path is found; every class path keeps the radius from every occupied square
// (checked by an independent clearance); the shortest class is within 1 % of the 8-connected
// optimum; the classes are pairwise distinct.
#include "grid_maps.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>

#include "planner/topological_planner.h"

namespace tgnav::planner {
namespace {

struct MapCase {
  std::string name;
  std::string text;
};

std::vector<MapCase> mapCases() {
  using namespace testmaps;
  std::vector<MapCase> cases;
  for (std::uint32_t seed : {1u, 2u}) {
    const std::string s = std::to_string(seed);
    cases.push_back({"maze-" + s, mazeMap(12, 12, seed, /*extra_openings=*/6)});
    cases.push_back({"rooms-" + s, roomsMap(48, 40, 7, seed)});
    cases.push_back({"random15-" + s, randomCellsMap(40, 40, 0.15, seed)});
    cases.push_back({"blocks-" + s, blocksMap(90, 70, 18, seed)});
  }
  cases.push_back({"random20", randomCellsMap(36, 36, 0.20, 3)});
  return cases;
}

struct Tally {
  int queries = 0;
  int reachable = 0;
  int found = 0;
  double worst_ratio = 0.0;
};

void checkMap(const MapCase& m, double robot_radius_m, Tally* tally) {
  const OccupancyGrid2D grid = testmaps::gridFromMovingAi(m.text, 1.0);
  TopoPlannerConfig config;
  config.robot_radius_m = robot_radius_m;
  const TopologicalPlanner planner(grid, config);
  const std::vector<std::uint8_t> free = testmaps::inflatedFreeMask(grid, robot_radius_m);
  for (const auto& [s, g] : testmaps::randomQueries(grid, 12, robot_radius_m, 7)) {
    const std::string where = m.name + " r " + std::to_string(robot_radius_m) + " query (" + std::to_string(s.x()) +
                              "," + std::to_string(s.y()) + ") -> (" + std::to_string(g.x()) + "," +
                              std::to_string(g.y()) + ")";
    const testmaps::Inflated8Path oracle = testmaps::inflated8Path(grid, free, s, g);
    const Eigen::Vector2d start = grid.centreOf(s.x(), s.y());
    const Eigen::Vector2d goal = grid.centreOf(g.x(), g.y());
    const TopoPlan plan = planner.solve(start, goal);
    ++tally->queries;
    tally->reachable += oracle.found;
    if (oracle.found) {
      ASSERT_EQ(plan.status, PlanStatus::kSolved) << where;
    }
    if (plan.status != PlanStatus::kSolved) continue;
    ++tally->found;
    for (std::size_t i = 0; i < plan.classes.size(); ++i) {
      const auto& path = plan.classes[i].path;
      ASSERT_GE(path.size(), 2u) << where;
      EXPECT_LT((path.front() - start).norm(), 1e-9) << where;
      EXPECT_LT((path.back() - goal).norm(), 1e-9) << where;
      EXPECT_GE(testmaps::minClearanceAlong(grid, path, 0.01), robot_radius_m - 1e-6) << where << " class " << i;
      for (std::size_t j = 0; j < i; ++j) {
        EXPECT_FALSE(TopologicalPlanner::sameClass(plan.classes[i].h_signature, plan.classes[j].h_signature))
            << where << " classes " << i << " and " << j;
      }
    }
    if (oracle.found && oracle.length_m > 0.0) {
      const double ratio = plan.classes.front().length_m / oracle.length_m;
      tally->worst_ratio = std::max(tally->worst_ratio, ratio);
      EXPECT_LE(ratio, 1.01) << where << ": shortest class " << plan.classes.front().length_m << " m, 8-connected "
                             << oracle.length_m << " m";
    }
  }
}

TEST(GridMaps, EveryInflatedPathIsFoundClearAndNearTheOctileOptimum) {
  for (double r : {0.3, 0.0}) {
    Tally tally;
    for (const MapCase& m : mapCases()) checkMap(m, r, &tally);
    std::cout << "r " << r << ": " << tally.found << " found of " << tally.queries << " queries (" << tally.reachable
              << " reachable on the inflated 8-connected grid); worst shortest / optimum " << tally.worst_ratio << "\n";
    EXPECT_GE(tally.reachable, tally.queries / 2) << "the generators should give mostly reachable queries";
  }
}

// Warehouse maps (issue 41): regular shelf grids where hundreds of homotopy classes have nearly the
// same length. Far-apart queries (at least half the map's diagonal): the shortest class is always
// among those returned, within 1.000x of the 8-connected optimum (an any-angle path is never
// longer than the octile one).
struct WarehouseCase {
  std::string name;
  int cols, rows, shelf_w, shelf_h, aisle, margin_x, margin_y;
};

TEST(GridMaps, WarehouseShortestClassIsAlwaysReturned) {
  const std::vector<WarehouseCase> cases = {
      {"movingai-like-200", 10, 20, 10, 2, 1, 25, 1}, {"100-shelves", 10, 10, 10, 2, 1, 15, 1},
      {"500-shelves", 20, 25, 5, 2, 1, 10, 2},        {"200-shelves-aisle2", 10, 20, 10, 2, 2, 25, 2},
      {"150-shelves-aisle3", 10, 15, 6, 3, 3, 12, 3},
  };
  for (double r : {0.3, 0.0}) {
    int queries = 0;
    int diag_in_returned = 0;
    double worst = 0.0;
    for (const WarehouseCase& w : cases) {
      const OccupancyGrid2D grid = testmaps::gridFromMovingAi(
          testmaps::warehouseMap(w.cols, w.rows, w.shelf_w, w.shelf_h, w.aisle, w.margin_x, w.margin_y), 1.0);
      TopoPlannerConfig config;
      config.robot_radius_m = r;
      const TopologicalPlanner planner(grid, config);
      const std::vector<std::uint8_t> free = testmaps::inflatedFreeMask(grid, r);
      const double diagonal = std::hypot(grid.width, grid.height);
      int used = 0;
      for (const auto& [s, g] : testmaps::randomQueries(grid, 200, r, 11, true)) {
        if ((s - g).cast<double>().norm() < 0.5 * diagonal || used >= 6) continue;
        ++used;
        ++queries;
        const testmaps::Inflated8Path oracle = testmaps::inflated8Path(grid, free, s, g);
        ASSERT_TRUE(oracle.found);
        const Eigen::Vector2d start = grid.centreOf(s.x(), s.y());
        const Eigen::Vector2d goal = grid.centreOf(g.x(), g.y());
        const TopoPlan plan = planner.solve(start, goal);
        const std::string where = w.name + " r " + std::to_string(r) + " (" + std::to_string(s.x()) + "," +
                                  std::to_string(s.y()) + ") -> (" + std::to_string(g.x()) + "," +
                                  std::to_string(g.y()) + ")";
        ASSERT_EQ(plan.status, PlanStatus::kSolved) << where;
        std::vector<Eigen::Vector2d> oracle_path;
        for (const Eigen::Vector2i& c : oracle.cells) oracle_path.push_back(grid.centreOf(c.x(), c.y()));
        const std::vector<double> sig = planner.hSignature(oracle_path);
        bool in_returned = false;
        for (const HomologyClass& c : plan.classes) {
          in_returned = in_returned || TopologicalPlanner::sameClass(c.h_signature, sig);
        }
        diag_in_returned += in_returned;
        const double ratio = plan.classes.front().length_m / oracle.length_m;
        worst = std::max(worst, ratio);
        EXPECT_LE(ratio, 1.0 + 1e-9) << where << ": shortest class " << plan.classes.front().length_m
                                     << " m, 8-connected " << oracle.length_m << " m; the optimum's class is "
                                     << (in_returned ? "returned (shortening stopped short)" : "not returned");
      }
      EXPECT_GE(used, 3) << w.name;
    }
    std::cout << "warehouse r " << r << ": " << queries << " far-apart queries, the 8-connected optimum's class among "
              << "those returned in " << diag_in_returned << "; worst shortest / optimum " << worst << "\n";
  }
}

}  // namespace
}  // namespace tgnav::planner
