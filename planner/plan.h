#pragma once
// What every planner of the harness returns (proposed, perception-agnostic, perception-aware
// RRT*): the candidate paths it considered and the 4-DoF path it chose. plan.json mirrors it.
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "planner/pose4.h"
#include "planner/topological_planner.h"

namespace tgnav::planner {

// A stretch of a candidate path and its perception score (eq. 8 over the poses in it).
struct ScoredSegment {
  double s_begin_m = 0.0;  // arclength along the candidate's reference path
  double s_end_m = 0.0;
  int covisible = 0;       // |CV| of its end points
  double c_p = std::numeric_limits<double>::quiet_NaN();
};

struct CandidatePath {
  std::vector<double> h_signature;      // winding angles (TopologicalPlanner::hSignature)
  double length_m = 0.0;                // of `path`
  double c_p = std::numeric_limits<double>::quiet_NaN();      // eq. 8 over the whole path
  double c_p_min = std::numeric_limits<double>::quiet_NaN();  // eq. 10: weakest segment
  double cost = std::numeric_limits<double>::quiet_NaN();     // selection cost (eq. 9) or planner's own
  bool feasible = true;                 // false: no collision-free 4-DoF path in this class
  std::vector<ScoredSegment> segments;
  std::vector<Pose4> path;
};

struct Plan {
  PlanStatus status = PlanStatus::kNoPath;
  std::vector<CandidatePath> candidates;
  int chosen = -1;                      // index into candidates
  std::vector<Pose4> path;              // the chosen 4-DoF path (empty unless solved)
};

}  // namespace tgnav::planner
