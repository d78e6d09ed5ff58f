#pragma once
// A scene: the MJCF world plus what the planner and the trial need to know about it.
#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "planner/pose4.h"

namespace tgnav::harness {

// How the mapping run covers the scene: positions on a horizontal grid over the bounds (kept
// only where they are at least clearance_m from all geometry), at each of heights_m, each
// rendering yaw_count views at equally spaced yaws.
struct SurveyPlan {
  double spacing_m = 1.0;
  std::vector<double> heights_m = {1.0};
  int yaw_count = 8;
  double clearance_m = 0.5;

  // The keys of a scene's `survey:` (harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a("spacing_m", spacing_m);
    a("heights_m", heights_m);
    a("yaw_count", yaw_count);
    a("clearance_m", clearance_m);
  }
};

struct SceneConfig {
  std::filesystem::path source;  // the YAML file (or the MJCF itself, see loadScene)
  std::filesystem::path mjcf;    // absolute
  double flight_height_m = 1.0;
  planner::Pose4 start;
  planner::Pose4 goal;
  Eigen::Vector3d bounds_min_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d bounds_max_m = Eigen::Vector3d::Zero();
  SurveyPlan survey;
  // The vehicle description (harness/config/vehicle_config.h) that flies the scene unless a
  // scenario names another; absolute. Empty: the vehicle the MJCF includes.
  std::filesystem::path vehicle;

  // The keys of a scene file, all required but `vehicle` (harness/config/yaml_util.h); `source` has none.
  template <typename Archive>
  void visit(Archive& a) {
    a("mjcf", mjcf);  // in the file: relative to it
    a("flight_height_m", flight_height_m);
    a("start", start);
    a("goal", goal);
    a.group("bounds", [&](auto& g) {
      g("min", bounds_min_m);
      g("max", bounds_max_m);
    });
    a("survey", survey);
    a("vehicle", vehicle);  // in the file: relative to it
  }
};

// Loads configs/scenes/<name>.yaml (strict keys, all required; `mjcf` relative to the YAML file),
// then checks that the MJCF exists, bounds.max > bounds.min, the start, the goal, the flight
// height and the survey heights lie inside the bounds, survey.heights_m is not empty,
// survey.spacing_m >= 0.1, survey.clearance_m >= 0 and survey.yaw_count is in [1, 64], and that
// the optional `vehicle` (relative to the YAML file) is a vehicle description.
SceneConfig loadSceneConfig(const std::filesystem::path& yaml);

// `path` may be a scene YAML or a bare MJCF file (.xml: only `mjcf` and `source` are set).
SceneConfig loadScene(const std::filesystem::path& path);

}  // namespace tgnav::harness
