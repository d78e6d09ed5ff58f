#pragma once
// The paper's planner (Alg. 1) and its perception-agnostic baseline on a feature map, both
// behind the Planner interface (planner.h) and both starting from the same GVD homology classes
// on the flight-height slice (Sec. V-B), one candidate per class in the classes' order.
//
// Proposed: per class, in parallel: path segments by co-visibility (Sec. V-C), the 4-DoF pose
// graph and its exact DAG search (Sec. V-D), and the selection cost (Sec. V-E, eq. 9). Agnostic
// (AP): the shortest class, yaw along the direction of travel.
//
// Eq. 9 as printed, q = eta_d (d/d_min - 1) - eta_p f(c_p,min - c_p,thr) with f(x) = 1/(1+e^x),
// rewards a class whose weakest segment has LITTLE information (f grows as c_p,min falls), and
// the text says the smallest q wins while Alg. 1 takes the argmax. The intent stated in the text
// is to penalise extra length and to avoid paths through feature-poor regions, so we use
//     q = eta_d (d/d_min - 1) + eta_p f(c_p,min - c_p,thr),   the smallest q wins:
// a class pays up to eta_p when its weakest segment falls below c_p,thr, and eta_d per unit of
// relative extra length. With Table I (eta_d 0.2, eta_p 1.5) a fully feature-poor class loses
// to a feature-rich one up to 1 + 1.5/0.2 = 8.5 times its length.
//
// Below the threshold (ours, SelectionConfig::perception_first): f saturates, so when no class's
// c_p,min reaches c_p,thr, a class blind somewhere (c_p,min = 6 ln eps = -27.6) and a class with
// weak but real information everywhere (c_p,min = 0.5) both pay ~eta_p and eq. 9 falls back to the
// shortest, blind segment included; on a scene from outside the repository that lost the VO in
// 4 of 5 trials. In that regime we rank by perception first: the classes with the least blind
// length (path length around poses that score blind, within blind_tolerance_m of the least) stay;
// of those, the classes whose c_p,min is within perception_tolerance of their best compete by
// eq. 9, the others are out. The blind length comes first because a minimum is a poor summary:
// with the image-coverage limit (perception.h) the gallery's start and goal score blind for a
// pose or two in every class, and c_p,min = -27.6 everywhere could no longer tell a class blind
// for 14 m from one blind for 0.6 m. With some class at or above c_p,thr, eq. 9 decides alone,
// as in the paper.
#include "planner/covisibility.h"
#include "planner/perception.h"
#include "planner/planner.h"
#include "planner/pose_graph.h"
#include "planner/topological_planner.h"
#include "planner/voxel_map.h"

namespace tgnav::planner {

struct SelectionConfig {
  double c_p_threshold = 6.0;         // c_p,thr (Table I)
  double distance_weight = 0.2;       // eta_d
  double perception_weight = 1.5;     // eta_p
  bool perception_first = true;       // below c_p,thr: rank by c_p,min first (ours, see above)
  double perception_tolerance = 1.0;  // c_p,min this close to the best counts as equal there
  double blind_tolerance_m = 0.5;     // blind length this close to the least counts as equal there

  // Names every field once, for the harness's config files (a(key, field); harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a("c_p_threshold", c_p_threshold);
    a("distance_weight", distance_weight);
    a("perception_weight", perception_weight);
    a("perception_first", perception_first);
    a("perception_tolerance", perception_tolerance);
    a("blind_tolerance_m", blind_tolerance_m);
  }

  void validate() const;
};

struct PerceptionPlannerConfig {
  double robot_radius_m = 0.3;       // clearance in the GVD slice and for every 4-DoF node and edge
  double slice_half_height_m = 0.3;  // the GVD slice spans flight height +- this
  TopoPlannerConfig topo;            // its robot_radius_m is replaced by the one above
  VisibilityConfig visibility;
  InformationConfig information;
  SegmentConfig segments;
  PoseGraphConfig graph;  // its robot_radius_m and turn_floor are replaced by the one above and c_p,thr
  SelectionConfig selection;
  bool keep_start_yaw = false;  // false: the MAV may turn on the spot before it sets off,
                                // so the first pose's yaw is searched like the others
  int threads = 0;              // classes evaluated in parallel; 0 = one per core

  // Names every field once, for the harness's config files (a(key, field), nested configs as
  // mappings; harness/config/yaml_util.h): configs/planner.yaml.
  template <typename Archive>
  void visit(Archive& a) {
    a("robot_radius_m", robot_radius_m);
    a("slice_half_height_m", slice_half_height_m);
    a("keep_start_yaw", keep_start_yaw);
    a("threads", threads);
    a("topology", topo);
    a("visibility", visibility);
    a("information", information);
    a("segments", segments);
    a("pose_graph", graph);
    a("selection", selection);
  }

  void validate() const;
};

// Eq. 9 with the intended sign (see above). The smallest wins.
double selectionCost(double length_m, double shortest_m, double c_p_min, const SelectionConfig& config);

// Sets every feasible candidate's eq. 9 cost and returns the index of the chosen one (-1: none
// feasible): the cheapest, among the classes still in the running (all of them, unless no class
// reaches c_p,thr and perception_first holds; see above). Ties go to the lower index.
int selectCandidate(std::vector<CandidatePath>& candidates, const SelectionConfig& config);

// Alg. 1. Candidates: every class's best 4-DoF path (infeasible where the pose graph finds none),
// with its eq. 9 cost; the cheapest is chosen. details: per class. chosen_class = chosen.
class ProposedPlanner final : public Planner {
 public:
  // Keeps a reference to `voxels`: it must outlive the planner.
  ProposedPlanner(const VoxelMap& voxels, const PerceptionPlannerConfig& config);

  // Deterministic for a given seed, whatever the number of threads.
  Plan solve(const PlanRequest& request) const override;
  const char* name() const override { return toString(PlannerKind::kProposed); }

 private:
  const VoxelMap& voxels_;
  PerceptionPlannerConfig config_;
};

// AP. Candidates: every class's shortened path with the yaw along the direction of travel, no
// perception figures; the shortest (TopoPlan::chosen) is chosen. chosen_class = chosen. The seed
// is not used. Only the robot radius, the slice and the topology of the config are read, but all
// of it is validated (one config for both planners).
class AgnosticPlanner final : public Planner {
 public:
  // Keeps a reference to `voxels`: it must outlive the planner.
  AgnosticPlanner(const VoxelMap& voxels, const PerceptionPlannerConfig& config);

  Plan solve(const PlanRequest& request) const override;
  const char* name() const override { return toString(PlannerKind::kAgnostic); }

 private:
  const VoxelMap& voxels_;
  PerceptionPlannerConfig config_;
};

}  // namespace tgnav::planner
