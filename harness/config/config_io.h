#pragma once
// YAML <-> the module config structs, through their visit() (harness/config/yaml_util.h): keys
// are optional (defaults come from the structs), unknown keys are errors, and validate()
// failures are reported with the file they came from. The keys of each file:
//   configs/camera.yaml      CameraConfig
//   configs/controller.yaml  control::CascadeConfig
//   configs/vo.yaml          vo::OdometryConfig (`features:` vo::FeatureConfig)
//   configs/trial.yaml       TrialConfig
//   configs/planner.yaml     PlannerSettings (harness/config/planner_config.h)
// toYaml(config) (yaml_util.h) writes every key, so files written by the harness always load back.
#include <filesystem>

#include "control/cascade.h"
#include "harness/config/camera_config.h"
#include "harness/config/trial_config.h"
#include "harness/config/yaml_util.h"
#include "vo/odometry.h"

namespace tgnav::harness {

// loadConfigFile() by the config's name.
inline CameraConfig loadCameraConfig(const std::filesystem::path& yaml, CameraConfig base = {}) {
  return loadConfigFile(yaml, std::move(base));
}
inline control::CascadeConfig loadCascadeConfig(const std::filesystem::path& yaml, control::CascadeConfig base = {}) {
  return loadConfigFile(yaml, std::move(base));
}
inline vo::OdometryConfig loadOdometryConfig(const std::filesystem::path& yaml, vo::OdometryConfig base = {}) {
  return loadConfigFile(yaml, base);
}
inline TrialConfig loadTrialConfig(const std::filesystem::path& yaml, TrialConfig base = {}) {
  return loadConfigFile(yaml, base);
}

}  // namespace tgnav::harness
