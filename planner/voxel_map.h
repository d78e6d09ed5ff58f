#pragma once
// A dense voxel copy of the feature map's occupancy over a box, for the planner's hot loops:
// V(p) by 3D DDA line-of-sight (same answer as FeatureMap::visibleFrom, ~20x faster), the
// flight-height slice for the GVD, and an exact 3D Euclidean distance field (with feature
// transform) for collision checks of 4-DoF poses and edges (paper Sec. V-D: "3D obstacles cannot
// be considered in the sparse graph"). Voxels are the octree's own voxels.
//
// Obstacles for collision are occupied or never-observed voxels and everything outside the box;
// line of sight stops only at occupied voxels (unknown is ignored, as in FeatureMap).
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "planner/feature_map.h"
#include "planner/occupancy_grid.h"

namespace tgnav::planner {

enum class VoxelState : std::uint8_t { kUnknown = 0, kFree = 1, kOccupied = 2 };

// Landmarks that share a surface voxel: visibility is decided once per voxel.
struct LandmarkVoxel {
  int index = 0;             // flat voxel index in the VoxelMap
  Eigen::Vector3d centre_W;  // voxel centre
  Eigen::Vector3d mean_W;    // mean position of its landmarks
  // Outward surface normal: the mean direction to the free voxels within two voxels (unit; zero
  // where free space lies on opposite sides alike, e.g. a thin panel, or there is none).
  Eigen::Vector3d normal_W = Eigen::Vector3d::Zero();
  std::vector<int> ids;     // landmark ids, ascending
  double detections = 0.0;  // sum of their Landmark::detectability(): what one view is expected to find
};

class VoxelMap {
 public:
  // The box [min_W, max_W] is widened to whole octree voxels. Landmarks whose voxel lies
  // outside it are not visible through this map. clearance() answers for heights in
  // [clearance_z_lo_m, clearance_z_hi_m] (everything above or below counts as blocked): the
  // distance field then covers only that band plus kClearanceReach_m, which is exact for every
  // clearance up to kClearanceReach_m (planners only ask whether clearance >= robot radius).
  // With `unknown_free`, voxels never observed count as free (an online planner's optimism about
  // space it has not seen yet); by default they block like occupied ones.
  VoxelMap(const FeatureMap& map, const Eigen::Vector3d& min_W, const Eigen::Vector3d& max_W,
           double clearance_z_lo_m = -1e9, double clearance_z_hi_m = 1e9, bool unknown_free = false);
  static constexpr double kClearanceReach_m = 1.0;

  double resolution() const { return res_; }
  Eigen::Vector3i size() const { return size_; }
  Eigen::Vector3d origin() const { return origin_; }  // corner of voxel (0, 0, 0)
  VoxelState state(const Eigen::Vector3d& p_W) const;
  // Whether p's voxel was observed (free or occupied in the octree), whatever `unknown_free` made
  // of it for collision; false outside the box.
  bool observed(const Eigen::Vector3d& p_W) const;
  const std::vector<LandmarkVoxel>& landmarkVoxels() const { return landmark_voxels_; }
  // Index into landmarkVoxels() of landmark `id` (-1: outside the box).
  int landmarkSlot(int id) const { return landmark_slot_.at(static_cast<std::size_t>(id)); }
  // Number of landmarks in landmarkVoxels()[slot].
  int landmarksIn(int slot) const {
    return static_cast<int>(landmark_voxels_.at(static_cast<std::size_t>(slot)).ids.size());
  }
  // Landmark::detectability() of landmark `id`.
  double detectability(int id) const { return detectability_.at(static_cast<std::size_t>(id)); }

  // V(p): landmarks within range and the vertical FoV of a camera at p (any yaw) whose voxel is
  // the first occupied voxel on the segment from p to its centre. Sorted ascending.
  std::vector<int> visibleFrom(const Eigen::Vector3d& p_W, const VisibilityConfig& config) const;
  // The same as indices into landmarkVoxels() (ascending): visibility is decided per voxel, so
  // V(p) is the union of these voxels' ids. With `keep`, only among the voxels it accepts, asked
  // before the (costly) line of sight: e.g. those in one yaw's horizontal field of view, for a
  // caller that looks at one yaw only.
  std::vector<int> visibleSlots(const Eigen::Vector3d& p_W, const VisibilityConfig& config,
                                const std::function<bool(const LandmarkVoxel&)>& keep = {}) const;
  // True if the first occupied voxel from p towards voxel `index` is that voxel.
  bool lineOfSight(const Eigen::Vector3d& p_W, int index) const;
  // The same by walking every voxel from p (lineOfSight first looks at the voxel the segment
  // enters the target from, which answers most blocked rays at once): the reference for tests.
  bool lineOfSightWalked(const Eigen::Vector3d& p_W, int index) const;
  // Whether p sees the face of voxel `index` that looks most toward it: the first occupied voxel
  // from p towards the centre of the voxel beyond that face (not occupied; the faces whose plane p
  // lies beyond, and whose voxel beyond is inside the box) is none. A landmark lies on its
  // surface's face, not at its voxel's centre: a segment to the centre of a wall's voxel seen
  // within about 45 deg of the wall's plane runs through the wall's next voxel first, and
  // lineOfSight() rates that landmark hidden by its own wall (VisibilityConfig::sight_to_face).
  bool lineOfSightToFace(const Eigen::Vector3d& p_W, int index) const;
  // lineOfSightToFace() where config.sight_to_face, else lineOfSight().
  bool sees(const Eigen::Vector3d& p_W, int index, const VisibilityConfig& config) const {
    return config.sight_to_face ? lineOfSightToFace(p_W, index) : lineOfSight(p_W, index);
  }

