#include "harness/run/online_metrics.h"

#include <algorithm>

#include "harness/run/incremental_map.h"
#include "harness/run/plan_run.h"
#include "harness/sim/scene_geometry.h"

namespace tgnav::harness {

double mapCoverage(const octomap::OcTree& tree, const Scenario& scenario) {
  const double res = tree.getResolution();
  const SceneConfig& scene = scenario.scene;
  const ClearanceBand band = clearanceBand(scenario);
  long known = 0;
  long total = 0;
  for (double z = band.lo_m + 0.5 * res; z < band.hi_m; z += res) {
    for (double y = scene.bounds_min_m.y() + 0.5 * res; y < scene.bounds_max_m.y(); y += res) {
      for (double x = scene.bounds_min_m.x() + 0.5 * res; x < scene.bounds_max_m.x(); x += res) {
        ++total;
        known += tree.search(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)) != nullptr ? 1 : 0;
      }
    }
  }
  return total > 0 ? static_cast<double>(known) / static_cast<double>(total) : 0.0;
}

MapError mapError(const octomap::OcTree& tree, const SceneConfig& scene, const SceneGeometry& truth) {
  const double res = tree.getResolution();
  const Eigen::Vector3d lo = scene.bounds_min_m - Eigen::Vector3d::Constant(kPlanningBoxMargin_m);
  const Eigen::Vector3d hi = scene.bounds_max_m + Eigen::Vector3d::Constant(kPlanningBoxMargin_m);
  double sum = 0.0;
  long far = 0;
  long n = 0;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    forEachVoxel(it, res, [&](const Eigen::Vector3d& p) {
      if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) return;
      const double d = std::max(0.0, truth.signedDistance(p));
      sum += d;
      far += d > 2.0 * res ? 1 : 0;
      ++n;
    });
  }
  MapError e;
  e.occupied_voxels = static_cast<int>(n);
  e.mean_m = n > 0 ? sum / static_cast<double>(n) : 0.0;
  e.far_share = n > 0 ? static_cast<double>(far) / static_cast<double>(n) : 0.0;
  return e;
}

MapHoles mapHoles(const octomap::OcTree& tree, const Scenario& scenario, const SceneGeometry& truth) {
  const double res = tree.getResolution();
  const SceneConfig& scene = scenario.scene;
  const ClearanceBand band = clearanceBand(scenario);
  // -1 unknown, 0 free, 1 occupied.
  const auto state = [&](const Eigen::Vector3d& p) {
    const octomap::OcTreeNode* n = tree.search(p.x(), p.y(), p.z());
    return n == nullptr ? -1 : tree.isNodeOccupied(n) ? 1 : 0;
  };
  MapHoles out;
  for (double z = band.lo_m + 0.5 * res; z < band.hi_m; z += res) {
    for (double y = scene.bounds_min_m.y() + 0.5 * res; y < scene.bounds_max_m.y(); y += res) {
      for (double x = scene.bounds_min_m.x() + 0.5 * res; x < scene.bounds_max_m.x(); x += res) {
        const Eigen::Vector3d c(x, y, z);
        if (truth.signedDistance(c) <= 0.0) continue;
        for (const Eigen::Vector3d& step : {Eigen::Vector3d(res, 0, 0), Eigen::Vector3d(-res, 0, 0),
                                            Eigen::Vector3d(0, res, 0), Eigen::Vector3d(0, -res, 0)}) {
          const Eigen::Vector3d n = c + step;
          if (truth.signedDistance(n) > 0.0) continue;
          const int sc = state(c);
          const int sn = state(n);
          if (sc < 0 && sn < 0) continue;
          ++out.crossings;
          out.holes += sn == 0 && sc != 1 ? 1 : 0;
        }
      }
    }
  }
  return out;
}

namespace {

// The plan in effect at time t: the last that took effect by then (the first before any).
const OnlinePlan* planAt(const std::vector<OnlinePlan>& plans, double t_s) {
  const OnlinePlan* in_effect = nullptr;
  for (const OnlinePlan& p : plans) {
    if (!p.adopted) continue;
    if (in_effect == nullptr || p.effective_s <= t_s) in_effect = &p;
  }
  return in_effect;
}

}  // namespace

double unknownShare(const std::vector<OnlinePlan>& plans,
                    const std::vector<std::pair<double, Eigen::Vector3d>>& flown) {
  long unknown = 0;
  for (const auto& [t, p] : flown) {
    const OnlinePlan* plan = planAt(plans, t);
    if (plan == nullptr || plan->path.empty()) continue;
    std::size_t best = 0;
    for (std::size_t i = 1; i < plan->path.size(); ++i) {
      if ((plan->path[i] - p).squaredNorm() < (plan->path[best] - p).squaredNorm()) best = i;
    }
    unknown += plan->path_unknown[best] ? 1 : 0;
  }
  return flown.empty() ? 0.0 : static_cast<double>(unknown) / static_cast<double>(flown.size());
}

}  // namespace tgnav::harness
