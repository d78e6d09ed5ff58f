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
#include <cstdint>

#include "planner/feature_map.h"
#include "planner/perception.h"
#include "planner/plan.h"
#include "planner/pose4.h"
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

  void validate() const;
};

class PerceptionRrtStar {
 public:
  // Keeps a reference to `voxels`: it must outlive the planner.
  PerceptionRrtStar(const VoxelMap& voxels, const RrtStarConfig& config);

  // Plans at the start's height (start.p_WB.z(); the goal's z is ignored) in (x, y, yaw) over the
  // voxel map's box; path yaws are wrapped to [-pi, pi]. The result depends on the seed alone (no
  // process-wide random state is used): the same seed gives the same plan. kSolved needs an exact
  // solution (a tree node within goal_tolerance_m of the goal); the path then ends exactly at the
  // goal (x, y, goal yaw) unless the last step there is blocked. Candidate cost is RRT*'s best
  // cost, i.e. without that last step.
  Plan solve(const Pose4& start, const Pose4& goal, std::uint64_t seed) const;

 private:
  const VoxelMap& voxels_;
  RrtStarConfig config_;
};

}  // namespace tgnav::planner
