#pragma once
// Test support for acceptance tests of the 2D topological planner on MovingAI-style maps:
// seeded map generators (emitting MovingAI text, so tests can go through the real loader), a small
// in-memory parser, and an independent oracle (inflated 8-connected A*, brute-force clearance) to
// compare the planner against. Nothing here uses the planner's own distance field or graph, so a
// bug there cannot hide in the reference.
//
// Determinism: generators draw only raw std::mt19937 outputs and reduce them with integer
// arithmetic. std::uniform_int_distribution & co. are implementation-defined, so maps built with
// them would differ between libstdc++ and libc++ and break golden values.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <queue>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "planner/occupancy_grid.h"

namespace tgnav::planner::testmaps {

namespace detail {

// Rows in MovingAI order (row 0 = top = largest y), '.' free and '@' blocked.
using Rows = std::vector<std::string>;

inline std::string toMovingAi(const Rows& rows) {
  const int h = static_cast<int>(rows.size());
  const int w = h > 0 ? static_cast<int>(rows[0].size()) : 0;
  std::string out = "type octile\nheight " + std::to_string(h) + "\nwidth " + std::to_string(w) + "\nmap\n";
  for (const std::string& row : rows) out += row + "\n";
  return out;
}

// Uniform-enough integer in [0, n); modulo bias is irrelevant for test maps, portability is not.
inline int below(std::mt19937& rng, int n) {
  assert(n > 0);
  return static_cast<int>(rng() % static_cast<std::uint32_t>(n));
}

// Fisher-Yates with below(): std::shuffle's draws are implementation-defined too.
template <typename T>
void shuffle(std::vector<T>& v, std::mt19937& rng) {
  for (int i = static_cast<int>(v.size()) - 1; i > 0; --i) std::swap(v[i], v[below(rng, i + 1)]);
}

// Centre-to-square gap along one axis for a square `d` cells away, in cells (0 for the same column).
inline double axisGapCells(int d) { return d == 0 ? 0.0 : std::abs(d) - 0.5; }

// Offsets (dx, dy) of squares closer than `r` to a cell's centre, nearest first so that a blocked
// cell is usually rejected after a few lookups. Squares farther than ceil(r/res)+1 cells cannot
// be closer than r, which bounds the window. The cell itself is excluded: callers test it apart,
// because at r = 0 its gap (0) is not < r yet an occupied cell must never count as free.
inline std::vector<Eigen::Vector2i> inflationOffsets(double resolution_m, double r) {
  std::vector<std::pair<double, Eigen::Vector2i>> within;
  const int k = static_cast<int>(std::ceil(r / resolution_m)) + 1;
  for (int dy = -k; dy <= k; ++dy) {
    for (int dx = -k; dx <= k; ++dx) {
      if (dx == 0 && dy == 0) continue;
      const double gx = axisGapCells(dx) * resolution_m;
      const double gy = axisGapCells(dy) * resolution_m;
      const double d = std::sqrt(gx * gx + gy * gy);
      if (d < r) within.emplace_back(d, Eigen::Vector2i(dx, dy));
    }
  }
  std::stable_sort(within.begin(), within.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Eigen::Vector2i> out;
  out.reserve(within.size());
  for (const auto& w : within) out.push_back(w.second);
  return out;
}

// isOccupied() is true outside the grid, so the same offsets also measure the map boundary:
// the map behaves as if surrounded by occupied squares.
inline bool freeWithOffsets(const OccupancyGrid2D& g, int ix, int iy, const std::vector<Eigen::Vector2i>& offsets) {
  if (g.isOccupied(ix, iy)) return false;
  for (const Eigen::Vector2i& o : offsets) {
    if (g.isOccupied(ix + o.x(), iy + o.y())) return false;
  }
  return true;
}

// Distance from `p` to the closed square of cell (ix, iy).
inline double pointToSquare(const OccupancyGrid2D& g, const Eigen::Vector2d& p, int ix, int iy) {
  const Eigen::Vector2d gap =
      ((p - g.centreOf(ix, iy)).cwiseAbs().array() - 0.5 * g.resolution_m).cwiseMax(0.0).matrix();
  return gap.norm();
}

}  // namespace detail

// ---------------------------------------------------------------------------------------------
// Generators. Each returns MovingAI text; the same seed always gives the same bytes.
// ---------------------------------------------------------------------------------------------

// A maze of cells_w x cells_h rooms on a (2*cells_w+1) x (2*cells_h+1) grid: 1-cell corridors and
// 1-cell walls. Without openings it is a perfect maze (a tree: one homotopy class per query);
// each of the `extra_openings` removed interior walls adds exactly one loop, so a topological
// planner has several homotopy classes to find.
inline std::string mazeMap(int cells_w, int cells_h, std::uint32_t seed, int extra_openings = 0) {
  assert(cells_w >= 1 && cells_h >= 1);
  std::mt19937 rng(seed);
  const int w = 2 * cells_w + 1;
  const int h = 2 * cells_h + 1;
  detail::Rows rows(h, std::string(w, '@'));
  std::vector<std::uint8_t> visited(static_cast<std::size_t>(cells_w) * cells_h, 0);
  const auto open = [&](int x, int y) { rows[y][x] = '.'; };

  // Recursive backtracker with an explicit stack: deep recursion would overflow on big mazes.
  static const int kDx[4] = {1, -1, 0, 0};
  static const int kDy[4] = {0, 0, 1, -1};
  std::vector<Eigen::Vector2i> stack;
  const Eigen::Vector2i start(detail::below(rng, cells_w), detail::below(rng, cells_h));
  stack.push_back(start);
  visited[static_cast<std::size_t>(start.y()) * cells_w + start.x()] = 1;
  open(2 * start.x() + 1, 2 * start.y() + 1);
  while (!stack.empty()) {
    const Eigen::Vector2i c = stack.back();
    int candidates[4];
    int n = 0;
    for (int d = 0; d < 4; ++d) {
      const int nx = c.x() + kDx[d];
      const int ny = c.y() + kDy[d];
      if (nx < 0 || ny < 0 || nx >= cells_w || ny >= cells_h) continue;
      if (!visited[static_cast<std::size_t>(ny) * cells_w + nx]) candidates[n++] = d;
    }
    if (n == 0) {
      stack.pop_back();
      continue;
    }
    const int d = candidates[detail::below(rng, n)];
    const Eigen::Vector2i next(c.x() + kDx[d], c.y() + kDy[d]);
    visited[static_cast<std::size_t>(next.y()) * cells_w + next.x()] = 1;
    open(2 * c.x() + 1 + kDx[d], 2 * c.y() + 1 + kDy[d]);
    open(2 * next.x() + 1, 2 * next.y() + 1);
    stack.push_back(next);
  }

  // Only walls between two rooms qualify (one even and one odd coordinate, not on the border):
  // pillars at even/even would open nothing, and border walls would open onto outside space.
  std::vector<Eigen::Vector2i> walls;
  for (int y = 1; y < h - 1; ++y) {
    for (int x = 1; x < w - 1; ++x) {
      if ((x % 2) != (y % 2) && rows[y][x] == '@') walls.emplace_back(x, y);
    }
  }
  detail::shuffle(walls, rng);
  for (int i = 0; i < extra_openings && i < static_cast<int>(walls.size()); ++i) open(walls[i].x(), walls[i].y());
  return detail::toMovingAi(rows);
}

// A w x h map cut into a grid of rooms (at least room_size cells inside; the leftover is spread
// over the rooms) by 1-cell walls, with an outer border wall. Every wall between two adjacent
// rooms has a 1-cell door at a random position; about one wall in four has a second door, which
// makes a loop around that wall piece. Door-width passages are what inflation closes first, so
// these maps probe the planner's clearance handling.
inline std::string roomsMap(int w, int h, int room_size, std::uint32_t seed) {
  assert(room_size >= 1 && w >= room_size + 2 && h >= room_size + 2);
  std::mt19937 rng(seed);
  // Wall coordinates along one axis: 0, ..., side-1, spaced at least room_size+1 apart.
  const auto wallsAlong = [room_size](int side) {
    const int rooms = std::max(1, (side - 1) / (room_size + 1));
    std::vector<int> at(rooms + 1);
    for (int k = 0; k <= rooms; ++k) at[k] = k * (side - 1) / rooms;
    return at;
  };
  const std::vector<int> xs = wallsAlong(w);
  const std::vector<int> ys = wallsAlong(h);
  detail::Rows rows(h, std::string(w, '.'));
  for (int x : xs) {
    for (int y = 0; y < h; ++y) rows[y][x] = '@';
  }
  for (int y : ys) rows[y] = std::string(w, '@');

  // Doors go strictly between two wall crossings, so no door ever opens onto a pillar.
  const auto pierce = [&](int lo, int hi, const std::function<void(int)>& openAt) {
    const int len = hi - lo - 1;
    const int first = detail::below(rng, len);
    openAt(lo + 1 + first);
    if (len >= 2 && detail::below(rng, 4) == 0) openAt(lo + 1 + (first + 1 + detail::below(rng, len - 1)) % len);
  };
  for (std::size_t j = 0; j + 1 < ys.size(); ++j) {
    for (std::size_t i = 1; i + 1 < xs.size(); ++i) {
      pierce(ys[j], ys[j + 1], [&](int y) { rows[y][xs[i]] = '.'; });
    }
  }
  for (std::size_t j = 1; j + 1 < ys.size(); ++j) {
    for (std::size_t i = 0; i + 1 < xs.size(); ++i) {
      pierce(xs[i], xs[i + 1], [&](int x) { rows[ys[j]][x] = '.'; });
    }
  }
  return detail::toMovingAi(rows);
}

// A w x h map where each cell is blocked independently with probability `fraction` (intended
// 0.10-0.20). Single-cell obstacles give many small holes, i.e. many homotopy classes, and
// corner-touching pairs that test the no-corner-cutting rule. The border is not forced blocked.
inline std::string randomCellsMap(int w, int h, double fraction, std::uint32_t seed) {
  assert(w >= 1 && h >= 1 && fraction >= 0.0 && fraction <= 1.0);
  std::mt19937 rng(seed);
  // Compare the raw 32-bit draw against a fixed threshold: exact and library-independent.
  const std::uint64_t threshold = static_cast<std::uint64_t>(fraction * 4294967296.0);
  detail::Rows rows(h, std::string(w, '.'));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (static_cast<std::uint64_t>(rng()) < threshold) rows[y][x] = '@';
    }
  }
  return detail::toMovingAi(rows);
}

