#include "harness/run/trial_status.h"

#include <algorithm>
#include <sstream>

namespace tgnav::harness {

const char* toString(TrialStatus status) {
  switch (status) {
    case TrialStatus::kSuccess:
      return "success";
    case TrialStatus::kDrifted:
      return "drifted";
    case TrialStatus::kVoLost:
      return "vo_lost";
    case TrialStatus::kCollision:
      return "collision";
    case TrialStatus::kDiverged:
      return "diverged";
    case TrialStatus::kTimeout:
      return "timeout";
    case TrialStatus::kPlanFailed:
      return "plan_failed";
    case TrialStatus::kNoPath:
      return "no_path";
    case TrialStatus::kInterrupted:
      return "incomplete";
  }
  return "unknown";
}

std::string formatPoint(const Eigen::Vector3d& p) {
  std::ostringstream s;
  s.precision(2);
  s << std::fixed << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return s.str();
}

TrialVerdict decideStatus(const TrialEvents& e) {
  std::ostringstream why;
  why.precision(2);
  why << std::fixed;
  std::string after_loss;
  if (e.vo_lost) {
    std::ostringstream s;
    s.precision(2);
    s << std::fixed << ", after VO was lost at t = " << e.vo_lost->t_s << " s";
    after_loss = s.str();
  }
  TrialVerdict v;
  if (e.interrupted) {
    v.status = TrialStatus::kInterrupted;
    why << "interrupted at t = " << e.sim_time_s << " s of " << e.planned_end_s << " s";
  } else if (e.collision) {
    v.status = TrialStatus::kCollision;
    why << "collision with " << e.collision->what << " at t = " << e.collision->t_s << " s at "
        << formatPoint(e.collision->p_WB) << after_loss;
  } else if (!e.flight_completed || e.left_bounds) {
    v.status = TrialStatus::kDiverged;
    why << e.flight_reason << " at t = " << e.sim_time_s << " s" << after_loss;
  } else if (e.vo_lost) {
    v.status = TrialStatus::kVoLost;
    why << "VO lost at t = " << e.vo_lost->t_s << " s at " << formatPoint(e.vo_lost->p_WB) << ": " << e.vo_lost->what;
  } else if (e.no_path) {
    v.status = TrialStatus::kNoPath;
    why << "no path at t = " << e.no_path->t_s << " s at " << formatPoint(e.no_path->p_WB) << ": " << e.no_path->what;
  } else if (e.final_distance_to_goal_m > e.goal_radius_m) {
    v.status = TrialStatus::kTimeout;
    why << "the flight ended " << e.final_distance_to_goal_m << " m from the goal (goal radius " << e.goal_radius_m
        << " m)";
  } else if (e.goal_error_m && *e.goal_error_m > e.max_drift_ratio * e.path_length_m) {
    v.status = TrialStatus::kDrifted;
    why << "reached the goal (" << e.final_distance_to_goal_m << " m from it), but the VO ended " << *e.goal_error_m
        << " m off, " << 100.0 * *e.goal_error_m / std::max(e.path_length_m, 1e-9) << " % of the " << e.path_length_m
        << " m flown (bound " << 100.0 * e.max_drift_ratio << " %)";
  } else {
    v.status = TrialStatus::kSuccess;
    why << "reached the goal (" << e.final_distance_to_goal_m << " m from it) with VO tracking all " << e.frames
        << " frames";
  }
  v.detail = why.str();
  return v;
}

}  // namespace tgnav::harness
