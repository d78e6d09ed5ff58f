#pragma once
// The paper's planner (Alg. 1) and its perception-agnostic baseline on a feature map.
//
// Proposed: GVD homology classes on the flight-height slice (Sec. V-B), then per class, in
// parallel: path segments by co-visibility (Sec. V-C), the 4-DoF pose graph and its exact DAG
// search (Sec. V-D), and the selection cost (Sec. V-E, eq. 9). Agnostic (AP): the shortest
// class, yaw along the direction of travel.
//
// Eq. 9 as printed, q = eta_d (d/d_min - 1) - eta_p f(c_p,min - c_p,thr) with f(x) = 1/(1+e^x),
// rewards a class whose weakest segment has LITTLE information (f grows as c_p,min falls), and
// the text says the smallest q wins while Alg. 1 takes the argmax. The intent stated in the text
// is to penalise extra length and to avoid paths through feature-poor regions, so we use
//     q = eta_d (d/d_min - 1) + eta_p f(c_p,min - c_p,thr),   the smallest q wins:
// a class pays up to eta_p when its weakest segment falls below c_p,thr, and eta_d per unit of
// relative extra length. With Table I (eta_d 0.2, eta_p 1.5) a fully feature-poor class loses
// to a feature-rich one up to 1 + 1.5/0.2 = 8.5 times its length.
#include <cstdint>
#include <vector>

#include "planner/covisibility.h"
#include "planner/feature_map.h"
#include "planner/perception.h"
#include "planner/plan.h"
#include "planner/pose_graph.h"
#include "planner/topological_planner.h"
#include "planner/voxel_map.h"

namespace tgnav::planner {

struct SelectionConfig {
  double c_p_threshold = 6.0;     // c_p,thr (Table I)
  double distance_weight = 0.2;   // eta_d
  double perception_weight = 1.5; // eta_p

  void validate() const;
};

struct PerceptionPlannerConfig {
  double robot_radius_m = 0.3;        // clearance in the GVD slice and for every 4-DoF node and edge
  double slice_half_height_m = 0.3;   // the GVD slice spans flight height +- this
  TopoPlannerConfig topo;             // its robot_radius_m is replaced by the one above
  VisibilityConfig visibility;
  InformationConfig information;
  SegmentConfig segments;
  PoseGraphConfig graph;              // its robot_radius_m is replaced by the one above
  SelectionConfig selection;
  bool keep_start_yaw = false;        // false: the MAV may turn on the spot before it sets off,
                                      // so the first pose's yaw is searched like the others
  int threads = 0;                    // classes evaluated in parallel; 0 = one per core

  void validate() const;
};

// Eq. 9 with the intended sign (see above). The smallest wins.
double selectionCost(double length_m, double shortest_m, double c_p_min, const SelectionConfig& config);

struct ClassDetail {
  std::vector<PathSegment> segments;
  PoseGraphResult graph;
  int visibility_queries = 0;
};

struct PerceptionPlanReport {
  Plan plan;
  TopoPlan topo;                     // classes in the same order as plan.candidates
  std::vector<ClassDetail> details;  // per class (proposed only)
  double flight_height_m = 0.0;
};

enum class PlannerKind { kProposed, kAgnostic };

class PerceptionPlanner {
 public:
  PerceptionPlanner(const VoxelMap& voxels, const PerceptionPlannerConfig& config);

  // Plans at the start's height. Deterministic for a given seed, whatever the number of threads.
  PerceptionPlanReport solve(const Pose4& start, const Pose4& goal, PlannerKind kind, std::uint64_t seed) const;

 private:
  const VoxelMap& voxels_;
  PerceptionPlannerConfig config_;
};

}  // namespace tgnav::planner
