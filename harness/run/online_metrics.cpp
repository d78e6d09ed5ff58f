#include "harness/run/online_metrics.h"

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

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
  // The centres in the bounds (as mapCoverage steps them), and one more on each side: the scene's
  // outer walls lie just outside its free-space bounds.
  const auto centres = [res](double lo, double hi) {
    std::vector<double> c{lo + 0.5 * res - res};
    for (double v = lo + 0.5 * res; v < hi; v += res) c.push_back(v);
    c.push_back(c.back() + res);
    return c;
  };
  const std::vector<double> xs = centres(scene.bounds_min_m.x(), scene.bounds_max_m.x());
  const std::vector<double> ys = centres(scene.bounds_min_m.y(), scene.bounds_max_m.y());
  const int nx = static_cast<int>(xs.size());
  const int ny = static_cast<int>(ys.size());
  MapHoles out;
  // Per centre of a layer, computed when first asked: the map's state, and whether it lies inside
  // the true geometry. The geometry is asked only next to what the map knows: that is most of the
  // cost.
  enum : std::uint8_t { kNotYet, kUnknown, kFree, kOccupied, kOutside, kInside };
  std::vector<std::uint8_t> state(static_cast<std::size_t>(nx) * ny);
  std::vector<std::uint8_t> inside(state.size());
  const auto at = [nx](int i, int j) { return static_cast<std::size_t>(j) * nx + i; };
  for (double z = band.lo_m + 0.5 * res; z < band.hi_m; z += res) {
    std::fill(state.begin(), state.end(), kNotYet);
    std::fill(inside.begin(), inside.end(), kNotYet);
    const auto stateOf = [&](int i, int j) {
      std::uint8_t& s = state[at(i, j)];
      if (s == kNotYet) {
        const octomap::OcTreeNode* n = tree.search(xs[i], ys[j], z);
        s = n == nullptr ? kUnknown : tree.isNodeOccupied(n) ? kOccupied : kFree;
      }
      return s;
    };
    const auto insideOf = [&](int i, int j) {
      std::uint8_t& s = inside[at(i, j)];
      if (s == kNotYet) s = truth.signedDistance(Eigen::Vector3d(xs[i], ys[j], z)) <= 0.0 ? kInside : kOutside;
      return s == kInside;
    };
    for (int j = 1; j + 1 < ny; ++j) {
      for (int i = 1; i + 1 < nx; ++i) {
        const std::uint8_t sc = stateOf(i, j);
        for (const auto& [di, dj] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
          const std::uint8_t sn = stateOf(i + di, j + dj);
          if ((sc == kUnknown && sn == kUnknown) || insideOf(i, j) || !insideOf(i + di, j + dj)) continue;
          ++out.crossings;
          out.holes += sn == kFree && sc != kOccupied ? 1 : 0;
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
