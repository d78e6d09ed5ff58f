#pragma once
// RGB-D feature visual odometry: ORB features (grid-spread) with depth, tracked against a local
// map of the recent keyframes' 3D landmarks by descriptor matching inside a motion-model window,
// pose by PnP RANSAC refined on the inliers (Levenberg-Marquardt on reprojection error),
// keyframes by one of two policies (keyframe_policy), landmarks culled when they stop being
// matched. When a keyframe is added, a local bundle adjustment (vo/bundle_adjustment.h) refines
// the local map's keyframes and the landmarks they observe, with the last keyframes that left the
// local map held fixed as the gauge (their observations anchor the landmarks that outlived them);
// outlier observations are dropped, and a landmark left without any is removed.
//
// Keyframe policies. `ratio`: a keyframe when the inliers fall below keyframe_inlier_ratio of
// those the last keyframe tracked and created, or the camera moved or turned far enough since
// it, or (keyframe_richer_ratio r > 0) the frame has more than r times as many features with
// depth as the last keyframe tracked and created: after a keyframe made in a near-blind view, a
// view that offers far more than the map holds makes one (the inlier rule need not fire there:
// the frame may track more than the near-blind keyframe had). `orbslam2`: ORB-SLAM2's decision
// for an RGB-D camera (Tracking::NeedNewKeyFrame): the frame tracks fewer than
// keyframe_reference_ratio (0.75; 0.4 while there is one keyframe) of the reference keyframe's
// well-observed landmarks (observed twice or more: ORB-SLAM2 counts an
// observation with depth twice and wants 3 counts, 2 while there are at most two keyframes), or
// it tracks fewer than 100 close landmarks (depth below keyframe_close_depth_m) while 70 close
// features are unmatched; and it tracks more than 15; and either keyframe_max_frames frames
// passed since the last keyframe, or bundle adjustment is idle, or tracking is weak (fewer than a
// quarter of the reference count, or the close condition). The reference keyframe is the last
// one (ORB-SLAM2 takes the one sharing most landmarks with the frame); ORB-SLAM2 also culls
// redundant keyframes later, which this VO does not (its local map is the last
// local_map_keyframes keyframes, so the window's length in time grows as keyframes thin out).
//
// Bundle adjustment in the background (ba.latency_frames = L > 0): the adjustment of a keyframe
// added at frame k is solved on a thread of its own, on a copy of the window as it was at k, and
// applied at frame k + L, before that frame is tracked, whether it finished early or the frame
// waits for it; so the result is the same however fast the thread runs, and the same in every
// run. While one is in flight a new keyframe's adjustment waits: it starts when the one in
// flight is applied (ORB-SLAM2's local mapping takes keyframes from a queue the same way). Where
// the window moved, the frames tracked meanwhile move with it: the current pose, and the
// keyframes and landmarks added after the copy, take the correction of the newest adjusted
// keyframe. L = 0 adjusts at the keyframe itself, before the next frame.
//
// Tracking status per frame, with the counts behind it: ok, weak (few inliers), lost (inliers
// below min_inliers, ORB-SLAM2's 30 by default). The paper counts a run as failed at the first
// loss: after it, failed() stays true; with reinitialise_after_lost the odometry starts again
// from the next frame with enough features (its pose continues from the last good one).
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <deque>
#include <limits>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "vo/bundle_adjustment.h"
#include "vo/camera_intrinsics.h"
#include "vo/features.h"

