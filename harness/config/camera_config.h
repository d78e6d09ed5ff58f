#pragma once
// Settings of the onboard RGB-D camera (configs/camera.yaml): what the renderer draws and the
// sensor noise added to it. The renderer itself is harness/sim/camera.h.
#include <string>

namespace tgnav::harness {

// The camera name that stands for the camera the vehicle description names.
inline constexpr const char* kVehicleCamera = "vehicle";

struct CameraConfig {
  std::string name = kVehicleCamera;  // MJCF camera name, or "vehicle": the vehicle's camera
  int width_px = 640;
  int height_px = 480;
  double near_clip_m = 0.05;  // OpenGL clipping planes
  double far_clip_m = 40.0;
  double min_depth_m = 0.1;  // depth outside [min, max] is reported invalid (0)
  double max_depth_m = 10.0;
  double rgb_noise_sigma = 0.0;           // Gaussian pixel noise, 8-bit intensity units
  double depth_noise_sigma_per_m2 = 0.0;  // depth noise sigma = k z^2 (structured light)
  // Multisample anti-aliasing of the offscreen render (MuJoCo's <quality offsamples>, whose
  // default is 4): 0 renders one sample per pixel, as a real camera's pixels integrate no
  // sub-pixel geometry edges either. Overrides the model's setting.
  int offscreen_samples = 0;

  // The keys of configs/camera.yaml (harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a("name", name);
    a("width_px", width_px);
    a("height_px", height_px);
    a("near_clip_m", near_clip_m);
    a("far_clip_m", far_clip_m);
    a("min_depth_m", min_depth_m);
    a("max_depth_m", max_depth_m);
    a("rgb_noise_sigma", rgb_noise_sigma);
    a("depth_noise_sigma_per_m2", depth_noise_sigma_per_m2);
    a("offscreen_samples", offscreen_samples);
  }

  // Throws std::invalid_argument naming the field and value.
  void validate() const;
  // The MJCF camera this config renders from: `name`, or `vehicle_camera` for "vehicle".
  std::string cameraName(const std::string& vehicle_camera) const {
    return name == kVehicleCamera ? vehicle_camera : name;
  }
  // This config with cameraName() as its name.
  CameraConfig on(const std::string& vehicle_camera) const {
    CameraConfig c = *this;
    c.name = cameraName(vehicle_camera);
    return c;
  }
};

}  // namespace tgnav::harness
