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
};

// Loads configs/scenes/<name>.yaml (strict keys; `mjcf` relative to the YAML file).
SceneConfig loadSceneConfig(const std::filesystem::path& yaml);

// `path` may be a scene YAML or a bare MJCF file (.xml: only `mjcf` and `source` are set).
SceneConfig loadScene(const std::filesystem::path& path);

}  // namespace tgnav::harness
