#include "planner/topo_graph.h"

#include <algorithm>
#include <cmath>
#include <queue>
#include <stdexcept>

#include "planner/check.h"

namespace tgnav::planner {

namespace {

// The 8 neighbours in ring order (counter-clockwise from +x).
const int kRingDx[8] = {1, 1, 0, -1, -1, -1, 0, 1};
const int kRingDy[8] = {0, 1, 1, 1, 0, -1, -1, -1};

struct Mask {
  int w, h;
  std::vector<std::uint8_t>& m;
  bool at(int x, int y) const { return x >= 0 && y >= 0 && x < w && y < h && m[static_cast<std::size_t>(y) * w + x]; }
  void set(int x, int y, bool v) { m[static_cast<std::size_t>(y) * w + x] = v ? 1 : 0; }
  int neighbours(int x, int y) const {
    int n = 0;
    for (int k = 0; k < 8; ++k) n += at(x + kRingDx[k], y + kRingDy[k]);
    return n;
  }
};

// Zhang-Suen thinning: one cell thick, connectivity and end points kept.
void thin(Mask& mask) {
  bool changed = true;
  std::vector<std::size_t> remove;
  while (changed) {
    changed = false;
    for (int pass = 0; pass < 2; ++pass) {
      remove.clear();
      for (int y = 0; y < mask.h; ++y) {
        for (int x = 0; x < mask.w; ++x) {
          if (!mask.at(x, y)) continue;
          // P2..P9 clockwise from north.
          const bool p[8] = {mask.at(x, y + 1), mask.at(x + 1, y + 1), mask.at(x + 1, y), mask.at(x + 1, y - 1),
                             mask.at(x, y - 1), mask.at(x - 1, y - 1), mask.at(x - 1, y), mask.at(x - 1, y + 1)};
          int b = 0;
          int a = 0;
          for (int k = 0; k < 8; ++k) {
            b += p[k];
            a += (!p[k] && p[(k + 1) % 8]);
          }
          if (b < 2 || b > 6 || a != 1) continue;
          const bool ok = pass == 0 ? (!(p[0] && p[2] && p[4]) && !(p[2] && p[4] && p[6]))
                                    : (!(p[0] && p[2] && p[6]) && !(p[0] && p[4] && p[6]));
          if (ok) remove.push_back(static_cast<std::size_t>(y) * mask.w + x);
        }
      }
      for (std::size_t i : remove) mask.m[i] = 0;
      changed = changed || !remove.empty();
    }
  }
}

// Removes dead-end branches shorter than `min_cells` (measured in steps).
void pruneSpurs(Mask& mask, double min_length_cells) {
  for (int round = 0; round < 3; ++round) {
    bool removed_any = false;
    for (int y = 0; y < mask.h; ++y) {
      for (int x = 0; x < mask.w; ++x) {
        if (!mask.at(x, y)) continue;
        const int n = mask.neighbours(x, y);
        if (n == 0) {
          mask.set(x, y, false);
          continue;
        }
        if (n != 1) continue;
        // Walk from the end point to the first junction.
        std::vector<Eigen::Vector2i> branch{{x, y}};
        double length = 0.0;
        Eigen::Vector2i prev(-1, -1);
        Eigen::Vector2i cur(x, y);
        bool reached_junction = false;
        while (length <= min_length_cells) {
          Eigen::Vector2i next(-1, -1);
          int count = 0;
          for (int k = 0; k < 8; ++k) {
            const Eigen::Vector2i c(cur.x() + kRingDx[k], cur.y() + kRingDy[k]);
            if (!mask.at(c.x(), c.y()) || c == prev) continue;
            if (std::find(branch.begin(), branch.end(), c) != branch.end()) continue;
            ++count;
            next = c;
          }
          if (count == 0) break;  // isolated segment: leave it
          if (mask.neighbours(next.x(), next.y()) >= 3 || count > 1) {
            reached_junction = true;
            break;
          }
          length += (next - cur).cwiseAbs().sum() == 2 ? std::sqrt(2.0) : 1.0;
          prev = cur;
          cur = next;
          branch.push_back(cur);
        }
        if (reached_junction && length < min_length_cells) {
          for (const auto& c : branch) mask.set(c.x(), c.y(), false);
          removed_any = true;
        }
      }
    }
    if (!removed_any) break;
  }
}

}  // namespace

void GvdConfig::validate() const {
  require(robot_radius_m >= 0.0, "robot_radius_m", robot_radius_m, "must be >= 0");
  require(min_spur_length_m >= 0.0, "min_spur_length_m", min_spur_length_m, "must be >= 0");
}

std::vector<std::uint8_t> computeGvd(const DistanceField& field, const GvdConfig& config) {
  config.validate();
  const OccupancyGrid2D& grid = field.grid();
  std::vector<std::uint8_t> gvd(static_cast<std::size_t>(grid.width) * grid.height, 0);
  Mask mask{grid.width, grid.height, gvd};
  auto sq = [](const Eigen::Vector2i& v) { return static_cast<double>(v.squaredNorm()); };
  for (int y = 0; y < grid.height; ++y) {
    for (int x = 0; x < grid.width; ++x) {
      if (grid.isOccupied(x, y)) continue;
      const Eigen::Vector2i s(x, y);
      const Eigen::Vector2i os = field.nearestObstacle(x, y);
      for (const Eigen::Vector2i& d : {Eigen::Vector2i(1, 0), Eigen::Vector2i(0, 1)}) {
        const Eigen::Vector2i n = s + d;
        if (grid.isOccupied(n.x(), n.y())) continue;
        const Eigen::Vector2i on = field.nearestObstacle(n.x(), n.y());
        if ((os - on).cwiseAbs().maxCoeff() <= 1) continue;  // same or adjacent obstacle cells
        // The bisector runs between s and n: mark whichever is closer to it.
        const double ds = sq(s - on) - sq(s - os);
        const double dn = sq(n - os) - sq(n - on);
        if (ds <= dn) mask.set(s.x(), s.y(), true);
        if (dn <= ds) mask.set(n.x(), n.y(), true);
      }
    }
  }
  thin(mask);
  for (int y = 0; y < grid.height; ++y) {
    for (int x = 0; x < grid.width; ++x) {
      if (mask.at(x, y) && field.clearance(grid.centreOf(x, y)) < config.robot_radius_m) mask.set(x, y, false);
    }
  }
  pruneSpurs(mask, config.min_spur_length_m / grid.resolution_m);
  return gvd;
}

int TopoGraph::vertexAt(const Eigen::Vector2i& cell) const {
  for (int i = 0; i < static_cast<int>(vertices.size()); ++i) {
    if (vertices[i].cell == cell) return i;
  }
  return -1;
}

TopoGraph buildTopoGraph(const DistanceField& field, const std::vector<std::uint8_t>& skeleton,
                         const std::vector<Eigen::Vector2i>& forced) {
  const OccupancyGrid2D& grid = field.grid();
  std::vector<std::uint8_t> sk = skeleton;
  Mask mask{grid.width, grid.height, sk};
  const std::size_t n_cells = sk.size();
  std::vector<std::uint8_t> is_vertex_cell(n_cells, 0);
  for (int y = 0; y < grid.height; ++y) {
    for (int x = 0; x < grid.width; ++x) {
      if (!mask.at(x, y)) continue;
      const int n = mask.neighbours(x, y);
      if (n == 1 || n >= 3) is_vertex_cell[grid.index(x, y)] = 1;
    }
  }
  for (const auto& f : forced) {
    if (mask.at(f.x(), f.y())) is_vertex_cell[grid.index(f.x(), f.y())] = 1;
  }

  TopoGraph g;
  std::vector<int> cluster(n_cells, -1);  // vertex id of each vertex cell
  auto makeClusters = [&](int x0, int y0) {
    // Flood the 8-connected vertex cells into one vertex; forced cells become the vertex's cell.
    std::vector<Eigen::Vector2i> cells{{x0, y0}};
    const int id = static_cast<int>(g.vertices.size());
    cluster[grid.index(x0, y0)] = id;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      for (int k = 0; k < 8; ++k) {
        const int nx = cells[i].x() + kRingDx[k];
        const int ny = cells[i].y() + kRingDy[k];
        if (!mask.at(nx, ny) || !is_vertex_cell[grid.index(nx, ny)] || cluster[grid.index(nx, ny)] >= 0) continue;
        cluster[grid.index(nx, ny)] = id;
        cells.emplace_back(nx, ny);
      }
    }
    Eigen::Vector2i chosen = cells.front();
    bool has_forced = false;
    for (const auto& c : cells) {
      if (std::find(forced.begin(), forced.end(), c) != forced.end()) {
        chosen = c;
        has_forced = true;
        break;
      }
    }
    if (!has_forced) {
      Eigen::Vector2d mean = Eigen::Vector2d::Zero();
      for (const auto& c : cells) mean += c.cast<double>();
      mean /= static_cast<double>(cells.size());
      for (const auto& c : cells) {
        if ((c.cast<double>() - mean).squaredNorm() < (chosen.cast<double>() - mean).squaredNorm()) chosen = c;
      }
    }
    g.vertices.push_back(TopoVertex{chosen, grid.centreOf(chosen.x(), chosen.y())});
  };
  for (int y = 0; y < grid.height; ++y) {
    for (int x = 0; x < grid.width; ++x) {
      if (is_vertex_cell[grid.index(x, y)] && cluster[grid.index(x, y)] < 0) makeClusters(x, y);
    }
  }

