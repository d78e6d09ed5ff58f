#include "harness/run/trial_route.h"

#include "harness/run/given_route.h"

namespace tgnav::harness {

namespace {

// A given path, or an external planner's, smoothed into result->setpoints as a plan's path is
// (without the homology check: it has no class); false with the status set when that fails.
bool smoothGivenPath(const Scenario& scenario, std::vector<planner::Pose4> path, const std::string& who,
                     TrialResult* result) {
  result->plan.plan.path = std::move(path);
  smoothPath(scenario, result->plan.plan.path, nullptr, &result->plan);
  if (!result->plan.trajectory.trajectory) {
    result->status = TrialStatus::kPlanFailed;
    result->detail = who + "trajectory generation failed: " + result->plan.trajectory.reason;
    return false;
  }
  result->setpoints = setpoints(result->plan, scenario.planner.trajectory.sample_rate_hz);
  return true;
}

}  // namespace

// The route to fly into result->setpoints: given, asked of the external planner or planned.
// False with the status set when there is none.
bool makeRoute(const Scenario& scenario, const planner::FeatureMap& map, const TrialOptions& options,
               const std::atomic<bool>* interrupt, TrialResult* result) {
  if (!options.given() && !options.external) {
    result->plan = runPlanner(scenario, map, options.planner, options.seed, options.rrt_samples, options.oracle_option);
    const planner::Plan& plan = result->plan.plan;
    if (plan.chosen < 0 || !result->plan.trajectory.trajectory) {
      result->status = TrialStatus::kPlanFailed;
      result->detail = plan.chosen < 0 ? std::string("no path: ") + planner::toString(plan.status)
                                       : "trajectory generation failed: " + result->plan.trajectory.reason;
      return false;
    }
    result->setpoints = setpoints(result->plan, scenario.planner.trajectory.sample_rate_hz);
    return true;
  }
  result->plan.planner = options.planner;
  result->plan.seed = options.seed;
  buildPlanningVoxels(scenario, map, &result->plan);
  if (options.given_trajectory) {
    checkGivenTrajectory(scenario, *result->plan.voxels, *options.given_trajectory, options.given_file);
    result->setpoints = options.given_trajectory;
    return true;
  }
  if (options.given_path) {
    checkGivenPath(scenario, *result->plan.voxels, *options.given_path, options.given_file);
    return smoothGivenPath(scenario, *options.given_path, "", result);
  }
  result->external = askExternalPlanner(scenario, options.map_dir, *result->plan.voxels, options.seed, interrupt);
  ExternalPlan& ext = *result->external;
  result->plan.solve_s = ext.total_s();
  result->plan.plan.topo = std::move(ext.topo);
  result->plan.plan.chosen_class = ext.homology_class.value_or(-1);
  if (!ext.ok) {
    const bool interrupted = interrupt != nullptr && interrupt->load();
    result->status = interrupted ? TrialStatus::kInterrupted : TrialStatus::kPlanFailed;
    result->detail = ext.detail;
    return false;
  }
  result->plan.plan.status = planner::PlanStatus::kSolved;
  if (ext.trajectory) {
    result->setpoints = ext.trajectory;
    return true;
  }
  return smoothGivenPath(scenario, *ext.path, "external planner " + scenario.planner.external.name + ": ", result);
}

}  // namespace tgnav::harness
