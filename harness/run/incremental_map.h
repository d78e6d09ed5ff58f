#pragma once
// A feature map built frame by frame (paper Sec. IV): depth ray-inserted into an OctoMap, ORB
// keypoints back-projected at the frame's pose and merged into landmarks, and each landmark's
// detectability counted over the frames that had it in view. The survey (map_builder.h) feeds it
// the survey's frames at their true poses; an online trial (online_planning.h) feeds it the onboard
// camera's keyframes at the pose it maps at, and takes a snapshot whenever it plans.
#include <octomap/OcTree.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "harness/config/map_build_config.h"
#include "harness/sim/camera.h"
#include "planner/feature_map.h"
#include "vo/features.h"

namespace tgnav::harness {

// Calls fn(p) with the centre of every map voxel that the leaf at `it` covers (a leaf may be a
// merged cube of many voxels).
template <typename LeafIterator, typename Fn>
void forEachVoxel(const LeafIterator& it, double res, const Fn& fn) {
  const int n = std::max(1, static_cast<int>(std::lround(it.getSize() / res)));
  const Eigen::Vector3d corner =
      Eigen::Vector3d(it.getX(), it.getY(), it.getZ()) - Eigen::Vector3d::Constant(0.5 * it.getSize() - 0.5 * res);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) fn(Eigen::Vector3d(corner + res * Eigen::Vector3d(i, j, k)));
    }
  }
}

// The occupancy of `tree` within `radius_m` (horizontally) of `centre`, voxel by voxel (an online
// trial's prior of the survey near the start).
octomap::OcTree cropOccupancy(const octomap::OcTree& tree, const Eigen::Vector3d& centre, double radius_m);

// True when an occupied voxel of `tree` lies within `radius_m` of one of `points`: the distance
// from the point to the voxel's cube, as the planners' clearance measures it.
bool occupiedWithin(const octomap::OcTree& tree, const std::vector<Eigen::Vector3d>& points, double radius_m);

class IncrementalMapper {
 public:
  // config.validate() is the caller's. `k`: the camera whose frames are integrated (setCamera()
  // may name it later, before the first frame).
  explicit IncrementalMapper(const MapBuildConfig& config, const Intrinsics& k = Intrinsics{});
  void setCamera(const Intrinsics& k);
  ~IncrementalMapper();
  IncrementalMapper(const IncrementalMapper&) = delete;
  IncrementalMapper& operator=(const IncrementalMapper&) = delete;
  IncrementalMapper(IncrementalMapper&&) = delete;
  IncrementalMapper& operator=(IncrementalMapper&&) = delete;

  // Starts from a map known beforehand: its occupancy, and its landmarks as they are (their
  // detectability counted elsewhere); the frames' landmarks are added to them.
  void setPrior(const octomap::OcTree& occupancy, std::vector<planner::Landmark> landmarks);

  // Ray-inserts every `stride_px`-th depth pixel of `frame` at frame.X_WC (short of the surface
  // with config.free_short_of_surface; with config.no_return_depth_m, the pixels without depth
  // too).
  void insertDepth(const RgbdFrame& frame, int stride_px);
  // Detects its ORB keypoints, merges those with a stable depth into the landmarks, and keeps a
  // sampled depth of the view for counting opportunities.
  void observeFeatures(const RgbdFrame& frame);

  const octomap::OcTree& occupancy() const { return *tree_; }
  long keypoints() const { return keypoints_; }
  long observations() const { return observations_; }  // keypoints with usable depth
  int views() const;                                   // frames whose features were observed
  int tracks() const;                                  // landmarks before the min_observations cut

  struct Built {
    planner::FeatureMap map;
    int dropped_few_observations = 0;
    int dropped_not_embedded = 0;
    double opportunities_s = 0.0;  // wall time counting opportunities
  };
  // The map so far (a copy; the mapper goes on): the prior's landmarks and the frames' landmarks
  // seen at least config.min_observations times, their opportunities counted over every observed
  // frame, embedded in the occupancy. A landmark not observed since the last snapshot keeps its
  // count and has only the frames observed since counted (the same count, in less time).
  Built snapshot();
  // The same, moving the occupancy out (the mapper is spent).
  Built release();

 private:
  struct Associator;
  struct View;
  // A track's opportunities as last counted: over views [0, views) at its mean after
  // `observations` observations (its mean changes only with a new observation).
  struct Counted {
    int observations = 0;
    int views = 0;
    int opportunities = 0;
  };
  Built build(std::unique_ptr<octomap::OcTree> tree);
  void insertDepthRays(const RgbdFrame& frame, int stride_px);
  void insertDepthShortOfSurface(const RgbdFrame& frame, int stride_px);
  void clearNoReturn(const RgbdFrame& frame, int stride_px);

  MapBuildConfig config_;
  Intrinsics k_;
  vo::FeatureDetector detector_;
  std::unique_ptr<octomap::OcTree> tree_;
  std::unique_ptr<Associator> associator_;
  std::vector<View> views_;
  std::vector<Counted> counted_;  // per track
  std::vector<planner::Landmark> prior_landmarks_;
  long keypoints_ = 0;
  long observations_ = 0;
};

}  // namespace tgnav::harness