  // Distance from p to the nearest obstacle voxel's cube (0 inside one, outside the box or the
  // clearance band).
  double clearance(const Eigen::Vector3d& p_W) const;
  // The same, and its gradient (unit vector away from the nearest obstacle; zero where the
  // clearance is 0 or beyond the field's reach).
  double clearance(const Eigen::Vector3d& p_W, Eigen::Vector3d* gradient) const;
  // Every point of the segment keeps `clearance_m` (rigorous: sampled densely enough that
  // the 1-Lipschitz clearance cannot dip between samples).
  bool segmentClear(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double clearance_m) const;
  // The nearest point to p at p's height, at most `max_distance_m` from it, whose clearance() is at
  // least `clearance_m`: p itself if it has it, else the clearest of 64 directions on the nearest
  // ring (rings a quarter voxel apart) that has one (the first from +x counter-clockwise on ties).
  // nullopt if none does. Where a vehicle that flew too close to an obstacle can plan from.
  std::optional<Eigen::Vector3d> nearestClear(const Eigen::Vector3d& p_W, double clearance_m,
                                              double max_distance_m) const;
  // How much more than `clearance_m` segmentClear may ask of a point (its samples' half spacing):
  // paths planned on a slice keep this margin (TopoPlannerConfig::path_margin_m) so that the
  // check passes them.
  double segmentCheckMargin() const { return 0.25 * res_; }

  // 2D grid at the map's resolution over the box: a cell is blocked when any voxel of its
  // column in [z_lo, z_hi] is occupied or unknown (the flight-height band, like sliceOccupancy).
  OccupancyGrid2D slice(double z_lo, double z_hi) const;

 private:
  int flat(int x, int y, int z) const { return (z * size_.y() + y) * size_.x() + x; }
  Eigen::Vector3i cellOfIndex(int index) const {  // flat()'s inverse
    return {index % size_.x(), (index / size_.x()) % size_.y(), index / (size_.x() * size_.y())};
  }
  Eigen::Vector3i cellOf(const Eigen::Vector3d& p_W) const;
  bool inside(const Eigen::Vector3i& c) const { return (c.array() >= 0).all() && (c.array() < size_.array()).all(); }
  Eigen::Vector3d centreOf(int index) const;
  Eigen::Vector3d surfaceNormal(int index) const;
  double centreDistance(const Eigen::Vector3i& c) const;
  void computeDistanceField();

  double res_ = 0.1;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  Eigen::Vector3i size_ = Eigen::Vector3i::Zero();
  std::vector<VoxelState> state_;
  std::vector<bool> observed_;  // per voxel: a leaf of the octree covers it
  // Distance field over voxel layers [edt_z0_, edt_z0_ + edt_nz_), padded by one voxel on every
  // side (obstacles where the padding lies outside the box, free where it is only outside the band).
  int edt_z0_ = 0;
  int edt_nz_ = 0;
  int clear_z0_ = 0;  // voxel layers where clearance() answers
  int clear_z1_ = 0;
  std::size_t padded(const Eigen::Vector3i& c) const {
    return (static_cast<std::size_t>(c.z() - edt_z0_ + 1) * (size_.y() + 2) + c.y() + 1) * (size_.x() + 2) + c.x() + 1;
  }
  std::vector<float> dist2_;  // squared distance in voxels from each centre to the nearest obstacle centre
  std::vector<int> site_;     // that obstacle voxel (padded flat index; -1: none within the band)
  std::vector<LandmarkVoxel> landmark_voxels_;
  std::vector<int> landmark_slot_;
  std::vector<double> detectability_;
};

}  // namespace tgnav::planner
