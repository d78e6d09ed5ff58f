#pragma once
// Perception-aware RRT*, the sampling-based baseline of the paper's validation (Sec. VI-A, "R-N"),
// "similar to [Sadat 2014], with some modification": OMPL's RRT* in (x, y, yaw) at a fixed
// flight height, where each edge pays for its length and for the weakness of the landmarks
// co-visible from both of its poses: "at each sample, visible landmarks are queried, and the
// perception cost is evaluated using landmarks co-visible from the sample pose and its parent's
// pose". The path cost is a weighted sum of distance and perception cost, like the proposed
// planner (eq. 7 weights lambda_d, lambda_p of Table I; the sigmoid f and c_p,thr of eq. 9).
//
// Edge cost (non-negative, so RRT* stays correct):
//   cost(p1 -> p2) = |p2 - p1|_xy * (lambda_d + lambda_p * f(c - c_p,thr)),  f(x) = 1 / (1 + e^x),
// where c is the regularised log det of the bearing Fisher information (fisher.h) at p2 from the
// landmarks in V(p1) ∩ V(p2) that lie in the field of view of both poses.
//
// RRT* knows nothing of homology classes; its path is labelled afterwards with the class of the
// flight-height slice's GVD classes (Sec. V-B, as the proposed planner finds them) whose
// H-signature it shares, so that R-N's choices compare with the others' class by class.
#include "planner/perception.h"
#include "planner/planner.h"
#include "planner/pose4.h"
#include "planner/topological_planner.h"
#include "planner/voxel_map.h"

namespace tgnav::planner {

struct RrtStarConfig {
  int samples = 1000;    // iteration budget N of R-N (RRT* iterations, not tree size)
  double range_m = 1.0;  // max extension per step, in OMPL's SE2 metric (xy + 0.5 |d yaw|)
  double goal_bias = 0.05;
  double goal_tolerance_m = 0.2;   // xy distance that counts as reaching the goal (any yaw)
  double robot_radius_m = 0.3;     // 3D clearance kept from obstacles at flight height
  double distance_weight = 0.1;    // lambda_d (Table I)
  double perception_weight = 1.0;  // lambda_p (Table I)
  double c_p_threshold = 6.0;      // c_p,thr (Table I)
  VisibilityConfig visibility;
  InformationConfig information;
  // The labelling classes only (they do not change the plan): to be the proposed planner's
  // classes, these are PerceptionPlannerConfig's fields of the same names.
  double slice_half_height_m = 0.3;  // the GVD slice spans flight height +- this
  TopoPlannerConfig topo;            // its robot_radius_m is replaced by the one above

  // Names every field once, for the harness's config files (a(key, field), nested configs as
  // mappings; harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a("samples", samples);
    a("range_m", range_m);
    a("goal_bias", goal_bias);
    a("goal_tolerance_m", goal_tolerance_m);
    a("robot_radius_m", robot_radius_m);
    a("distance_weight", distance_weight);
    a("perception_weight", perception_weight);
    a("c_p_threshold", c_p_threshold);
    a("visibility", visibility);
    a("information", information);
    a("slice_half_height_m", slice_half_height_m);
    a("topology", topo);
  }

  void validate() const;
};

class PerceptionRrtStar final : public Planner {
 public:
  // Keeps a reference to `voxels`: it must outlive the planner.
  PerceptionRrtStar(const VoxelMap& voxels, const RrtStarConfig& config);

  // Plans at the start's height (start.p_WB.z(); the goal's z is ignored) in (x, y, yaw) over the
  // voxel map's box; path yaws are wrapped to [-pi, pi]. The result depends on the seed alone (no
  // process-wide random state is used): the same seed gives the same plan. kSolved needs an exact
  // solution (a tree node within goal_tolerance_m of the goal); the path then ends exactly at the
  // goal (x, y, goal yaw) unless the last step there is blocked. One candidate, the path, with
  // its H-signature; its cost is RRT*'s best cost, i.e. without that last step. topo holds the
  // slice's classes whatever the status; chosen_class is the one the path is in (-1 if none).
  Plan solve(const PlanRequest& request) const override;
  const char* name() const override { return toString(PlannerKind::kRrtStar); }

 private:
  // RRT* itself: the plan without the labelling (topo, the h_signature, chosen_class).
  Plan searchTree(const Pose4& start, const Pose4& goal, std::uint64_t seed) const;

  const VoxelMap& voxels_;
  RrtStarConfig config_;
};

}  // namespace tgnav::planner