namespace tgnav::vo {

enum class KeyframePolicy { kRatio, kOrbSlam2 };
inline std::vector<std::pair<std::string, KeyframePolicy>> keyframePolicyNames() {
  return {{"ratio", KeyframePolicy::kRatio}, {"orbslam2", KeyframePolicy::kOrbSlam2}};
}

class StageClock;  // vo/stage_clock.h

struct OdometryConfig {
  FeatureConfig features;
  double min_depth_m = 0.2;    // features with depth outside this range have no 3D point
  double max_depth_m = 10.0;   // the sensor's range (a RealSense D435's, configs/camera.yaml);
                               // BA weighs a far point's depth by its noise
  double depth_edge_m = 0.05;  // ... nor those on a depth discontinuity (3x3 spread above
                               // this times the depth)
  // The neighbourhood of that check. 0: the keypoint's 3x3 pixels in the full image, whatever its
  // pyramid level (before 2026-11-30). r > 0: the square of radius r x scale_factor^octave pixels,
  // r pixels at the keypoint's own level (3: FAST's circle there). A corner that a near
  // silhouette makes against a far texture (a T-junction) is no point in space: it slides along
  // the silhouette as the camera moves; at a coarse level its circle reaches the silhouette from
  // pixels beyond the 3x3. Measured at 3 (docs/results/vo_jumps): smaller errors, but fewer
  // features with depth, and the VO lost sooner on sparse views.
  double depth_edge_radius_px = 0.0;
  int init_min_features = 100;     // features with depth needed to start (or restart)
  int min_inliers = 30;            // below: lost (ORB-SLAM2: 30 local-map inliers)
  int weak_inliers = 60;           // below: weak
  double search_radius_px = 24.0;  // matching window around the motion-model prediction
  // Where the prediction tracks too few, match again in a window twice as wide around it, then
  // around the last pose (ORB-SLAM2's TrackWithMotionModel widens its window the same way, then
  // falls back to the reference keyframe). A quadrotor's attitude turns back within a frame or
  // two when it stops: the constant-velocity prediction was then 40 px off and the VO lost 400-700
  // inliers at once (docs/results/lead). A frame it tracks would have been tracked without it, so
  // it changes nothing before the first frame that would have been lost. false: the prediction's
  // window alone (before 2026-11-29).
  bool wide_retry = true;
  // Each frame's pose refined on the matched keypoints' measured depths too (the disparity
  // residual of ba.virtual_baseline_m and ba.depth_sigma_px, as ORB-SLAM2's motion-only BA for
  // RGB-D), not on their reprojections alone. Measured (docs/results/vo_jumps): fewer frames
  // tracked but placed 0.1-0.3 m off, not none; held-out replays mixed. false: reprojection alone.
  bool pose_depth = false;
  int max_descriptor_distance = 64;  // Hamming, of 256 bits
  double ratio_test = 0.8;           // best / second best within the window
  double ransac_reprojection_px = 2.0;
  int ransac_iterations = 200;
  double ransac_confidence = 0.995;
  int local_map_keyframes = 5;          // keyframes whose landmarks form the local map
  double keyframe_inlier_ratio = 0.7;   // new keyframe when tracked landmarks fall below this
                                        // fraction of the last keyframe's
  double keyframe_translation_m = 0.4;  // ... or the camera moved this far
  double keyframe_rotation_rad = 0.35;  // ... or turned this much
  double keyframe_richer_ratio = 0.0;   // ratio: ... or the frame's features with depth exceed
                                        // this multiple of the last keyframe's (0: off; else > 1)
  int landmark_max_misses = 10;         // cull a landmark not matched in this many frames it was expected in
  KeyframePolicy keyframe_policy = KeyframePolicy::kRatio;
  double keyframe_reference_ratio = 0.75;  // orbslam2: ORB-SLAM2's thRefRatio for RGB-D
  int keyframe_max_frames = 20;            // orbslam2: frames after which a keyframe may come even
                                           // while BA is busy (ORB-SLAM2: the camera's rate)
  double keyframe_close_depth_m = 3.2;     // orbslam2: "close" landmarks (ORB-SLAM2: 40 baselines,
                                           // here of ba.virtual_baseline_m)
  bool reinitialise_after_lost = false;
  BundleAdjustmentConfig ba;  // local bundle adjustment over the local map's keyframes

