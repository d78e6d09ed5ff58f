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
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "control/state_estimator.h"
#include "harness/config/scenario.h"
#include "harness/run/external_plan.h"
#include "harness/run/frame_prediction.h"
#include "harness/run/online_planning.h"
#include "harness/run/plan_run.h"
#include "harness/run/trial_profile.h"
#include "harness/run/trial_status.h"
#include "harness/sim/flight_loop.h"
#include "planner/feature_map.h"
#include "vo/odometry.h"
#include "vo/tum.h"

namespace tgnav::harness {

struct TrialOptions {
  planner::PlannerKind planner = planner::PlannerKind::kProposed;
  int rrt_samples = 0;  // 0: the planner config's
  std::uint64_t seed = 0;
  int strip_frames = 0;                                // > 0: keep this many frames, evenly spread, for a frame strip
  std::string oracle_option = "planner.oracle_class";  // names the oracle class in errors
  // A trajectory to fly instead of planning (`tgnav trial --trajectory FILE`; `given_file` names
  // it in errors and results), checked against the map before the flight (given_route.h).
  std::optional<control::SetpointTrajectory> given_trajectory;
  // Or a 4-DoF path (`--path FILE`), checked the same way (waypoints and the lines between them),
  // then smoothed by the trajectory generator under the scenario's limits.
  std::optional<std::vector<planner::Pose4>> given_path;
  std::string given_file;
  bool given() const { return given_trajectory.has_value() || given_path.has_value(); }
  // "trajectory" or "path" (its option without the dashes, and the planner's name in results);
  // nullptr when the trial plans.
  const char* givenKind() const { return given_path ? "path" : given_trajectory ? "trajectory" : nullptr; }
  // Or ask the scenario's external planner (scenario.planner.external; `--planner external`),
  // sending it the feature map's files in `map_dir` (external_plan.h).
  bool external = false;
  std::filesystem::path map_dir;
};

// The planner's name in results: "trajectory"/"path" for a given route, the external planner's
// name, or the built-in planner's.
std::string plannerLabel(const Scenario& scenario, const TrialOptions& options);

struct TrialProgress {
  double sim_s = 0.0;
  double sim_total_s = 0.0;    // the planned flight's length in sim time
  double path_fraction = 0.0;  // of the trajectory's time flown
  double wall_s = 0.0;         // since the flight started
};

// One camera frame as the VO saw it.
struct TrialFrame {
  vo::FrameResult vo;  // status, counts, estimated pose
  Eigen::Isometry3d X_WC_true = Eigen::Isometry3d::Identity();
  FramePrediction predicted;  // the planner's perception model at X_WC_true (frame_prediction.h)
  bool tracked() const { return vo.status != vo::TrackingStatus::kLost; }
};

struct TrialResult {
  TrialStatus status = TrialStatus::kPlanFailed;
  std::string detail;  // one line: what decided the status
  PlanRun plan;
  std::optional<ExternalPlan> external;                  // what the external planner did (TrialOptions::external)
  std::optional<control::SetpointTrajectory> setpoints;  // the flown trajectory (none without a plan)
  FlightResult flight;
  Eigen::Isometry3d X_BC = Eigen::Isometry3d::Identity();  // the camera on the body
  std::vector<TrialFrame> frames;  // in time order; after the first loss only while re-initialising
  std::optional<TrialEvent> vo_lost;
  std::optional<TrialEvent> collision;
  std::optional<TrialEvent> no_path;      // online: the flight stopped without a route
  std::optional<OnlineResult> online;     // online: plans, map, their metrics (online_planning.h)
  double final_distance_to_goal_m = 0.0;  // true position at the end of the flight
  double sim_time_s = 0.0;
  double flight_wall_s = 0.0;
  double planned_flight_s = 0.0;
  control::FusionTally vo_fusion;  // what the estimator did with the VO's poses (state source vo)
  TrialProfile profile;            // where the flight's wall time went (trial_profile.h)
  std::vector<cv::Mat> strip;      // frames for the frame strip (TrialOptions::strip_frames)
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

}  // namespace tgnav::harness
