#include "harness/run/unseen_prior.h"

#include <octomap/OcTree.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "harness/run/incremental_map.h"

namespace tgnav::harness {

namespace {

enum : std::uint8_t { kPriorUnknown = 0, kPriorFree = 1, kPriorOccupied = 2 };

// The box's voxels (the octree's own, by key), each unknown, free or occupied.
class BoxStates {
 public:
  BoxStates(const octomap::OcTree& tree, const Eigen::Vector3d& min_W, const Eigen::Vector3d& max_W) {
    const double res = tree.getResolution();
    const octomap::OcTreeKey lo = tree.coordToKey(min_W.x(), min_W.y(), min_W.z());
    const octomap::OcTreeKey hi = tree.coordToKey(max_W.x(), max_W.y(), max_W.z());
    for (int k = 0; k < 3; ++k) {
      lo_[k] = lo[k];
      n_[k] = std::max(0, static_cast<int>(hi[k]) - static_cast<int>(lo[k]) + 1);
    }
    state_.assign(static_cast<std::size_t>(n_[0]) * n_[1] * n_[2], kPriorUnknown);
    if (state_.empty()) return;
    const octomap::point3d bmin(static_cast<float>(min_W.x()), static_cast<float>(min_W.y()),
                                static_cast<float>(min_W.z()));
    const octomap::point3d bmax(static_cast<float>(max_W.x()), static_cast<float>(max_W.y()),
                                static_cast<float>(max_W.z()));
    for (auto it = tree.begin_leafs_bbx(bmin, bmax); it != tree.end_leafs_bbx(); ++it) {
      const std::uint8_t s = tree.isNodeOccupied(*it) ? kPriorOccupied : kPriorFree;
      forEachVoxel(it, res, [&](const Eigen::Vector3d& c) {
        const int i = index(tree.coordToKey(c.x(), c.y(), c.z()));
        if (i >= 0) state_[static_cast<std::size_t>(i)] = s;
      });
    }
  }

  int size() const { return static_cast<int>(state_.size()); }
  std::uint8_t at(int i) const { return state_[static_cast<std::size_t>(i)]; }
  // Flat index of a key, -1 outside the box.
  int index(const octomap::OcTreeKey& key) const {
    std::array<int, 3> c{};
    for (int k = 0; k < 3; ++k) {
      c[k] = static_cast<int>(key[k]) - lo_[k];
      if (c[k] < 0 || c[k] >= n_[k]) return -1;
    }
    return c[0] + n_[0] * (c[1] + n_[1] * c[2]);
  }
  octomap::OcTreeKey key(int i) const {
    const int x = i % n_[0];
    const int y = (i / n_[0]) % n_[1];
    const int z = i / (n_[0] * n_[1]);
    return octomap::OcTreeKey(static_cast<octomap::key_type>(lo_[0] + x), static_cast<octomap::key_type>(lo_[1] + y),
                              static_cast<octomap::key_type>(lo_[2] + z));
  }
  // True when one of voxel i's six face neighbours inside the box is free.
  bool bordersFree(int i) const {
    const int x = i % n_[0];
    const int y = (i / n_[0]) % n_[1];
    const int z = i / (n_[0] * n_[1]);
    const int sy = n_[0];
    const int sz = n_[0] * n_[1];
    return (x > 0 && at(i - 1) == kPriorFree) || (x + 1 < n_[0] && at(i + 1) == kPriorFree) ||
           (y > 0 && at(i - sy) == kPriorFree) || (y + 1 < n_[1] && at(i + sy) == kPriorFree) ||
           (z > 0 && at(i - sz) == kPriorFree) || (z + 1 < n_[2] && at(i + sz) == kPriorFree);
  }

 private:
  std::array<int, 3> lo_{};
  std::array<int, 3> n_{};
  std::vector<std::uint8_t> state_;
};

}  // namespace

UnseenPriorStats addUnseenPrior(planner::FeatureMap* map, const Eigen::Vector3d& min_W, const Eigen::Vector3d& max_W) {
  UnseenPriorStats out;
  const octomap::OcTree& tree = map->occupancy();
  const BoxStates box(tree, min_W, max_W);
  std::vector<int> frontier;
  for (int i = 0; i < box.size(); ++i) {
    if (!box.bordersFree(i)) continue;
    if (box.at(i) == kPriorOccupied) ++out.surface_voxels;
    if (box.at(i) == kPriorUnknown) frontier.push_back(i);
  }
  out.frontier_voxels = static_cast<int>(frontier.size());
  double detectability = 0.0;
  for (int id = 0; id < static_cast<int>(map->landmarks().size()); ++id) {
    const Eigen::Vector3d v = map->landmarkVoxel(id);
    if (box.index(tree.coordToKey(v.x(), v.y(), v.z())) < 0) continue;
    ++out.surface_landmarks;
    detectability += map->landmarks()[static_cast<std::size_t>(id)].detectability();
  }
  if (out.surface_voxels == 0 || out.surface_landmarks == 0) return out;
  out.density = static_cast<double>(out.surface_landmarks) / out.surface_voxels;
  out.detectability = detectability / out.surface_landmarks;

  // Each prior landmark is detected as often as the seen ones on average.
  constexpr int kChances = 1000;
  planner::Landmark prior;
  prior.opportunities = kChances;
  prior.observations = std::max(1, static_cast<int>(std::lround(out.detectability * kChances)));
  // The density spread evenly: each frontier voxel takes what the running sum has reached.
  std::vector<planner::Landmark> landmarks;
  double owed = 0.0;
  for (int i : frontier) {
    owed += out.density;
    const int n = static_cast<int>(std::floor(owed));
    owed -= n;
    if (n == 0) continue;
    const octomap::point3d c = tree.keyToCoord(box.key(i));
    prior.p_W = Eigen::Vector3d(c.x(), c.y(), c.z());
    prior.ref_kf_p_W = prior.p_W;
    landmarks.insert(landmarks.end(), static_cast<std::size_t>(n), prior);
  }
  out.added = static_cast<int>(landmarks.size());
  map->addPlacedLandmarks(landmarks);
  return out;
}

}  // namespace tgnav::harness
