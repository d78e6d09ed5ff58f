#pragma once
// The one interface of the three planners the paper compares (Sec. VI-A, Table II): the proposed
// planner (Alg. 1), its perception-agnostic baseline AP, and the perception-aware RRT* baseline
// R-N. OMPL style: a planner is configured once on a map, then solve() answers one query with a
// status. Each planner also says which homology class (Sec. V-B) of the flight-height slice its
// path is in, so that the three compare class by class (which route each took, Fig. 3) and the
// trajectory generator keeps any of their paths in its class. plan.json mirrors Plan.
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "planner/covisibility.h"
#include "planner/pose4.h"
#include "planner/pose_graph.h"
#include "planner/topological_planner.h"
#include "planner/voxel_map.h"

namespace tgnav::planner {

struct PerceptionPlannerConfig;  // perception_planner.h
struct RrtStarConfig;            // rrt_star.h

// A stretch of a candidate path and its perception score (eq. 8 over the poses in it).
struct ScoredSegment {
  double s_begin_m = 0.0;  // arclength along the candidate's reference path
  double s_end_m = 0.0;
  int covisible = 0;  // |CV| of its end points
  double c_p = std::numeric_limits<double>::quiet_NaN();
};

struct CandidatePath {
  std::vector<double> h_signature;                            // winding angles (TopologicalPlanner::hSignature)
  double length_m = 0.0;                                      // of `path`
  double c_p = std::numeric_limits<double>::quiet_NaN();      // eq. 8 over the whole path
  double c_p_min = std::numeric_limits<double>::quiet_NaN();  // eq. 10: weakest segment
  double blind_length_m = 0.0;  // path length around the poses that score blind (6 ln eps; proposed only)
  double cost = std::numeric_limits<double>::quiet_NaN();  // selection cost (eq. 9) or planner's own
  bool feasible = true;                                    // false: no collision-free 4-DoF path in this class
  std::vector<ScoredSegment> segments;
  std::vector<Pose4> path;
};

// How the proposed planner got one class's candidate: its segments (Sec. V-C) and the 4-DoF pose
// graph searched over them (Sec. V-D).
struct ClassDetail {
  std::vector<PathSegment> segments;
  PoseGraphResult graph;
  int visibility_queries = 0;
};

struct PlanRequest {
  Pose4 start;  // its z is the flight height: that of the GVD slice and of RRT*'s plane; the goal's z is ignored
  Pose4 goal;
  std::uint64_t seed = 0;  // the plan depends on it alone: the same seed gives the same plan
  // The oracle (which classes can the VO fly?): >= 0 makes the proposed and agnostic planners fly
  // this class of Plan::topo.classes instead of choosing one (proposed: its pose-graph path;
  // agnostic: its shortest path), with every class still scored; no such class, or no 4-DoF path
  // in it, is kNoPath. RRT* has no classes to choose from and refuses it (std::invalid_argument).
  int homology_class = -1;
};

struct Plan {
  PlanStatus status = PlanStatus::kNoPath;
  // Proposed and AP: one per class of `topo`, in its order. RRT*: its one path.
  std::vector<CandidatePath> candidates;
  int chosen = -1;          // index into candidates
  std::vector<Pose4> path;  // the chosen 4-DoF path (empty unless solved)
  // The homology classes on the flight-height slice, whichever planner: plan.json lists them and
  // the trajectory generator keeps the path in its class by topo.obstacle_points.
  TopoPlan topo;
  int chosen_class = -1;             // index into topo.classes of `path`'s class; -1: none, or not listed
  std::vector<ClassDetail> details;  // per class of `topo` (proposed only)
  double flight_height_m = 0.0;      // the request's start z
};

enum class PlannerKind { kProposed, kAgnostic, kRrtStar };
// "proposed", "agnostic", "rrtstar": the names on the command line, in configs and result files.
const char* toString(PlannerKind kind);
// The inverse of toString: false, leaving *kind as it is, for any other text.
bool parsePlannerKind(const std::string& text, PlannerKind* kind);

class Planner {
 public:
  virtual ~Planner() = default;
  // kSolved with a path from the start to the goal pose, or why there is none. Deterministic for
  // a given request.
  virtual Plan solve(const PlanRequest& request) const = 0;
  virtual const char* name() const = 0;  // toString of its kind

 protected:
  // Copied and moved only as part of a derived planner (no slicing).
  Planner() = default;
  Planner(const Planner&) = default;
  Planner& operator=(const Planner&) = default;
  Planner(Planner&&) = default;
  Planner& operator=(Planner&&) = default;
};

// The planner of `kind` on `voxels`, which must outlive it: proposed and AP take `perception`, RRT*
// takes `rrt_star` (the other config is not read). std::invalid_argument naming the field of a
// bad config, as the planners' constructors.
std::unique_ptr<Planner> makePlanner(PlannerKind kind, const VoxelMap& voxels,
                                     const PerceptionPlannerConfig& perception, const RrtStarConfig& rrt_star);

}  // namespace tgnav::planner