  // Names every field once, for the harness's config files (a(key, field), `features` as a
  // mapping; harness/config/yaml_util.h): configs/vo.yaml.
  template <typename Archive>
  void visit(Archive& a) {
    a("features", features);
    a("min_depth_m", min_depth_m);
    a("max_depth_m", max_depth_m);
    a("depth_edge_m", depth_edge_m);
    a("depth_edge_radius_px", depth_edge_radius_px);
    a("init_min_features", init_min_features);
    a("min_inliers", min_inliers);
    a("weak_inliers", weak_inliers);
    a("search_radius_px", search_radius_px);
    a("wide_retry", wide_retry);
    a("pose_depth", pose_depth);
    a("max_descriptor_distance", max_descriptor_distance);
    a("ratio_test", ratio_test);
    a("ransac_reprojection_px", ransac_reprojection_px);
    a("ransac_iterations", ransac_iterations);
    a("ransac_confidence", ransac_confidence);
    a("local_map_keyframes", local_map_keyframes);
    a("keyframe_inlier_ratio", keyframe_inlier_ratio);
    a("keyframe_translation_m", keyframe_translation_m);
    a("keyframe_rotation_rad", keyframe_rotation_rad);
    a("keyframe_richer_ratio", keyframe_richer_ratio);
    a("landmark_max_misses", landmark_max_misses);
    a.choice("keyframe_policy", keyframe_policy, keyframePolicyNames());
    a("keyframe_reference_ratio", keyframe_reference_ratio);
    a("keyframe_max_frames", keyframe_max_frames);
    a("keyframe_close_depth_m", keyframe_close_depth_m);
    a("reinitialise_after_lost", reinitialise_after_lost);
    a("ba", ba);
  }

  void validate() const;  // std::invalid_argument naming the field and value
};

enum class TrackingStatus { kOk, kWeak, kLost };
const char* toString(TrackingStatus status);

// A tracked frame's status from the inliers of its refined pose: lost below config.min_inliers,
// weak below config.weak_inliers, ok from there on.
TrackingStatus decideStatus(int inliers, const OdometryConfig& config);

struct FrameResult {
  double t_s = 0.0;
  TrackingStatus status = TrackingStatus::kLost;
  Eigen::Isometry3d X_WC = Eigen::Isometry3d::Identity();  // estimate (last good one when lost)
  int features = 0;                                        // ORB keypoints detected
  int with_depth = 0;                                      // ... of which with a valid 3D point
  int matches = 0;                                         // putative matches to the local map
  int inliers = 0;                                         // PnP RANSAC inliers after refinement
  // Where the inliers lie across the image: their keypoints' columns in kColumnBins equal bins
  // from the left edge (the first frame: its keypoints with depth). A turn moves them sideways,
  // so a client can tell how many would stay in view after it (harness/run/view_guard.h).
  static constexpr int kColumnBins = 32;
  std::array<int, kColumnBins> inlier_columns{};
  bool keyframe = false;      // this frame became a keyframe
  std::string keyframe_rule;  // which rules asked for it, '+'-joined: "first" (initialisation);
                              // ratio: "inliers", "translation", "rotation", "richer"; orbslam2:
                              // "reference", "close"; empty for other frames
  bool reinitialised = false;
  // For a frame where a bundle adjustment was applied (NaN otherwise; the keyframe itself with
  // ba.latency_frames 0, latency_frames later otherwise): how far BA moved and turned the
  // newest keyframe of its window, and the observations it rejected as outliers in the window.
  double ba_correction_m = std::numeric_limits<double>::quiet_NaN();
  double ba_correction_rad = std::numeric_limits<double>::quiet_NaN();
  int ba_outliers = 0;
  std::string reason;  // for lost frames: why (e.g. "12 inliers < 30")
  // Seconds of track()'s stages (not deterministic; never written to results that must repeat):
  // ORB and back-projection, local-map matching, PnP (RANSAC and refinement), local-map upkeep
  // (keyframe, landmarks), bundle adjustment; on the wall clock (`timing`) and on the CPU clock of
  // the thread that ran the stage (`cpu`). Bundle adjustment in the background: `timing.ba_s` is
  // what the tracking waited for it and spent applying it; `cpu.ba_s` also holds the solve's CPU,
  // on its own thread, counted at the frame that applies it.
  struct Timing {
    double features_s = 0.0;
    double matching_s = 0.0;
    double pnp_s = 0.0;
    double map_s = 0.0;
    double ba_s = 0.0;
    double total() const { return features_s + matching_s + pnp_s + map_s + ba_s; }
  };
  Timing timing;
  Timing cpu;
};

class RgbdOdometry {
 public:
  // `X_WC0`: the pose the first frame is given (e.g. ground truth's, or identity).
  RgbdOdometry(const CameraIntrinsics& camera, const OdometryConfig& config,
               const Eigen::Isometry3d& X_WC0 = Eigen::Isometry3d::Identity());
  ~RgbdOdometry();  // waits for a bundle adjustment in flight
  RgbdOdometry(const RgbdOdometry&) = delete;
  RgbdOdometry& operator=(const RgbdOdometry&) = delete;
  RgbdOdometry(RgbdOdometry&&) = delete;
  RgbdOdometry& operator=(RgbdOdometry&&) = delete;

