#include "planner/voxel_map.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "planner/edt.h"

namespace tgnav::planner {

namespace {
constexpr double kFar = 1e20;
// lineOfSight's shortcut: the second largest component of the ray at most this share of the
// largest. The segment then enters the target's face at least 0.5 * (1 - kClearLead) voxel from
// its edges, far beyond rounding.
constexpr double kClearLead = 1.0 - 1e-6;
}  // namespace

VoxelMap::VoxelMap(const FeatureMap& map, const Eigen::Vector3d& min_W, const Eigen::Vector3d& max_W,
                   double clearance_z_lo_m, double clearance_z_hi_m, bool unknown_free)
    : res_(map.resolution()) {
  const Eigen::Vector3d lo = (min_W / res_).array().floor();
  const Eigen::Vector3d hi = (max_W / res_).array().ceil();
  origin_ = lo * res_;
  size_ = (hi - lo).cast<int>().cwiseMax(1);
  state_.assign(static_cast<std::size_t>(size_.prod()), unknown_free ? VoxelState::kFree : VoxelState::kUnknown);
  observed_.assign(state_.size(), false);

  const octomap::OcTree& tree = map.occupancy();
  const octomap::point3d bmin(static_cast<float>(origin_.x()), static_cast<float>(origin_.y()),
                              static_cast<float>(origin_.z()));
  const Eigen::Vector3d top = origin_ + size_.cast<double>() * res_;
  const octomap::point3d bmax(static_cast<float>(top.x()), static_cast<float>(top.y()), static_cast<float>(top.z()));
  for (auto it = tree.begin_leafs_bbx(bmin, bmax), end = tree.end_leafs_bbx(); it != end; ++it) {
    const VoxelState s = tree.isNodeOccupied(*it) ? VoxelState::kOccupied : VoxelState::kFree;
    const double half = 0.5 * it.getSize();
    const Eigen::Vector3d c(it.getX(), it.getY(), it.getZ());
    // Leaves may be merged cubes of many voxels: fill every voxel they cover inside the box.
    const Eigen::Vector3i a = cellOf(c - Eigen::Vector3d::Constant(half - 0.5 * res_)).cwiseMax(0);
    const Eigen::Vector3i b =
        cellOf(c + Eigen::Vector3d::Constant(half - 0.5 * res_)).cwiseMin(size_ - Eigen::Vector3i::Ones());
    for (int z = a.z(); z <= b.z(); ++z) {
      for (int y = a.y(); y <= b.y(); ++y) {
        for (int x = a.x(); x <= b.x(); ++x) {
          state_[static_cast<std::size_t>(flat(x, y, z))] = s;
          observed_[static_cast<std::size_t>(flat(x, y, z))] = true;
        }
      }
    }
  }

  std::map<int, std::vector<int>> by_voxel;
  for (int id = 0; id < static_cast<int>(map.landmarks().size()); ++id) {
    const Eigen::Vector3i c = cellOf(map.landmarkVoxel(id));
    if (inside(c)) by_voxel[flat(c.x(), c.y(), c.z())].push_back(id);
  }
  landmark_slot_.assign(map.landmarks().size(), -1);
  detectability_.reserve(map.landmarks().size());
  for (const Landmark& lm : map.landmarks()) detectability_.push_back(lm.detectability());
  for (auto& [index, ids] : by_voxel) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double detections = 0.0;
    for (int id : ids) {
      sum += map.landmarks()[static_cast<std::size_t>(id)].p_W;
      detections += detectability_[static_cast<std::size_t>(id)];
      landmark_slot_[static_cast<std::size_t>(id)] = static_cast<int>(landmark_voxels_.size());
    }
    const Eigen::Vector3d mean = sum / static_cast<double>(ids.size());
    landmark_voxels_.push_back({index, centreOf(index), mean, surfaceNormal(index), std::move(ids), detections});
  }
  auto layer = [&](double z) {
    return static_cast<int>(std::clamp(std::floor((z - origin_.z()) / res_), -1.0, static_cast<double>(size_.z())));
  };
  clear_z0_ = std::max(0, layer(clearance_z_lo_m));
  clear_z1_ = std::min(size_.z() - 1, layer(clearance_z_hi_m));
  const int reach = static_cast<int>(std::ceil(kClearanceReach_m / res_));
  edt_z0_ = std::max(0, clear_z0_ - reach);
  edt_nz_ = std::max(0, std::min(size_.z() - 1, clear_z1_ + reach) - edt_z0_ + 1);
  computeDistanceField();
}

