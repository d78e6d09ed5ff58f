#include "planner/distance_field.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "planner/edt.h"

namespace tgnav::planner {

namespace {
constexpr double kInf = 1e20;
}

DistanceField::DistanceField(const OccupancyGrid2D& grid) : grid_(grid) {
  const int w = grid.width + 2;
  const int h = grid.height + 2;
  auto occupied = [&](int px, int py) { return grid.isOccupied(px - 1, py - 1); };  // padding: outside = occupied
  // Pass 1, along y: squared distance to the nearest occupied cell of the same column.
  std::vector<double> g(static_cast<std::size_t>(w) * h, kInf);
  std::vector<int> gy(static_cast<std::size_t>(w) * h, -1);
  for (int x = 0; x < w; ++x) {
    int last = -1;
    for (int y = 0; y < h; ++y) {
      if (occupied(x, y)) last = y;
      if (last >= 0) {
        g[static_cast<std::size_t>(y) * w + x] = static_cast<double>(y - last) * (y - last);
        gy[static_cast<std::size_t>(y) * w + x] = last;
      }
    }
    last = -1;
    for (int y = h - 1; y >= 0; --y) {
      if (occupied(x, y)) last = y;
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      if (last >= 0 && static_cast<double>(last - y) * (last - y) < g[i]) {
        g[i] = static_cast<double>(last - y) * (last - y);
        gy[i] = last;
      }
    }
  }
  // Pass 2, along x: lower envelope of the parabolas (x - q)^2 + g(q).
  dist2_cells_.assign(static_cast<std::size_t>(w) * h, kInf);
  site_.assign(static_cast<std::size_t>(w) * h, Eigen::Vector2i(-1, -1));
  EnvelopeScratch scratch;
  std::vector<int> arg(w);
  for (int y = 0; y < h; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * w;
    lowerEnvelope(&g[row], w, &dist2_cells_[row], arg.data(), &scratch);
    for (int x = 0; x < w; ++x) site_[row + x] = Eigen::Vector2i(arg[x] - 1, gy[row + arg[x]] - 1);
  }
}

double DistanceField::centreDistance(int ix, int iy) const {
  if (!grid_.inside(ix, iy)) return 0.0;
  return std::sqrt(dist2_cells_[padded(ix, iy)]) * grid_.resolution_m;
}

Eigen::Vector2i DistanceField::nearestObstacle(int ix, int iy) const { return site_[padded(ix, iy)]; }

double DistanceField::clearance(const Eigen::Vector2d& p_m) const { return clearance(p_m, nullptr); }

double DistanceField::clearance(const Eigen::Vector2d& p_m, Eigen::Vector2d* gradient) const {
  if (gradient) gradient->setZero();
  const Eigen::Vector2i c = grid_.cellOf(p_m);
  if (grid_.isOccupied(c.x(), c.y())) return -1.0;
  // The nearest obstacle cell of p is the nearest of its own cell or of a neighbour cell (the
  // feature transform is exact at cell centres); measure to that cell's square exactly.
  const double half = 0.5 * grid_.resolution_m;
  double best = std::numeric_limits<double>::infinity();
  Eigen::Vector2d best_offset = Eigen::Vector2d::Zero();
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const int nx = c.x() + dx;
      const int ny = c.y() + dy;
      if (nx < -1 || ny < -1 || nx > grid_.width || ny > grid_.height) continue;
      const Eigen::Vector2i site = site_[padded(nx, ny)];
      const Eigen::Vector2d r = p_m - grid_.centreOf(site.x(), site.y());
      // From the nearest point of the obstacle square to p.
      const Eigen::Vector2d d = (r.cwiseAbs().array() - half).cwiseMax(0.0).matrix().cwiseProduct(r.cwiseSign());
      const double n = d.norm();
      if (n < best) {
        best = n;
        best_offset = d;
      }
    }
  }
  if (gradient && best > 0.0 && std::isfinite(best)) *gradient = best_offset / best;
  return best;
}

bool DistanceField::segmentClear(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double clearance_m) const {
  // Clearance is 1-Lipschitz: every point lies within h/2 of a sample spaced h apart, so
  // samples with clearance >= clearance_m + h/2 prove the whole segment clear.
  const double len = (b - a).norm();
  const int steps = std::max(1, static_cast<int>(std::ceil(len / (0.5 * grid_.resolution_m))));
  const double need = clearance_m + 0.5 * len / steps;
  // A point is at most 0.71 cells from its cell's centre and an obstacle cell's square reaches
  // 0.71 cells from its own: the centre distance less 1.42 cells bounds the clearance from below.
  const double slack = 1.4143 * grid_.resolution_m;
  for (int i = 0; i <= steps; ++i) {
    const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(i) / steps);
    const Eigen::Vector2i c = grid_.cellOf(p);
    if (grid_.inside(c.x(), c.y()) && centreDistance(c.x(), c.y()) - slack >= need) continue;
    if (clearance(p) < need) return false;
  }
  return true;
}

}  // namespace tgnav::planner
