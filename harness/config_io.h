#pragma once
// YAML -> module Config structs. Keys are optional (defaults come from the structs), unknown
// keys are errors, and validate() failures are reported with the file they came from.
#include <filesystem>

#include "control/cascade.h"
#include "harness/camera.h"

namespace tgnav::harness {

CameraConfig loadCameraConfig(const std::filesystem::path& yaml, CameraConfig base = {});
control::CascadeConfig loadCascadeConfig(const std::filesystem::path& yaml,
                                         control::CascadeConfig base = {});

}  // namespace tgnav::harness
