#pragma once
// Sparse topological graph from the generalized Voronoi diagram of a 2D occupancy grid (paper
// Sec. V-B; GVD after Lau et al. 2013): cells equidistant to two non-adjacent obstacle cells,
// thinned to one cell, kept where the robot fits, short spurs pruned; graph vertices at
// skeleton ends and junctions, edges along the cell chains between them.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "planner/distance_field.h"

namespace tgnav::planner {

struct GvdConfig {
  double robot_radius_m = 0.3;     // skeleton cells need at least this clearance
  double min_spur_length_m = 0.5;  // dead-end branches shorter than this are dropped

  void validate() const;
};

// One-cell-thick GVD skeleton as a mask over the grid's cells (1 = skeleton).
std::vector<std::uint8_t> computeGvd(const DistanceField& field, const GvdConfig& config);

struct TopoVertex {
  Eigen::Vector2i cell = Eigen::Vector2i::Zero();
  Eigen::Vector2d p_m = Eigen::Vector2d::Zero();
};

struct TopoEdge {
  int a = -1;
  int b = -1;
  std::vector<Eigen::Vector2d> points_m;  // from vertex a to vertex b, both included
  double length_m = 0.0;
  double min_clearance_m = 0.0;
};

struct TopoGraph {
  std::vector<TopoVertex> vertices;
  std::vector<TopoEdge> edges;
  std::vector<std::vector<int>> incident;  // vertex -> edge ids
  // Vertex at a given skeleton cell, or -1.
  int vertexAt(const Eigen::Vector2i& cell) const;
};

// Vertices: skeleton cells with 1 or >= 3 skeleton neighbours (8-connected), adjacent ones
// merged into one, every cell of `forced` (e.g. where start and goal attach), and one per
// loop that has none. Edges: the cell chains between them.
TopoGraph buildTopoGraph(const DistanceField& field, const std::vector<std::uint8_t>& skeleton,
                         const std::vector<Eigen::Vector2i>& forced);

}  // namespace tgnav::planner
