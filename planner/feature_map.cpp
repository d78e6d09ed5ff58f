#include "planner/feature_map.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "planner/check.h"
#include "planner/occupancy_grid.h"

namespace tgnav::planner {

namespace {
Eigen::Vector3d toEigen(const octomap::point3d& p) { return Eigen::Vector3d(p.x(), p.y(), p.z()); }
}  // namespace

void VisibilityConfig::validate() const {
  require(hfov_rad > 0.0 && hfov_rad < M_PI, "hfov_rad", hfov_rad, "must be in (0, pi)");
  require(vfov_rad > 0.0 && vfov_rad < M_PI, "vfov_rad", vfov_rad, "must be in (0, pi)");
  require(min_range_m >= 0.0, "min_range_m", min_range_m, "must be >= 0");
  require(max_range_m > min_range_m, "max_range_m", max_range_m, "must exceed min_range_m");
  // >= 0: a yaw whose camera sees a point then also sees it from the body's centre, which lets the
  // pose graph pick each point's candidate yaws from the body (pose_graph.cpp).
  require(std::isfinite(camera_forward_m) && camera_forward_m >= 0.0 && camera_forward_m < 1.0, "camera_forward_m",
          camera_forward_m, "must be in [0, 1)");
  require(std::isfinite(camera_up_m) && std::abs(camera_up_m) < 1.0, "camera_up_m", camera_up_m, "must be in (-1, 1)");
}

OccupancyGrid2D sliceOccupancy(const FeatureMap& map, const Eigen::Vector2d& min_xy, const Eigen::Vector2d& max_xy,
                               double z_lo, double z_hi, double resolution_m) {
  const Eigen::Vector2d extent = max_xy - min_xy;
  OccupancyGrid2D grid(static_cast<int>(std::ceil(extent.x() / resolution_m - 1e-9)),
                       static_cast<int>(std::ceil(extent.y() / resolution_m - 1e-9)), resolution_m, min_xy);
  const double step = std::min(resolution_m, map.resolution()) * 0.5;
  for (int iy = 0; iy < grid.height; ++iy) {
    for (int ix = 0; ix < grid.width; ++ix) {
      const Eigen::Vector2d c = grid.centreOf(ix, iy);
      bool occupied = false;
      bool unseen = false;
      // Sample the cell's column at the map's resolution (cells may be larger than voxels).
      for (double dx = -0.5 * resolution_m + 0.5 * step; dx < 0.5 * resolution_m && !occupied; dx += step) {
        for (double dy = -0.5 * resolution_m + 0.5 * step; dy < 0.5 * resolution_m && !occupied; dy += step) {
          for (double z = z_lo; z <= z_hi + 1e-9 && !occupied; z += map.resolution()) {
            const Eigen::Vector3d p(c.x() + dx, c.y() + dy, z);
            if (map.isOccupied(p)) {
              occupied = true;
            } else if (!map.isKnown(p)) {
              unseen = true;
            }
          }
        }
      }
      grid.set(ix, iy, occupied || unseen);
    }
  }
  return grid;
}

int hammingDistance(const std::array<std::uint8_t, 32>& a, const std::array<std::uint8_t, 32>& b) {
  int bits = 0;
  for (int i = 0; i < 32; i += 8) {
    std::uint64_t x = 0;
    std::uint64_t y = 0;
    std::memcpy(&x, a.data() + i, 8);
    std::memcpy(&y, b.data() + i, 8);
    bits += __builtin_popcountll(x ^ y);
  }
  return bits;
}

FeatureMap::FeatureMap(double resolution_m) : tree_(std::make_unique<octomap::OcTree>(resolution_m)) {}

FeatureMap::FeatureMap(std::unique_ptr<octomap::OcTree> occupancy) : tree_(std::move(occupancy)) {
  if (!tree_) throw std::invalid_argument("FeatureMap: no occupancy map");
}

bool FeatureMap::isOccupied(const Eigen::Vector3d& p_W) const {
  const octomap::OcTreeNode* node = tree_->search(toOcto(p_W));
  return node != nullptr && tree_->isNodeOccupied(node);
}

bool FeatureMap::isKnown(const Eigen::Vector3d& p_W) const { return tree_->search(toOcto(p_W)) != nullptr; }

void FeatureMap::setLandmarks(std::vector<Landmark> landmarks) {
  landmarks_ = std::move(landmarks);
  landmark_key_.clear();
  by_voxel_.clear();
}

int FeatureMap::embedLandmarks(double max_shift_m) {
  std::vector<Landmark> kept;
  std::vector<octomap::OcTreeKey> keys;
  const double res = resolution();
  for (const Landmark& lm : landmarks_) {
    const Eigen::Vector3d ray = lm.p_W - lm.ref_kf_p_W;
    const double dist = ray.norm();
    if (dist < 1e-6) continue;
    octomap::point3d hit;
    const bool found =
        tree_->castRay(toOcto(lm.ref_kf_p_W), toOcto(ray), hit, /*ignoreUnknownCells=*/true, dist + max_shift_m + res);
    if (!found || (toEigen(hit) - lm.p_W).norm() > max_shift_m + 0.5 * std::sqrt(3.0) * res) continue;
    kept.push_back(lm);
    keys.push_back(tree_->coordToKey(hit));
  }
  const int dropped = static_cast<int>(landmarks_.size() - kept.size());
  landmarks_ = std::move(kept);
  landmark_key_ = std::move(keys);
  by_voxel_.clear();
  for (int i = 0; i < static_cast<int>(landmarks_.size()); ++i) by_voxel_[landmark_key_[i]].push_back(i);
  return dropped;
}

void FeatureMap::addPlacedLandmarks(const std::vector<Landmark>& landmarks) {
  if (landmark_key_.size() != landmarks_.size()) {
    throw std::logic_error("FeatureMap::addPlacedLandmarks: the map's landmarks are not embedded");
  }
  for (const Landmark& lm : landmarks) {
    const auto id = static_cast<int>(landmarks_.size());
    landmarks_.push_back(lm);
    landmark_key_.push_back(tree_->coordToKey(toOcto(lm.p_W)));
    by_voxel_[landmark_key_.back()].push_back(id);
  }
}

Eigen::Vector3d FeatureMap::landmarkVoxel(int id) const {
  return toEigen(tree_->keyToCoord(landmark_key_.at(static_cast<std::size_t>(id))));
}

std::vector<int> FeatureMap::visibleFrom(const Eigen::Vector3d& p_W, const VisibilityConfig& config) const {
  std::vector<int> visible;
  const octomap::point3d origin = toOcto(p_W);
  const double half_vfov = 0.5 * config.vfov_rad;
  for (const auto& [key, ids] : by_voxel_) {
    const Eigen::Vector3d centre = toEigen(tree_->keyToCoord(key));
    const Eigen::Vector3d d = centre - p_W;
    const double range = d.norm();
    if (range < config.min_range_m || range > config.max_range_m) continue;
    const double elevation = std::atan2(d.z(), d.head<2>().norm());
    if (std::abs(elevation) > half_vfov) continue;
    octomap::point3d hit;
    if (!tree_->castRay(origin, toOcto(d), hit, /*ignoreUnknownCells=*/true, range + resolution())) continue;
    if (tree_->coordToKey(hit) != key) continue;  // something else is in the way
    visible.insert(visible.end(), ids.begin(), ids.end());
  }
  std::sort(visible.begin(), visible.end());
  return visible;
}

std::vector<int> FeatureMap::inHorizontalFov(const Eigen::Vector3d& p_W, double yaw_rad,
                                             const std::vector<int>& candidates, const VisibilityConfig& config) const {
  std::vector<int> out;
  const double half_hfov = 0.5 * config.hfov_rad;
  for (int id : candidates) {
    const Eigen::Vector3d d = landmarkVoxel(id) - p_W;
    const double bearing = std::remainder(std::atan2(d.y(), d.x()) - yaw_rad, 2.0 * M_PI);
    if (std::abs(bearing) <= half_hfov) out.push_back(id);
  }
  return out;
}

void FeatureMap::save(const std::filesystem::path& dir) const {
  // A stream's last bytes reach the file at close(): each file is checked after it.
  auto fail = [](const std::filesystem::path& file) {
    throw std::runtime_error(file.string() + ": cannot write: " + std::strerror(errno));
  };
  std::ofstream bt(dir / "map.bt", std::ios::binary | std::ios::trunc);
  if (!bt || !tree_->writeBinaryConst(bt)) fail(dir / "map.bt");
  bt.close();
  if (!bt) fail(dir / "map.bt");
  std::ofstream out(dir / "landmarks.csv");
  out << "id,x,y,z,observations,opportunities,ref_x,ref_y,ref_z,voxel_x,voxel_y,voxel_z,descriptor\n";
  out.precision(6);
  out << std::fixed;
  static const char* kHex = "0123456789abcdef";
  for (std::size_t i = 0; i < landmarks_.size(); ++i) {
    const Landmark& lm = landmarks_[i];
    const Eigen::Vector3d v = landmark_key_.empty() ? lm.p_W : landmarkVoxel(static_cast<int>(i));
    std::string hex;
    for (std::uint8_t b : lm.descriptor) {
      hex += kHex[b >> 4];
      hex += kHex[b & 15];
    }
    out << i << ',' << lm.p_W.x() << ',' << lm.p_W.y() << ',' << lm.p_W.z() << ',' << lm.observations << ','
        << lm.opportunities << ',' << lm.ref_kf_p_W.x() << ',' << lm.ref_kf_p_W.y() << ',' << lm.ref_kf_p_W.z() << ','
        << v.x() << ',' << v.y() << ',' << v.z() << ',' << hex << '\n';
  }
  out.close();
  if (!out) fail(dir / "landmarks.csv");
}

FeatureMap FeatureMap::load(const std::filesystem::path& dir) {
  const std::string bt = (dir / "map.bt").string();
  auto tree = std::make_unique<octomap::OcTree>(0.1);
  if (!std::filesystem::is_regular_file(bt) || !tree->readBinary(bt)) {
    throw std::runtime_error(bt + ": missing or not an OctoMap binary file");
  }
  FeatureMap map(tree->getResolution());
  map.tree_ = std::move(tree);
  const std::string csv = (dir / "landmarks.csv").string();
  std::ifstream in(csv);
  if (!in) throw std::runtime_error(csv + ": cannot open");
  std::string line;
  std::getline(in, line);
  int line_no = 1;
  std::vector<Landmark> landmarks;
  std::vector<octomap::OcTreeKey> keys;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty()) continue;
    std::stringstream ss(line);
    std::string field;
    std::vector<std::string> f;
    while (std::getline(ss, field, ',')) f.push_back(field);
    // 13 columns; 12 in maps saved before the opportunities column.
    const std::size_t n = f.size();
    if ((n != 12 && n != 13) || f[n - 1].size() != 64) {
      throw std::runtime_error(csv + ":" + std::to_string(line_no) +
                               ": expected 13 columns (12 without opportunities) with a 64-digit descriptor");
    }
    const std::size_t extra = n - 12;  // the opportunities column shifts the ones after it
    Landmark lm;
    double v[10];
    try {
      for (std::size_t k = 0; k < 4; ++k) v[k] = std::stod(f[k + 1]);
      if (extra == 1) lm.opportunities = std::stoi(f[5]);
      for (std::size_t k = 4; k < 10; ++k) v[k] = std::stod(f[k + 1 + extra]);
      for (int b = 0; b < 32; ++b) {
        lm.descriptor[b] =
            static_cast<std::uint8_t>(std::stoi(f[n - 1].substr(2 * static_cast<std::size_t>(b), 2), nullptr, 16));
      }
    } catch (const std::exception&) {
      throw std::runtime_error(csv + ":" + std::to_string(line_no) + ": malformed number or descriptor");
    }
    if (lm.opportunities < 0) {
      throw std::runtime_error(csv + ":" + std::to_string(line_no) + ": opportunities " + f[5] + " is negative");
    }
    lm.p_W = Eigen::Vector3d(v[0], v[1], v[2]);
    lm.observations = static_cast<int>(v[3]);
    lm.ref_kf_p_W = Eigen::Vector3d(v[4], v[5], v[6]);
    landmarks.push_back(lm);
    keys.push_back(map.tree_->coordToKey(toOcto(Eigen::Vector3d(v[7], v[8], v[9]))));
  }
  map.landmarks_ = std::move(landmarks);
  map.landmark_key_ = std::move(keys);
  for (int i = 0; i < static_cast<int>(map.landmarks_.size()); ++i) map.by_voxel_[map.landmark_key_[i]].push_back(i);
  return map;
}

}  // namespace tgnav::planner