// A large open w x h map with `n_blocks` building-like rectangles of 3..20 cells a side (clipped
// to the map). Every third block is pushed against a random border, so that the boundary (which
// counts as obstacle) takes part in the topology. Blocks may overlap and may wall off pockets;
// queries there are simply unreachable (inflated8Path reports found = false).
inline std::string blocksMap(int w, int h, int n_blocks, std::uint32_t seed) {
  assert(w >= 1 && h >= 1 && n_blocks >= 0);
  std::mt19937 rng(seed);
  detail::Rows rows(h, std::string(w, '.'));
  for (int b = 0; b < n_blocks; ++b) {
    const int bw = std::min(w, 3 + detail::below(rng, 18));
    const int bh = std::min(h, 3 + detail::below(rng, 18));
    int x0 = detail::below(rng, w - bw + 1);
    int y0 = detail::below(rng, h - bh + 1);
    if (b % 3 == 0) {
      switch (detail::below(rng, 4)) {
        case 0:
          x0 = 0;
          break;
        case 1:
          x0 = w - bw;
          break;
        case 2:
          y0 = 0;
          break;
        default:
          y0 = h - bh;
          break;
      }
    }
    for (int y = y0; y < y0 + bh; ++y) {
      for (int x = x0; x < x0 + bw; ++x) rows[y][x] = '@';
    }
  }
  return detail::toMovingAi(rows);
}

