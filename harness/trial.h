#pragma once
// One closed-loop trial: plan on the scene's feature map, generate the trajectory, fly it in
// MuJoCo through the PX4-like cascade while the onboard camera renders at the camera rate and
// the VO tracks every frame, then score what happened.
//
// Rendering and VO form a two-stage pipeline. With `trial.pipeline` the VO (with the camera
// noise) runs on a second thread while the simulation renders the next frames; the frames, their
// noise and their order are the same as in the sequential run, and with the `vo` state source a
// VO pose is fused exactly one camera period after its image was taken (the simulation waits for
// it if needed), so both modes give identical results.
//
// Seeds: the planner takes the trial's seed; the camera noise and the IMU take streams derived
// from it (trialSeed).
#include <atomic>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "harness/flight_loop.h"
#include "harness/plan_run.h"
#include "harness/scenario.h"
#include "planner/feature_map.h"
#include "vo/odometry.h"
#include "vo/tum.h"

namespace tgnav::harness {

enum class TrialStatus { kSuccess, kVoLost, kCollision, kDiverged, kTimeout, kPlanFailed, kInterrupted };
const char* toString(TrialStatus status);  // "success", "vo_lost", ..., "incomplete"

struct TrialOptions {
  PlannerName planner = PlannerName::kProposed;
  int rrt_samples = 0;  // 0: the planner config's
  std::uint64_t seed = 0;
  int strip_frames = 0;  // > 0: keep this many frames, evenly spread, for a frame strip
};

struct TrialProgress {
  double sim_s = 0.0;
  double sim_total_s = 0.0;     // the planned flight's length in sim time
  double path_fraction = 0.0;   // of the trajectory's time flown
  double wall_s = 0.0;          // since the flight started
};

// One camera frame as the VO saw it.
struct TrialFrame {
  vo::FrameResult vo;                                        // status, counts, estimated pose
  Eigen::Isometry3d X_WC_true = Eigen::Isometry3d::Identity();
  bool tracked() const { return vo.status != vo::TrackingStatus::kLost; }
};

struct TrialEvent {
  double t_s = 0.0;
  Eigen::Vector3d p_WB = Eigen::Vector3d::Zero();  // true position then
  std::string what;
};

struct TrialResult {
  TrialStatus status = TrialStatus::kPlanFailed;
  std::string detail;  // one line: what decided the status
  PlanRun plan;
  std::optional<control::SetpointTrajectory> setpoints;  // the flown trajectory (none without a plan)
  FlightResult flight;
  Eigen::Isometry3d X_BC = Eigen::Isometry3d::Identity();  // the camera on the body
  std::vector<TrialFrame> frames;  // in time order; after the first loss only while re-initialising
  std::optional<TrialEvent> vo_lost;
  std::optional<TrialEvent> collision;
  double final_distance_to_goal_m = 0.0;  // true position at the end of the flight
  double sim_time_s = 0.0;
  double flight_wall_s = 0.0;
  double planned_flight_s = 0.0;
  int vo_fused = 0;     // VO poses the estimator took (state source vo)
  int vo_rejected = 0;  // ... and rejected by its gate
  std::vector<cv::Mat> strip;  // frames for the frame strip (TrialOptions::strip_frames)
  std::vector<std::string> strip_captions;
};

using ProgressFn = std::function<void(const TrialProgress&)>;

// Derived seed of stream `stream` (1: camera noise, 2: IMU) from the trial's seed.
std::uint64_t trialSeed(std::uint64_t seed, std::uint64_t stream);

// Runs the trial. `interrupt`, when set and raised, stops the flight at the next physics step
// (status kInterrupted). Bad settings (a camera rate that does not divide the physics rate) are
// InputErrors; expected outcomes (no path, VO lost, a crash) are statuses.
TrialResult runTrial(const Scenario& scenario, const planner::FeatureMap& map, const TrialOptions& options,
                     const ProgressFn& progress = {}, const std::atomic<bool>* interrupt = nullptr);

// Scores of a finished trial (deterministic: no wall-clock figures).
struct TrialScores {
  double path_length_m = 0.0;       // flown (true) body path, take-off to the end
  double planned_length_m = 0.0;    // the chosen planner path
  double trajectory_length_m = 0.0;
  std::optional<double> goal_error_m;  // |estimated - true| camera position at the last frame
  double ate_rmse_m = 0.0;           // tracked frames, SE(3)-aligned
  double ate_anchored_rmse_m = 0.0;  // tracked frames, VO frame = true frame at the start
  double ate_max_m = 0.0;            // anchored
  int vo_frames = 0;
  int vo_ok = 0;
  int vo_weak = 0;
  int vo_lost = 0;
  double distance_tracked_m = 0.0;
  std::vector<double> error_distance_m;  // per tracked frame: distance travelled, anchored error
  std::vector<double> error_m;
};
TrialScores scoreTrial(const TrialResult& result);

// metrics.json: the fields of DESIGN.md, the wall-clock ones (plan_time_s, wall_time_s,
// real_time_factor, peak_rss_mb) also under `timing`, which holds every wall-clock figure;
// everything outside `timing` and those four is deterministic for a scenario and seed.
struct TrialTiming {
  double plan_time_s = 0.0;
  double trajectory_s = 0.0;
  double flight_wall_s = 0.0;
  double wall_time_s = 0.0;
  double peak_rss_mb = 0.0;
};
nlohmann::ordered_json trialMetricsJson(const Scenario& scenario, const TrialOptions& options,
                                        const TrialResult& result, const TrialScores& scores,
                                        const TrialTiming& timing);

// The camera's true trajectory along a flight log (TUM's convention: camera in world).
std::vector<vo::StampedPose> cameraPoses(const FlightResult& flight, const Eigen::Isometry3d& X_BC);

// Peak resident memory of this process (VmHWM), MB; 0 where unavailable.
double peakRssMb();

}  // namespace tgnav::harness
