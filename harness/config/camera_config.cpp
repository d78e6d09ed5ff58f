#include "harness/config/camera_config.h"

#include <stdexcept>
#include <string>

#include "harness/config/check.h"

namespace tgnav::harness {

void CameraConfig::validate() const {
  if (name.empty()) throw std::invalid_argument("name: must not be empty");
  require(width_px >= 16 && width_px <= 4096, "width_px", width_px, "must be in [16, 4096]");
  require(height_px >= 16 && height_px <= 4096, "height_px", height_px, "must be in [16, 4096]");
  require(near_clip_m > 0.0, "near_clip_m", near_clip_m, "must be > 0");
  require(far_clip_m > near_clip_m, "far_clip_m", far_clip_m, "must be > near_clip_m");
  require(min_depth_m >= near_clip_m, "min_depth_m", min_depth_m, "must be >= near_clip_m");
  require(max_depth_m > min_depth_m && max_depth_m <= far_clip_m, "max_depth_m", max_depth_m,
          "must be in (min_depth_m, far_clip_m]");
  require(rgb_noise_sigma >= 0.0, "rgb_noise_sigma", rgb_noise_sigma, "must be >= 0");
  require(offscreen_samples == 0 || offscreen_samples == 2 || offscreen_samples == 4 || offscreen_samples == 8,
          "offscreen_samples", offscreen_samples, "must be 0, 2, 4 or 8");
  require(depth_noise_sigma_per_m2 >= 0.0, "depth_noise_sigma_per_m2", depth_noise_sigma_per_m2, "must be >= 0");
}

}  // namespace tgnav::harness