// A warehouse: a regular grid of cols x rows rectangular shelves, each shelf_w x shelf_h cells,
// `aisle` free cells between neighbouring shelves, and margin_x / margin_y free cells between the
// outer shelves and the map's edge (which counts as obstacle). The MovingAI MAPF map
// warehouse-10-20-10-2-1 is warehouseMap(10, 20, 10, 2, 1, 25, 1) inside its one-cell border: with
// one-cell aisles, every monotone route through the shelves has the same 4-connected length, so a
// far-apart query has hundreds of near-equal homotopy classes. No randomness: queries vary.
inline std::string warehouseMap(int cols, int rows, int shelf_w, int shelf_h, int aisle, int margin_x, int margin_y) {
  assert(cols >= 1 && rows >= 1 && shelf_w >= 1 && shelf_h >= 1 && aisle >= 1 && margin_x >= 1 && margin_y >= 1);
  const int w = 2 * margin_x + cols * shelf_w + (cols - 1) * aisle;
  const int h = 2 * margin_y + rows * shelf_h + (rows - 1) * aisle;
  detail::Rows out(h, std::string(w, '.'));
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const int x0 = margin_x + c * (shelf_w + aisle);
      const int y0 = margin_y + r * (shelf_h + aisle);
      for (int y = y0; y < y0 + shelf_h; ++y) {
        for (int x = x0; x < x0 + shelf_w; ++x) out[y][x] = '@';
      }
    }
  }
  return detail::toMovingAi(out);
}

