#pragma once
// YAML -> module Config structs. Keys are optional (defaults come from the structs), unknown
// keys are errors, and validate() failures are reported with the file they came from.
#include <filesystem>

#include "control/cascade.h"
#include "harness/camera.h"
#include "vo/odometry.h"

namespace tgnav::harness {

CameraConfig loadCameraConfig(const std::filesystem::path& yaml, CameraConfig base = {});
control::CascadeConfig loadCascadeConfig(const std::filesystem::path& yaml, control::CascadeConfig base = {});
// Keys are the fields of vo::OdometryConfig, `features:` those of vo::FeatureConfig.
vo::OdometryConfig loadOdometryConfig(const std::filesystem::path& yaml, vo::OdometryConfig base = {});

}  // namespace tgnav::harness
