// The EDT is exact: it equals a brute-force search on random grids, and its feature transform
// points at an occupied cell at that distance.
#include "planner/distance_field.h"

#include <gtest/gtest.h>

#include <random>

namespace tgnav::planner {
namespace {

TEST(DistanceField, EqualsBruteForceOnRandomGrids) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    OccupancyGrid2D grid(37, 23, 0.1, Eigen::Vector2d(-1.0, 2.0));
    std::bernoulli_distribution obstacle(trial % 2 ? 0.02 : 0.15);
    for (int y = 0; y < grid.height; ++y) {
      for (int x = 0; x < grid.width; ++x) grid.set(x, y, obstacle(rng));
    }
    const DistanceField df(grid);
    for (int y = 0; y < grid.height; ++y) {
      for (int x = 0; x < grid.width; ++x) {
        // Brute force over occupied cells and the padding ring.
        double best = 1e18;
        for (int oy = -1; oy <= grid.height; ++oy) {
          for (int ox = -1; ox <= grid.width; ++ox) {
            if (!grid.isOccupied(ox, oy)) continue;
            best = std::min(best, std::hypot(ox - x, oy - y));
          }
        }
        ASSERT_NEAR(df.centreDistance(x, y), best * grid.resolution_m, 1e-9) << x << "," << y;
        const Eigen::Vector2i s = df.nearestObstacle(x, y);
        ASSERT_TRUE(grid.isOccupied(s.x(), s.y()));
        ASSERT_NEAR(std::hypot(s.x() - x, s.y() - y), best, 1e-9);
      }
    }
  }
}

TEST(DistanceField, SegmentClearanceRespectsObstacles) {
  OccupancyGrid2D grid(50, 50, 0.1, Eigen::Vector2d::Zero());
  for (int y = 20; y < 30; ++y) {
    for (int x = 20; x < 30; ++x) grid.set(x, y, true);  // block [2, 3] x [2, 3] m
  }
  const DistanceField df(grid);
  EXPECT_TRUE(df.segmentClear({0.5, 1.0}, {4.5, 1.0}, 0.3));   // 1 m below the block
  EXPECT_FALSE(df.segmentClear({0.5, 2.5}, {4.5, 2.5}, 0.3));  // through it
  EXPECT_FALSE(df.segmentClear({0.5, 1.8}, {4.5, 1.8}, 0.3));  // 0.2 m below it: too close
  EXPECT_LT(df.clearance({-1.0, 0.0}), 0.0);                   // outside the map
}

}  // namespace
}  // namespace tgnav::planner
