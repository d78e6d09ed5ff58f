#include "harness/config/planner_config.h"

#include <stdexcept>
#include <string>

#include "harness/config/check.h"

namespace tgnav::harness {

const std::vector<std::string>& PlannerSettings::sharedKeys() {
  static const std::vector<std::string> keys = {"topology.robot_radius_m", "pose_graph.robot_radius_m",
                                                "rrt_star.robot_radius_m", "rrt_star.visibility",
                                                "rrt_star.information",    "rrt_star.slice_half_height_m",
                                                "rrt_star.topology",       "trajectory.robot_radius_m"};
  return keys;
}

void PlannerSettings::shareFromPerception() {
  const planner::PerceptionPlannerConfig& p = perception;
  perception.topo.robot_radius_m = p.robot_radius_m;
  perception.graph.robot_radius_m = p.robot_radius_m;
  rrt_star.robot_radius_m = p.robot_radius_m;
  rrt_star.visibility = p.visibility;
  rrt_star.information = p.information;
  rrt_star.slice_half_height_m = p.slice_half_height_m;
  rrt_star.topo = p.topo;
  trajectory.robot_radius_m = p.robot_radius_m;
}

void PlannerSettings::validate() const {
  perception.validate();
  rrt_star.validate();
  trajectory.validate();
  try {
    external.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("external.") + e.what());
  }
  require(oracle_class >= -1, "oracle_class", oracle_class, "must be -1 (the planner chooses) or a class index >= 0");
}

}  // namespace tgnav::harness
