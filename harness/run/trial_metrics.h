#pragma once
// What a finished trial is scored by: flown and planned lengths, the VO's trajectory errors
// (ATE aligned and anchored, goal error) and its per-frame counts; and metrics.json.
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "harness/run/trial.h"

namespace tgnav::harness {

// Scores of a finished trial (deterministic: no wall-clock figures).
struct TrialScores {
  double path_length_m = 0.0;     // flown (true) body path, take-off to the end
  double planned_length_m = 0.0;  // the chosen planner path
  double trajectory_length_m = 0.0;
  std::optional<double> goal_error_m;  // |estimated - true| camera position at the last frame
  double ate_rmse_m = 0.0;             // tracked frames, SE(3)-aligned
  double ate_anchored_rmse_m = 0.0;    // tracked frames, VO frame = true frame at the start
  double ate_max_m = 0.0;              // anchored
  int vo_frames = 0;
  int vo_ok = 0;
  int vo_weak = 0;
  int vo_lost = 0;
  double distance_tracked_m = 0.0;
};
TrialScores scoreTrial(const TrialResult& result);

// The pieces of the score the trial's status needs (trial.cpp decides `drifted` with them):
// the length of the flown body path, and the VO's goal error over the frames (none when the
// last frame was not tracked).
double flownLength(const FlightResult& flight);
std::optional<double> trackedGoalError(const std::vector<TrialFrame>& frames);

// metrics.json: the fields the README documents, the wall-clock ones (plan_time_s, wall_time_s,
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

}  // namespace tgnav::harness