  // A frame's keypoints with their descriptors and 3D points: all track() needs of the images.
  // Preparing does not depend on the odometry's state, so one thread may prepare the next frames
  // while another tracks (the results are the same).
  struct PreparedFrame {
    double t_s = 0.0;
    Features features;
    std::vector<Eigen::Vector3d> p_C;  // per keypoint, where valid
    std::vector<bool> valid;           // depth in range and not on a discontinuity
    int with_depth = 0;                // valid ones
    double prepare_s = 0.0;            // wall-clock seconds it took (FrameResult::timing.features_s)
    double prepare_cpu_s = 0.0;        // ... and CPU seconds of the thread that prepared it
  };

  // `image`: CV_8UC1 or CV_8UC3 (BGR); `depth_m`: CV_32FC1 metres along the optical axis, 0 or
  // non-finite = invalid; both of the camera's size (std::invalid_argument otherwise).
  PreparedFrame prepare(double t_s, const cv::Mat& image, const cv::Mat& depth_m) const;
  // Frames must come in increasing time (std::invalid_argument otherwise).
  FrameResult track(const PreparedFrame& frame);
  FrameResult track(double t_s, const cv::Mat& image, const cv::Mat& depth_m) {
    return track(prepare(t_s, image, depth_m));
  }

  bool failed() const { return failed_; }         // lost at least once
  double failedAt() const { return failed_at_; }  // time of the first loss (NaN if none)
  const std::vector<FrameResult>& history() const { return history_; }

 private:
  struct Landmark {
    long id = 0;  // unique over the run (keyframe observations refer to it)
    Eigen::Vector3d p_W;
    std::array<std::uint64_t, 4> descriptor{};  // the 256-bit ORB descriptor
    int misses = 0;
    int keyframe = 0;      // id of the newest keyframe that observed it (created or tracked it)
    int observations = 0;  // ORB-SLAM2's count: 2 per keyframe that observed it with depth, else 1
  };
  struct Observation {
    long landmark = 0;  // Landmark::id
    Eigen::Vector2d uv;
    double depth_m = 0.0;   // 0: none
    double sigma_px = 1.0;  // the keypoint's scale
  };
  struct Keyframe {
    int id = 0;
    Eigen::Isometry3d X_WC;
    int tracked = 0;                        // landmarks it tracked or created
    std::vector<Observation> observations;  // landmarks it tracked or created, where it saw them
  };
  struct LocalMapMatches;  // landmarks matched to a frame's keypoints
  struct PoseEstimate;     // PnP RANSAC and its refinement
  struct BaJob;            // a bundle adjustment: its window, and its solution or the thread solving it