// ---------------------------------------------------------------------------------------------
// Parsing.
// ---------------------------------------------------------------------------------------------

// Parses the generators' output into a grid with origin (0, 0), flipping rows exactly as
// harness::loadMovingAiMap does (text row 0 is the largest y). Not a validating loader: malformed
// input only trips asserts. Passable terrain matches the loader ('.', 'G', 'S').
inline OccupancyGrid2D gridFromMovingAi(const std::string& text, double resolution_m) {
  std::istringstream in(text);
  std::string key;
  std::string type;
  int height = 0;
  int width = 0;
  in >> key >> type;
  assert(key == "type" && type == "octile");
  in >> key >> height;
  assert(key == "height" && height > 0);
  in >> key >> width;
  assert(key == "width" && width > 0);
  in >> key;
  assert(key == "map");
  OccupancyGrid2D grid(width, height, resolution_m, Eigen::Vector2d::Zero());
  std::string row;
  for (int r = 0; r < height; ++r) {
    in >> row;
    assert(static_cast<int>(row.size()) == width);
    for (int ix = 0; ix < width; ++ix) {
      const char c = row[ix];
      grid.set(ix, height - 1 - r, !(c == '.' || c == 'G' || c == 'S'));
    }
  }
  return grid;
}

// ---------------------------------------------------------------------------------------------
// Oracle: inflation and 8-connected A*.
// ---------------------------------------------------------------------------------------------

// True when cell (ix, iy) is inside the grid, not occupied, and its centre is at least `r` from
// every occupied square, the space outside the map included. Builds the offset kernel per call:
// for many cells use inflatedFreeMask(). Gaps are computed from integer cell offsets, so the answer
// is the same for every cell position; still, avoid radii equal to a gap ((k - 0.5) * res, or a
// hypot of two such) in tests unless res is a power of two: there the planner's own arithmetic
// may round the other way.
inline bool inflatedFree(const OccupancyGrid2D& g, int ix, int iy, double r) {
  if (!g.inside(ix, iy)) return false;
  return detail::freeWithOffsets(g, ix, iy, detail::inflationOffsets(g.resolution_m, r));
}

