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

double DistanceField::segmentClearance(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double reach_m) const {
  // Every square closer than reach_m to the segment has a cell within the segment's box grown by
  // reach_m; for a segment and a square that do not meet, the nearest pair has a corner of one.
  const double res = grid_.resolution_m;
  const Eigen::Vector2i lo = grid_.cellOf(a.cwiseMin(b) - Eigen::Vector2d::Constant(reach_m));
  const Eigen::Vector2i hi = grid_.cellOf(a.cwiseMax(b) + Eigen::Vector2d::Constant(reach_m));
  const Eigen::Vector2d ab = b - a;
  auto pointToSegment = [&](const Eigen::Vector2d& p) {
    const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
    return (a + t * ab - p).norm();
  };
  double best = std::numeric_limits<double>::infinity();
  for (int iy = lo.y(); iy <= hi.y(); ++iy) {
    for (int ix = lo.x(); ix <= hi.x(); ++ix) {
      if (!grid_.isOccupied(ix, iy)) continue;
      const Eigen::Vector2d sq_lo = grid_.origin_m + res * Eigen::Vector2d(ix, iy);
      const Eigen::Vector2d sq_hi = sq_lo + Eigen::Vector2d::Constant(res);
      // Liang-Barsky: does the segment enter the square?
      double t0 = 0.0;
      double t1 = 1.0;
      bool meets = true;
      for (int k = 0; k < 2 && meets; ++k) {
        if (std::abs(ab[k]) < 1e-300) {
          meets = a[k] >= sq_lo[k] && a[k] <= sq_hi[k];
          continue;
        }
        double ta = (sq_lo[k] - a[k]) / ab[k];
        double tb = (sq_hi[k] - a[k]) / ab[k];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
        meets = t0 <= t1;
      }
      if (meets) return 0.0;
      auto toSquare = [&](const Eigen::Vector2d& p) { return (p - p.cwiseMax(sq_lo).cwiseMin(sq_hi)).norm(); };
      best = std::min({best, toSquare(a), toSquare(b), pointToSegment(sq_lo), pointToSegment(sq_hi),
                       pointToSegment(Eigen::Vector2d(sq_lo.x(), sq_hi.y())),
                       pointToSegment(Eigen::Vector2d(sq_hi.x(), sq_lo.y()))});
    }
  }
  return best;
}

bool DistanceField::segmentClear(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double clearance_m) const {
  // Marching from a to b: clearance is 1-Lipschitz, so at a point whose clearance is at least
  // clearance_m + d the next d metres are clear and can be skipped (sphere tracing); where the
  // margin is less than four cells, the next four cells are measured exactly against the squares
  // near them (cheaper than many short steps along a wall).
  const double len = (b - a).norm();
  if (len == 0.0) return clearance(a) >= clearance_m;
  const Eigen::Vector2d dir = (b - a) / len;
  const double res = grid_.resolution_m;
  const double min_step = 0.25 * res;
  // A point is at most 0.71 cells from its cell's centre and an obstacle cell's square reaches
  // 0.71 cells from its own: the centre distance less 1.42 cells bounds the clearance from below.
  const double slack = 1.4143 * res;
  const double exact_stretch = 4.0 * res;
  double t = 0.0;
  while (true) {
    const Eigen::Vector2d p = a + t * dir;
    const Eigen::Vector2i c = grid_.cellOf(p);
    double margin = grid_.inside(c.x(), c.y()) ? centreDistance(c.x(), c.y()) - slack - clearance_m : -1.0;
    if (margin < min_step) margin = clearance(p) - clearance_m;
    if (margin < 0.0) return false;
    if (margin < exact_stretch) {
      const double to = std::min(len, t + exact_stretch);
      if (segmentClearance(p, a + to * dir, clearance_m) < clearance_m) return false;
      margin = to - t;
    }
    if (t + margin >= len) return true;
    t += margin;
  }
}

}  // namespace tgnav::planner
