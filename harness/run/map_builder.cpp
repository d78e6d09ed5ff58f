#include "harness/run/map_builder.h"

#include <chrono>
#include <cmath>
#include <cstring>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "harness/base/clock.h"
#include "harness/base/errors.h"
#include "harness/base/ordered_worker.h"
#include "harness/sim/camera.h"
#include "harness/sim/mujoco_sim.h"
#include "harness/sim/scene_geometry.h"
#include "harness/sim/vehicle_model.h"

namespace tgnav::harness {

namespace {

using Clock = std::chrono::steady_clock;
// Rotor tips of models/quadrotor.xml (0.25 m arm + 0.12 m propeller), rounded down: the start
// and goal of a scene must leave at least this much room (a property of the scene, checked the
// same whatever vehicle flies it).
constexpr double kVehicleRadiusM = 0.3;
// Survey frames rendered ahead of their integration (bounds the memory of a fast renderer).
constexpr std::size_t kSurveyQueueFrames = 4;
// Every survey frame's depth is kept at every kViewStridePx-th pixel (in millimetres) to count
// each landmark's opportunities once all landmarks are known (9.6 MB per 1000 frames at 640x480).
constexpr int kViewStridePx = 8;

// A landmark being accumulated over observations.
struct Track {
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

class LandmarkAssociator {
 public:
  LandmarkAssociator(double radius, int max_hamming) : radius_(radius), max_hamming_(max_hamming) {}

  void observe(const Eigen::Vector3d& p_W, const std::array<std::uint8_t, 32>& desc, const Eigen::Vector3d& kf) {
    const CellKey c = cell(p_W);
    int best = -1;
    int best_bits = max_hamming_ + 1;
    for (long dx = -1; dx <= 1; ++dx) {
      for (long dy = -1; dy <= 1; ++dy) {
        for (long dz = -1; dz <= 1; ++dz) {
          const auto it = grid_.find(CellKey{c.x + dx, c.y + dy, c.z + dz});
          if (it == grid_.end()) continue;
          for (int id : it->second) {
            if ((tracks_[id].mean() - p_W).norm() > radius_) continue;
            const int bits = planner::hammingDistance(tracks_[id].descriptor, desc);
            if (bits < best_bits) {
              best_bits = bits;
              best = id;
            }
          }
        }
      }
    }
    if (best >= 0) {
      tracks_[best].sum_p_W += p_W;
      ++tracks_[best].observations;
      return;
    }
    Track t;
    t.sum_p_W = p_W;
    t.observations = 1;
    t.ref_kf_p_W = kf;
    t.descriptor = desc;
    grid_[c].push_back(static_cast<int>(tracks_.size()));
    tracks_.push_back(t);
  }
  const std::vector<Track>& tracks() const { return tracks_; }

