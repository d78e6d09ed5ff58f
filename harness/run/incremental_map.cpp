#include "harness/run/incremental_map.h"

#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

#include "harness/base/clock.h"

namespace tgnav::harness {

namespace {

// Every observed frame's depth is kept at every kViewStridePx-th pixel (in millimetres) to count
// each landmark's opportunities once all landmarks are known (9.6 KB per frame at 640x480).
constexpr int kViewStridePx = 8;

// A landmark being accumulated over observations.
struct LandmarkTrack {
  Eigen::Vector3d sum_p_W = Eigen::Vector3d::Zero();
  int observations = 0;
  Eigen::Vector3d ref_kf_p_W = Eigen::Vector3d::Zero();
  std::array<std::uint8_t, 32> descriptor{};
  Eigen::Vector3d mean() const { return sum_p_W / observations; }
};

// Spatial hash of tracks by the cell of their first observation, cell size = merge radius.
struct CellKey {
  long x, y, z;
  bool operator==(const CellKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct CellHash {
  std::size_t operator()(const CellKey& k) const {
    return static_cast<std::size_t>(k.x * 73856093L ^ k.y * 19349663L ^ k.z * 83492791L);
  }
};

// Depth at (u, v) if it and its 3x3 neighbourhood are valid and continuous, else 0.
float stableDepth(const cv::Mat& depth, int u, int v, double edge_m) {
  if (u < 1 || v < 1 || u >= depth.cols - 1 || v >= depth.rows - 1) return 0.0f;
  float lo = 1e9f;
  float hi = 0.0f;
  for (int dv = -1; dv <= 1; ++dv) {
    for (int du = -1; du <= 1; ++du) {
      const float z = depth.at<float>(v + dv, u + du);
      if (z <= 0.0f) return 0.0f;
      lo = std::min(lo, z);
      hi = std::max(hi, z);
    }
  }
  return (hi - lo) > edge_m ? 0.0f : depth.at<float>(v, u);
}

}  // namespace

// Merges observations into tracks: the nearest track within the merge radius whose descriptor is
// close enough, else a new one.
struct IncrementalMapper::Associator {
  Associator(double radius, int max_hamming) : radius(radius), max_hamming(max_hamming) {}

  void observe(const Eigen::Vector3d& p_W, const std::array<std::uint8_t, 32>& desc, const Eigen::Vector3d& kf) {
    const CellKey c = cell(p_W);
    int best = -1;
    int best_bits = max_hamming + 1;
    for (long dx = -1; dx <= 1; ++dx) {
      for (long dy = -1; dy <= 1; ++dy) {
        for (long dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find(CellKey{c.x + dx, c.y + dy, c.z + dz});
          if (it == grid.end()) continue;
          for (int id : it->second) {
            if ((tracks[id].mean() - p_W).norm() > radius) continue;
            const int bits = planner::hammingDistance(tracks[id].descriptor, desc);
            if (bits < best_bits) {
              best_bits = bits;
              best = id;
            }
          }
        }
      }
    }
    if (best >= 0) {
      tracks[best].sum_p_W += p_W;
      ++tracks[best].observations;
      return;
    }
    LandmarkTrack t;
    t.sum_p_W = p_W;
    t.observations = 1;
    t.ref_kf_p_W = kf;
    t.descriptor = desc;
    grid[c].push_back(static_cast<int>(tracks.size()));
    tracks.push_back(t);
  }

  CellKey cell(const Eigen::Vector3d& p) const {
    return CellKey{static_cast<long>(std::floor(p.x() / radius)), static_cast<long>(std::floor(p.y() / radius)),
                   static_cast<long>(std::floor(p.z() / radius))};
  }

  double radius;
  int max_hamming;
  std::vector<LandmarkTrack> tracks;
  std::unordered_map<CellKey, std::vector<int>, CellHash> grid;
};

// An observed frame as the opportunity count needs it: where the camera was and its depth, sampled.
struct IncrementalMapper::View {
  Eigen::Isometry3d X_CW;  // world to camera
  cv::Mat depth_mm;        // CV_16UC1, pixel (r, c) = depth at image pixel (r, c) * kViewStridePx; 0 invalid

  explicit View(const RgbdFrame& frame) : X_CW(frame.X_WC.inverse()) {
    const cv::Mat& d = frame.depth_m;
    depth_mm.create((d.rows + kViewStridePx - 1) / kViewStridePx, (d.cols + kViewStridePx - 1) / kViewStridePx,
                    CV_16UC1);
    for (int r = 0; r < depth_mm.rows; ++r) {
      for (int c = 0; c < depth_mm.cols; ++c) {
        const double z = d.at<float>(r * kViewStridePx, c * kViewStridePx);
        depth_mm.at<std::uint16_t>(r, c) =
            static_cast<std::uint16_t>(z > 0.0 ? std::min(65535.0, std::round(z * 1000.0)) : 0.0);
      }
    }
  }

