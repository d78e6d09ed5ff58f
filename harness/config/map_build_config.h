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
  // true: each depth ray clears free space only up to one voxel short of the surface it hits,
  // measured along the surface's normal (from the depth image), so a ray that grazes a wall does
  // not clear the wall's own voxels on its way to a point farther along it. false: OctoMap's
  // insertion of the endpoints moved to their voxels' centres, which clears them: at a grazing
  // angle the last stretch of the ray runs inside the surface's layer of voxels
  // (docs/results/grazing). Online maps only (trial.map_short_of_surface); the survey keeps false.
  bool free_short_of_surface = false;
  CameraConfig camera;
  vo::FeatureConfig features;

  void validate() const;
};

}  // namespace tgnav::harness
