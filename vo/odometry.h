#pragma once
// RGB-D feature visual odometry: ORB features (grid-spread) with depth, tracked against a local
// map of the recent keyframes' 3D landmarks by descriptor matching inside a motion-model window,
// pose by PnP RANSAC refined on the inliers (Levenberg-Marquardt on reprojection error),
// keyframes by inlier ratio and motion, landmarks culled when they stop being matched. When a
// keyframe is added, a local bundle adjustment (vo/bundle_adjustment.h) refines the local map's
// keyframes and the landmarks they observe, with the last keyframes that left the local map held
// fixed as the gauge (their observations anchor the landmarks that outlived them); outlier
// observations are dropped, and a landmark left without any is removed.
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
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "vo/bundle_adjustment.h"
#include "vo/camera_intrinsics.h"
#include "vo/features.h"

namespace tgnav::vo {

struct OdometryConfig {
  FeatureConfig features;
  double min_depth_m = 0.2;          // features with depth outside this range have no 3D point
  double max_depth_m = 10.0;         // the sensor's range (a RealSense D435's, configs/camera.yaml);
                                     // BA weighs a far point's depth by its noise
  double depth_edge_m = 0.05;        // ... nor those on a depth discontinuity (3x3 spread above
                                     // this times the depth)
  int init_min_features = 100;       // features with depth needed to start (or restart)
  int min_inliers = 30;              // below: lost (ORB-SLAM2: 30 local-map inliers)
  int weak_inliers = 60;             // below: weak
  double search_radius_px = 24.0;    // matching window around the motion-model prediction
  int max_descriptor_distance = 64;  // Hamming, of 256 bits
  double ratio_test = 0.8;           // best / second best within the window
  double ransac_reprojection_px = 2.0;
  int ransac_iterations = 200;
  double ransac_confidence = 0.995;
  int local_map_keyframes = 5;          // keyframes whose landmarks form the local map
  double keyframe_inlier_ratio = 0.6;   // new keyframe when tracked landmarks fall below this
                                        // fraction of the last keyframe's
  double keyframe_translation_m = 0.4;  // ... or the camera moved this far
  double keyframe_rotation_rad = 0.35;  // ... or turned this much
  int landmark_max_misses = 10;         // cull a landmark not matched in this many frames it was expected in
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
    a("init_min_features", init_min_features);
    a("min_inliers", min_inliers);
    a("weak_inliers", weak_inliers);
    a("search_radius_px", search_radius_px);
    a("max_descriptor_distance", max_descriptor_distance);
    a("ratio_test", ratio_test);
    a("ransac_reprojection_px", ransac_reprojection_px);
    a("ransac_iterations", ransac_iterations);
    a("ransac_confidence", ransac_confidence);
    a("local_map_keyframes", local_map_keyframes);
    a("keyframe_inlier_ratio", keyframe_inlier_ratio);
    a("keyframe_translation_m", keyframe_translation_m);
    a("keyframe_rotation_rad", keyframe_rotation_rad);
    a("landmark_max_misses", landmark_max_misses);
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
  bool keyframe = false;                                   // this frame became a keyframe
  std::string keyframe_rule;  // which rules asked for it, '+'-joined: "first" (initialisation),
                              // "inliers", "translation", "rotation"; empty for other frames
  bool reinitialised = false;
  // For a keyframe after bundle adjustment (NaN otherwise): how far BA moved and turned this
  // keyframe's pose, and the observations it rejected as outliers in the window.
  double ba_correction_m = std::numeric_limits<double>::quiet_NaN();
  double ba_correction_rad = std::numeric_limits<double>::quiet_NaN();
  int ba_outliers = 0;
  std::string reason;  // for lost frames: why (e.g. "12 inliers < 30")
  // Seconds of track()'s stages (not deterministic; never written to results that must repeat):
  // ORB and back-projection, local-map matching, PnP (RANSAC and refinement), local-map upkeep
  // (keyframe, landmarks), bundle adjustment; on the wall clock (`timing`) and on the CPU clock of
  // the thread that ran the stage (`cpu`).
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
    int keyframe = 0;  // id of the newest keyframe that observed it (created or tracked it)
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

  // The steps of track, in order (initialise instead of the rest for a first frame, or the
  // first after a loss with reinitialise_after_lost).
  void checkImages(const cv::Mat& image, const cv::Mat& depth_m) const;
  FrameResult initialise(FrameResult result, const PreparedFrame& frame);
  Eigen::Isometry3d predictPose() const { return X_WC_ * velocity_; }  // constant-velocity motion model
  LocalMapMatches matchLocalMap(const PreparedFrame& frame, const Eigen::Isometry3d& X_CW_pred) const;
  PoseEstimate estimatePose(const LocalMapMatches& matches, const Eigen::Isometry3d& X_CW_pred) const;
  // Returns the keyframe rules that made the frame a keyframe (empty: not one).
  std::string updateLocalMap(const PreparedFrame& frame, const LocalMapMatches& matches, const PoseEstimate& pose);
  FrameResult lose(FrameResult result, const std::string& why);  // where a step fails
  // Their parts.
  bool backProject(const cv::KeyPoint& keypoint, const cv::Mat& depth_m, Eigen::Vector3d* p_C) const;
  int refinePose(const LocalMapMatches& matches, const std::vector<cv::Point3d>& object_in,
                 const std::vector<cv::Point2d>& pixels_in, cv::Mat rvec, cv::Mat tvec, Eigen::Isometry3d* X_CW,
                 std::vector<bool>* is_inlier) const;
  // The keyframe rules that fire for the current pose and inliers ('+'-joined; empty: none).
  std::string keyframeRules(int inliers) const;
  void addKeyframe(const Eigen::Isometry3d& X_WC, const PreparedFrame& frame, const std::vector<int>& matched_landmark,
                   int tracked);
  // Local bundle adjustment after a keyframe; fills result's ba_* fields.
  void adjustLocalMap(FrameResult* result);
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
  std::vector<FrameResult> history_;
};

}  // namespace tgnav::vo
