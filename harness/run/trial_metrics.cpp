#include "harness/run/trial_metrics.h"

#include <cmath>

#include "vo/metrics.h"

namespace tgnav::harness {

std::vector<vo::StampedPose> cameraPoses(const FlightResult& flight, const Eigen::Isometry3d& X_BC) {
  std::vector<vo::StampedPose> poses;
  poses.reserve(flight.log.size());
  for (const FlightSample& f : flight.log) {
    Eigen::Isometry3d X_WB = Eigen::Isometry3d::Identity();
    X_WB.linear() = f.state.q_WB.toRotationMatrix();
    X_WB.translation() = f.state.p_WB;
    poses.push_back(vo::StampedPose{f.t_s, X_WB * X_BC});
  }
  return poses;
}

double flownLength(const FlightResult& flight) {
  double length = 0.0;
  for (std::size_t i = 1; i < flight.log.size(); ++i) {
    length += (flight.log[i].state.p_WB - flight.log[i - 1].state.p_WB).norm();
  }
  return length;
}

// The goal error needs an estimate at the end of the flight.
std::optional<double> trackedGoalError(const std::vector<TrialFrame>& frames) {
  if (frames.empty() || !frames.back().tracked()) return std::nullopt;
  std::vector<vo::PosePair> pairs;
  for (const TrialFrame& f : frames) {
    if (f.tracked()) pairs.push_back(vo::PosePair{f.vo.t_s, f.vo.X_WC, f.X_WC_true});
  }
  return vo::goalError(pairs);
}

TrialScores scoreTrial(const TrialResult& result) {
  TrialScores s;
  const planner::Plan& plan = result.plan.plan;
  if (plan.chosen >= 0) s.planned_length_m = plan.candidates[static_cast<std::size_t>(plan.chosen)].length_m;
  s.trajectory_length_m = result.plan.trajectory.length_m;
  if (plan.chosen < 0 && !plan.path.empty()) {  // a given path: its polyline, smoothed as planned
    s.planned_length_m = 0.0;
    for (std::size_t i = 1; i < plan.path.size(); ++i) {
      s.planned_length_m += (plan.path[i].p_WB - plan.path[i - 1].p_WB).norm();
    }
  } else if (plan.chosen < 0 && result.setpoints) {  // a given trajectory: its setpoints' polyline
    const std::vector<control::TrajectorySetpoint>& sp = result.setpoints->setpoints();
    double length = 0.0;
    for (std::size_t i = 1; i < sp.size(); ++i) length += (sp[i].p_WB - sp[i - 1].p_WB).norm();
    s.planned_length_m = s.trajectory_length_m = length;
  }
  s.path_length_m = flownLength(result.flight);

  std::vector<vo::PosePair> pairs;
  double distance = 0.0;
  for (std::size_t i = 0; i < result.frames.size(); ++i) {
    const TrialFrame& f = result.frames[i];
    if (i > 0) distance += (f.X_WC_true.translation() - result.frames[i - 1].X_WC_true.translation()).norm();
    switch (f.vo.status) {
      case vo::TrackingStatus::kOk:
        ++s.vo_ok;
        break;
      case vo::TrackingStatus::kWeak:
        ++s.vo_weak;
        break;
      case vo::TrackingStatus::kLost:
        ++s.vo_lost;
        break;
    }
    if (!f.tracked()) continue;
    pairs.push_back(vo::PosePair{f.vo.t_s, f.vo.X_WC, f.X_WC_true});
    s.distance_tracked_m = distance;
  }
  s.vo_frames = static_cast<int>(result.frames.size());
  if (!pairs.empty()) {
    const vo::AteResult anchored = vo::absoluteTrajectoryError(pairs, false);
    s.ate_anchored_rmse_m = anchored.rmse_m;
    s.ate_max_m = anchored.max_m;
    s.ate_rmse_m = vo::absoluteTrajectoryError(pairs, true).rmse_m;
    if (result.status != TrialStatus::kInterrupted) s.goal_error_m = trackedGoalError(result.frames);
  }
  return s;
}

namespace {

// Sim time at which the true position first came within the goal radius (none: never).
std::optional<double> timeToGoal(const Scenario& scenario, const TrialResult& result) {
  for (const FlightSample& f : result.flight.log) {
    if ((f.state.p_WB - scenario.scene.goal.p_WB).norm() <= scenario.trial.goal_radius_m) return f.t_s;
  }
  return std::nullopt;
}

// metrics.json's `online` object: the plans and the map (deterministic values only).
nlohmann::ordered_json onlineJson(const Scenario& scenario, const TrialResult& result) {
  using nlohmann::ordered_json;
  const OnlineResult& o = *result.online;
  const OnlineConfig& c = scenario.trial.online;
  ordered_json j;
  j["prior_map"] = nameOf(c.prior_map, priorMapNames());
  j["map_pose"] = nameOf(c.map_pose, mapPoseNames());
  j["unknown_space"] = nameOf(c.unknown_space, unknownSpaceNames());
  j["plan_latency_s"] = c.plan_latency_s;
  int ok = 0;
  int adopted = 0;
  int renewed = 0;
  ordered_json times = ordered_json::array();
  for (std::size_t i = 0; i < o.plans.size(); ++i) {
    ok += o.plans[i].ok ? 1 : 0;
    adopted += o.plans[i].adopted ? 1 : 0;
    renewed += o.plans[i].views_renewed ? 1 : 0;
    if (i > 0) times.push_back(o.plans[i].t_s);
  }
  j["plans"] = o.plans.size();
  j["plans_without_route"] = static_cast<int>(o.plans.size()) - ok;
  j["replans"] = o.plans.empty() ? 0 : static_cast<int>(o.plans.size()) - 1;
  j["plans_flown"] = adopted;  // the first, and those that changed the route
  j["plans_renewing_views"] = renewed;
  j["guard_trips"] = o.guards.size();  // trial.guard_tracking
  j["replan_times_s"] = times;
  const std::optional<double> reached = timeToGoal(scenario, result);
  j["time_to_goal_s"] = reached ? ordered_json(*reached) : ordered_json(nullptr);
  j["keyframes"] = o.keyframes;
  j["map_coverage"] = o.coverage;
  j["map_landmarks"] = o.final_map ? o.final_map->landmarks().size() : 0;
  j["map_occupied_voxels"] = o.occupied_voxels;
  j["map_error_mean_m"] = o.map_error_mean_m;
  j["map_error_far_share"] = o.map_error_far_share;
  j["map_surface_crossings"] = o.map_surface_crossings;
  j["map_hole_share"] = o.map_hole_share;
  j["unknown_share"] = o.unknown_share;
  return j;
}

// The wall-clock figures of an online trial: its plans, and its map updates per keyframe and per
// camera frame (the speed target is the latter).
void addOnlineTiming(const OnlineResult& o, int frames, nlohmann::ordered_json* timing) {
  double plan_s = 0.0;
  for (const OnlinePlan& p : o.plans) plan_s += p.snapshot_s + p.voxel_map_s + p.solve_s + p.trajectory_s;
  (*timing)["online_plans_s"] = plan_s;
  (*timing)["map_update_s"] = o.map_update_s;
  (*timing)["map_update_ms_per_keyframe"] = o.keyframes > 0 ? 1e3 * o.map_update_s / o.keyframes : 0.0;
  (*timing)["map_update_ms_per_frame"] = frames > 0 ? 1e3 * o.map_update_s / frames : 0.0;
}

// What the estimator did with the VO's poses (metrics.json's vo_* keys).
nlohmann::ordered_json fusionJson(const control::FusionTally& f) {
  return {{"vo_poses_fused", f.fused},
          {"vo_poses_rejected", f.rejected},
          {"vo_jumps_taken_off", f.jumps},
          {"vo_offset_m", f.offset_m}};
}

}  // namespace

nlohmann::ordered_json trialMetricsJson(const Scenario& scenario, const TrialOptions& options,
                                        const TrialResult& result, const TrialScores& scores,
                                        const TrialTiming& timing) {
  using nlohmann::ordered_json;
  auto orNull = [](const std::optional<double>& v) { return v ? ordered_json(*v) : ordered_json(nullptr); };
  auto point = [](const Eigen::Vector3d& p) { return ordered_json::array({p.x(), p.y(), p.z()}); };
  ordered_json j;
  j["scenario"] = scenario.source.string();
  j["scene"] = scenario.scene.source.stem().string();
  const bool given = options.given();
  j["planner"] = plannerLabel(scenario, options);
  j["given_file"] = given ? ordered_json(options.given_file) : ordered_json(nullptr);
  const bool built_in = !given && !options.external;
  j["samples"] = options.planner == planner::PlannerKind::kRrtStar && built_in ? ordered_json(result.plan.rrt_samples)
                                                                               : ordered_json(nullptr);
  j["seed"] = options.seed;
  j["oracle_class"] =
      scenario.planner.oracle_class >= 0 ? ordered_json(scenario.planner.oracle_class) : ordered_json(nullptr);
  j["state_source"] = toString(scenario.trial.state_source);
  j["status"] = toString(result.status);
  j["detail"] = result.detail;
  j["path_length_m"] = scores.path_length_m;
  j["planned_length_m"] = scores.planned_length_m;
  j["trajectory_length_m"] = scores.trajectory_length_m;
  j["goal_error_m"] = orNull(scores.goal_error_m);
  j["final_distance_to_goal_m"] = result.final_distance_to_goal_m;
  j["ate_rmse_m"] = scores.ate_rmse_m;
  j["ate_anchored_rmse_m"] = scores.ate_anchored_rmse_m;
  j["ate_max_m"] = scores.ate_max_m;
  j["vo_frames"] = scores.vo_frames;
  j["vo_ok"] = scores.vo_ok;
  j["vo_weak"] = scores.vo_weak;
  j["vo_lost_frames"] = scores.vo_lost;
  j["vo_lost_at_s"] = result.vo_lost ? ordered_json(result.vo_lost->t_s) : ordered_json(nullptr);
  j["vo_lost_position"] = result.vo_lost ? point(result.vo_lost->p_WB) : ordered_json(nullptr);
  j["vo_lost_reason"] = result.vo_lost ? ordered_json(result.vo_lost->what) : ordered_json(nullptr);
  j["distance_tracked_m"] = scores.distance_tracked_m;
  j["collision"] = result.collision ? ordered_json{{"t_s", result.collision->t_s},
                                                   {"position", point(result.collision->p_WB)},
                                                   {"with", result.collision->what}}
                                    : ordered_json(nullptr);
  const planner::Plan& plan = result.plan.plan;
  j["plan_status"] = given                                                           ? "given"
                     : options.external && !(result.external && result.external->ok) ? "failed"
                                                                                     : planner::toString(plan.status);
  j["classes"] = result.plan.plan.topo.classes.size();
  j["chosen_class"] =
      result.plan.plan.chosen_class >= 0 ? ordered_json(result.plan.plan.chosen_class) : ordered_json(nullptr);
  j["c_p_min"] = plan.chosen >= 0 && std::isfinite(plan.candidates[static_cast<std::size_t>(plan.chosen)].c_p_min)
                     ? ordered_json(plan.candidates[static_cast<std::size_t>(plan.chosen)].c_p_min)
                     : ordered_json(nullptr);
  const bool trajectory_given = options.given_trajectory || (result.external && result.external->trajectory);
  j["trajectory_status"] = trajectory_given ? "given" : planner::toString(result.plan.trajectory.status);
  const TrackingSummary tracking = summarizeTracking(result.flight);
  j["tracking_rmse_m"] = tracking.position_rmse_m;
  j.update(fusionJson(result.vo_fusion));
  j["camera"] = {{"width_px", scenario.camera.width_px},
                 {"height_px", scenario.camera.height_px},
                 {"rate_hz", scenario.trial.camera_rate_hz}};
  j["sim_time_s"] = result.sim_time_s;
  j["mode"] = result.online ? "online" : "prior";
  j["online"] = result.online ? onlineJson(scenario, result) : ordered_json(nullptr);
  const double rtf = result.flight_wall_s > 0 ? result.sim_time_s / result.flight_wall_s : 0.0;
  // Wall-clock figures: the documented names (README) at the top level, and all of them under `timing`.
  j["plan_time_s"] = timing.plan_time_s;
  j["wall_time_s"] = timing.wall_time_s;
  j["real_time_factor"] = rtf;
  j["peak_rss_mb"] = timing.peak_rss_mb;
  j["timing"] = {{"plan_time_s", timing.plan_time_s},
                 {"trajectory_s", timing.trajectory_s},
                 {"flight_wall_s", timing.flight_wall_s},
                 {"wall_time_s", timing.wall_time_s},
                 {"real_time_factor", rtf},
                 {"peak_rss_mb", timing.peak_rss_mb},
                 {"profile", result.profile.toJson()}};
  if (result.online) addOnlineTiming(*result.online, scores.vo_frames, &j["timing"]);
  return j;
}

}  // namespace tgnav::harness
