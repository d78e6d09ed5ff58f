// Geometry of a layout at the flight height: distances, rays and the connectivity check.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <limits>

#include "harness/scenes/scene_layout.h"

namespace tgnav::harness::scenes {

namespace {

// Distance along the ray (ox, oy) + t (dx, dy) to where it enters `b`; infinity when it misses.
double rayDistance(const Block& b, double ox, double oy, double dx, double dy) {
  constexpr double kMiss = std::numeric_limits<double>::infinity();
  if (b.cylinder) {
    const double px = ox - b.cx, py = oy - b.cy;
    const double bq = px * dx + py * dy;
    const double c = px * px + py * py - b.hx * b.hx;
    if (c <= 0.0) return 0.0;
    const double disc = bq * bq - c;
    if (disc < 0.0) return kMiss;
    const double t = -bq - std::sqrt(disc);
    return t >= 0.0 ? t : kMiss;
  }
  double t_in = 0.0, t_out = kMiss;
  const double o[2] = {ox - b.cx, oy - b.cy}, d[2] = {dx, dy}, h[2] = {b.hx, b.hy};
  for (int k = 0; k < 2; ++k) {
    if (std::abs(d[k]) < 1e-12) {
      if (std::abs(o[k]) > h[k]) return kMiss;
      continue;
    }
    double t0 = (-h[k] - o[k]) / d[k], t1 = (h[k] - o[k]) / d[k];
    if (t0 > t1) std::swap(t0, t1);
    t_in = std::max(t_in, t0);
    t_out = std::min(t_out, t1);
  }
  return t_in <= t_out ? t_in : kMiss;
}

std::string describe(const char* what, double value, double minimum) {
  char text[160];
  std::snprintf(text, sizeof text, "%s %.3f m < %.2f m", what, value, minimum);
  return text;
}

}  // namespace

double round2(double v) { return std::round(v * 100.0) / 100.0; }

double distanceTo(const Block& b, double x, double y) {
  if (b.cylinder) return std::max(0.0, std::hypot(x - b.cx, y - b.cy) - b.hx);
  const double dx = std::max(0.0, std::abs(x - b.cx) - b.hx);
  const double dy = std::max(0.0, std::abs(y - b.cy) - b.hy);
  return std::hypot(dx, dy);
}

double gapBetween(const Block& a, const Block& b) {
  if (a.cylinder && b.cylinder) return std::max(0.0, std::hypot(a.cx - b.cx, a.cy - b.cy) - a.hx - b.hx);
  if (a.cylinder) return std::max(0.0, distanceTo(b, a.cx, a.cy) - a.hx);
  if (b.cylinder) return std::max(0.0, distanceTo(a, b.cx, b.cy) - b.hx);
  const double dx = std::max(0.0, std::abs(a.cx - b.cx) - a.hx - b.hx);
  const double dy = std::max(0.0, std::abs(a.cy - b.cy) - a.hy - b.hy);
  return std::hypot(dx, dy);
}

double clearanceAt(const Layout& layout, double x, double y) {
  double best = std::numeric_limits<double>::infinity();
  for (const Block& b : layout.blocks) best = std::min(best, distanceTo(b, x, y));
  return best;
}

int firstHit(const Layout& layout, double x, double y, double angle_rad, double range_m) {
  const double dx = std::cos(angle_rad), dy = std::sin(angle_rad);
  int hit = -1;
  double nearest = range_m;
  for (std::size_t i = 0; i < layout.blocks.size(); ++i) {
    const double t = rayDistance(layout.blocks[i], x, y, dx, dy);
    if (t < nearest) {
      nearest = t;
      hit = static_cast<int>(i);
    }
  }
  return hit;
}

bool connected(const Layout& layout, double inflation_m) {
  const int nx = static_cast<int>(std::ceil((layout.xmax - layout.xmin) / kCellM));
  const int ny = static_cast<int>(std::ceil((layout.ymax - layout.ymin) / kCellM));
  auto cellOf = [&](double x, double y) {
    const int i = std::clamp(static_cast<int>((x - layout.xmin) / kCellM), 0, nx - 1);
    const int j = std::clamp(static_cast<int>((y - layout.ymin) / kCellM), 0, ny - 1);
    return j * nx + i;
  };
  std::vector<char> free(static_cast<std::size_t>(nx) * ny);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const double x = layout.xmin + (i + 0.5) * kCellM, y = layout.ymin + (j + 0.5) * kCellM;
      free[j * nx + i] = clearanceAt(layout, x, y) >= inflation_m;
    }
  }
  const int from = cellOf(layout.start.x, layout.start.y), to = cellOf(layout.goal.x, layout.goal.y);
  if (!free[from] || !free[to]) return false;
  std::vector<char> seen(free.size(), 0);
  std::deque<int> queue{from};
  seen[from] = 1;
  while (!queue.empty()) {
    const int c = queue.front();
    queue.pop_front();
    if (c == to) return true;
    const int i = c % nx, j = c / nx;
    const int next[4][2] = {{i + 1, j}, {i - 1, j}, {i, j + 1}, {i, j - 1}};
    for (const auto& n : next) {
      if (n[0] < 0 || n[0] >= nx || n[1] < 0 || n[1] >= ny) continue;
      const int k = n[1] * nx + n[0];
      if (free[k] && !seen[k]) {
        seen[k] = 1;
        queue.push_back(k);
      }
    }
  }
  return false;
}

std::string validateLayout(const Layout& layout) {
  if (layout.obstacles.empty()) return "no free-standing obstacle";
  const double start = clearanceAt(layout, layout.start.x, layout.start.y);
  if (start < kEndClearanceM) return describe("start clearance", start, kEndClearanceM);
  const double goal = clearanceAt(layout, layout.goal.x, layout.goal.y);
  if (goal < kEndClearanceM) return describe("goal clearance", goal, kEndClearanceM);
  const auto& blocks = layout.blocks;
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    for (std::size_t j = i + 1; j < blocks.size(); ++j) {
      if (blocks[i].obstacle == blocks[j].obstacle) continue;  // one obstacle, or two wall panels
      const double gap = gapBetween(blocks[i], blocks[j]);
      if (gap < kObstacleGapM - 1e-9) {
        return describe((blocks[i].name + "/" + blocks[j].name + " gap").c_str(), gap, kObstacleGapM);
      }
    }
  }
  if (!connected(layout, kInflationM)) return "start and goal are not connected";
  return "";
}

}  // namespace tgnav::harness::scenes