  // True if the view had p_W in its image (off the detector's border), within range and in front
  // of the surface its depth shows there (by 0.1 m + 2 % of the range: the landmark is a mean of
  // observations near that surface, and the sampled depth a pixel or a few away).
  bool hadInView(const Eigen::Vector3d& p_W, const Intrinsics& k, const MapBuildConfig& config) const {
    const Eigen::Vector3d p_C = X_CW * p_W;
    const double z = p_C.z();
    if (z <= 0.0 || z > config.max_range_m) return false;
    const double u = k.fx * p_C.x() / z + k.cx;
    const double v = k.fy * p_C.y() / z + k.cy;
    const double border = config.features.edge_threshold_px;
    if (u < border || v < border || u > k.width_px - 1 - border || v > k.height_px - 1 - border) return false;
    const int c = std::min(depth_mm.cols - 1, static_cast<int>(std::lround(u / kViewStridePx)));
    const int r = std::min(depth_mm.rows - 1, static_cast<int>(std::lround(v / kViewStridePx)));
    const double surface = 1e-3 * depth_mm.at<std::uint16_t>(r, c);
    return surface > 0.0 && z <= surface + 0.1 + 0.02 * z;
  }
};

IncrementalMapper::IncrementalMapper(const MapBuildConfig& config, const Intrinsics& k)
    : config_(config),
      k_(k),
      detector_(config.features),
      tree_(std::make_unique<octomap::OcTree>(config.resolution_m)),
      associator_(std::make_unique<Associator>(config.merge_radius_m, config.max_hamming)) {}

IncrementalMapper::~IncrementalMapper() = default;

void IncrementalMapper::setCamera(const Intrinsics& k) {
  if (!views_.empty()) throw std::logic_error("IncrementalMapper::setCamera after the first frame");
  k_ = k;
}

int IncrementalMapper::views() const { return static_cast<int>(views_.size()); }
int IncrementalMapper::tracks() const { return static_cast<int>(associator_->tracks.size()); }

void IncrementalMapper::setPrior(const octomap::OcTree& occupancy, std::vector<planner::Landmark> landmarks) {
  tree_ = std::make_unique<octomap::OcTree>(occupancy);
  prior_landmarks_ = std::move(landmarks);
}

void IncrementalMapper::insertDepth(const RgbdFrame& frame, int stride_px) {
  if (config_.free_short_of_surface) {
    insertDepthShortOfSurface(frame, stride_px);
  } else {
    insertDepthRays(frame, stride_px);
  }
  if (config_.no_return_depth_m > 0.0) clearNoReturn(frame, stride_px);
}

void IncrementalMapper::insertDepthRays(const RgbdFrame& frame, int stride_px) {
  const Eigen::Vector3d origin = frame.X_WC.translation();
  octomap::Pointcloud cloud;
  for (int v = 0; v < k_.height_px; v += stride_px) {
    const float* row = frame.depth_m.ptr<float>(v);
    for (int u = 0; u < k_.width_px; u += stride_px) {
      const double z = row[u];
      if (z <= 0.0) continue;
      const Eigen::Vector3d p_W = frame.X_WC * Eigen::Vector3d((u - k_.cx) / k_.fx * z, (v - k_.cy) / k_.fy * z, z);
      cloud.push_back(static_cast<float>(p_W.x()), static_cast<float>(p_W.y()), static_cast<float>(p_W.z()));
    }
  }
  tree_->insertPointCloud(cloud, octomap::point3d(origin.x(), origin.y(), origin.z()), config_.max_range_m,
                          /*lazy_eval=*/false, /*discretize=*/true);
}

void IncrementalMapper::insertDepthShortOfSurface(const RgbdFrame& frame, int stride_px) {
  const double res = config_.resolution_m;
  const octomap::point3d o = planner::toOcto(frame.X_WC.translation());
  const cv::Mat& depth = frame.depth_m;
  const auto point = [&](int u, int v) {
    const double z = depth.at<float>(v, u);
    return Eigen::Vector3d((u - k_.cx) / k_.fx * z, (v - k_.cy) / k_.fy * z, z);
  };
  // The step to the pixel `stride_px` on along one image axis, on the side whose depth changes
  // least (off a depth edge); zero where neither has depth. The stride, not the next pixel: a
  // longer base averages out depth noise (camera.depth_noise_sigma_per_m2) in the normal.
  const auto step = [&](int u, int v, const Eigen::Vector3d& p_C, int du, int dv) -> Eigen::Vector3d {
    Eigen::Vector3d best = Eigen::Vector3d::Zero();
    double best_dz = std::numeric_limits<double>::infinity();
    for (const int sign : {1, -1}) {
      const int u2 = u + sign * du;
      const int v2 = v + sign * dv;
      if (u2 < 0 || v2 < 0 || u2 >= depth.cols || v2 >= depth.rows || depth.at<float>(v2, u2) <= 0.0F) continue;
      const double dz = std::abs(depth.at<float>(v2, u2) - p_C.z());
      if (dz < best_dz) {
        best_dz = dz;
        best = sign * (point(u2, v2) - p_C);
      }
    }
    return best;
  };
  octomap::KeySet free_cells;
  octomap::KeySet occupied_cells;
  octomap::KeyRay ray;
  const auto clearTo = [&](const Eigen::Vector3d& end_W) {
    const octomap::point3d e = planner::toOcto(end_W);
    if (tree_->computeRayKeys(o, e, ray)) free_cells.insert(ray.begin(), ray.end());
    octomap::OcTreeKey key;
    if (tree_->coordToKeyChecked(e, key)) free_cells.insert(key);
  };
  for (int v = 0; v < k_.height_px; v += stride_px) {
    for (int u = 0; u < k_.width_px; u += stride_px) {
      if (depth.at<float>(v, u) <= 0.0F) continue;
      const Eigen::Vector3d p_C = point(u, v);
      const double range = p_C.norm();
      const Eigen::Vector3d dir_C = p_C / range;
      if (range > config_.max_range_m) {  // as OctoMap: free up to the range, no surface
        clearTo(frame.X_WC * (config_.max_range_m * dir_C));
        continue;
      }
      octomap::OcTreeKey hit;
      if (!tree_->coordToKeyChecked(planner::toOcto(frame.X_WC * p_C), hit)) continue;
      occupied_cells.insert(hit);
      const Eigen::Vector3d normal = step(u, v, p_C, stride_px, 0).cross(step(u, v, p_C, 0, stride_px));
      const double n = normal.norm();
      // Where the surface's normal is unknown (an isolated pixel), as at a grazing angle.
      const double cos_incidence = n > 0.0 ? std::abs(normal.dot(dir_C)) / n : 0.0;
      const double short_m = cos_incidence * range > res ? res / cos_incidence : range;
      if (short_m < range) clearTo(frame.X_WC * ((range - short_m) * dir_C));
    }
  }
  for (const octomap::OcTreeKey& key : free_cells) {
    if (occupied_cells.count(key) == 0) tree_->updateNode(key, false);
  }
  for (const octomap::OcTreeKey& key : occupied_cells) tree_->updateNode(key, true);
}

void IncrementalMapper::clearNoReturn(const RgbdFrame& frame, int stride_px) {
  const octomap::point3d o = planner::toOcto(frame.X_WC.translation());
  octomap::KeySet free_cells;
  octomap::KeyRay ray;
  for (int v = 0; v < k_.height_px; v += stride_px) {
    const float* row = frame.depth_m.ptr<float>(v);
    for (int u = 0; u < k_.width_px; u += stride_px) {
      if (row[u] > 0.0F) continue;
      const Eigen::Vector3d dir_C = Eigen::Vector3d((u - k_.cx) / k_.fx, (v - k_.cy) / k_.fy, 1.0).normalized();
      const double length = std::min(config_.max_range_m, config_.no_return_depth_m / dir_C.z());
      const octomap::point3d e = planner::toOcto(frame.X_WC * (length * dir_C));
      if (tree_->computeRayKeys(o, e, ray)) free_cells.insert(ray.begin(), ray.end());
      octomap::OcTreeKey key;
      if (tree_->coordToKeyChecked(e, key)) free_cells.insert(key);
    }
  }
  // Only voxels not observed yet: a ray without a return says nothing against a surface another
  // ray saw (a voxel it crosses at a corner may hold one).
  for (const octomap::OcTreeKey& key : free_cells) {
    if (tree_->search(key) == nullptr) tree_->updateNode(key, false);
  }
}

void IncrementalMapper::observeFeatures(const RgbdFrame& frame) {
  const Eigen::Vector3d origin = frame.X_WC.translation();
  cv::Mat gray;
  cv::cvtColor(frame.bgr, gray, cv::COLOR_BGR2GRAY);
  const vo::Features feats = detector_.detect(gray);
  keypoints_ += static_cast<long>(feats.keypoints.size());
  for (std::size_t i = 0; i < feats.keypoints.size(); ++i) {
    const cv::Point2f& px = feats.keypoints[i].pt;
    const int u = static_cast<int>(std::lround(px.x));
    const int v = static_cast<int>(std::lround(px.y));
    const double z = stableDepth(frame.depth_m, u, v, config_.depth_edge_m);
    if (z <= 0.0 || z > config_.max_range_m) continue;
    const Eigen::Vector3d p_W = frame.X_WC * Eigen::Vector3d((px.x - k_.cx) / k_.fx * z, (px.y - k_.cy) / k_.fy * z, z);
    std::array<std::uint8_t, 32> desc{};
    std::memcpy(desc.data(), feats.descriptors.ptr<std::uint8_t>(static_cast<int>(i)), 32);
    associator_->observe(p_W, desc, origin);
    ++observations_;
  }
  views_.emplace_back(frame);
}

IncrementalMapper::Built IncrementalMapper::build(std::unique_ptr<octomap::OcTree> tree) {
  Built out{planner::FeatureMap(std::move(tree))};
  std::vector<planner::Landmark> landmarks = prior_landmarks_;
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<LandmarkTrack>& tracks = associator_->tracks;
  counted_.resize(tracks.size());
  for (std::size_t i = 0; i < tracks.size(); ++i) {
    const LandmarkTrack& t = tracks[i];
    if (t.observations < config_.min_observations) {
      ++out.dropped_few_observations;
      continue;
    }
    planner::Landmark lm;
    lm.p_W = t.mean();
    lm.observations = t.observations;
    lm.ref_kf_p_W = t.ref_kf_p_W;
    lm.descriptor = t.descriptor;
    // Landmark::opportunities: the frames that had it in view, a sum over the frames in order; a
    // frame may have detected it twice (two keypoints merged into it): never below the detections.
    // Counted again from the first frame only when its mean moved since the last count.
    Counted& c = counted_[i];
    if (c.observations != t.observations) c = Counted{t.observations, 0, 0};
    for (; c.views < static_cast<int>(views_.size()); ++c.views) {
      c.opportunities += views_[static_cast<std::size_t>(c.views)].hadInView(lm.p_W, k_, config_) ? 1 : 0;
    }
    lm.opportunities = std::max(c.opportunities, lm.observations);
    landmarks.push_back(lm);
  }
  out.opportunities_s = secondsSince(t0);
  out.map.setLandmarks(std::move(landmarks));
  out.dropped_not_embedded = out.map.embedLandmarks(config_.max_shift_m);
  return out;
}

IncrementalMapper::Built IncrementalMapper::snapshot() { return build(std::make_unique<octomap::OcTree>(*tree_)); }

IncrementalMapper::Built IncrementalMapper::release() { return build(std::move(tree_)); }

bool occupiedWithin(const octomap::OcTree& tree, const std::vector<Eigen::Vector3d>& points, double radius_m) {
  const double res = tree.getResolution();
  const int n = static_cast<int>(std::ceil(radius_m / res));
  // Each voxel near the points once (neighbouring points share most of theirs).
  std::unordered_set<octomap::OcTreeKey, octomap::OcTreeKey::KeyHash> near;
  for (const Eigen::Vector3d& p : points) {
    const octomap::OcTreeKey key = tree.coordToKey(p.x(), p.y(), p.z());
    for (int i = -n; i <= n; ++i) {
      for (int j = -n; j <= n; ++j) {
        for (int k = -n; k <= n; ++k) {
          octomap::OcTreeKey v = key;
          v[0] = static_cast<octomap::key_type>(v[0] + i);
          v[1] = static_cast<octomap::key_type>(v[1] + j);
          v[2] = static_cast<octomap::key_type>(v[2] + k);
          const octomap::point3d c = tree.keyToCoord(v);
          const Eigen::Vector3d gap =
              ((p - Eigen::Vector3d(c.x(), c.y(), c.z())).cwiseAbs().array() - 0.5 * res).cwiseMax(0.0).matrix();
          if (gap.norm() < radius_m) near.insert(v);
        }
      }
    }
  }
  return std::any_of(near.begin(), near.end(), [&](const octomap::OcTreeKey& v) {
    const octomap::OcTreeNode* node = tree.search(v);
    return node != nullptr && tree.isNodeOccupied(node);
  });
}

octomap::OcTree cropOccupancy(const octomap::OcTree& tree, const Eigen::Vector3d& centre, double radius_m) {
  const double res = tree.getResolution();
  octomap::OcTree out(res);
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    forEachVoxel(it, res, [&](const Eigen::Vector3d& p) {
      if ((p - centre).head<2>().norm() > radius_m) return;
      out.setNodeValue(planner::toOcto(p), it->getLogOdds(), /*lazy_eval=*/true);
    });
  }
  out.updateInnerOccupancy();
  return out;
}

}  // namespace tgnav::harness