Eigen::Vector3i VoxelMap::cellOf(const Eigen::Vector3d& p_W) const {
  return ((p_W - origin_) / res_).array().floor().cast<int>();
}

Eigen::Vector3d VoxelMap::centreOf(int index) const {
  return origin_ + res_ * (cellOfIndex(index).cast<double>() + Eigen::Vector3d::Constant(0.5));
}

VoxelState VoxelMap::state(const Eigen::Vector3d& p_W) const {
  const Eigen::Vector3i c = cellOf(p_W);
  return inside(c) ? state_[static_cast<std::size_t>(flat(c.x(), c.y(), c.z()))] : VoxelState::kUnknown;
}

bool VoxelMap::observed(const Eigen::Vector3d& p_W) const {
  const Eigen::Vector3i c = cellOf(p_W);
  return inside(c) && observed_[static_cast<std::size_t>(flat(c.x(), c.y(), c.z()))];
}

bool VoxelMap::lineOfSight(const Eigen::Vector3d& p_W, int index) const {
  // Most rays that fail end on the target's own solid: its surface seen from behind, or along the
  // surface. The segment ends at the target voxel's centre, so it enters that voxel through the
  // face across the axis along which it runs furthest; where that axis leads clearly (no tie that
  // the walk would break either way), the walk's voxel before the target is that face's neighbour,
  // and an occupied one blocks the view (as it does when p lies in it). Same answer as the walk.
  const Eigen::Vector3d d = centreOf(index) - p_W;
  const Eigen::Vector3d a = d.cwiseAbs();
  int axis = 0;
  const double lead = a.maxCoeff(&axis);
  const double second = std::max(a[(axis + 1) % 3], a[(axis + 2) % 3]);
  if (lead > res_ && second < kClearLead * lead) {  // p outside the target voxel, a clear lead
    Eigen::Vector3i before = cellOfIndex(index);
    before[axis] -= d[axis] > 0.0 ? 1 : -1;
    if (inside(before) &&
        state_[static_cast<std::size_t>(flat(before.x(), before.y(), before.z()))] == VoxelState::kOccupied) {
      return false;
    }
  }
  return lineOfSightWalked(p_W, index);
}

bool VoxelMap::lineOfSightWalked(const Eigen::Vector3d& p_W, int index) const {
  // Amanatides & Woo voxel traversal from p to the target voxel's centre.
  const Eigen::Vector3d target = centreOf(index);
  const Eigen::Vector3d start = (p_W - origin_) / res_;
  const Eigen::Vector3d dir = (target - p_W) / res_;
  Eigen::Vector3i c = start.array().floor().cast<int>();
  const Eigen::Vector3i goal = ((target - origin_) / res_).array().floor().cast<int>();
  Eigen::Vector3i step;
  Eigen::Vector3d t_max;
  Eigen::Vector3d t_delta;
  for (int k = 0; k < 3; ++k) {
    if (dir[k] > 0.0) {
      step[k] = 1;
      t_max[k] = (c[k] + 1 - start[k]) / dir[k];
      t_delta[k] = 1.0 / dir[k];
    } else if (dir[k] < 0.0) {
      step[k] = -1;
      t_max[k] = (c[k] - start[k]) / dir[k];
      t_delta[k] = -1.0 / dir[k];
    } else {
      step[k] = 0;
      t_max[k] = kFar;
      t_delta[k] = kFar;
    }
  }
  if (!inside(c)) return false;
  // Both ends are inside the (convex) box, so every voxel between them is: walk flat indices.
  // The axis and its parameters in scalars (same arithmetic, same order: the same voxels).
  const int stride_x = step[0];
  const int stride_y = step[1] * size_.x();
  const int stride_z = step[2] * size_.x() * size_.y();
  double tx = t_max[0];
  double ty = t_max[1];
  double tz = t_max[2];
  const double dx = t_delta[0];
  const double dy = t_delta[1];
  const double dz = t_delta[2];
  const VoxelState* state = state_.data();
  const int voxels = static_cast<int>(state_.size());
  int idx = flat(c.x(), c.y(), c.z());
  const int remaining = (goal - c).cwiseAbs().sum();
  for (int n = 0; n <= remaining; ++n) {
    if (idx == index) return true;
    if (state[idx] == VoxelState::kOccupied) return false;
    if (ty < tx) {
      if (tz < ty) {
        idx += stride_z;
        tz += dz;
      } else {
        idx += stride_y;
        ty += dy;
      }
    } else if (tz < tx) {
      idx += stride_z;
      tz += dz;
    } else {
      idx += stride_x;
      tx += dx;
    }
    if (idx < 0 || idx >= voxels) return false;
  }
  return false;  // numerical miss of the target voxel: treat as not seen
}

