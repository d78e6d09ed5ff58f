#pragma once
// Path segment extraction (paper Sec. V-C). With V(p) the landmarks a camera at p could see
// (range, vertical FoV, occlusion; any yaw):
//   CV(p, q) = V(p) ∩ V(q)                      (eq. 1, co-visible candidate set)
//   CR(p, q) = |CV(p, q)| / |V(p) ∪ V(q)|       (eq. 2, co-visibility ratio)
// A path is split at its arclength midpoint, recursively, until every segment's end points
// have CR >= eta or the segment is no longer than l_min. Each segment keeps CV of its end points:
// the pose graph reads the landmarks of its nodes from it instead of casting rays again.
//
// V(p) may be given as landmark ids, or as landmark voxels (VoxelMap::visibleSlots) with each
// voxel weighted by its number of landmarks: V(p) in ids is the union of whole voxels' ids, so
// the weighted counts are the same integers and CR the same number, without sorting ids.
//
// When neither end sees anything (V(p) ∪ V(q) empty) CR is taken as 0: blind ends say nothing
// about what lies between them, so the segment is split further (the paper leaves 0/0 open).
#include <Eigen/Core>
#include <functional>
#include <vector>

namespace tgnav::planner {

struct SegmentConfig {
  double min_length_m = 0.5;        // l_min (Table I)
  double covisibility_ratio = 0.5;  // eta (Table I)

  // Names every field once, for the harness's config files (a(key, field); harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a("min_length_m", min_length_m);
    a("covisibility_ratio", covisibility_ratio);
  }

  void validate() const;
};

struct PathSegment {
  double s_begin_m = 0.0;  // arclength along the path
  double s_end_m = 0.0;
  Eigen::Vector3d p_begin = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_end = Eigen::Vector3d::Zero();
  std::vector<int> covisible;   // CV(p_begin, p_end): ascending keys of the query (ids or voxel slots)
  int covisible_landmarks = 0;  // |CV(p_begin, p_end)| in landmarks
  double ratio = 0.0;           // CR(p_begin, p_end)
};

// V(p) as ascending keys.
using VisibilityQuery = std::function<std::vector<int>(const Eigen::Vector3d&)>;
// The number of landmarks a key stands for (its voxel's, for a voxel slot).
using KeyWeight = std::function<int(int)>;

// CR of two sorted key sets, each key counted `weight(key)` times (once without a weight); also
// returns their intersection, and its weighted size in `common` when given.
double covisibilityRatio(const std::vector<int>& a, const std::vector<int>& b, std::vector<int>* intersection,
                         const KeyWeight& weight = {}, int* common = nullptr);

// Point at arclength s of a polyline (clamped to its ends).
Eigen::Vector3d pointAt(const std::vector<Eigen::Vector3d>& path, double s);
double polylineLength3(const std::vector<Eigen::Vector3d>& path);

// Segments in path order covering [0, length]. `visible` answers V(p), as keys weighted by
// `weight` (ids when none); it is called once per distinct split point. A path of zero length is
// one segment.
std::vector<PathSegment> extractSegments(const std::vector<Eigen::Vector3d>& path, const SegmentConfig& config,
                                         const VisibilityQuery& visible, int* queries = nullptr,
                                         const KeyWeight& weight = {});

}  // namespace tgnav::planner
