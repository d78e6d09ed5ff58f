#pragma once
// The measures of an online trial against the truth (OnlinePlanning::finish): how much of the
// flight band the map observed, how far its occupied voxels lie from the true surfaces, and how
// much of the flight ran through space unknown when it was planned.
#include <octomap/OcTree.h>

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "harness/config/scenario.h"
#include "harness/run/online_planning.h"

namespace tgnav::harness {

class SceneGeometry;

// Share of the voxels of the scene's bounds within the flight band (clearanceBand) observed.
double mapCoverage(const octomap::OcTree& tree, const Scenario& scenario);

struct MapError {
  int occupied_voxels = 0;  // inside the bounds widened by kPlanningBoxMargin_m
  double mean_m = 0.0;      // their centres' mean distance to the true geometry
  double far_share = 0.0;   // ... share farther than two voxels from it
};
MapError mapError(const octomap::OcTree& tree, const SceneConfig& scene, const SceneGeometry& truth);

// The other side of the map's error: true surfaces the map lets a planner through. At the voxel
// centres of the flight band (clearanceBand) inside the scene's bounds, a crossing is a step to a
// horizontal neighbour from a centre outside the true geometry to one inside it: a surface lies
// between them, or in one of the two. It is observed when the map knows either voxel, and a hole
// when the inside voxel is known free and neither is occupied (the map says free inside a solid).
struct MapHoles {
  int crossings = 0;  // observed
  int holes = 0;
  double share() const { return crossings > 0 ? static_cast<double>(holes) / crossings : 0.0; }
};
MapHoles mapHoles(const octomap::OcTree& tree, const Scenario& scenario, const SceneGeometry& truth);

// Of the flown points (time, estimated position), the share whose nearest point on the plan in
// effect then (the last adopted one to have taken effect; the first before any) was unknown when
// that plan was made.
double unknownShare(const std::vector<OnlinePlan>& plans, const std::vector<std::pair<double, Eigen::Vector3d>>& flown);

}  // namespace tgnav::harness