// inflatedFree() for every cell, indexed like g.occupied (1 = free).
inline std::vector<std::uint8_t> inflatedFreeMask(const OccupancyGrid2D& g, double r) {
  const std::vector<Eigen::Vector2i> offsets = detail::inflationOffsets(g.resolution_m, r);
  std::vector<std::uint8_t> free(g.occupied.size(), 0);
  for (int iy = 0; iy < g.height; ++iy) {
    for (int ix = 0; ix < g.width; ++ix) free[g.index(ix, iy)] = detail::freeWithOffsets(g, ix, iy, offsets) ? 1 : 0;
  }
  return free;
}

struct Inflated8Path {
  bool found = false;
  double length_m = std::numeric_limits<double>::infinity();  // sum of move costs; inf when not found
  std::vector<Eigen::Vector2i> cells;                         // start..goal inclusive; empty when not found
};

namespace detail {

// 8-neighbourhood in a fixed order (4-moves first) so that expansions, and thus the returned
// path among equal-length ones, never depend on the platform.
inline const std::array<Eigen::Vector2i, 8>& moves8() {
  static const std::array<Eigen::Vector2i, 8> kMoves = {
      Eigen::Vector2i(1, 0), Eigen::Vector2i(-1, 0), Eigen::Vector2i(0, 1),  Eigen::Vector2i(0, -1),
      Eigen::Vector2i(1, 1), Eigen::Vector2i(-1, 1), Eigen::Vector2i(1, -1), Eigen::Vector2i(-1, -1)};
  return kMoves;
}

inline double octile(const Eigen::Vector2i& a, const Eigen::Vector2i& b, double res) {
  const int dx = std::abs(a.x() - b.x());
  const int dy = std::abs(a.y() - b.y());
  return res * (std::max(dx, dy) + (std::sqrt(2.0) - 1.0) * std::min(dx, dy));
}

// Diagonal moves need both side cells free (MovingAI's no-corner-cutting rule); otherwise the
// move would clip the corner of a cell the robot may not occupy.
inline bool moveAllowed(const OccupancyGrid2D& g, const std::vector<std::uint8_t>& free, const Eigen::Vector2i& c,
                        const Eigen::Vector2i& m) {
  const auto isFree = [&](int x, int y) { return g.inside(x, y) && free[g.index(x, y)] != 0; };
  if (!isFree(c.x() + m.x(), c.y() + m.y())) return false;
  if (m.x() != 0 && m.y() != 0) return isFree(c.x() + m.x(), c.y()) && isFree(c.x(), c.y() + m.y());
  return true;
}

}  // namespace detail

