#pragma once
// YAML -> module Config structs. Keys are optional (defaults come from the structs), unknown
// keys are errors, and validate() failures are reported with the file they came from.
#include <filesystem>

#include "harness/camera.h"

namespace tgnav::harness {

CameraConfig loadCameraConfig(const std::filesystem::path& yaml, CameraConfig base = {});

}  // namespace tgnav::harness
