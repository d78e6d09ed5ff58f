#pragma once
// Exact Euclidean distance transform of a 2D occupancy grid with its feature transform (the
// nearest occupied cell of every cell), Felzenszwalb & Huttenlocher 2012, O(cells). The map's
// outside counts as occupied: the grid is padded by one occupied cell on every side.
#include <Eigen/Core>
#include <vector>

#include "planner/occupancy_grid.h"

namespace tgnav::planner {

class DistanceField {
 public:
  explicit DistanceField(const OccupancyGrid2D& grid);

  const OccupancyGrid2D& grid() const { return grid_; }
  // Distance in metres from the centre of cell (ix, iy) to the centre of the nearest occupied
  // cell (0 in occupied cells). Cells outside the grid: 0.
  double centreDistance(int ix, int iy) const;
  // Clearance of a point: its distance to the boundary of the nearest occupied cell (negative
  // inside an occupied cell or outside the map).
  double clearance(const Eigen::Vector2d& p_m) const;
  // The same, and its gradient (unit vector away from the nearest obstacle; zero where the
  // clearance is not positive).
  double clearance(const Eigen::Vector2d& p_m, Eigen::Vector2d* gradient) const;
  // Nearest occupied cell of (ix, iy), in grid coordinates (may be -1 or width/height: the
  // padding ring outside the map).
  Eigen::Vector2i nearestObstacle(int ix, int iy) const;
  // True if every point of the segment keeps `clearance_m` (exact: a path along a corridor whose
  // clearance is exactly `clearance_m` is clear).
  bool segmentClear(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double clearance_m) const;
  // Exact distance from a segment to the nearest occupied square, when below `reach_m`
  // (otherwise some value >= reach_m). Cost grows with the segment's box: for short segments.
  double segmentClearance(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double reach_m) const;

 private:
  std::size_t padded(int ix, int iy) const { return static_cast<std::size_t>(iy + 1) * (grid_.width + 2) + ix + 1; }
  OccupancyGrid2D grid_;
  std::vector<double> dist2_cells_;    // squared distance in cells, padded grid
  std::vector<Eigen::Vector2i> site_;  // nearest obstacle, grid coordinates
};

}  // namespace tgnav::planner
