#pragma once
// A route given to `tgnav trial` instead of a plan (TrialOptions::given_trajectory, given_path),
// checked against the map before anything flies: it must start at the scenario's start (within
// kGivenStartTolerance_m horizontally: the vehicle takes off there), stay inside the scene's
// bounds, and keep the planner's robot radius from every obstacle, its points and the straight
// lines between them, within the planners' clearance band (clearanceBand(); outside it, its points
// must not lie in an occupied voxel). InputError naming the file and the first offending point.
#include <string>
#include <vector>

#include "control/trajectory.h"
#include "harness/config/scenario.h"
#include "planner/pose4.h"
#include "planner/voxel_map.h"

namespace tgnav::harness {

constexpr double kGivenStartTolerance_m = 0.1;

// `voxels`: buildPlanningVoxels() of the scenario's map.
void checkGivenTrajectory(const Scenario& scenario, const planner::VoxelMap& voxels,
                          const control::SetpointTrajectory& trajectory, const std::string& file);
void checkGivenPath(const Scenario& scenario, const planner::VoxelMap& voxels, const std::vector<planner::Pose4>& path,
                    const std::string& file);

}  // namespace tgnav::harness
