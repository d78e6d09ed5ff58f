#include "vo/odometry.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <utility>

#include "vo/check.h"
#include "vo/odometry_detail.h"
#include "vo/pose_refine.h"
#include "vo/stage_clock.h"

namespace tgnav::vo {

namespace {

using detail::descriptorBits;

// The time since the clock's previous lap, added to a stage of `result` (wall and CPU seconds).
void timeStage(StageClock& clock, double FrameResult::Timing::*stage, FrameResult* result) {
  const StageClock::Lap lap = clock.lap();
  result->timing.*stage += lap.wall_s;
  result->cpu.*stage += lap.cpu_s;
}

// Keypoints bucketed on a coarse grid, for window searches around a predicted pixel. Each
// cell's keypoints, in index order, are stored one after another with their pixel and descriptor
// (the search reads them in sequence instead of gathering them from the frame).
class KeypointGrid {
 public:
  struct Entry {
    float x = 0.0f, y = 0.0f;  // the keypoint's pixel
    int index = 0;             // the keypoint's index in the frame
    std::array<std::uint64_t, 4> bits{};
  };

  KeypointGrid(const Features& f, int width, int height, double cell_px)
      : cell_(cell_px),
        cols_(std::max(1, static_cast<int>(std::ceil(width / cell_px)))),
        rows_(std::max(1, static_cast<int>(std::ceil(height / cell_px)))),
        start_(static_cast<std::size_t>(cols_) * static_cast<std::size_t>(rows_) + 1, 0) {
    const std::size_t n = f.keypoints.size();
    std::vector<std::size_t> cell_of(n);
    for (std::size_t i = 0; i < n; ++i) {
      const int cx = std::clamp(static_cast<int>(f.keypoints[i].pt.x / cell_), 0, cols_ - 1);
      const int cy = std::clamp(static_cast<int>(f.keypoints[i].pt.y / cell_), 0, rows_ - 1);
      cell_of[i] = cellIndex(cx, cy);
      ++start_[cell_of[i] + 1];
    }
    for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    entries_.resize(n);
    std::vector<std::size_t> next(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i) {  // a stable counting sort: index order within a cell
      Entry& e = entries_[next[cell_of[i]]++];
      e.x = f.keypoints[i].pt.x;
      e.y = f.keypoints[i].pt.y;
      e.index = static_cast<int>(i);
      e.bits = descriptorBits(f.descriptors, static_cast<int>(i));
    }
  }
  // Calls fn(entry) for the keypoints of the 3x3 cells around (u, v), row by row of cells.
  template <typename Fn>
  void forEachNear(double u, double v, Fn fn) const {
    const int cx = static_cast<int>(std::floor(u / cell_));
    const int cy = static_cast<int>(std::floor(v / cell_));
    const int x0 = std::max(0, cx - 1), x1 = std::min(cols_ - 1, cx + 1);
    for (int y = std::max(0, cy - 1); y <= std::min(rows_ - 1, cy + 1); ++y) {
      // The row's cells are consecutive: one run of entries.
      const std::size_t end = start_[cellIndex(x1, y) + 1];
      for (std::size_t k = start_[cellIndex(x0, y)]; k < end; ++k) fn(entries_[k]);
    }
  }

 private:
  // The cell of column x, row y (both in range, so not negative), widened before multiplying.
  std::size_t cellIndex(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(cols_) + static_cast<std::size_t>(x);
  }

