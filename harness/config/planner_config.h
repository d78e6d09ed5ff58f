#pragma once
// configs/planner.yaml <-> the planners' Config structs (strict keys; defaults are Table I).
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "harness/config/external_planner_config.h"
#include "harness/config/yaml_util.h"
#include "planner/perception_planner.h"
#include "planner/rrt_star.h"
#include "planner/trajectory_generator.h"

namespace tgnav::harness {

// The planners' default robot radius in the harness: it bounds the vehicle it flies. The propeller
// discs of models/quadrotor.xml reach 0.372 m from the body origin at any attitude
// (tests/harness/vehicle_test.cpp checks it), so 0.38 m, that rounded up to the centimetre. The
// planner library's own default, 0.3 m, is for a smaller robot. A scene flown by another vehicle
// sets planner.robot_radius_m to that vehicle's bound (harness::vehicleReach).
inline constexpr double kVehicleRobotRadiusM = 0.38;

struct PlannerSettings {
  PlannerSettings() {
    perception.robot_radius_m = kVehicleRobotRadiusM;
    shareFromPerception();
  }

  planner::PerceptionPlannerConfig perception;  // proposed and agnostic
  planner::RrtStarConfig rrt_star;              // its robot radius, visibility, information and
                                                // labelling classes follow `perception`'s (one
                                                // robot, one sensor, one set of classes)
  planner::TrajectoryConfig trajectory;         // its robot radius is perception's too
  // The oracle: >= 0 makes proposed and agnostic fly this homology class (an index into plan.json's
  // classes) instead of choosing one (planner::PlanRequest::homology_class); -1: they choose.
  int oracle_class = -1;
  // A planner run as a child process (`--planner external`; docs/PLANNER_PROTOCOL.md).
  ExternalPlannerConfig external;

  // The dotted keys of the fields that follow perception's: they have no keys of their own in
  // planner.yaml, and shareFromPerception() sets them.
  static const std::vector<std::string>& sharedKeys();

  // The keys of planner.yaml (a scenario's `planner:` section): perception's at the top level,
  // then `rrt_star:`, `trajectory:` and `external:`, less sharedKeys(); after each visit the shared fields are
  // perception's again.
  template <typename Archive>
  void visit(Archive& a) {
    SkipKeys<Archive> s(a, sharedKeys());
    perception.visit(s);
    s("rrt_star", rrt_star);
    s("trajectory", trajectory);
    s("oracle_class", oracle_class);
    s("external", external);
    shareFromPerception();
  }
  // Copies perception's robot radius, visibility, information, slice and topology settings into
  // the fields named by sharedKeys().
  void shareFromPerception();

  void validate() const;  // std::invalid_argument naming the key
};

// A planner.yaml read over `base`, then validated (InputError naming the file).
inline PlannerSettings loadPlannerSettings(const std::filesystem::path& yaml, PlannerSettings base = {}) {
  return loadConfigFile(yaml, std::move(base));
}

}  // namespace tgnav::harness
