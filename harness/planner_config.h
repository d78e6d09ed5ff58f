#pragma once
// configs/planner.yaml <-> the planners' Config structs (strict keys; defaults are Table I).
#include <filesystem>

#include "harness/yaml_util.h"
#include "planner/perception_planner.h"
#include "planner/rrt_star.h"
#include "planner/trajectory_generator.h"

namespace tgnav::harness {

struct PlannerSettings {
  planner::PerceptionPlannerConfig perception;  // proposed and agnostic
  planner::RrtStarConfig rrt_star;              // its visibility, information and robot radius
                                                // follow `perception`'s (one sensor, one robot)
  planner::TrajectoryConfig trajectory;         // its robot radius is perception's too
  void validate() const;                        // std::invalid_argument naming the key
};

// Reads the keys present in `r` (a planner.yaml root or a scenario's `planner:` section) over `s`;
// on a FieldReader::writer, writes them all. RRT*'s and the trajectory's robot radius, visibility
// and information are perception's, so they have no keys of their own.
void readPlannerSettings(FieldReader r, PlannerSettings* s);
// Every key of planner.yaml with its value.
YAML::Node toYaml(const PlannerSettings& s);
PlannerSettings loadPlannerSettings(const std::filesystem::path& yaml, PlannerSettings base = {});
// Re-raises validate() failures as InputError naming `source`.
void validatePlannerSettings(const PlannerSettings& s, const std::string& source);

}  // namespace tgnav::harness
