#include "harness/config/map_build_config.h"

#include <sstream>
#include <stdexcept>
#include <string>

namespace tgnav::harness {

void MapBuildConfig::validate() const {
  auto fail = [](const std::string& field, double v, const std::string& rule) {
    std::ostringstream msg;
    msg << field << " = " << v << ": " << rule;
    throw std::invalid_argument(msg.str());
  };
  if (!(resolution_m >= 0.02 && resolution_m <= 1.0)) fail("resolution_m", resolution_m, "must be in [0.02, 1]");
  if (!(max_range_m > 0.5)) fail("max_range_m", max_range_m, "must be > 0.5");
  if (occupancy_stride_px < 1) fail("occupancy_stride_px", occupancy_stride_px, "must be >= 1");
  if (!(merge_radius_m > 0.0)) fail("merge_radius_m", merge_radius_m, "must be > 0");
  if (max_hamming < 0 || max_hamming > 256) fail("max_hamming", max_hamming, "must be in [0, 256]");
  if (min_observations < 1) fail("min_observations", min_observations, "must be >= 1");
  if (!(max_shift_m >= 0.0)) fail("max_shift_m", max_shift_m, "must be >= 0");
  if (!(depth_edge_m > 0.0)) fail("depth_edge_m", depth_edge_m, "must be > 0");
  camera.validate();
  features.validate();
}

}  // namespace tgnav::harness