bool VoxelMap::lineOfSightToFace(const Eigen::Vector3d& p_W, int index) const {
  const Eigen::Vector3i c = cellOfIndex(index);
  const Eigen::Vector3d to_p = p_W - centreOf(index);
  int best = -1;
  double best_lead = 0.5 * res_;  // p beyond the face's plane
  for (int axis = 0; axis < 3; ++axis) {
    for (const int side : {-1, 1}) {
      const double lead = side * to_p[axis];
      if (lead <= best_lead) continue;
      Eigen::Vector3i n = c;
      n[axis] += side;
      if (!inside(n)) continue;
      const int beyond = flat(n.x(), n.y(), n.z());
      if (state_[static_cast<std::size_t>(beyond)] == VoxelState::kOccupied) continue;
      best = beyond;
      best_lead = lead;
    }
  }
  return best >= 0 && lineOfSight(p_W, best);
}

namespace {

// Calls visit(slot) for each landmark voxel within range and the vertical FoV of p that `keep`
// accepts (when given) and p sees, in slot order.
template <typename Visit>
void forVisibleVoxels(const VoxelMap& map, const Eigen::Vector3d& p_W, const VisibilityConfig& config,
                      const std::function<bool(const LandmarkVoxel&)>& keep, Visit&& visit) {
  const double tan_half_vfov = std::tan(0.5 * config.vfov_rad);
  const double min2 = config.min_range_m * config.min_range_m;
  const double max2 = config.max_range_m * config.max_range_m;
  const std::vector<LandmarkVoxel>& voxels = map.landmarkVoxels();
  for (std::size_t slot = 0; slot < voxels.size(); ++slot) {
    const LandmarkVoxel& v = voxels[slot];
    const Eigen::Vector3d d = v.centre_W - p_W;
    const double r2 = d.squaredNorm();
    if (r2 < min2 || r2 > max2) continue;
    if (std::abs(d.z()) > tan_half_vfov * d.head<2>().norm()) continue;
    if (keep && !keep(v)) continue;
    if (!map.sees(p_W, v.index, config)) continue;
    visit(slot);
  }
}

}  // namespace

std::vector<int> VoxelMap::visibleFrom(const Eigen::Vector3d& p_W, const VisibilityConfig& config) const {
  std::vector<int> visible;
  forVisibleVoxels(*this, p_W, config, {}, [&](std::size_t slot) {
    const std::vector<int>& ids = landmark_voxels_[slot].ids;
    visible.insert(visible.end(), ids.begin(), ids.end());
  });
  std::sort(visible.begin(), visible.end());
  return visible;
}

std::vector<int> VoxelMap::visibleSlots(const Eigen::Vector3d& p_W, const VisibilityConfig& config,
                                        const std::function<bool(const LandmarkVoxel&)>& keep) const {
  std::vector<int> slots;
  forVisibleVoxels(*this, p_W, config, keep, [&](std::size_t slot) { slots.push_back(static_cast<int>(slot)); });
  return slots;
}

