#pragma once
// The mapping run (paper Sec. IV): render RGB-D from survey poses covering the free space,
// integrate depth into an OctoMap by ray insertion, detect ORB features, back-project them into
// world landmarks, merge repeated observations, and embed the landmarks in surface voxels.
#include <functional>
#include <vector>

#include "harness/camera.h"
#include "harness/scene_config.h"
#include "planner/feature_map.h"
#include "vo/features.h"

namespace tgnav::harness {

struct MapBuildConfig {
  double resolution_m = 0.1;
  double max_range_m = 6.0;        // depth beyond this is not integrated (RGB-D noise grows as z^2)
  int occupancy_stride_px = 4;     // every Nth pixel in both directions is ray-inserted
  double merge_radius_m = 0.08;    // observations closer than this with similar descriptors merge
  int max_hamming = 40;            // ORB descriptor distance for "the same landmark"
  int min_observations = 2;        // landmarks seen fewer times are dropped (ORB-SLAM culls these too)
  double max_shift_m = 0.15;       // landmark -> surface voxel embedding tolerance
  double depth_edge_m = 0.05;      // keypoints on a depth discontinuity larger than this are rejected
  CameraConfig camera;
  vo::FeatureConfig features;

  void validate() const;
};

struct MapBuildStats {
  int survey_positions = 0;
  int frames = 0;
  long keypoints = 0;
  long observations = 0;      // keypoints with usable depth
  int landmarks_merged = 0;   // distinct landmarks after merging
  int dropped_few_observations = 0;
  int dropped_not_embedded = 0;
  int landmarks = 0;          // in the final map
  double render_s = 0.0;
  double integrate_s = 0.0;
  double features_s = 0.0;
  double total_s = 0.0;
};

class SceneGeometry;

// Vehicle poses of the mapping run: grid positions over the scene bounds at every survey
// height, kept where the static geometry is at least survey.clearance_m away, times
// survey.yaw_count yaws. Deterministic order. InputError if none is free.
std::vector<planner::Pose4> surveyPoses(const SceneConfig& scene, const SceneGeometry& geometry);

planner::FeatureMap buildFeatureMap(const SceneConfig& scene, const MapBuildConfig& config,
                                    MapBuildStats* stats,
                                    const std::function<void(int done, int total)>& progress = {});

}  // namespace tgnav::harness