  // Within a vertex's cluster, the cells from its chosen cell to any other (breadth-first tree):
  // an edge leaving the cluster elsewhere goes through them, never straight across (a cluster
  // need not be convex).
  std::vector<int> cluster_parent(n_cells, -1);
  for (const TopoVertex& v : g.vertices) {
    std::vector<std::size_t> queue{grid.index(v.cell.x(), v.cell.y())};
    const int id = cluster[queue.front()];
    cluster_parent[queue.front()] = static_cast<int>(queue.front());
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const int x = static_cast<int>(queue[q] % grid.width);
      const int y = static_cast<int>(queue[q] / grid.width);
      for (int k = 0; k < 8; ++k) {
        const int nx = x + kRingDx[k];
        const int ny = y + kRingDy[k];
        if (!mask.at(nx, ny)) continue;
        const std::size_t j = grid.index(nx, ny);
        if (cluster[j] != id || cluster_parent[j] >= 0) continue;
        cluster_parent[j] = static_cast<int>(queue[q]);
        queue.push_back(j);
      }
    }
  }
  // Centres from `cell` back to its cluster's chosen cell, both excluded.
  auto inCluster = [&](const Eigen::Vector2i& cell) {
    std::vector<Eigen::Vector2d> pts;
    std::size_t i = grid.index(cell.x(), cell.y());
    while (cluster_parent[i] >= 0 && static_cast<std::size_t>(cluster_parent[i]) != i) {
      pts.push_back(grid.centreOf(static_cast<int>(i % grid.width), static_cast<int>(i / grid.width)));
      i = static_cast<std::size_t>(cluster_parent[i]);
    }
    return pts;
  };

  std::vector<std::uint8_t> visited(n_cells, 0);
  auto trace = [&](int from, const Eigen::Vector2i& start_cell, const Eigen::Vector2i& first) {
    std::vector<Eigen::Vector2i> chain{first};
    visited[grid.index(first.x(), first.y())] = 1;
    Eigen::Vector2i prev = start_cell;
    Eigen::Vector2i cur = first;
    while (true) {
      int end_vertex = -1;
      Eigen::Vector2i end_cell(-1, -1);
      Eigen::Vector2i next(-1, -1);
      for (int k = 0; k < 8 && end_vertex < 0; ++k) {
        const Eigen::Vector2i c(cur.x() + kRingDx[k], cur.y() + kRingDy[k]);
        if (!mask.at(c.x(), c.y()) || c == prev) continue;
        const int v = cluster[grid.index(c.x(), c.y())];
        if (v >= 0 && !(v == from && chain.size() < 3)) {
          end_vertex = v;
          end_cell = c;
        }
      }
      if (end_vertex >= 0) {
        TopoEdge e;
        e.a = from;
        e.b = end_vertex;
        e.points_m.push_back(g.vertices[from].p_m);
        std::vector<Eigen::Vector2d> lead = inCluster(start_cell);
        e.points_m.insert(e.points_m.end(), lead.rbegin(), lead.rend());
        double min_clear = 1e18;
        for (const auto& c : chain) {
          e.points_m.push_back(grid.centreOf(c.x(), c.y()));
          min_clear = std::min(min_clear, field.clearance(grid.centreOf(c.x(), c.y())));
        }
        const std::vector<Eigen::Vector2d> tail = inCluster(end_cell);
        e.points_m.insert(e.points_m.end(), tail.begin(), tail.end());
        e.points_m.push_back(g.vertices[end_vertex].p_m);
        for (std::size_t i = 1; i < e.points_m.size(); ++i) e.length_m += (e.points_m[i] - e.points_m[i - 1]).norm();
        e.min_clearance_m = std::min(
            min_clear, std::min(field.clearance(g.vertices[from].p_m), field.clearance(g.vertices[end_vertex].p_m)));
        g.edges.push_back(std::move(e));
        return;
      }
      // Continue along the chain: prefer 4-neighbours (the diagonal is a shortcut of the same line).
      for (int pass = 0; pass < 2 && next.x() < 0; ++pass) {
        for (int k = pass; k < 8; k += 2) {
          const Eigen::Vector2i c(cur.x() + kRingDx[k], cur.y() + kRingDy[k]);
          if (!mask.at(c.x(), c.y()) || visited[grid.index(c.x(), c.y())] || cluster[grid.index(c.x(), c.y())] >= 0) {
            continue;
          }
          next = c;
          break;
        }
      }
      if (next.x() < 0) return;  // dead end without a vertex: nothing to connect
      visited[grid.index(next.x(), next.y())] = 1;
      chain.push_back(next);
      prev = cur;
      cur = next;
    }
  };
  auto traceFromVertexCells = [&](std::size_t first_vertex) {
    for (int y = 0; y < grid.height; ++y) {
      for (int x = 0; x < grid.width; ++x) {
        const int v = cluster[grid.index(x, y)];
        if (v < static_cast<int>(first_vertex)) continue;
        for (int k = 0; k < 8; ++k) {
          const Eigen::Vector2i c(x + kRingDx[k], y + kRingDy[k]);
          if (!mask.at(c.x(), c.y()) || visited[grid.index(c.x(), c.y())] || cluster[grid.index(c.x(), c.y())] >= 0) {
            continue;
          }
          trace(v, Eigen::Vector2i(x, y), c);
        }
      }
    }
  };
  traceFromVertexCells(0);
  // Loops without any vertex: give each one a vertex and trace it.
  for (int y = 0; y < grid.height; ++y) {
    for (int x = 0; x < grid.width; ++x) {
      if (!mask.at(x, y) || visited[grid.index(x, y)] || cluster[grid.index(x, y)] >= 0) continue;
      const std::size_t first = g.vertices.size();
      is_vertex_cell[grid.index(x, y)] = 1;
      makeClusters(x, y);
      traceFromVertexCells(first);
    }
  }
  g.incident.assign(g.vertices.size(), {});
  for (int e = 0; e < static_cast<int>(g.edges.size()); ++e) {
    g.incident[g.edges[e].a].push_back(e);
    if (g.edges[e].b != g.edges[e].a) g.incident[g.edges[e].b].push_back(e);
  }
  return g;
}

}  // namespace tgnav::planner