 private:
  CellKey cell(const Eigen::Vector3d& p) const {
    return CellKey{static_cast<long>(std::floor(p.x() / radius_)), static_cast<long>(std::floor(p.y() / radius_)),
                   static_cast<long>(std::floor(p.z() / radius_))};
  }
  double radius_;
  int max_hamming_;
  std::vector<Track> tracks_;
  std::unordered_map<CellKey, std::vector<int>, CellHash> grid_;
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

// Ray-inserts every occupancy_stride_px-th depth pixel of `frame` into the OctoMap.
void insertDepth(const RgbdFrame& frame, const Intrinsics& k, const MapBuildConfig& config, octomap::OcTree* tree) {
  const Eigen::Vector3d origin = frame.X_WC.translation();
  octomap::Pointcloud cloud;
  for (int v = 0; v < k.height_px; v += config.occupancy_stride_px) {
    const float* row = frame.depth_m.ptr<float>(v);
    for (int u = 0; u < k.width_px; u += config.occupancy_stride_px) {
      const double z = row[u];
      if (z <= 0.0) continue;
      const Eigen::Vector3d p_W = frame.X_WC * Eigen::Vector3d((u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z);
      cloud.push_back(static_cast<float>(p_W.x()), static_cast<float>(p_W.y()), static_cast<float>(p_W.z()));
    }
  }
  tree->insertPointCloud(cloud, octomap::point3d(origin.x(), origin.y(), origin.z()), config.max_range_m,
                         /*lazy_eval=*/false, /*discretize=*/true);
}

// Back-projects the ORB keypoints of `frame` that have a stable depth and hands them to the
// associator.
void observeFeatures(const RgbdFrame& frame, const Intrinsics& k, const MapBuildConfig& config,
                     const vo::FeatureDetector& detector, LandmarkAssociator* associator, MapBuildStats* stats) {
  const Eigen::Vector3d origin = frame.X_WC.translation();
  cv::Mat gray;
  cv::cvtColor(frame.bgr, gray, cv::COLOR_BGR2GRAY);
  const vo::Features feats = detector.detect(gray);
  stats->keypoints += static_cast<long>(feats.keypoints.size());
  for (std::size_t i = 0; i < feats.keypoints.size(); ++i) {
    const cv::Point2f& px = feats.keypoints[i].pt;
    const int u = static_cast<int>(std::lround(px.x));
    const int v = static_cast<int>(std::lround(px.y));
    const double z = stableDepth(frame.depth_m, u, v, config.depth_edge_m);
    if (z <= 0.0 || z > config.max_range_m) continue;
    const Eigen::Vector3d p_W = frame.X_WC * Eigen::Vector3d((px.x - k.cx) / k.fx * z, (px.y - k.cy) / k.fy * z, z);
    std::array<std::uint8_t, 32> desc{};
    std::memcpy(desc.data(), feats.descriptors.ptr<std::uint8_t>(static_cast<int>(i)), 32);
    associator->observe(p_W, desc, origin);
    ++stats->observations;
  }
}

// A survey frame as the opportunity count needs it: where the camera was and its depth, sampled.
struct SurveyView {
  Eigen::Isometry3d X_CW;  // world to camera
  cv::Mat depth_mm;        // CV_16UC1, pixel (r, c) = depth at image pixel (r, c) * kViewStridePx; 0 invalid
};

SurveyView keepView(const RgbdFrame& frame) {
  SurveyView view{frame.X_WC.inverse(), cv::Mat()};
  const cv::Mat& d = frame.depth_m;
  view.depth_mm.create((d.rows + kViewStridePx - 1) / kViewStridePx, (d.cols + kViewStridePx - 1) / kViewStridePx,
                       CV_16UC1);
  for (int r = 0; r < view.depth_mm.rows; ++r) {
    for (int c = 0; c < view.depth_mm.cols; ++c) {
      const double z = d.at<float>(r * kViewStridePx, c * kViewStridePx);
      view.depth_mm.at<std::uint16_t>(r, c) =
          static_cast<std::uint16_t>(z > 0.0 ? std::min(65535.0, std::round(z * 1000.0)) : 0.0);
    }
  }
  return view;
}

// True if `view` had p_W in its image (off the detector's border), within range and in front of
// the surface its depth shows there (by 0.1 m + 2 % of the range: the landmark is a mean of
// observations near that surface, and the sampled depth a pixel or a few away).
bool hadInView(const SurveyView& view, const Eigen::Vector3d& p_W, const Intrinsics& k, const MapBuildConfig& config) {
  const Eigen::Vector3d p_C = view.X_CW * p_W;
  const double z = p_C.z();
  if (z <= 0.0 || z > config.max_range_m) return false;
  const double u = k.fx * p_C.x() / z + k.cx;
  const double v = k.fy * p_C.y() / z + k.cy;
  const double border = config.features.edge_threshold_px;
  if (u < border || v < border || u > k.width_px - 1 - border || v > k.height_px - 1 - border) return false;
  const int c = std::min(view.depth_mm.cols - 1, static_cast<int>(std::lround(u / kViewStridePx)));
  const int r = std::min(view.depth_mm.rows - 1, static_cast<int>(std::lround(v / kViewStridePx)));
  const double surface = 1e-3 * view.depth_mm.at<std::uint16_t>(r, c);
  return surface > 0.0 && z <= surface + 0.1 + 0.02 * z;
}

// Landmark::opportunities: the survey frames that had each landmark in view. Deterministic: each
// landmark's count is a sum over the frames in order.
void countOpportunities(const std::vector<SurveyView>& views, const Intrinsics& k, const MapBuildConfig& config,
                        std::vector<planner::Landmark>* landmarks) {
  for (planner::Landmark& lm : *landmarks) {
    int n = 0;
    for (const SurveyView& view : views) n += hadInView(view, lm.p_W, k, config) ? 1 : 0;
    // A frame may have detected it twice (two keypoints merged into it): never below the detections.
    lm.opportunities = std::max(n, lm.observations);
  }
}

// The merged landmarks seen at least `min_observations` times.
std::vector<planner::Landmark> keptLandmarks(const LandmarkAssociator& associator, int min_observations,
                                             MapBuildStats* stats) {
  std::vector<planner::Landmark> landmarks;
  for (const Track& t : associator.tracks()) {
    if (t.observations < min_observations) {
      ++stats->dropped_few_observations;
      continue;
    }
    planner::Landmark lm;
    lm.p_W = t.mean();
    lm.observations = t.observations;
    lm.ref_kf_p_W = t.ref_kf_p_W;
    lm.descriptor = t.descriptor;
    landmarks.push_back(lm);
  }
  return landmarks;
}

}  // namespace

std::vector<planner::Pose4> surveyPoses(const SceneConfig& scene, const SceneGeometry& geometry) {
  const SurveyPlan& plan = scene.survey;
  std::vector<planner::Pose4> poses;
  const Eigen::Vector3d lo = scene.bounds_min_m;
  const Eigen::Vector3d hi = scene.bounds_max_m;
  // Grid centred in the bounds so that margins are equal on both sides.
  const int nx = static_cast<int>(std::floor((hi.x() - lo.x()) / plan.spacing_m));
  const int ny = static_cast<int>(std::floor((hi.y() - lo.y()) / plan.spacing_m));
  const double x0 = 0.5 * (lo.x() + hi.x()) - 0.5 * nx * plan.spacing_m;
  const double y0 = 0.5 * (lo.y() + hi.y()) - 0.5 * ny * plan.spacing_m;
  for (double z : plan.heights_m) {
    for (int i = 0; i <= nx; ++i) {
      for (int j = 0; j <= ny; ++j) {
        const Eigen::Vector3d p(x0 + i * plan.spacing_m, y0 + j * plan.spacing_m, z);
        if (geometry.signedDistance(p) < plan.clearance_m) continue;
        for (int k = 0; k < plan.yaw_count; ++k) {
          planner::Pose4 pose;
          pose.p_WB = p;
          pose.yaw_rad = -M_PI + 2.0 * M_PI * k / plan.yaw_count;
          poses.push_back(pose);
        }
      }
    }
  }
  if (poses.empty()) {
    throw InputError(scene.source.string() +
                     ": survey plan has no free pose (every grid position is within "
                     "survey.clearance_m of geometry)");
  }
  return poses;
}

planner::FeatureMap buildFeatureMap(const SceneConfig& scene, const MapBuildConfig& config, MapBuildStats* stats_out,
                                    const std::function<void(int, int)>& progress) {
  config.validate();
  const auto t_start = Clock::now();
  MapBuildStats stats;
  // The scene's own vehicle carries the survey camera, whatever vehicle a scenario flies: the
  // map is of the scene.
  VehicleModel vehicle = loadVehicleModel(scene.mjcf, scene.vehicle);
  ModelPtr model = std::move(vehicle.model);
  DataPtr data = makeData(model.get());
  mj_forward(model.get(), data.get());
  const SceneGeometry geometry(model.get(), data.get());
  checkStartGoalFree(scene, geometry, kVehicleRadiusM);
  const std::vector<planner::Pose4> poses = surveyPoses(scene, geometry);
  stats.survey_positions = static_cast<int>(poses.size()) / scene.survey.yaw_count;
  const VehicleIds& ids = vehicle.ids;
  EglContext gl;
  Camera camera(model.get(), gl, config.camera.on(vehicle.vehicle.camera), 0);
  const Intrinsics& k = camera.intrinsics();
  const vo::FeatureDetector detector(config.features);
  planner::FeatureMap map(config.resolution_m);
  LandmarkAssociator associator(config.merge_radius_m, config.max_hamming);
  std::vector<SurveyView> views;
  views.reserve(poses.size());

  // This thread renders the survey; a worker integrates the frames in order (depth into the
  // occupancy, keypoints into the landmark tracks) while the next ones render: the same map as one
  // thread doing both in turn. The two touch different fields of `stats`.
  OrderedWorker<RgbdFrame> integrator(kSurveyQueueFrames, [&](RgbdFrame& frame) {
    Clock::time_point t0 = Clock::now();
    insertDepth(frame, k, config, &map.occupancy());
    stats.integrate_s += secondsSince(t0);
    t0 = Clock::now();
    observeFeatures(frame, k, config, detector, &associator, &stats);
    views.push_back(keepView(frame));
    stats.features_s += secondsSince(t0);
  });
  for (std::size_t f = 0; f < poses.size(); ++f) {
    const Clock::time_point t0 = Clock::now();
    setVehiclePose(model.get(), data.get(), ids, poses[f]);
    RgbdFrame frame = camera.render(data.get());
    stats.render_s += secondsSince(t0);
    integrator.submit(std::move(frame));
    ++stats.frames;
    if (progress) progress(static_cast<int>(f + 1), static_cast<int>(poses.size()));
  }
  integrator.finish();

  std::vector<planner::Landmark> landmarks = keptLandmarks(associator, config.min_observations, &stats);
  const Clock::time_point t_opportunities = Clock::now();
  countOpportunities(views, k, config, &landmarks);
  stats.opportunities_s = secondsSince(t_opportunities);
  map.setLandmarks(std::move(landmarks));
  stats.landmarks_merged = static_cast<int>(associator.tracks().size());
  stats.dropped_not_embedded = map.embedLandmarks(config.max_shift_m);
  stats.landmarks = static_cast<int>(map.landmarks().size());
  for (const planner::Landmark& lm : map.landmarks()) stats.mean_detectability += lm.detectability();
  if (stats.landmarks > 0) stats.mean_detectability /= stats.landmarks;
  stats.total_s = secondsSince(t_start);
  if (stats_out != nullptr) *stats_out = stats;
  return map;
}

}  // namespace tgnav::harness
