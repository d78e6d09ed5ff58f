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

struct TopoPlan {
  PlanStatus status = PlanStatus::kNoPath;
  std::vector<HomologyClass> classes;  // sorted by length
  int chosen = -1;                     // the AP planner's choice: the shortest class
  int expansions = 0;
  std::vector<std::uint8_t> gvd;                 // skeleton mask (for plots)
  TopoGraph graph;                               // with start/goal attached
  std::vector<Eigen::Vector2d> obstacle_points;  // one point per obstacle component
};

class TopologicalPlanner {
 public:
  TopologicalPlanner(const OccupancyGrid2D& grid, const TopoPlannerConfig& config);
  TopoPlan solve(const Eigen::Vector2d& start_m, const Eigen::Vector2d& goal_m) const;

  const DistanceField& field() const { return field_; }
  // Winding angles of a polyline around every obstacle component point.
  std::vector<double> hSignature(const std::vector<Eigen::Vector2d>& path) const;
  static bool sameClass(const std::vector<double>& a, const std::vector<double>& b);

 private:
  std::vector<Eigen::Vector2d> shorten(std::vector<Eigen::Vector2d> path) const;
  bool obstacleInTriangle(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) const;

  TopoPlannerConfig config_;
  DistanceField field_;
  std::vector<std::uint8_t> skeleton_;
  std::vector<Eigen::Vector2d> obstacle_points_;
};

double polylineLength(const std::vector<Eigen::Vector2d>& path);
// Winding angle [rad] of a polyline around each point (the H-signature; TopoPlan::obstacle_points).
std::vector<double> windingAngles(const std::vector<Eigen::Vector2d>& path,
                                  const std::vector<Eigen::Vector2d>& obstacle_points);

}  // namespace tgnav::planner