// inflated8Path() over a precomputed inflatedFreeMask(g, r): many queries on one map then pay
// for the inflation once.
inline Inflated8Path inflated8Path(const OccupancyGrid2D& g, const std::vector<std::uint8_t>& free,
                                   Eigen::Vector2i start_cell, Eigen::Vector2i goal_cell) {
  assert(free.size() == g.occupied.size());
  Inflated8Path out;
  const auto isFree = [&](const Eigen::Vector2i& c) { return g.inside(c.x(), c.y()) && free[g.index(c.x(), c.y())]; };
  if (!isFree(start_cell) || !isFree(goal_cell)) return out;

  const double res = g.resolution_m;
  const double diag = res * std::sqrt(2.0);
  const std::size_t n = g.occupied.size();
  std::vector<double> cost(n, std::numeric_limits<double>::infinity());
  std::vector<std::int64_t> parent(n, -1);
  std::vector<std::uint8_t> closed(n, 0);
  // (f, h, index), popped smallest first: lower h prefers nodes nearer the goal among equal f,
  // and the index makes the order total, so ties never depend on the heap implementation.
  using Entry = std::tuple<double, double, std::size_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
  const std::size_t start = g.index(start_cell.x(), start_cell.y());
  const std::size_t goal = g.index(goal_cell.x(), goal_cell.y());
  cost[start] = 0.0;
  const double h0 = detail::octile(start_cell, goal_cell, res);
  open.emplace(h0, h0, start);
  while (!open.empty()) {
    const std::size_t i = std::get<2>(open.top());
    open.pop();
    if (closed[i]) continue;  // stale entry: lazy deletion instead of decrease-key
    closed[i] = 1;
    if (i == goal) break;
    const Eigen::Vector2i c(static_cast<int>(i % g.width), static_cast<int>(i / g.width));
    for (const Eigen::Vector2i& m : detail::moves8()) {
      if (!detail::moveAllowed(g, free, c, m)) continue;
      const Eigen::Vector2i nc = c + m;
      const std::size_t j = g.index(nc.x(), nc.y());
      if (closed[j]) continue;
      const double cj = cost[i] + ((m.x() != 0 && m.y() != 0) ? diag : res);
      if (cj < cost[j]) {
        cost[j] = cj;
        parent[j] = static_cast<std::int64_t>(i);
        const double hj = detail::octile(nc, goal_cell, res);
        open.emplace(cj + hj, hj, j);
      }
    }
  }
  if (!closed[goal]) return out;
  out.found = true;
  out.length_m = cost[goal];
  for (std::int64_t i = static_cast<std::int64_t>(goal); i >= 0; i = parent[static_cast<std::size_t>(i)]) {
    out.cells.emplace_back(static_cast<int>(i % g.width), static_cast<int>(i / g.width));
  }
  std::reverse(out.cells.begin(), out.cells.end());
  return out;
}

// Optimal 8-connected path between two cells over inflatedFree cells: 4-moves cost res, diagonal
// moves res*sqrt(2) without corner cutting. This is the MovingAI octile benchmark generalised to a
// robot radius (r = 0 reproduces the benchmark's optimal lengths). A planner working in continuous
// space may beat it: Euclidean length is at least 1/1.0824 (about 92.4 %) of octile length, so
// compare lengths with that slack. Reachability agrees with a continuous planner's only away
// from passages whose width is within about a cell of 2r.
inline Inflated8Path inflated8Path(const OccupancyGrid2D& g, Eigen::Vector2i start_cell, Eigen::Vector2i goal_cell,
                                   double robot_radius_m) {
  return inflated8Path(g, inflatedFreeMask(g, robot_radius_m), start_cell, goal_cell);
}

// ---------------------------------------------------------------------------------------------
// Independent clearance checks.
// ---------------------------------------------------------------------------------------------

// Exact distance from `p` to the nearest occupied square, the space outside the map counting as
// occupied (so the distance to the map boundary also bounds it). 0 inside an occupied square or
// outside the map. Searches square rings around p's cell: a square on ring d is at least
// (d - 1) * res away, so the search stops once the best distance found is no more than that.
// Cost grows with the clearance squared; fine for tests, and deliberately nothing like a
// distance transform, so that it can check one.
inline double clearanceToSquares(const OccupancyGrid2D& g, const Eigen::Vector2d& p) {
  const Eigen::Vector2i c = g.cellOf(p);
  if (g.isOccupied(c.x(), c.y())) return 0.0;
  double best = std::numeric_limits<double>::infinity();
  for (int d = 1;; ++d) {
    if (best <= (d - 1) * g.resolution_m) return best;
    for (int k = -d; k <= d; ++k) {
      // The ring's four sides; corners are visited twice, which is harmless.
      const int xs[4] = {c.x() + k, c.x() + k, c.x() - d, c.x() + d};
      const int ys[4] = {c.y() - d, c.y() + d, c.y() + k, c.y() + k};
      for (int s = 0; s < 4; ++s) {
        if (g.isOccupied(xs[s], ys[s])) best = std::min(best, detail::pointToSquare(g, p, xs[s], ys[s]));
      }
    }
  }
}