void VoxelMap::computeDistanceField() {
  // Padded by one obstacle voxel on every side: outside the box counts as an obstacle.
  const int nx = size_.x() + 2;
  const int ny = size_.y() + 2;
  const int nz = edt_nz_ + 2;
  const std::size_t n = static_cast<std::size_t>(nx) * ny * nz;
  auto pidx = [&](int x, int y, int z) { return (static_cast<std::size_t>(z) * ny + y) * nx + x; };
  std::vector<double> f(n, kFar);
  std::vector<int> site(n, -1);
  for (int z = 0; z < nz; ++z) {
    for (int y = 0; y < ny; ++y) {
      for (int x = 0; x < nx; ++x) {
        const bool pad_xy = x == 0 || y == 0 || x == nx - 1 || y == ny - 1;
        const bool pad_z = z == 0 || z == nz - 1;
        const bool outside_box = pad_xy || (z == 0 && edt_z0_ == 0) || (z == nz - 1 && edt_z0_ + edt_nz_ == size_.z());
        if (pad_z && !outside_box) continue;  // beyond the band, not beyond the box: no obstacle known
        const bool blocked =
            outside_box || state_[static_cast<std::size_t>(flat(x - 1, y - 1, edt_z0_ + z - 1))] != VoxelState::kFree;
        if (blocked) {
          f[pidx(x, y, z)] = 0.0;
          site[pidx(x, y, z)] = static_cast<int>(pidx(x, y, z));
        }
      }
    }
  }
  // One envelope pass per axis; the site follows the minimising sample.
  EnvelopeScratch scratch;
  const int longest = std::max({nx, ny, nz});
  std::vector<double> line(longest), out(longest);
  std::vector<int> line_site(longest), arg(longest);
  auto pass = [&](int len, int lines, auto&& at) {
    for (int l = 0; l < lines; ++l) {
      for (int i = 0; i < len; ++i) {
        line[i] = f[at(l, i)];
        line_site[i] = site[at(l, i)];
      }
      lowerEnvelope(line.data(), len, out.data(), arg.data(), &scratch);
      for (int i = 0; i < len; ++i) {
        f[at(l, i)] = out[i];
        site[at(l, i)] = line_site[arg[i]];
      }
    }
  };
  pass(nx, ny * nz, [&](int l, int i) { return static_cast<std::size_t>(l) * nx + i; });
  pass(ny, nx * nz, [&](int l, int i) { return pidx(l % nx, i, l / nx); });
  pass(nz, nx * ny, [&](int l, int i) { return pidx(l % nx, l / nx, i); });
  dist2_.assign(f.begin(), f.end());
  site_ = std::move(site);
}

double VoxelMap::centreDistance(const Eigen::Vector3i& c) const {
  return std::sqrt(static_cast<double>(dist2_[padded(c)])) * res_;
}

Eigen::Vector3d VoxelMap::surfaceNormal(int index) const {
  const Eigen::Vector3i at = cellOfIndex(index);
  const int x = at.x();
  const int y = at.y();
  const int z = at.z();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int free = 0;
  for (int dz = -2; dz <= 2; ++dz) {
    for (int dy = -2; dy <= 2; ++dy) {
      for (int dx = -2; dx <= 2; ++dx) {
        const Eigen::Vector3i c(x + dx, y + dy, z + dz);
        if ((dx == 0 && dy == 0 && dz == 0) || !inside(c)) continue;
        if (state_[static_cast<std::size_t>(flat(c.x(), c.y(), c.z()))] != VoxelState::kFree) continue;
        sum += Eigen::Vector3d(dx, dy, dz).normalized();
        ++free;
      }
    }
  }
  // Free space on one side only: the mean direction is long (about 0.5 for a flat wall).
  if (free == 0 || sum.norm() < 0.25 * free) return Eigen::Vector3d::Zero();
  return sum.normalized();
}

double VoxelMap::clearance(const Eigen::Vector3d& p_W) const { return clearance(p_W, nullptr); }

