#pragma once
// The mapping run (paper Sec. IV): render RGB-D from survey poses covering the free space,
// integrate depth into an OctoMap by ray insertion, detect ORB features, back-project them into
// world landmarks, merge repeated observations, count how many survey frames had each landmark in
// view (its detectability: planner::Landmark), and embed the landmarks in surface voxels.
#include <functional>
#include <vector>

#include "harness/config/map_build_config.h"
#include "harness/config/scene_config.h"
#include "planner/feature_map.h"

namespace tgnav::harness {

struct MapBuildStats {
  int survey_positions = 0;
  int frames = 0;
  long keypoints = 0;
  long observations = 0;     // keypoints with usable depth
  int landmarks_merged = 0;  // distinct landmarks after merging
  int dropped_few_observations = 0;
  int dropped_not_embedded = 0;
  int landmarks = 0;                // in the final map
  double mean_detectability = 0.0;  // their mean planner::Landmark::detectability()
  // Wall-clock seconds: rendering the survey (this thread), integrating its depth and keypoints
  // (a worker, overlapping the rendering), and the whole build.
  double render_s = 0.0;
  double integrate_s = 0.0;
  double features_s = 0.0;
  double opportunities_s = 0.0;  // counting each landmark's opportunities over the survey (after it)
  double total_s = 0.0;
};

class SceneGeometry;

// Vehicle poses of the mapping run: grid positions over the scene bounds at every survey
// height, kept where the static geometry is at least survey.clearance_m away, times
// survey.yaw_count yaws. Deterministic order. InputError if none is free.
std::vector<planner::Pose4> surveyPoses(const SceneConfig& scene, const SceneGeometry& geometry);

planner::FeatureMap buildFeatureMap(const SceneConfig& scene, const MapBuildConfig& config, MapBuildStats* stats,
                                    const std::function<void(int done, int total)>& progress = {});

}  // namespace tgnav::harness
