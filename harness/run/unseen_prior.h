#pragma once
// The perception model's prior for surfaces an online trial has not seen yet
// (trial.unseen_prior). `blind` adds nothing: a view of unseen space has no landmarks, so the
// perception-aware planners rate it blind, and every route into unknown space alike. `mean`
// rates it as textured as the surfaces seen so far, on average: every voxel not observed that
// borders observed free space (the frontier, where a ray of the camera's has not yet reached a
// surface) gets landmarks at the density of the observed surfaces (landmarks per occupied voxel
// bordering free space) with their mean detectability. A view into unknown space then promises
// what the scene has given so far, and a corridor seen bare rates blind beside one not yet seen.
// The frontier lies where the unseen surface lies at the nearest, so the prior's landmarks are
// nearer than the surface they stand for (more information per landmark, fewer in the field of
// view).
#include <Eigen/Core>

#include "planner/feature_map.h"

namespace tgnav::harness {

struct UnseenPriorStats {
  int surface_voxels = 0;      // observed occupied voxels bordering observed free space, in the box
  int surface_landmarks = 0;   // the map's landmarks in the box
  int frontier_voxels = 0;     // unobserved voxels bordering observed free space, in the box
  double density = 0.0;        // landmarks per surface voxel
  double detectability = 0.0;  // mean Landmark::detectability() of the map's landmarks in the box
  int added = 0;               // prior landmarks added
};

// Adds the `mean` prior's landmarks to `map` (embedded; FeatureMap::addPlacedLandmarks) over the
// box [min_W, max_W]. Without observed surfaces or landmarks there is nothing to average, and
// nothing is added.
UnseenPriorStats addUnseenPrior(planner::FeatureMap* map, const Eigen::Vector3d& min_W, const Eigen::Vector3d& max_W);

}  // namespace tgnav::harness