double VoxelMap::clearance(const Eigen::Vector3d& p_W, Eigen::Vector3d* gradient) const {
  if (gradient) gradient->setZero();
  const Eigen::Vector3i c = cellOf(p_W);
  if (!inside(c) || c.z() < clear_z0_ || c.z() > clear_z1_ ||
      state_[static_cast<std::size_t>(flat(c.x(), c.y(), c.z()))] != VoxelState::kFree) {
    return 0.0;
  }
  // The nearest obstacle voxel of p is the nearest one of its own voxel or of a neighbour (the
  // feature transform is exact at centres); measure to that voxel's cube exactly.
  const int nx = size_.x() + 2;
  const int ny = size_.y() + 2;
  const double half = 0.5 * res_;
  double best = std::numeric_limits<double>::infinity();
  Eigen::Vector3d best_offset = Eigen::Vector3d::Zero();
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int s = site_[padded(c + Eigen::Vector3i(dx, dy, dz))];
        if (s < 0) continue;
        const int ix = s % nx;  // the site's cell indices
        const int iy = (s / nx) % ny;
        const int iz = s / (nx * ny);
        const Eigen::Vector3d centre = origin_ + res_ * Eigen::Vector3d(ix - 0.5, iy - 0.5, iz - 0.5 + edt_z0_);
        const Eigen::Vector3d r = p_W - centre;
        // From the nearest point of the obstacle cube to p.
        const Eigen::Vector3d d = (r.cwiseAbs().array() - half).cwiseMax(0.0).matrix().cwiseProduct(r.cwiseSign());
        const double n = d.norm();
        if (n < best) {
          best = n;
          best_offset = d;
        }
      }
    }
  }
  if (gradient && best > 0.0 && std::isfinite(best)) *gradient = best_offset / best;
  return best;
}

bool VoxelMap::segmentClear(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double clearance_m) const {
  const double len = (b - a).norm();
  const int steps = std::max(1, static_cast<int>(std::ceil(len / (0.5 * res_))));
  const double need = clearance_m + 0.5 * len / steps;
  // A point is at most 0.87 voxels from its voxel's centre and an obstacle voxel's cube reaches
  // 0.87 voxels from its own: the centre distance less 1.74 voxels bounds the clearance.
  const double slack = 1.7321 * res_;
  for (int i = 0; i <= steps; ++i) {
    const Eigen::Vector3d p = a + (b - a) * (static_cast<double>(i) / steps);
    const Eigen::Vector3i c = cellOf(p);
    if (inside(c) && c.z() >= clear_z0_ && c.z() <= clear_z1_ && centreDistance(c) - slack >= need) continue;
    if (clearance(p) < need) return false;
  }
  return true;
}

std::optional<Eigen::Vector3d> VoxelMap::nearestClear(const Eigen::Vector3d& p_W, double clearance_m,
                                                      double max_distance_m) const {
  if (clearance(p_W) >= clearance_m) return p_W;
  constexpr int kDirections = 64;
  const double step = 0.25 * res_;
  for (int ring = 1; ring * step <= max_distance_m + 1e-9; ++ring) {
    const double d = ring * step;
    std::optional<Eigen::Vector3d> best;
    double best_clearance = -std::numeric_limits<double>::infinity();
    for (int k = 0; k < kDirections; ++k) {
      const double a = 2.0 * M_PI * k / kDirections;
      const Eigen::Vector3d q = p_W + d * Eigen::Vector3d(std::cos(a), std::sin(a), 0.0);
      const double c = clearance(q);
      if (c >= clearance_m && c > best_clearance) {
        best = q;
        best_clearance = c;
      }
    }
    if (best) return best;
  }
  return std::nullopt;
}

OccupancyGrid2D VoxelMap::slice(double z_lo, double z_hi) const {
  OccupancyGrid2D grid(size_.x(), size_.y(), res_, origin_.head<2>());
  const int z0 = std::max(0, cellOf(Eigen::Vector3d(origin_.x(), origin_.y(), z_lo)).z());
  const int z1 = std::min(size_.z() - 1, cellOf(Eigen::Vector3d(origin_.x(), origin_.y(), z_hi)).z());
  for (int y = 0; y < size_.y(); ++y) {
    for (int x = 0; x < size_.x(); ++x) {
      bool blocked = z0 > z1;
      for (int z = z0; z <= z1 && !blocked; ++z) {
        blocked = state_[static_cast<std::size_t>(flat(x, y, z))] != VoxelState::kFree;
      }
      grid.set(x, y, blocked);
    }
  }
  return grid;
}

}  // namespace tgnav::planner