  double cell_;
  int cols_;
  int rows_;
  std::vector<std::size_t> start_;  // per cell, where its entries begin (and one past the last)
  std::vector<Entry> entries_;
};

// Bits set, by the parallel bit count: a dozen instructions inline. __builtin_popcountll without
// -mpopcnt (Debian's x86-64 baseline) calls libgcc's table-driven __popcountdi2 instead.
struct SoftPopcount {
  static int count(std::uint64_t x) {
    x -= (x >> 1) & 0x5555555555555555ULL;
    x = (x & 0x3333333333333333ULL) + ((x >> 2) & 0x3333333333333333ULL);
    x = (x + (x >> 4)) & 0x0F0F0F0F0F0F0F0FULL;
    return static_cast<int>((x * 0x0101010101010101ULL) >> 56);
  }
};
// The CPU's instruction, where the caller was compiled for it (nearestWithPopcnt below).
struct BuiltinPopcount {
  static int count(std::uint64_t x) { return __builtin_popcountll(x); }
};

template <typename Popcount>
int hamming(const std::array<std::uint64_t, 4>& a, const std::array<std::uint64_t, 4>& b) {
  return Popcount::count(a[0] ^ b[0]) + Popcount::count(a[1] ^ b[1]) + Popcount::count(a[2] ^ b[2]) +
         Popcount::count(a[3] ^ b[3]);
}

// The keypoints within sqrt(r2) of (u, v) nearest to a descriptor: the best and second-best
// Hamming distances and the best one's index (-1: none in the window). Ties keep the first in
// the grid's order.
struct Nearest {
  int best = std::numeric_limits<int>::max();
  int second = std::numeric_limits<int>::max();
  int index = -1;
};

template <typename Popcount>
inline Nearest nearestInWindow(const KeypointGrid& grid, double u, double v, double r2,
                               const std::array<std::uint64_t, 4>& descriptor) {
  Nearest n;
  grid.forEachNear(u, v, [&](const KeypointGrid::Entry& e) {
    const double du = e.x - u;
    const double dv = e.y - v;
    if (du * du + dv * dv > r2) return;
    const int d = hamming<Popcount>(descriptor, e.bits);
    if (d < n.best) {
      n.second = n.best;
      n.best = d;
      n.index = e.index;
    } else if (d < n.second) {
      n.second = d;
    }
  });
  return n;
}

using NearestFn = Nearest (*)(const KeypointGrid&, double, double, double, const std::array<std::uint64_t, 4>&);

Nearest nearestPortable(const KeypointGrid& grid, double u, double v, double r2,
                        const std::array<std::uint64_t, 4>& descriptor) {
  return nearestInWindow<SoftPopcount>(grid, u, v, r2, descriptor);
}

#if defined(__x86_64__) && defined(__GNUC__)
// The same compiled for x86's POPCNT (every x86-64 CPU since 2008; chosen at run time), which
// counts a word's bits in one instruction: matching's Hamming distances at a third of the cost.
__attribute__((target("popcnt"))) Nearest nearestWithPopcnt(const KeypointGrid& grid, double u, double v, double r2,
                                                            const std::array<std::uint64_t, 4>& descriptor) {
  return nearestInWindow<BuiltinPopcount>(grid, u, v, r2, descriptor);
}
#endif

// The window search for this CPU. Both give the same distances, so the same matches.
NearestFn nearestForThisCpu() {
#if defined(__x86_64__) && defined(__GNUC__)
  if (__builtin_cpu_supports("popcnt")) return nearestWithPopcnt;
#endif
  return nearestPortable;
}

cv::Matx33d cameraMatrix(const CameraIntrinsics& c) {
  return cv::Matx33d(c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0);
}

cv::Mat toGray(const cv::Mat& image) {
  if (image.type() == CV_8UC1) return image;
  cv::Mat gray;
  cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  return gray;
}

}  // namespace

void OdometryConfig::validate() const {
  features.validate();
  require(std::isfinite(min_depth_m) && min_depth_m > 0.0, "min_depth_m", min_depth_m, "must be > 0");
  require(std::isfinite(max_depth_m) && max_depth_m > min_depth_m, "max_depth_m", max_depth_m, "must be > min_depth_m");
  require(std::isfinite(depth_edge_m) && depth_edge_m > 0.0, "depth_edge_m", depth_edge_m, "must be > 0");
  require(std::isfinite(depth_edge_radius_px) && depth_edge_radius_px >= 0.0 && depth_edge_radius_px <= 32.0,
          "depth_edge_radius_px", depth_edge_radius_px, "must be in [0, 32]");
  require(init_min_features >= 4, "init_min_features", init_min_features, "must be >= 4");
  require(min_inliers >= 4, "min_inliers", min_inliers, "must be >= 4 (PnP)");
  require(weak_inliers >= min_inliers, "weak_inliers", weak_inliers, "must be >= min_inliers");
  require(std::isfinite(search_radius_px) && search_radius_px > 0.0, "search_radius_px", search_radius_px,
          "must be > 0");
  require(max_descriptor_distance > 0 && max_descriptor_distance <= 256, "max_descriptor_distance",
          max_descriptor_distance, "must be in 1..256");
  require(ratio_test > 0.0 && ratio_test <= 1.0, "ratio_test", ratio_test, "must be in (0, 1]");
  require(ransac_reprojection_px > 0.0, "ransac_reprojection_px", ransac_reprojection_px, "must be > 0");
  require(ransac_iterations >= 1, "ransac_iterations", ransac_iterations, "must be >= 1");
  require(ransac_confidence > 0.0 && ransac_confidence < 1.0, "ransac_confidence", ransac_confidence,
          "must be in (0, 1)");
  require(local_map_keyframes >= 1, "local_map_keyframes", local_map_keyframes, "must be >= 1");
  require(keyframe_inlier_ratio > 0.0 && keyframe_inlier_ratio <= 1.0, "keyframe_inlier_ratio", keyframe_inlier_ratio,
          "must be in (0, 1]");
  require(keyframe_translation_m > 0.0, "keyframe_translation_m", keyframe_translation_m, "must be > 0");
  require(keyframe_rotation_rad > 0.0, "keyframe_rotation_rad", keyframe_rotation_rad, "must be > 0");
  require(keyframe_richer_ratio == 0.0 || (std::isfinite(keyframe_richer_ratio) && keyframe_richer_ratio > 1.0),
          "keyframe_richer_ratio", keyframe_richer_ratio, "must be 0 (off) or > 1");
  require(keyframe_richer_ratio == 0.0 || keyframe_policy == KeyframePolicy::kRatio, "keyframe_richer_ratio",
          keyframe_richer_ratio, "applies to keyframe_policy ratio only (set it to 0 with orbslam2)");
  require(landmark_max_misses >= 1, "landmark_max_misses", landmark_max_misses, "must be >= 1");
  require(keyframe_reference_ratio > 0.0 && keyframe_reference_ratio <= 1.0, "keyframe_reference_ratio",
          keyframe_reference_ratio, "must be in (0, 1]");
  require(keyframe_max_frames >= 1, "keyframe_max_frames", keyframe_max_frames, "must be >= 1");
  require(std::isfinite(keyframe_close_depth_m) && keyframe_close_depth_m > 0.0, "keyframe_close_depth_m",
          keyframe_close_depth_m, "must be > 0");
  ba.validate();
}

const char* toString(TrackingStatus status) {
  switch (status) {
    case TrackingStatus::kOk:
      return "ok";
    case TrackingStatus::kWeak:
      return "weak";
    case TrackingStatus::kLost:
      return "lost";
  }
  return "?";
}

TrackingStatus decideStatus(int inliers, const OdometryConfig& config) {
  if (inliers < config.min_inliers) return TrackingStatus::kLost;
  return inliers < config.weak_inliers ? TrackingStatus::kWeak : TrackingStatus::kOk;
}

RgbdOdometry::RgbdOdometry(const CameraIntrinsics& camera, const OdometryConfig& config, const Eigen::Isometry3d& X_WC0)
    : camera_(camera),
      config_(config),
      detector_(config.features),
      X_WC0_(X_WC0),
      failed_at_(std::numeric_limits<double>::quiet_NaN()),
      last_t_(-std::numeric_limits<double>::infinity()),
      X_WC_(X_WC0) {
  config_.validate();
  require(camera.width_px > 0 && camera.height_px > 0, "camera.width_px", camera.width_px, "image size must be > 0");
  require(std::isfinite(camera.fx) && camera.fx > 0.0 && std::isfinite(camera.fy) && camera.fy > 0.0, "camera.fx",
          camera.fx, "focal lengths must be > 0");
  require(std::isfinite(camera.cx) && std::isfinite(camera.cy), "camera.cx", camera.cx, "must be finite");
}

FrameResult RgbdOdometry::track(const PreparedFrame& frame) {
  const double t_s = frame.t_s;
  if (!std::isfinite(t_s) || t_s <= last_t_) {
    std::ostringstream msg;
    msg << "frame time " << t_s << " s does not come after the previous frame's (" << last_t_ << " s)";
    throw std::invalid_argument(msg.str());
  }
  last_t_ = t_s;
  ++frame_;

  FrameResult result;
  result.t_s = t_s;
  result.X_WC = X_WC_;
  if (failed_ && !config_.reinitialise_after_lost) {
    std::ostringstream msg;
    msg << "lost at t = " << failed_at_ << " s (no re-initialisation)";
    result.reason = msg.str();
    return record(result);
  }
  StageClock clock;
  result.timing.features_s = frame.prepare_s;
  result.cpu.features_s = frame.prepare_cpu_s;
  result.features = static_cast<int>(frame.features.keypoints.size());
  result.with_depth = frame.with_depth;
  if (!initialised_) {
    FrameResult first = initialise(result, frame);
    timeStage(clock, &FrameResult::Timing::map_s, &first);
    return record(first);
  }

  applyDueAdjustment(&result);  // the bundle adjustment due now, if one is
  timeStage(clock, &FrameResult::Timing::ba_s, &result);
  const Attempt attempt = trackPose(frame, clock, &result);
  const LocalMapMatches& matches = attempt.matches;
  const PoseEstimate& pose = attempt.pose;
  result.matches = static_cast<int>(matches.object.size());
  if (result.matches < config_.min_inliers) {
    return lose(result, std::to_string(result.matches) + " matches < " + std::to_string(config_.min_inliers));
  }
  if (!pose.ransac_ok) {
    result.inliers = pose.ransac_inliers;
    return lose(result, std::to_string(result.inliers) + " PnP inliers < " + std::to_string(config_.min_inliers));
  }
  if (pose.inliers < 0) return lose(result, "PnP gave a non-finite pose");
  result.inliers = pose.inliers;
  for (std::size_t m = 0; m < pose.is_inlier.size(); ++m) {
    if (pose.is_inlier[m]) countColumn(matches.pixels[m].x, &result);
  }
  result.status = decideStatus(pose.inliers, config_);
  if (result.status == TrackingStatus::kLost) {
    return lose(result, std::to_string(pose.inliers) + " inliers < " + std::to_string(config_.min_inliers));
  }

  const Eigen::Isometry3d X_WC = pose.X_CW.inverse();
  velocity_ = X_WC_.inverse() * X_WC;
  X_WC_ = X_WC;
  result.keyframe_rule = updateLocalMap(frame, matches, pose);
  result.keyframe = !result.keyframe_rule.empty();
  timeStage(clock, &FrameResult::Timing::map_s, &result);
  if (result.keyframe && config_.ba.enabled) {
    adjustAfterKeyframe(&result);
    timeStage(clock, &FrameResult::Timing::ba_s, &result);
  }
  result.X_WC = X_WC_;
  return record(result);
}

void RgbdOdometry::checkImages(const cv::Mat& image, const cv::Mat& depth_m) const {
  if (image.empty() || (image.type() != CV_8UC1 && image.type() != CV_8UC3) || image.cols != camera_.width_px ||
      image.rows != camera_.height_px) {
    throw std::invalid_argument("image: expected 8-bit gray or BGR of " + std::to_string(camera_.width_px) + "x" +
                                std::to_string(camera_.height_px));
  }
  if (depth_m.type() != CV_32FC1 || depth_m.cols != camera_.width_px || depth_m.rows != camera_.height_px) {
    throw std::invalid_argument("depth: expected CV_32FC1 metres of " + std::to_string(camera_.width_px) + "x" +
                                std::to_string(camera_.height_px));
  }
}

void RgbdOdometry::countColumn(double u_px, FrameResult* result) const {
  const int bin = static_cast<int>(std::floor(u_px / camera_.width_px * FrameResult::kColumnBins));
  ++result->inlier_columns[static_cast<std::size_t>(std::clamp(bin, 0, FrameResult::kColumnBins - 1))];
}

RgbdOdometry::PreparedFrame RgbdOdometry::prepare(double t_s, const cv::Mat& image, const cv::Mat& depth_m) const {
  checkImages(image, depth_m);
  StageClock clock;
  PreparedFrame frame;
  frame.t_s = t_s;
  frame.features = detector_.detect(toGray(image));
  const std::size_t n = frame.features.keypoints.size();
  frame.p_C.resize(n);
  frame.valid.assign(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    if (!backProject(frame.features.keypoints[i], depth_m, &frame.p_C[i])) continue;
    frame.valid[i] = true;
    ++frame.with_depth;
  }
  const StageClock::Lap lap = clock.lap();
  frame.prepare_s = lap.wall_s;
  frame.prepare_cpu_s = lap.cpu_s;
  return frame;
}

// The keypoint's 3D point in the camera frame, if its depth is in range and reliable.
bool RgbdOdometry::backProject(const cv::KeyPoint& keypoint, const cv::Mat& depth_m, Eigen::Vector3d* p_C) const {
  const int u = static_cast<int>(std::lround(keypoint.pt.x));
  const int v = static_cast<int>(std::lround(keypoint.pt.y));
  const int r =
      config_.depth_edge_radius_px > 0.0
          ? std::max(
                1, static_cast<int>(std::lround(config_.depth_edge_radius_px *
                                                std::pow(config_.features.scale_factor, std::max(0, keypoint.octave)))))
          : 1;
  if (u < r || v < r || u >= depth_m.cols - r || v >= depth_m.rows - r) return false;
  const float z = depth_m.at<float>(v, u);
  if (!std::isfinite(z) || z < config_.min_depth_m || z > config_.max_depth_m) return false;
  // Depth discontinuity: a keypoint on an object's silhouette has no reliable depth.
  float lo = z, hi = z;
  bool holes = false;
  for (int dv = -r; dv <= r; ++dv) {
    for (int du = -r; du <= r; ++du) {
      const float d = depth_m.at<float>(v + dv, u + du);
      if (!std::isfinite(d) || d <= 0.0f) holes = true;
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
  }
  if (holes || hi - lo > config_.depth_edge_m * z) return false;
  const double x = (keypoint.pt.x - camera_.cx) * z / camera_.fx;
  const double y = (keypoint.pt.y - camera_.cy) * z / camera_.fy;
  *p_C = Eigen::Vector3d(x, y, z);
  return true;
}

FrameResult RgbdOdometry::initialise(FrameResult result, const PreparedFrame& frame) {
  if (result.with_depth < config_.init_min_features) {
    result.status = TrackingStatus::kLost;
    result.reason = std::to_string(result.with_depth) + " features with depth < " +
                    std::to_string(config_.init_min_features) + " to initialise";
    markFailed(result.t_s);
    return result;
  }
  initialised_ = true;
  result.reinitialised = !history_.empty();
  X_WC_ = X_WC0_;
  velocity_.setIdentity();
  dropBundleAdjustment();
  landmarks_.clear();
  keyframes_.clear();
  retired_.clear();
  keyframes_since_init_ = 0;
  addKeyframe(X_WC_, frame, std::vector<int>(frame.features.keypoints.size(), -1), 0);
  result.X_WC = X_WC_;
  result.status = TrackingStatus::kOk;
  result.inliers = result.with_depth;
  for (std::size_t i = 0; i < frame.valid.size(); ++i) {
    if (frame.valid[i]) countColumn(frame.features.keypoints[i].pt.x, &result);
  }
  result.keyframe = true;
  result.keyframe_rule = "first";
  return result;
}

RgbdOdometry::Attempt RgbdOdometry::attemptPose(const PreparedFrame& frame, const Eigen::Isometry3d& X_CW_pred,
                                                double radius_px, StageClock& clock, FrameResult* result) const {
  Attempt a;
  a.matches = matchLocalMap(frame, X_CW_pred, radius_px);
  timeStage(clock, &FrameResult::Timing::matching_s, result);
  if (static_cast<int>(a.matches.object.size()) >= config_.min_inliers) {
    a.pose = estimatePose(a.matches, X_CW_pred);
    timeStage(clock, &FrameResult::Timing::pnp_s, result);
  }
  return a;
}

RgbdOdometry::Attempt RgbdOdometry::trackPose(const PreparedFrame& frame, StageClock& clock,
                                              FrameResult* result) const {
  const Eigen::Isometry3d X_CW_pred = predictPose().inverse();
  Attempt a = attemptPose(frame, X_CW_pred, config_.search_radius_px, clock, result);
  if (!config_.wide_retry || a.tracks(config_.min_inliers)) return a;
  for (const Eigen::Isometry3d& from : {X_CW_pred, Eigen::Isometry3d(X_WC_.inverse())}) {
    Attempt wide = attemptPose(frame, from, 2.0 * config_.search_radius_px, clock, result);
    if (wide.tracks(config_.min_inliers)) return wide;
  }
  return a;  // what the prediction's own window gave: why it is lost
}

// Matches the local map's landmarks to the frame's keypoints around their predicted pixels.
RgbdOdometry::LocalMapMatches RgbdOdometry::matchLocalMap(const PreparedFrame& frame,
                                                          const Eigen::Isometry3d& X_CW_pred, double radius) const {
  const Features& f = frame.features;
  const KeypointGrid grid(f, camera_.width_px, camera_.height_px, radius);
  const double r2 = radius * radius;
  static const NearestFn nearest = nearestForThisCpu();
  LocalMapMatches m;
  m.landmark_of.assign(f.keypoints.size(), -1);
  std::vector<int> best_distance(f.keypoints.size(), std::numeric_limits<int>::max());
  m.expected.assign(landmarks_.size(), false);
  for (std::size_t l = 0; l < landmarks_.size(); ++l) {
    const Eigen::Vector3d q = X_CW_pred * landmarks_[l].p_W;
    if (q.z() < config_.min_depth_m) continue;
    const double u = camera_.fx * q.x() / q.z() + camera_.cx;
    const double v = camera_.fy * q.y() / q.z() + camera_.cy;
    if (u < 0.0 || v < 0.0 || u > camera_.width_px - 1 || v > camera_.height_px - 1) continue;
    m.expected[l] = true;
    const Nearest n = nearest(grid, u, v, r2, landmarks_[l].descriptor);
    const int best = n.best, second = n.second, best_i = n.index;
    if (best_i < 0 || best > config_.max_descriptor_distance) continue;
    if (second != std::numeric_limits<int>::max() && best >= config_.ratio_test * second) continue;
    const std::size_t k = static_cast<std::size_t>(best_i);
    if (best < best_distance[k]) {  // one landmark per keypoint: the closest in descriptor space
      best_distance[k] = best;
      m.landmark_of[k] = static_cast<int>(l);
    }
  }
  for (std::size_t i = 0; i < f.keypoints.size(); ++i) {
    if (m.landmark_of[i] < 0) continue;
    const Eigen::Vector3d& p = landmarks_[static_cast<std::size_t>(m.landmark_of[i])].p_W;
    m.object.emplace_back(p.x(), p.y(), p.z());
    m.pixels.emplace_back(f.keypoints[i].pt.x, f.keypoints[i].pt.y);
    m.keypoint.push_back(static_cast<int>(i));
    m.depth_m.push_back(frame.valid[i] ? frame.p_C[i].z() : 0.0);
  }
  return m;
}

// Pose: PnP RANSAC from the prediction, Levenberg-Marquardt on the inliers, inliers again.
RgbdOdometry::PoseEstimate RgbdOdometry::estimatePose(const LocalMapMatches& matches,
                                                      const Eigen::Isometry3d& X_CW_pred) const {
  const cv::Matx33d K = cameraMatrix(camera_);
  cv::Mat rvec, tvec;
  {
    cv::Mat R;
    cv::eigen2cv(Eigen::Matrix3d(X_CW_pred.linear()), R);
    cv::Rodrigues(R, rvec);
    cv::eigen2cv(Eigen::Vector3d(X_CW_pred.translation()), tvec);
  }
  std::vector<int> inliers;
  PoseEstimate pose;
  const bool ok = cv::solvePnPRansac(matches.object, matches.pixels, K, cv::noArray(), rvec, tvec, true,
                                     config_.ransac_iterations, static_cast<float>(config_.ransac_reprojection_px),
                                     config_.ransac_confidence, inliers, cv::SOLVEPNP_EPNP);
  pose.ransac_inliers = static_cast<int>(inliers.size());
  pose.ransac_ok = ok && pose.ransac_inliers >= config_.min_inliers;
  if (!pose.ransac_ok) return pose;
  std::vector<cv::Point3d> obj_in;
  std::vector<cv::Point2d> pix_in;
  std::vector<double> depth_in;
  for (int i : inliers) {
    obj_in.push_back(matches.object[static_cast<std::size_t>(i)]);
    pix_in.push_back(matches.pixels[static_cast<std::size_t>(i)]);
    depth_in.push_back(matches.depth_m[static_cast<std::size_t>(i)]);
  }
  Eigen::Isometry3d X_CW_ransac = Eigen::Isometry3d::Identity();
  {
    cv::Mat R;
    cv::Rodrigues(rvec, R);
    Eigen::Matrix3d R_CW;
    Eigen::Vector3d t_CW;
    cv::cv2eigen(R, R_CW);
    cv::cv2eigen(tvec, t_CW);
    X_CW_ransac.linear() = R_CW;
    X_CW_ransac.translation() = t_CW;
  }
  // Levenberg-Marquardt on RANSAC's inliers from two starts: RANSAC's pose, which EPnP on a
  // near-planar set (a wall filling the view) can get badly wrong, and the motion-model
  // prediction. The start whose refined pose has more inliers among all matches wins.
  pose.inliers = refinePose(matches, obj_in, pix_in, depth_in, X_CW_ransac, &pose.X_CW, &pose.is_inlier);
  Eigen::Isometry3d X_CW_alt;
  std::vector<bool> alt_inlier;
  const int n_alt = refinePose(matches, obj_in, pix_in, depth_in, X_CW_pred, &X_CW_alt, &alt_inlier);
  if (n_alt > pose.inliers) {
    pose.inliers = n_alt;
    pose.X_CW = X_CW_alt;
    pose.is_inlier = std::move(alt_inlier);
  }
  return pose;
}

// Levenberg-Marquardt from `start` on RANSAC's inliers (vo/pose_refine.h; with pose_depth, their
// measured depths too); returns the refined pose's inliers among all matches (reprojection within
// ransac_reprojection_px), -1 if it failed.
int RgbdOdometry::refinePose(const LocalMapMatches& matches, const std::vector<cv::Point3d>& object_in,
                             const std::vector<cv::Point2d>& pixels_in, const std::vector<double>& depth_in,
                             const Eigen::Isometry3d& start, Eigen::Isometry3d* X_CW,
                             std::vector<bool>* is_inlier) const {
  *X_CW = start;
  is_inlier->assign(matches.object.size(), false);
  PoseDepth depth;
  if (config_.pose_depth) {
    depth.depth_m = &depth_in;
    depth.bf_px = camera_.fx * config_.ba.virtual_baseline_m;
    depth.depth_sigma_px = config_.ba.depth_sigma_px;
  }
  if (!refinePoseLm(object_in, pixels_in, camera_, X_CW, 20, depth).ok) return -1;
  const double thr2 = config_.ransac_reprojection_px * config_.ransac_reprojection_px;
  int n = 0;
  for (std::size_t m = 0; m < matches.object.size(); ++m) {
    const cv::Point3d& o = matches.object[m];
    const Eigen::Vector3d q = *X_CW * Eigen::Vector3d(o.x, o.y, o.z);
    if (q.z() <= 0.0) continue;
    const double du = camera_.fx * q.x() / q.z() + camera_.cx - matches.pixels[m].x;
    const double dv = camera_.fy * q.y() / q.z() + camera_.cy - matches.pixels[m].y;
    if (du * du + dv * dv <= thr2) {
      (*is_inlier)[m] = true;
      ++n;
    }
  }
  return n;
}

// Lost: the last good pose stands; with reinitialise_after_lost the next frame with enough
// features starts again from it.
FrameResult RgbdOdometry::lose(FrameResult result, const std::string& why) {
  result.status = TrackingStatus::kLost;
  result.reason = why;
  result.X_WC = X_WC_;
  markFailed(result.t_s);
  if (config_.reinitialise_after_lost) {
    initialised_ = false;
    X_WC0_ = X_WC_;  // carry on from the last good pose
    dropBundleAdjustment();
    landmarks_.clear();
    keyframes_.clear();
    retired_.clear();
    velocity_.setIdentity();
  }
  return record(result);
}

void RgbdOdometry::markFailed(double t_s) {
  if (failed_) return;
  failed_ = true;
  failed_at_ = t_s;
}

FrameResult RgbdOdometry::record(const FrameResult& result) {
  history_.push_back(result);
  return result;
}

}  // namespace tgnav::vo
