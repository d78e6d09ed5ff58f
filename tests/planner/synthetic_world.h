#pragma once
// Synthetic feature maps for planner tests: a box of observed free space with solid boxes in it
// and landmarks on chosen faces, built directly into an OctoMap (no rendering).
#include <Eigen/Geometry>
#include <vector>

#include "planner/feature_map.h"

namespace tgnav::planner::testing {

struct SyntheticWorld {
  Eigen::Vector3d min_W{0.0, 0.0, 0.0};
  Eigen::Vector3d max_W{10.0, 10.0, 2.0};
  double resolution_m = 0.1;
  std::vector<Eigen::AlignedBox3d> solids;
  std::vector<Landmark> landmarks;

  // Landmarks on the face of `solid` whose outward normal is `normal` (an axis, e.g. (0, -1, 0)),
  // on a grid `spacing_m` apart, each seen from 1 m in front of the face.
  void texture(const Eigen::AlignedBox3d& solid, const Eigen::Vector3d& normal, double spacing_m) {
    int axis = 0;
    normal.cwiseAbs().maxCoeff(&axis);
    const int u = (axis + 1) % 3;
    const int v = (axis + 2) % 3;
    const double plane = normal[axis] > 0 ? solid.max()[axis] : solid.min()[axis];
    for (double a = solid.min()[u] + 0.5 * spacing_m; a < solid.max()[u]; a += spacing_m) {
      for (double b = solid.min()[v] + 0.5 * spacing_m; b < solid.max()[v]; b += spacing_m) {
        Landmark lm;
        lm.p_W[axis] = plane;
        lm.p_W[u] = a;
        lm.p_W[v] = b;
        lm.ref_kf_p_W = lm.p_W + normal.normalized();
        lm.descriptor[0] = static_cast<std::uint8_t>(landmarks.size());
        landmarks.push_back(lm);
      }
    }
  }

  // Every voxel of [min_W, max_W] is observed: occupied inside a solid, free elsewhere.
  FeatureMap build() const {
    FeatureMap map(resolution_m);
    octomap::OcTree& tree = map.occupancy();
    const double h = 0.5 * resolution_m;
    for (double z = min_W.z() + h; z < max_W.z(); z += resolution_m) {
      for (double y = min_W.y() + h; y < max_W.y(); y += resolution_m) {
        for (double x = min_W.x() + h; x < max_W.x(); x += resolution_m) {
          const Eigen::Vector3d p(x, y, z);
          bool solid = false;
          for (const auto& box : solids) solid = solid || box.contains(p);
          tree.updateNode(octomap::point3d(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)), solid,
                          /*lazy_eval=*/true);
        }
      }
    }
    tree.updateInnerOccupancy();
    map.setLandmarks(landmarks);
    map.embedLandmarks(0.15);
    return map;
  }
};

}  // namespace tgnav::planner::testing
