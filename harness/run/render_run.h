#pragma once
// The `tgnav render` job: one RGB-D frame of a scene from a vehicle pose, for looking at scenes:
// rgb.png (8-bit), depth.png (16-bit millimetres, 0 = invalid) and intrinsics.yaml (with the
// camera pose X_WC and the renderer).
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace tgnav::harness {

struct RenderJob {
  std::filesystem::path scene;    // scene YAML, or an MJCF that includes the vehicle
  std::string pose;               // "x,y,z,yaw"; "" = the scene's start (required for an MJCF)
  std::filesystem::path vehicle;  // vehicle description; empty: the scene's
  std::filesystem::path out;
  std::string camera_config;    // camera YAML; "" = built-in
  std::optional<int> width_px;  // override the camera config
  std::optional<int> height_px;
  std::uint64_t seed = 0;  // camera noise
};

// The line `tgnav render` prints. InputError for bad input.
std::string runRender(const RenderJob& job);

}  // namespace tgnav::harness
