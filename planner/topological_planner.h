#pragma once
// Topological planning on a 2D occupancy grid (paper Sec. V-B): GVD graph, simple paths from
// start to goal searched in order of length, kept when their homology class (H-signature) is
// new, each shortened within its class. The perception-agnostic planner (AP) of the paper's
// Table II picks the shortest class.
//
// H-signature: instead of the complex-analytic H-signature of Bhattacharya 2012, whose
// coefficients underflow with ~100 obstacles, each path gets the vector of its winding angles
// around one point of every obstacle component; two paths with the same ends are in the same
// homology class iff every winding angle agrees (differences are multiples of 2 pi; the
// tolerance is pi).
#include <Eigen/Core>
#include <string>
#include <vector>

#include "planner/topo_graph.h"

namespace tgnav::planner {

enum class PlanStatus { kSolved, kNoPath, kInvalidStart, kInvalidGoal, kTimeout };
const char* toString(PlanStatus status);

struct TopoPlannerConfig {
  double robot_radius_m = 0.3;
  double min_spur_length_m = 0.5;
  int max_classes = 10;           // cap on homology classes
  int max_expansions = 100000;    // cap on search effort (partial paths expanded)
  double max_length_ratio = 3.0;  // graph paths longer than this x the shortest are not searched
  // Clearance the class paths keep beyond robot_radius_m, for callers that check paths with a
  // conservative sampled test (VoxelMap::segmentClear asks a quarter voxel more): set in code,
  // not a config key.
  double path_margin_m = 0.0;

  // Names every field once, for the harness's config files (a(key, field); harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a("robot_radius_m", robot_radius_m);
    a("max_classes", max_classes);
    a("max_expansions", max_expansions);
    a("max_length_ratio", max_length_ratio);
    a("min_spur_length_m", min_spur_length_m);
  }

  void validate() const;
};

struct HomologyClass {
  std::vector<double> h_signature;          // winding angle [rad] around each obstacle component
  std::vector<Eigen::Vector2d> graph_path;  // along the GVD
  std::vector<Eigen::Vector2d> path;        // shortened within the class
  double length_m = 0.0;                    // of `path`
};

// Cells per native cell side of the working grid on which the distance field and the GVD are
// built: fine enough that the GVD resolves the robot radius (working cell <= 2/3 of it) and a
// one-cell corridor has a centre line of its own (>= 3 when a one-cell corridor is passable,
// i.e. resolution >= 2 r, and always when r = 0). Odd, so that every native cell centre is a
// working cell centre: a native path through cell centres is a path through working cells.
// Never so fine that the working grid exceeds kMaxWorkingCells (the largest odd k that fits).
int workingGridFactor(int width, int height, double resolution_m, double robot_radius_m);
constexpr long long kMaxWorkingCells = 40'000'000;
// Each cell split k x k (same origin, resolution / k): occupied squares stay exactly what they were.
OccupancyGrid2D refineGrid(const OccupancyGrid2D& grid, int k);

struct TopoPlan {
  PlanStatus status = PlanStatus::kNoPath;
  std::vector<HomologyClass> classes;  // sorted by length
  int chosen = -1;                     // the AP planner's choice: the shortest class
  int expansions = 0;
  std::vector<std::uint8_t> gvd;                 // skeleton mask over the working grid (for plots)
  int working_factor = 1;                        // working cells per native cell side
  TopoGraph graph;                               // with start/goal attached
  std::vector<Eigen::Vector2d> obstacle_points;  // one point per obstacle component
};

class TopologicalPlanner {
 public:
  // Builds the working grid, its distance field and the GVD once; solve() answers queries.
  TopologicalPlanner(const OccupancyGrid2D& grid, const TopoPlannerConfig& config);
  TopoPlan solve(const Eigen::Vector2d& start_m, const Eigen::Vector2d& goal_m) const;

  // The distance field of the working grid (clearances are exact to the native squares).
  const DistanceField& field() const { return field_; }
  int workingFactor() const { return working_factor_; }
  // GVD cells added to join GVD fragments within one connected free region.
  int repairCells() const { return repair_cells_; }
  // Winding angles of a polyline around every obstacle component point.
  std::vector<double> hSignature(const std::vector<Eigen::Vector2d>& path) const;
  static bool sameClass(const std::vector<double>& a, const std::vector<double>& b);

 private:
  std::vector<Eigen::Vector2d> shorten(std::vector<Eigen::Vector2d> path) const;
  std::vector<Eigen::Vector2d> shortcut(const std::vector<Eigen::Vector2d>& path) const;
  std::vector<Eigen::Vector2d> relax(std::vector<Eigen::Vector2d> path) const;
  // Where a segment between two cells of clearance >= r dips below r (past an obstacle corner),
  // inserts points pushed up the clearance gradient; false if that does not clear it.
  bool keepClearance(std::vector<Eigen::Vector2d>* path) const;
  bool obstacleInTriangle(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) const;
  // The skeleton cell where a start or goal attaches and the points leading to it: the nearest
  // skeleton cell seen along a clear segment, else the nearest reached through free cells.
  bool attach(const Eigen::Vector2d& p, Eigen::Vector2i* cell, std::vector<Eigen::Vector2d>* points) const;
  bool freeCell(int x, int y) const { return free_[field_.grid().index(x, y)] != 0; }
  // The shortest 8-connected path from start to goal over the free working cells (A*, octile
  // heuristic; diagonal steps need both side cells free), shortened within its class and kept
  // clear, or as found when that is shorter; empty when there is none or it cannot be kept clear.
  std::vector<Eigen::Vector2d> freeSpaceShortest(const Eigen::Vector2d& start, const Eigen::Vector2d& goal) const;
  // Makes sure plan->classes holds the class of freeSpaceShortest() with a path no longer than it:
  // replaces a longer path of that class, or adds the class (in place of the last one found when
  // there are max_classes already).
  void ensureShortestClass(const Eigen::Vector2d& start, const Eigen::Vector2d& goal, TopoPlan* plan) const;

  TopoPlannerConfig config_;
  int working_factor_ = 1;
  DistanceField field_;
  // The clearance kept: the robot radius, or for a point robot (r = 0) a hair's breadth, so that
  // paths may pass obstacles as close as they like but never touch or cross a corner.
  double clearance_m_ = 0.0;
  static constexpr double kPointRobotClearance = 1e-3;  // cells
  std::vector<std::uint8_t> free_;                      // working cells whose centre keeps the robot radius
  std::vector<std::uint8_t> skeleton_;
  std::vector<Eigen::Vector2i> skeleton_cells_;
  int repair_cells_ = 0;
  std::vector<Eigen::Vector2d> obstacle_points_;
  OccupancyGrid2D native_;              // for the obstacle-point index
  std::vector<int> obstacle_point_at_;  // native cell -> index into obstacle_points_, or -1
};

double polylineLength(const std::vector<Eigen::Vector2d>& path);
// Winding angle [rad] of a polyline around each point (the H-signature; TopoPlan::obstacle_points).
std::vector<double> windingAngles(const std::vector<Eigen::Vector2d>& path,
                                  const std::vector<Eigen::Vector2d>& obstacle_points);

}  // namespace tgnav::planner
