#pragma once
// Settings of the mapping run (harness/run/map_builder.h): the survey camera, the OctoMap's
// resolution and range, and how ORB observations merge into landmarks.
#include "harness/config/camera_config.h"
#include "vo/features.h"

namespace tgnav::harness {

struct MapBuildConfig {
  double resolution_m = 0.1;
  double max_range_m = 6.0;      // depth beyond this is not integrated (RGB-D noise grows as z^2)
  int occupancy_stride_px = 4;   // every Nth pixel in both directions is ray-inserted
  double merge_radius_m = 0.08;  // observations closer than this with similar descriptors merge
  int max_hamming = 40;          // ORB descriptor distance for "the same landmark"
  int min_observations = 2;      // landmarks seen fewer times are dropped (ORB-SLAM culls these too)
  double max_shift_m = 0.15;     // landmark -> surface voxel embedding tolerance
  double depth_edge_m = 0.05;    // keypoints on a depth discontinuity larger than this are rejected
  CameraConfig camera;
  vo::FeatureConfig features;

  void validate() const;
};

}  // namespace tgnav::harness
