#pragma once
// A 2D occupancy grid in the map frame: ROS map_server's convention (origin = world position
// of the lower-left corner of cell (0, 0), x right, y up). Cell (ix, iy) covers
// [origin + (ix, iy) * res, origin + (ix + 1, iy + 1) * res). Unknown space is stored as
// occupied: the planner never plans through what it has not seen.
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <vector>

namespace tgnav::planner {

struct OccupancyGrid2D {
  int width = 0;   // cells along x
  int height = 0;  // cells along y
  double resolution_m = 0.1;
  Eigen::Vector2d origin_m = Eigen::Vector2d::Zero();
  std::vector<std::uint8_t> occupied;  // row-major from the lowest y: index = iy * width + ix

  OccupancyGrid2D() = default;
  OccupancyGrid2D(int w, int h, double res, const Eigen::Vector2d& origin)
      : width(w), height(h), resolution_m(res), origin_m(origin), occupied(static_cast<std::size_t>(w) * h, 0) {}

  bool inside(int ix, int iy) const { return ix >= 0 && iy >= 0 && ix < width && iy < height; }
  // Outside the grid counts as occupied.
  bool isOccupied(int ix, int iy) const { return !inside(ix, iy) || occupied[index(ix, iy)] != 0; }
  void set(int ix, int iy, bool occ) { occupied[index(ix, iy)] = occ ? 1 : 0; }
  std::size_t index(int ix, int iy) const { return static_cast<std::size_t>(iy) * width + ix; }
  Eigen::Vector2i cellOf(const Eigen::Vector2d& p_m) const {
    const Eigen::Vector2d c = (p_m - origin_m) / resolution_m;
    return Eigen::Vector2i(static_cast<int>(std::floor(c.x())), static_cast<int>(std::floor(c.y())));
  }
  Eigen::Vector2d centreOf(int ix, int iy) const {
    return origin_m + resolution_m * Eigen::Vector2d(ix + 0.5, iy + 0.5);
  }
  int freeCells() const {
    int n = 0;
    for (std::uint8_t o : occupied) n += (o == 0);
    return n;
  }
};

}  // namespace tgnav::planner
