#pragma once
// Exact signed distances to a scene's static geometry: boxes, planes and spheres exactly, other
// primitives through their bounding sphere (conservative outside). Used to plan the mapping
// run through free space and, in tests, as ground truth for the map built from images.
#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <vector>

namespace tgnav::harness {

class SceneGeometry {
 public:
  // Takes every geom of `d`'s current state that does not move with a joint (the vehicle's
  // geoms are excluded). `d` must have had mj_forward.
  SceneGeometry(const mjModel* m, const mjData* d);

  // Negative inside geometry.
  double signedDistance(const Eigen::Vector3d& p_W) const;
  // Distance to the nearest surface (|signed distance| of the nearest geom).
  double distanceToSurface(const Eigen::Vector3d& p_W) const;
  std::size_t size() const { return shapes_.size(); }

 private:
  struct Shape {
    int type = 0;
    Eigen::Isometry3d X_WG = Eigen::Isometry3d::Identity();
    Eigen::Vector3d size = Eigen::Vector3d::Zero();
    double rbound = 0.0;
  };
  static double shapeDistance(const Shape& s, const Eigen::Vector3d& p_W);
  std::vector<Shape> shapes_;
};

struct SceneConfig;

// InputError naming the scene file, the key and the value if the start or the goal lies within
// `clearance_m` of the scene's geometry (inside an obstacle, or touching one).
void checkStartGoalFree(const SceneConfig& scene, const SceneGeometry& geometry, double clearance_m);

}  // namespace tgnav::harness
