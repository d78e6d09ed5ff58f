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
  // > 0: a depth pixel without a return clears space along its ray. An RGB-D camera gives no depth
  // beyond its range (camera.max_depth_m), so a pixel without depth sees a surface farther than
  // that: its ray is free up to where its depth would reach this, within max_range_m. Online: the
  // camera's max depth less three sigmas of its depth noise there (a surface just within range
  // may read beyond it). It marks only voxels not yet observed free; a voxel observed (free or occupied)
  // stays as it is. Down a corridor longer than the camera's range, the voxels at flight height
  // are otherwise never observed: only the rays that hit its floor or walls within range clear
  // space, and those reach flight height only close by. 0: such pixels are skipped (OctoMap's
  // insertion of a depth image). A pixel nearer than camera.min_depth_m (0.1 m) has no depth
  // either; the vehicle's robot radius keeps surfaces farther. Online maps only
  // (trial.map_clear_no_return); the survey keeps 0.
  double no_return_depth_m = 0.0;
  CameraConfig camera;
  vo::FeatureConfig features;

  void validate() const;
};

// The depth to which a pixel without a return is free (MapBuildConfig::no_return_depth_m) for
// `camera`: its max depth less three sigmas of its depth noise there (sigma = k z^2), where a
// surface just within range may read beyond it. Scenario loading rejects trial.map_clear_no_return
// where this is not above kMinNoReturnDepthM.
inline double noReturnDepth(const CameraConfig& camera) {
  const double z = camera.max_depth_m;
  return z - 3.0 * camera.depth_noise_sigma_per_m2 * z * z;
}
constexpr double kMinNoReturnDepthM = 0.5;

}  // namespace tgnav::harness