// Smallest clearanceToSquares() over points sampled along each segment of `path` at most step_m
// apart, both endpoints of every segment included. +inf for an empty path.
inline double minClearanceAlong(const OccupancyGrid2D& g, const std::vector<Eigen::Vector2d>& path, double step_m) {
  assert(step_m > 0.0);
  double best = std::numeric_limits<double>::infinity();
  if (path.size() == 1) return clearanceToSquares(g, path[0]);
  for (std::size_t s = 0; s + 1 < path.size(); ++s) {
    const Eigen::Vector2d& a = path[s];
    const Eigen::Vector2d& b = path[s + 1];
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step_m)));
    for (int i = 0; i <= n; ++i) best = std::min(best, clearanceToSquares(g, a + (b - a) * (double(i) / n)));
  }
  return best;
}

// ---------------------------------------------------------------------------------------------
// Queries.
// ---------------------------------------------------------------------------------------------

// `n` start/goal cell pairs, both inflatedFree at radius r and distinct, drawn from `seed`. With
// connected_only, each pair is also joined by an inflated8Path (same moves, same corner rule), so
// a test can demand success on every query; otherwise unreachable pairs occur and test the
// planner's failure path. Empty when fewer than two cells qualify (or, with connected_only, no
// component has two cells).
inline std::vector<std::pair<Eigen::Vector2i, Eigen::Vector2i>> randomQueries(const OccupancyGrid2D& g, int n, double r,
                                                                              std::uint32_t seed,
                                                                              bool connected_only = false) {
  std::vector<std::pair<Eigen::Vector2i, Eigen::Vector2i>> out;
  const std::vector<std::uint8_t> free = inflatedFreeMask(g, r);
  // Component labels under the oracle's move rule (flood fill; the rule is symmetric).
  std::vector<int> label(free.size(), -1);
  std::vector<std::vector<std::size_t>> members;  // cells of each component, in index order
  std::vector<std::size_t> free_cells;
  for (std::size_t i = 0; i < free.size(); ++i) {
    if (!free[i]) continue;
    free_cells.push_back(i);
    if (label[i] >= 0) continue;
    const int id = static_cast<int>(members.size());
    members.emplace_back();
    std::vector<std::size_t> stack{i};
    label[i] = id;
    while (!stack.empty()) {
      const std::size_t k = stack.back();
      stack.pop_back();
      members[id].push_back(k);
      const Eigen::Vector2i c(static_cast<int>(k % g.width), static_cast<int>(k / g.width));
      for (const Eigen::Vector2i& m : detail::moves8()) {
        if (!detail::moveAllowed(g, free, c, m)) continue;
        const std::size_t j = g.index(c.x() + m.x(), c.y() + m.y());
        if (label[j] < 0) {
          label[j] = id;
          stack.push_back(j);
        }
      }
    }
  }
  for (auto& cells : members) std::sort(cells.begin(), cells.end());
  // Starts come only from cells that have a possible partner, so each goal draw below succeeds
  // with probability >= 1/2 and the retry loop ends quickly.
  std::vector<std::size_t> starts;
  for (std::size_t i : free_cells) {
    if (connected_only ? members[label[i]].size() >= 2 : free_cells.size() >= 2) starts.push_back(i);
  }
  if (starts.empty()) return out;

  std::mt19937 rng(seed);
  const auto cellAt = [&](std::size_t i) {
    return Eigen::Vector2i(static_cast<int>(i % g.width), static_cast<int>(i / g.width));
  };
  for (int q = 0; q < n; ++q) {
    const std::size_t s = starts[detail::below(rng, static_cast<int>(starts.size()))];
    const std::vector<std::size_t>& goals = connected_only ? members[label[s]] : free_cells;
    std::size_t t = s;
    while (t == s) t = goals[detail::below(rng, static_cast<int>(goals.size()))];
    out.emplace_back(cellAt(s), cellAt(t));
  }
  return out;
}

}  // namespace tgnav::planner::testmaps