  // The steps of track, in order (initialise instead of the rest for a first frame, or the
  // first after a loss with reinitialise_after_lost).
  void checkImages(const cv::Mat& image, const cv::Mat& depth_m) const;
  void countColumn(double u_px, FrameResult* result) const;  // one inlier into inlier_columns
  FrameResult initialise(FrameResult result, const PreparedFrame& frame);
  Eigen::Isometry3d predictPose() const { return X_WC_ * velocity_; }  // constant-velocity motion model
  LocalMapMatches matchLocalMap(const PreparedFrame& frame, const Eigen::Isometry3d& X_CW_pred, double radius_px) const;
  PoseEstimate estimatePose(const LocalMapMatches& matches, const Eigen::Isometry3d& X_CW_pred) const;
  // Matching and pose from one prediction; with wide_retry, again in a window twice as wide around
  // the prediction and then around the last pose where the first try does not track.
  struct Attempt;
  // (`clock` times matching and pose into `result`'s stages.)
  Attempt attemptPose(const PreparedFrame& frame, const Eigen::Isometry3d& X_CW_pred, double radius_px,
                      StageClock& clock, FrameResult* result) const;
  Attempt trackPose(const PreparedFrame& frame, StageClock& clock, FrameResult* result) const;
  // Returns the keyframe rules that made the frame a keyframe (empty: not one).
  std::string updateLocalMap(const PreparedFrame& frame, const LocalMapMatches& matches, const PoseEstimate& pose);
  FrameResult lose(FrameResult result, const std::string& why);  // where a step fails
  // Their parts.
  bool backProject(const cv::KeyPoint& keypoint, const cv::Mat& depth_m, Eigen::Vector3d* p_C) const;
  int refinePose(const LocalMapMatches& matches, const std::vector<cv::Point3d>& object_in,
                 const std::vector<cv::Point2d>& pixels_in, const std::vector<double>& depth_in,
                 const Eigen::Isometry3d& start, Eigen::Isometry3d* X_CW, std::vector<bool>* is_inlier) const;
  // The keyframe rules that fire ('+'-joined; empty: none): ratioRules for the current pose,
  // inliers and the frame's features with depth, orbSlam2Rules also from the frame's close
  // features, tracked or not.
  std::string ratioRules(int inliers, int with_depth) const;
  std::string orbSlam2Rules(int inliers, const PreparedFrame& frame, const std::vector<int>& matched_landmark) const;
  void addKeyframe(const Eigen::Isometry3d& X_WC, const PreparedFrame& frame, const std::vector<int>& matched_landmark,
                   int tracked);
  // Local bundle adjustment: the window copied and solved (inline, or started on its own thread),
  // then applied to the map (at once, or at the frame it is due).
  std::unique_ptr<BaJob> startBundleAdjustment();
  void applyBundleAdjustment(BaJob& job, FrameResult* result);
  void adjustAfterKeyframe(FrameResult* result);  // at a keyframe: start one, or queue it
  void applyDueAdjustment(FrameResult* result);   // before tracking a frame: apply the one due
  void dropBundleAdjustment();                    // on a reset: the one in flight is discarded
  void markFailed(double t_s);                    // the first loss
  FrameResult record(const FrameResult& result);  // into history_

  CameraIntrinsics camera_;
  OdometryConfig config_;
  FeatureDetector detector_;
  Eigen::Isometry3d X_WC0_;
  bool initialised_ = false;
  bool failed_ = false;
  double failed_at_;
  double last_t_;
  Eigen::Isometry3d X_WC_ = Eigen::Isometry3d::Identity();      // last estimate
  Eigen::Isometry3d velocity_ = Eigen::Isometry3d::Identity();  // X_{C_prev C} of the last step
  std::vector<Landmark> landmarks_;
  std::deque<Keyframe> keyframes_;  // the local map's
  std::deque<Keyframe> retired_;    // the last ones that left it (bundle adjustment's gauge)
  int next_keyframe_id_ = 0;
  long next_landmark_id_ = 0;
  long frame_ = 0;  // frames tracked
  int keyframes_since_init_ = 0;
  long last_keyframe_frame_ = 0;
  std::unique_ptr<BaJob> ba_job_;  // the bundle adjustment in flight (ba.latency_frames > 0)
  bool ba_queued_ = false;         // a keyframe came while it was: adjust again once it is applied
  std::vector<FrameResult> history_;
};

}  // namespace tgnav::vo
