// The odometry's local map: landmark bookkeeping after a tracked frame, the keyframe policies,
// keyframes, and the local bundle adjustment (inline, or on a thread of its own with a fixed
// latency in frames). vo/odometry.h describes the rules; this file implements them.
#include <algorithm>
#include <cmath>
#include <future>
#include <unordered_map>
#include <utility>

#include "vo/odometry.h"
#include "vo/odometry_detail.h"
#include "vo/stage_clock.h"

namespace tgnav::vo {

using detail::descriptorBits;
using detail::rotationAngle;

namespace {

// ORB-SLAM2's count of an observation: one with depth (its virtual stereo pair) counts twice.
int observationWeight(double depth_m) { return depth_m > 0.0 ? 2 : 1; }

// ORB-SLAM2's close-point thresholds (Tracking::NeedNewKeyFrame).
constexpr int kCloseTrackedFew = 100;
constexpr int kCloseUntrackedMany = 70;
constexpr int kMinTrackedForKeyframe = 15;

}  // namespace

// After a tracked frame: landmark bookkeeping, a keyframe if needed, culling. Returns the rules
// that made the frame a keyframe (empty: it is not one).
std::string RgbdOdometry::updateLocalMap(const PreparedFrame& frame, const LocalMapMatches& matches,
                                         const PoseEstimate& pose) {
  // Landmark bookkeeping: matched inliers are fresh, expected but unmatched ones age.
  std::vector<bool> seen(landmarks_.size(), false);
  std::vector<int> matched_landmark(frame.features.keypoints.size(), -1);
  for (std::size_t m = 0; m < matches.object.size(); ++m) {
    if (!pose.is_inlier[m]) continue;
    const int k = matches.keypoint[m];
    const int l = matches.landmark_of[static_cast<std::size_t>(k)];
    seen[static_cast<std::size_t>(l)] = true;
    matched_landmark[static_cast<std::size_t>(k)] = l;
  }
  for (std::size_t l = 0; l < landmarks_.size(); ++l) {
    if (seen[l]) {
      landmarks_[l].misses = 0;
    } else if (matches.expected[l]) {
      ++landmarks_[l].misses;
    }
  }
  std::string keyframe = config_.keyframe_policy == KeyframePolicy::kRatio
                             ? ratioRules(pose.inliers, frame.with_depth)
                             : orbSlam2Rules(pose.inliers, frame, matched_landmark);
  if (!keyframe.empty()) addKeyframe(X_WC_, frame, matched_landmark, pose.inliers);
  // Cull landmarks that keep failing to match where they should be seen (after the keyframe
  // step, which indexes landmarks_ through matched_landmark).
  landmarks_.erase(std::remove_if(landmarks_.begin(), landmarks_.end(),
                                  [&](const Landmark& lm) { return lm.misses > config_.landmark_max_misses; }),
                   landmarks_.end());
  return keyframe;
}

namespace {

// Appends `name` to a '+'-joined list when `fires`.
void addRule(bool fires, const char* name, std::string* rules) {
  if (fires) *rules += (rules->empty() ? "" : "+") + std::string(name);
}

}  // namespace

// Keyframe (ratio): tracking thins out, or the camera moved or turned enough since the last one,
// or the view offers far more features with depth than the last one tracked and created.
std::string RgbdOdometry::ratioRules(int inliers, int with_depth) const {
  const Keyframe& last = keyframes_.back();
  const Eigen::Isometry3d rel = last.X_WC.inverse() * X_WC_;
  std::string rules;
  addRule(inliers < config_.keyframe_inlier_ratio * last.tracked, "inliers", &rules);
  addRule(rel.translation().norm() > config_.keyframe_translation_m, "translation", &rules);
  addRule(rotationAngle(rel.linear()) > config_.keyframe_rotation_rad, "rotation", &rules);
  addRule(config_.keyframe_richer_ratio > 0.0 && with_depth > config_.keyframe_richer_ratio * last.tracked, "richer",
          &rules);
  return rules;
}

// Keyframe (orbslam2): ORB-SLAM2's Tracking::NeedNewKeyFrame for an RGB-D camera, with the last
// keyframe as the reference and "local mapping idle" as no bundle adjustment in flight.
std::string RgbdOdometry::orbSlam2Rules(int inliers, const PreparedFrame& frame,
                                        const std::vector<int>& matched_landmark) const {
  const int min_observations = keyframes_since_init_ <= 2 ? 2 : 3;
  const int reference_id = keyframes_.back().id;
  int reference = 0;  // the reference keyframe's landmarks that are well observed
  for (const Landmark& lm : landmarks_) {
    if (lm.keyframe == reference_id && lm.observations >= min_observations) ++reference;
  }
  int tracked_close = 0, untracked_close = 0;
  for (std::size_t i = 0; i < frame.features.keypoints.size(); ++i) {
    if (!frame.valid[i] || frame.p_C[i].z() >= config_.keyframe_close_depth_m) continue;
    ++(matched_landmark[i] >= 0 ? tracked_close : untracked_close);
  }
  const bool need_close = tracked_close < kCloseTrackedFew && untracked_close > kCloseUntrackedMany;
  const double ratio = keyframes_since_init_ < 2 ? 0.4 : config_.keyframe_reference_ratio;
  const bool few_reference = inliers < ratio * reference;
  const bool waited = frame_ - last_keyframe_frame_ >= config_.keyframe_max_frames;
  const bool mapping_idle = ba_job_ == nullptr;
  const bool weak = inliers < 0.25 * reference || need_close;
  std::string rules;
  if ((waited || mapping_idle || weak) && (few_reference || need_close) && inliers > kMinTrackedForKeyframe) {
    addRule(few_reference, "reference", &rules);
    addRule(need_close, "close", &rules);
  }
  return rules;
}

void RgbdOdometry::addKeyframe(const Eigen::Isometry3d& X_WC, const PreparedFrame& frame,
                               const std::vector<int>& matched_landmark, int tracked) {
  Keyframe kf;
  kf.id = next_keyframe_id_++;
  kf.X_WC = X_WC;
  int created = 0;
  const double sigma_step = config_.features.scale_factor;
  for (std::size_t i = 0; i < frame.features.keypoints.size(); ++i) {
    const cv::KeyPoint& kp = frame.features.keypoints[i];
    Observation obs;
    obs.uv = Eigen::Vector2d(kp.pt.x, kp.pt.y);
    obs.depth_m = frame.valid[i] ? frame.p_C[i].z() : 0.0;
    obs.sigma_px = std::pow(sigma_step, std::max(0, kp.octave));
    if (matched_landmark[i] >= 0) {  // tracked: the landmark exists, and now belongs here
      Landmark& lm = landmarks_[static_cast<std::size_t>(matched_landmark[i])];
      obs.landmark = lm.id;
      lm.keyframe = kf.id;
      lm.observations += observationWeight(obs.depth_m);
      kf.observations.push_back(obs);
      continue;
    }
    if (!frame.valid[i]) continue;
    Landmark lm;
    lm.id = next_landmark_id_++;
    obs.landmark = lm.id;
    kf.observations.push_back(obs);
    lm.p_W = X_WC * frame.p_C[i];
    lm.descriptor = descriptorBits(frame.features.descriptors, static_cast<int>(i));
    lm.keyframe = kf.id;
    lm.observations = observationWeight(obs.depth_m);
    landmarks_.push_back(std::move(lm));
    ++created;
  }
  kf.tracked = tracked + created;
  keyframes_.push_back(kf);
  ++keyframes_since_init_;
  last_keyframe_frame_ = frame_;
  // The local map: landmarks observed by the last local_map_keyframes keyframes (a landmark
  // belongs to the newest keyframe that observed it, and leaves the map with that keyframe).
  while (static_cast<int>(keyframes_.size()) > config_.local_map_keyframes) {
    const int gone = keyframes_.front().id;
    // It stays, fixed, in bundle adjustment's window for a while: its observations of the
    // landmarks that outlive it anchor them.
    retired_.push_back(std::move(keyframes_.front()));
    while (static_cast<int>(retired_.size()) > config_.ba.fixed_keyframes) retired_.pop_front();
    keyframes_.pop_front();
    landmarks_.erase(
        std::remove_if(landmarks_.begin(), landmarks_.end(), [&](const Landmark& lm) { return lm.keyframe == gone; }),
        landmarks_.end());
  }
}

// Local bundle adjustment: the local map's keyframes are free, the last ba.fixed_keyframes that
// left it are fixed (the gauge; until there are any, the oldest local keyframe is fixed), and
// every landmark they observe is free. Returns nullptr when there is nothing to adjust.
std::unique_ptr<RgbdOdometry::BaJob> RgbdOdometry::startBundleAdjustment() {
  if (retired_.empty() && keyframes_.size() < 2) return nullptr;
  auto job = std::make_unique<BaJob>();
  std::vector<const Keyframe*> window;
  for (const Keyframe& kf : retired_) window.push_back(&kf);
  for (const Keyframe& kf : keyframes_) window.push_back(&kf);
  job->fixed = retired_.empty() ? 1 : retired_.size();
  std::unordered_map<long, int> index_of;  // landmark id -> index in landmarks_
  index_of.reserve(landmarks_.size());
  for (std::size_t l = 0; l < landmarks_.size(); ++l) index_of.emplace(landmarks_[l].id, static_cast<int>(l));

  BaProblem& problem = job->problem;
  std::vector<int> in_problem(landmarks_.size(), -1);  // landmarks_ index -> problem landmark
  for (std::size_t k = 0; k < window.size(); ++k) {
    job->keyframe_ids.push_back(window[k]->id);
    problem.X_CW.push_back(window[k]->X_WC.inverse());
    problem.fixed.push_back(k < job->fixed);
    const std::vector<Observation>& obs = window[k]->observations;
    for (std::size_t o = 0; o < obs.size(); ++o) {
      const auto found = index_of.find(obs[o].landmark);
      if (found == index_of.end()) continue;  // culled, or gone with its keyframe
      int& j = in_problem[static_cast<std::size_t>(found->second)];
      if (j < 0) {
        j = static_cast<int>(problem.p_W.size());
        problem.p_W.push_back(landmarks_[static_cast<std::size_t>(found->second)].p_W);
        job->landmark_index.push_back(found->second);
        job->landmark_ids.push_back(obs[o].landmark);
      }
      BaObservation b;
      b.keyframe = static_cast<int>(k);
      b.landmark = j;
      b.uv = obs[o].uv;
      b.depth_m = obs[o].depth_m;
      b.sigma_px = obs[o].sigma_px;
      problem.observations.push_back(b);
      job->source.emplace_back(static_cast<int>(k), static_cast<int>(o));
    }
  }
  job->newest_before = keyframes_.back().X_WC;
  job->next_landmark_id = next_landmark_id_;
  job->copied_at = frame_;
  job->apply_at = frame_ + config_.ba.latency_frames;
  BaJob* j = job.get();
  auto solve = [j, camera = camera_, ba = config_.ba] {
    StageClock clock;
    j->report = bundleAdjust(&j->problem, camera, ba);
    j->solve_cpu_s = clock.lap().cpu_s;
  };
  if (config_.ba.latency_frames > 0) {
    j->solving = std::async(std::launch::async, solve);
  } else {
    solve();
  }
  return job;
}

namespace {

// Keeps the elements whose flag is false, in order.
template <typename T>
void eraseFlagged(std::vector<T>* items, const std::vector<bool>& flagged) {
  std::size_t w = 0;
  for (std::size_t i = 0; i < items->size(); ++i) {
    if (!flagged[i]) (*items)[w++] = std::move((*items)[i]);
  }
  items->resize(w);
}

}  // namespace

// Applies a solved adjustment (waiting for its thread) to what is still in the map: the window's
// free keyframes and its landmarks take their adjusted values, outlier observations go, and a
// landmark left without any inlier goes too unless a later keyframe observed it. Copied at this
// very frame, the current pose becomes the newest keyframe's; otherwise it, and the keyframes and
// landmarks added since the copy, move with the newest keyframe's correction.
void RgbdOdometry::applyBundleAdjustment(BaJob& job, FrameResult* result) {
  if (job.solving.valid()) {  // solved on its own thread: its CPU is not this thread's
    job.solving.get();
    result->cpu.ba_s += job.solve_cpu_s;
  }
  if (!job.report.solved) return;
  const BaProblem& problem = job.problem;
  const bool same_frame = job.copied_at == frame_;
  std::unordered_map<int, Keyframe*> keyframe_of;
  for (Keyframe& kf : retired_) keyframe_of.emplace(kf.id, &kf);
  for (Keyframe& kf : keyframes_) keyframe_of.emplace(kf.id, &kf);
  std::vector<Keyframe*> window(job.keyframe_ids.size(), nullptr);
  for (std::size_t k = 0; k < window.size(); ++k) {
    const auto found = keyframe_of.find(job.keyframe_ids[k]);
    if (found != keyframe_of.end()) window[k] = found->second;
  }
  for (std::size_t k = job.fixed; k < window.size(); ++k) {
    if (window[k] != nullptr) window[k]->X_WC = problem.X_CW[k].inverse();
  }
  // Landmarks by id: at the copy's frame they are where the copy found them.
  std::vector<int> index(job.landmark_ids.size(), -1);
  if (same_frame) {
    index = job.landmark_index;
  } else {
    std::unordered_map<long, int> index_of;
    for (std::size_t l = 0; l < landmarks_.size(); ++l) index_of.emplace(landmarks_[l].id, static_cast<int>(l));
    for (std::size_t j = 0; j < index.size(); ++j) {
      const auto found = index_of.find(job.landmark_ids[j]);
      if (found != index_of.end()) index[j] = found->second;
    }
  }
  for (std::size_t j = 0; j < index.size(); ++j) {
    if (index[j] >= 0) landmarks_[static_cast<std::size_t>(index[j])].p_W = problem.p_W[j];
  }
  // Outlier observations go; a landmark with no observation left in the window goes too.
  std::vector<int> inliers_of(problem.p_W.size(), 0);
  std::vector<std::vector<bool>> drop(window.size());
  for (std::size_t k = 0; k < window.size(); ++k) {
    if (window[k] != nullptr) drop[k].assign(window[k]->observations.size(), false);
  }
  for (std::size_t i = 0; i < problem.observations.size(); ++i) {
    const BaObservation& o = problem.observations[i];
    if (!job.report.outlier[i]) {
      ++inliers_of[static_cast<std::size_t>(o.landmark)];
      continue;
    }
    const auto [k, obs] = job.source[i];
    if (window[static_cast<std::size_t>(k)] == nullptr) continue;
    drop[static_cast<std::size_t>(k)][static_cast<std::size_t>(obs)] = true;
    const int l = index[static_cast<std::size_t>(o.landmark)];
    if (l >= 0) landmarks_[static_cast<std::size_t>(l)].observations -= observationWeight(o.depth_m);
  }
  for (std::size_t k = 0; k < window.size(); ++k) {
    if (window[k] != nullptr) eraseFlagged(&window[k]->observations, drop[k]);
  }
  const int newest_id = job.keyframe_ids.back();
  std::vector<bool> remove(landmarks_.size(), false);
  for (std::size_t j = 0; j < index.size(); ++j) {
    const int l = index[j];
    if (l >= 0 && inliers_of[j] == 0 && landmarks_[static_cast<std::size_t>(l)].keyframe <= newest_id) {
      remove[static_cast<std::size_t>(l)] = true;
    }
  }
  eraseFlagged(&landmarks_, remove);

  const Eigen::Isometry3d newest_after = problem.X_CW.back().inverse();
  if (same_frame) {
    X_WC_ = newest_after;
  } else {
    const Eigen::Isometry3d correction = newest_after * job.newest_before.inverse();
    X_WC_ = correction * X_WC_;
    for (Keyframe& kf : keyframes_) {
      if (kf.id > newest_id) kf.X_WC = correction * kf.X_WC;
    }
    for (Landmark& lm : landmarks_) {
      if (lm.id >= job.next_landmark_id) lm.p_W = correction * lm.p_W;
    }
  }
  const Eigen::Isometry3d change = job.newest_before.inverse() * newest_after;
  result->ba_correction_m = change.translation().norm();
  result->ba_correction_rad = rotationAngle(change.linear());
  result->ba_outliers = job.report.outliers;
}

// At a keyframe: adjust now (latency 0), or start an adjustment on its own thread, or, while one
// is in flight, queue the request for when that one is applied.
void RgbdOdometry::adjustAfterKeyframe(FrameResult* result) {
  // keyframes_since_init_ counts the first keyframe too: this is the k-th after it.
  if ((keyframes_since_init_ - 1) % config_.ba.every_keyframes != 0) return;
  if (config_.ba.latency_frames == 0) {
    if (std::unique_ptr<BaJob> job = startBundleAdjustment()) applyBundleAdjustment(*job, result);
    return;
  }
  if (ba_job_ != nullptr) {
    ba_queued_ = true;
    return;
  }
  ba_job_ = startBundleAdjustment();
}

// Before tracking a frame: the adjustment due at this frame is applied (waiting for it if it is
// still solving), and a queued one starts.
void RgbdOdometry::applyDueAdjustment(FrameResult* result) {
  if (ba_job_ == nullptr || frame_ < ba_job_->apply_at) return;
  const std::unique_ptr<BaJob> job = std::move(ba_job_);
  applyBundleAdjustment(*job, result);
  if (ba_queued_) {
    ba_queued_ = false;
    ba_job_ = startBundleAdjustment();
  }
}

void RgbdOdometry::dropBundleAdjustment() {
  ba_job_.reset();  // its future waits for the thread
  ba_queued_ = false;
}

RgbdOdometry::~RgbdOdometry() = default;

}  // namespace tgnav::vo
