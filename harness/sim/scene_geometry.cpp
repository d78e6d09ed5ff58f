#include "harness/sim/scene_geometry.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <sstream>

#include "harness/base/errors.h"
#include "harness/config/scene_config.h"

namespace tgnav::harness {

SceneGeometry::SceneGeometry(const mjModel* m, const mjData* d) {
  for (int g = 0; g < m->ngeom; ++g) {
    // Static: the geom's body and all its ancestors have no joints.
    bool moves = false;
    for (int b = m->geom_bodyid[g]; b > 0; b = m->body_parentid[b]) moves = moves || m->body_jntnum[b] > 0;
    if (moves) continue;
    Shape s;
    s.type = m->geom_type[g];
    Eigen::Matrix3d R;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) R(r, c) = d->geom_xmat[9 * g + 3 * r + c];
    }
    s.X_WG.linear() = R;
    s.X_WG.translation() = Eigen::Vector3d(d->geom_xpos + 3 * static_cast<std::ptrdiff_t>(g));
    s.size = Eigen::Vector3d(m->geom_size + 3 * static_cast<std::ptrdiff_t>(g));
    s.rbound = m->geom_rbound[g];
    shapes_.push_back(s);
  }
}

double SceneGeometry::shapeDistance(const Shape& s, const Eigen::Vector3d& p_W) {
  const Eigen::Vector3d p = s.X_WG.inverse() * p_W;
  switch (s.type) {
    case mjGEOM_PLANE:
      return p.z();  // infinite half-space below the plane
    case mjGEOM_SPHERE:
      return p.norm() - s.size.x();
    case mjGEOM_BOX: {
      const Eigen::Vector3d q = p.cwiseAbs() - s.size;
      return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
    }
    default:
      return p.norm() - s.rbound;
  }
}

double SceneGeometry::signedDistance(const Eigen::Vector3d& p_W) const {
  double best = std::numeric_limits<double>::infinity();
  for (const Shape& s : shapes_) best = std::min(best, shapeDistance(s, p_W));
  return best;
}

double SceneGeometry::distanceToSurface(const Eigen::Vector3d& p_W) const {
  double best = std::numeric_limits<double>::infinity();
  for (const Shape& s : shapes_) best = std::min(best, std::abs(shapeDistance(s, p_W)));
  return best;
}

void checkStartGoalFree(const SceneConfig& scene, const SceneGeometry& geometry, double clearance_m) {
  for (const auto& [key, pose] : {std::pair<const char*, planner::Pose4>{"start", scene.start}, {"goal", scene.goal}}) {
    const double sd = geometry.signedDistance(pose.p_WB);
    if (sd < clearance_m) {
      std::ostringstream msg;
      msg << scene.source.string() << ": key '" << key << "' = [" << pose.p_WB.x() << ", " << pose.p_WB.y() << ", "
          << pose.p_WB.z() << "] is " << (sd < 0 ? "inside an obstacle" : "too close to an obstacle") << " (" << sd
          << " m from the geometry, need " << clearance_m << " m)";
      throw InputError(msg.str());
    }
  }
}

}  // namespace tgnav::harness
