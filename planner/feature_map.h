#pragma once
// Occlusion-aware feature map (paper Sec. IV): a volumetric occupancy map (OctoMap) with the
// SLAM landmarks embedded in its surface voxels, so that the planner can ask which landmarks a
// camera at a given pose would see, occlusion included.
#include <octomap/OcTree.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <unordered_map>
#include <vector>

namespace tgnav::planner {

// An Eigen point as OctoMap's (single precision).
inline octomap::point3d toOcto(const Eigen::Vector3d& p) {
  return octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
}

struct Landmark {
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();  // mean of its observations
  int observations = 1;
  // Survey frames that had it in view (in the image, in range, not occluded): its detections
  // are observations out of that many chances. 0: unknown (a map from before it was counted).
  int opportunities = 0;
  Eigen::Vector3d ref_kf_p_W = Eigen::Vector3d::Zero();  // camera position that first saw it
  std::array<std::uint8_t, 32> descriptor{};             // ORB, from the reference observation

  // The chance that a frame with it in view detects it again: observations / opportunities,
  // measured over the survey (1 where the opportunities are unknown). Views from other distances
  // and angles, and the detector's per-frame budget, miss most landmarks most of the time: the
  // generated scenes' maps average 0.06-0.09 on every texture level.
  double detectability() const {
    return opportunities > 0 ? std::min(1.0, static_cast<double>(observations) / opportunities) : 1.0;
  }
};

// Sensing model of the query (V(p) uses range and vertical FoV; yaw filters by horizontal FoV).
struct VisibilityConfig {
  double hfov_rad = 1.3125;  // 75.2 deg: fovy 60 deg at 4:3
  double vfov_rad = 1.0472;  // 60 deg
  double min_range_m = 0.3;
  // 10 m: the VO's depth range (vo.max_depth_m); the learned model's features are counted to it
  double max_range_m = 10.0;
  // Where the camera sits on the vehicle, in the body frame: this far ahead along the heading and
  // above the body's centre. The planner's poses are the body's; a view is scored from the camera
  // (cameraPosition()). 0: from the body's centre, as the paper.
  double camera_forward_m = 0.0;
  double camera_up_m = 0.0;
  // How a landmark's voxel is seen (ours). false, the paper's occlusion test: the segment from the
  // camera to the voxel's centre meets no occupied voxel before it. true: the segment to the free
  // voxel in front of the voxel's face toward the camera meets none (VoxelMap::lineOfSightToFace):
  // the landmark lies on that face, and the first test hides a wall's landmarks seen within about
  // 45 deg of the wall's plane behind the wall's own next voxel.
  bool sight_to_face = false;

  // Names every field once, for the harness's config files (a(key, field); harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a("hfov_rad", hfov_rad);
    a("vfov_rad", vfov_rad);
    a("min_range_m", min_range_m);
    a("max_range_m", max_range_m);
    a("camera_forward_m", camera_forward_m);
    a("camera_up_m", camera_up_m);
    a("sight_to_face", sight_to_face);
  }

  void validate() const;
};

class FeatureMap {
 public:
  explicit FeatureMap(double resolution_m);
  // Takes an occupancy map as it is (no landmarks yet).
  explicit FeatureMap(std::unique_ptr<octomap::OcTree> occupancy);

  octomap::OcTree& occupancy() { return *tree_; }
  const octomap::OcTree& occupancy() const { return *tree_; }
  double resolution() const { return tree_->getResolution(); }
  // Occupied per the map (unknown counts as not occupied).
  bool isOccupied(const Eigen::Vector3d& p_W) const;
  // Known (observed) at all.
  bool isKnown(const Eigen::Vector3d& p_W) const;

  // Adds landmarks; call embedLandmarks() once all are in.
  void setLandmarks(std::vector<Landmark> landmarks);
  const std::vector<Landmark>& landmarks() const { return landmarks_; }

  // Embeds every landmark in the surface voxel its reference keyframe sees it on: the first
  // occupied voxel on the ray from the keyframe towards the landmark, if that voxel lies
  // within `max_shift_m` of it. Landmarks without such a voxel (seen through free space, or
  // occluded from their own keyframe) are dropped. Returns how many were dropped.
  int embedLandmarks(double max_shift_m);
  // Appends landmarks already placed: each in the voxel holding its p_W, without a ray from a
  // keyframe (after embedLandmarks(); e.g. an online trial's prior for unseen surfaces, which lie
  // in voxels not observed occupied: visibleFrom() never finds those, VoxelMap does).
  void addPlacedLandmarks(const std::vector<Landmark>& landmarks);
  // Voxel centre each landmark is embedded in (after embedLandmarks()).
  Eigen::Vector3d landmarkVoxel(int id) const;

  // V(p): ids of the landmarks within range and the vertical FoV of a camera at p (any yaw)
  // whose surface voxel is the first occupied voxel on the line of sight. Sorted ascending.
  std::vector<int> visibleFrom(const Eigen::Vector3d& p_W, const VisibilityConfig& config) const;
  // The subset of `candidates` inside the horizontal FoV of a camera at p with yaw `yaw_rad`.
  std::vector<int> inHorizontalFov(const Eigen::Vector3d& p_W, double yaw_rad, const std::vector<int>& candidates,
                                   const VisibilityConfig& config) const;

  // map.bt (OctoMap binary) and landmarks.csv in `dir`; load() throws std::runtime_error naming
  // the file on malformed input. load() also reads landmarks.csv without the opportunities
  // column (maps saved before it: every landmark's detectability is then 1).
  void save(const std::filesystem::path& dir) const;
  static FeatureMap load(const std::filesystem::path& dir);

 private:
  std::unique_ptr<octomap::OcTree> tree_;
  std::vector<Landmark> landmarks_;
  std::vector<octomap::OcTreeKey> landmark_key_;
  // Embedded landmarks grouped by voxel: one ray per voxel answers for all of them.
  std::unordered_map<octomap::OcTreeKey, std::vector<int>, octomap::OcTreeKey::KeyHash> by_voxel_;
};

// 2D occupancy slice of the map over [min_xy, max_xy] for heights [z_lo, z_hi] (the flight
// height band): a cell is free when every voxel of its column in the band was observed free;
// anything occupied or never observed (box interiors, missed patches of a crate's top) blocks it.
struct OccupancyGrid2D;
OccupancyGrid2D sliceOccupancy(const FeatureMap& map, const Eigen::Vector2d& min_xy, const Eigen::Vector2d& max_xy,
                               double z_lo, double z_hi, double resolution_m);

// Number of differing bits between two ORB descriptors.
int hammingDistance(const std::array<std::uint8_t, 32>& a, const std::array<std::uint8_t, 32>& b);

}  // namespace tgnav::planner
