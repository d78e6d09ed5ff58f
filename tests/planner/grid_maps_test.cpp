// The topological planner on benchmark-like grid maps at 1 m per cell (MovingAI kinds, made here
// by tests/planner/grid_maps.h): wherever an 8-connected path exists on the map inflated by the
// robot radius, a path is found; every class path keeps the radius from every occupied square
// (checked by an independent clearance); the shortest class is within 1 % of the 8-connected
// optimum; the classes are pairwise distinct.
#include "grid_maps.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace tgnav::planner
