#include "harness/config/map_build_config.h"

#include "harness/config/check.h"

namespace tgnav::harness {

void MapBuildConfig::validate() const {
  require(resolution_m >= 0.02 && resolution_m <= 1.0, "resolution_m", resolution_m, "must be in [0.02, 1]");
  require(max_range_m > 0.5, "max_range_m", max_range_m, "must be > 0.5");
  require(occupancy_stride_px >= 1, "occupancy_stride_px", occupancy_stride_px, "must be >= 1");
  require(merge_radius_m > 0.0, "merge_radius_m", merge_radius_m, "must be > 0");
  require(max_hamming >= 0 && max_hamming <= 256, "max_hamming", max_hamming, "must be in [0, 256]");
  require(min_observations >= 1, "min_observations", min_observations, "must be >= 1");
  require(max_shift_m >= 0.0, "max_shift_m", max_shift_m, "must be >= 0");
  require(depth_edge_m > 0.0, "depth_edge_m", depth_edge_m, "must be > 0");
  require(no_return_depth_m >= 0.0, "no_return_depth_m", no_return_depth_m, "must be >= 0");
  camera.validate();
  features.validate();
}

}  // namespace tgnav::harness
