#pragma once
// One planning run on a scene's feature map (the "plan" stage of `tgnav plan` and `tgnav trial`):
// the dense voxel map, then the chosen planner, timed, and its plan.json.
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "control/trajectory.h"
#include "harness/config/scenario.h"
#include "planner/feature_map.h"
#include "planner/planner.h"
#include "planner/trajectory_generator.h"
#include "planner/voxel_map.h"

namespace tgnav::harness {

// planner::parsePlannerKind, with an InputError naming `option` for an unknown name.
planner::PlannerKind parsePlannerName(const std::string& text, const std::string& option);

struct PlanRun {
  planner::PlannerKind planner = planner::PlannerKind::kProposed;
  std::uint64_t seed = 0;
  int rrt_samples = 0;  // rrtstar only
  planner::Plan plan;   // candidates, the chosen path and its homology class, per-class details
  std::unique_ptr<planner::VoxelMap> voxels;
  double voxel_map_s = 0.0;  // wall time: dense voxel map + distance field
  double solve_s = 0.0;      // wall time: the planner itself
  double plan_time_s() const { return voxel_map_s + solve_s; }
  // The chosen path as a flyable trajectory (status kFailed with an empty trajectory when there
  // is no path or it cannot be flown); not part of plan_time_s.
  planner::TrajectoryReport trajectory;
  double trajectory_s = 0.0;  // wall time: trajectory generation
};

// The heights where the dense voxel map answers clearance: the flight height +- the pose graph's
// sample radius, the robot radius and 0.2 m.
struct ClearanceBand {
  double lo_m = 0.0;
  double hi_m = 0.0;
};
ClearanceBand clearanceBand(const Scenario& scenario);
// The planners' voxel box is the scene's bounds widened by this much.
constexpr double kPlanningBoxMargin_m = 0.5;
// The planners' dense voxel map of `map` into run->voxels (its time into voxel_map_s): the scene's
// bounds widened by 0.5 m (walls lie just outside the free-space bounds and must be inside the box
// to be seen and avoided), with the distance field over clearanceBand().
// With `unknown_free`, space never observed counts as free (online planning, trial.unknown_space).
void buildPlanningVoxels(const Scenario& scenario, const planner::FeatureMap& map, PlanRun* run,
                         bool unknown_free = false);
// `path` as a trajectory from the scene's start pose (the vehicle may turn on the spot first), kept
// at the configured clearance, into run->trajectory (its time into trajectory_s); with
// `obstacle_points`, also in the path's homology class. Needs run->voxels.
void smoothPath(const Scenario& scenario, const std::vector<planner::Pose4>& path,
                const std::vector<Eigen::Vector2d>* obstacle_points, PlanRun* run);

// `--class K`: sets scenario->planner.oracle_class; InputError for K < 0 or with RRT*, which has
// no homology classes to fly.
void applyOracleClass(int k, planner::PlannerKind planner, Scenario* scenario);

// An oracle class (scenario.planner.oracle_class) with RRT*, or beyond the classes found, is an
// InputError naming `oracle_option`.
// `unknown_free` as for buildPlanningVoxels.
PlanRun runPlanner(const Scenario& scenario, const planner::FeatureMap& map, planner::PlannerKind name,
                   std::uint64_t seed, int rrt_samples, const std::string& oracle_option = "planner.oracle_class",
                   bool unknown_free = false);
// runPlanner without the trajectory (run.trajectory left empty): where only the plan is wanted.
PlanRun solvePlan(const Scenario& scenario, const planner::FeatureMap& map, planner::PlannerKind name,
                  std::uint64_t seed, int rrt_samples, const std::string& oracle_option = "planner.oracle_class",
                  bool unknown_free = false);

nlohmann::ordered_json planJson(const Scenario& scenario, const PlanRun& run);
// A run's config.yaml: "# tgnav COMMAND --planner P [--samples N] --seed S [--class K]", then the
// resolved settings it ran with (resolvedScenarioYaml).
std::string runConfigYaml(const std::string& command, const Scenario& scenario, const PlanRun& run);
// The generated trajectory sampled at the configured rate, as the controller takes it (and
// `tgnav fly --trajectory` reads it back from trajectory.csv). Requires a trajectory.
control::SetpointTrajectory setpoints(const PlanRun& run, double rate_hz);

}  // namespace tgnav::harness
