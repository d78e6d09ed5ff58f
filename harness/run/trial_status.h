#pragma once
// A closed-loop trial's outcome, decided from what happened during it. decideStatus is a pure
// function of those events, so that its precedence (most severe first) is tested on its own.
#include <Eigen/Core>
#include <optional>
#include <string>

namespace tgnav::harness {

enum class TrialStatus {
  kSuccess,
  kDrifted,
  kVoLost,
  kCollision,
  kDiverged,
  kTimeout,
  kPlanFailed,
  kNoPath,  // online: the known and unknown space left no route, and the flight stopped
  kInterrupted
};
const char* toString(TrialStatus status);  // "success", "drifted", "vo_lost", ..., "incomplete"

struct TrialEvent {
  double t_s = 0.0;
  Eigen::Vector3d p_WB = Eigen::Vector3d::Zero();  // true position then
  std::string what;
};

// What happened in a flight that took off (a failed plan is decided before it).
struct TrialEvents {
  bool interrupted = false;
  std::optional<TrialEvent> collision;
  bool flight_completed = true;  // false: the flight loop diverged (flight_reason says how)
  std::string flight_reason;
  bool left_bounds = false;  // flight_reason says where
  std::optional<TrialEvent> vo_lost;
  // Online: the planner found no route and the current one was blocked or spent, so the flight
  // stopped (why, and when).
  std::optional<TrialEvent> no_path;
  double final_distance_to_goal_m = 0.0;
  double goal_radius_m = 0.5;
  double sim_time_s = 0.0;
  double planned_end_s = 0.0;
  int frames = 0;  // VO frames scored
  // The VO's goal error (|estimated - true| final camera position, anchored at take-off; none
  // when the last frame was not tracked), the distance flown, and the bound on their ratio.
  std::optional<double> goal_error_m;
  double path_length_m = 0.0;
  double max_drift_ratio = 0.01;
};

struct TrialVerdict {
  TrialStatus status = TrialStatus::kSuccess;
  std::string detail;  // one line: what decided it
};

// Most severe first: interrupted, collision, diverged (or left the scene), VO lost, no path (online:
// the flight stopped without a route), timeout (the
// flight ended outside the goal radius), drifted (the VO tracked to the end, but its goal error
// exceeds max_drift_ratio times the distance flown: the vehicle arrived without knowing where it
// was), success.
TrialVerdict decideStatus(const TrialEvents& events);

// "(x, y, z)" with 2 decimals, as details and messages print positions.
std::string formatPoint(const Eigen::Vector3d& p);

}  // namespace tgnav::harness
