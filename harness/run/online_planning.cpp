#include "harness/run/online_planning.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "harness/base/clock.h"
#include "harness/base/errors.h"
#include "harness/run/explore.h"
#include "harness/run/look_ahead.h"
#include "harness/run/online_metrics.h"
#include "harness/run/unseen_prior.h"
#include "harness/run/view_guard.h"

namespace tgnav::harness {

namespace {

// How far ahead (trajectory time) a new occupied voxel near the path asks for a plan.
constexpr double kBlockedHorizonS = 10.0;
constexpr double kBlockedStepS = 0.1;

MapBuildConfig onlineMapConfig(const planner::FeatureMap& survey, const Scenario& scenario) {
  const OnlineConfig& online = scenario.trial.online;
  MapBuildConfig config;
  config.resolution_m = survey.resolution();
  config.max_range_m = online.map_range_m;
  config.free_short_of_surface = online.map_short_of_surface;
  if (online.map_clear_no_return) config.no_return_depth_m = noReturnDepth(scenario.camera);  // checked at loading
  return config;
}

}  // namespace

OnlinePlanning::OnlinePlanning(const Scenario& scenario, const planner::FeatureMap& survey,
                               planner::PlannerKind planner, std::uint64_t seed, int rrt_samples, bool external)
    : scenario_(scenario),
      cfg_(scenario.trial.online),
      planner_(planner),
      seed_(seed),
      rrt_samples_(rrt_samples),
      mapper_(onlineMapConfig(survey, scenario)),
      external_(external ? std::make_unique<ExternalPlannerSession>() : nullptr) {
  if (scenario.planner.oracle_class >= 0) {
    throw InputError("planner.oracle_class = " + std::to_string(scenario.planner.oracle_class) +
                     ": an online trial plans again on the map it builds, whose classes change; use trial.mode prior");
  }
  if (cfg_.guard_tracking && !external) makeGuard(Intrinsics{});
  const planner::Pose4& start = scenario.scene.start;
  switch (cfg_.prior_map) {
    case PriorMap::kNone:
      break;
    case PriorMap::kSurvey:
      mapper_.setPrior(survey.occupancy(), survey.landmarks());
      break;
    case PriorMap::kRadius: {
      std::vector<planner::Landmark> near;
      for (const planner::Landmark& lm : survey.landmarks()) {
        if ((lm.p_W - start.p_WB).head<2>().norm() <= cfg_.prior_radius_m) near.push_back(lm);
      }
      mapper_.setPrior(cropOccupancy(survey.occupancy(), start.p_WB, cfg_.prior_radius_m), std::move(near));
      break;
    }
  }
}

OnlinePlanning::~OnlinePlanning() = default;

control::SetpointTrajectory OnlinePlanning::lookAhead(const control::SetpointTrajectory& trajectory,
                                                      const planner::FeatureMap& map,
                                                      const planner::VoxelMap& voxels) const {
  const planner::PerceptionPlannerConfig& perception = scenario_.planner.perception;
  const double half_fov = lookAheadHalfFov(perception);
  // The perception-aware planners keep their views trackable while they look ahead.
  const bool rate =
      (cfg_.look_ahead_keeps_tracking || cfg_.look_ahead_best_view) && planner_ != planner::PlannerKind::kAgnostic;
  ViewRater rater(voxels, perception.visibility, perception.information);
  return lookWhereUnknown(trajectory, map, cfg_.look_ahead_s, half_fov, cfg_.look_ahead_always,
                          scenario_.planner.trajectory.max_yaw_rate_rad_s, rate ? &rater : nullptr,
                          cfg_.look_ahead_best_view);
}

OnlinePlanning::Attempt OnlinePlanning::plan(const planner::Pose4& start, double t_s, const std::string& trigger) {
  Attempt a;
  a.record.t_s = t_s;
  a.record.effective_s = t_s + cfg_.plan_latency_s;
  a.record.trigger = trigger;
  a.record.start = start;
  const auto t0 = std::chrono::steady_clock::now();
  visited_.push_back(start.p_WB);
  IncrementalMapper::Built built = planningSnapshot();
  const double clear_m = clearOf(built.map);
  a.record.landmarks = static_cast<int>(built.map.landmarks().size());
  if (cfg_.unseen_prior == UnseenPrior::kMean && !external_ && planner_ != planner::PlannerKind::kAgnostic) {
    a.record.prior_landmarks = addPrior(&built.map);
  }
  a.record.snapshot_s = secondsSince(t0);
  Scenario from_here = planningScenario(start);
  const double rate_hz = scenario_.planner.trajectory.sample_rate_hz;
  const bool unknown_free = cfg_.unknown_space == UnknownSpace::kFree;
  if (external_) {
    if (!askExternal(from_here, built.map, &a)) return a;
  } else {
    if (cfg_.unseen_prior == UnseenPrior::kRouteMean && planner_ == planner::PlannerKind::kProposed &&
        from_here.planner.oracle_class < 0) {
      from_here.planner.oracle_class = rateClass(from_here, &a.record);  // -1 (no route): the planner chooses
    }
    a.run = runPlanner(from_here, built.map, planner_, seed_, rrt_samples_, "planner.oracle_class", unknown_free);
    if (a.record.rated_class >= 0 && a.run.plan.chosen < 0) {  // that class has no path here: the planner chooses
      from_here.planner.oracle_class = -1;
      a.run = runPlanner(from_here, built.map, planner_, seed_, rrt_samples_, "planner.oracle_class", unknown_free);
    }
    if (cfg_.look_keep_class) keepClass(&from_here, built.map, &a);
    a.record.voxel_map_s += a.run.voxel_map_s;
    a.record.solve_s += a.run.solve_s;
    a.record.trajectory_s = a.run.trajectory_s;
    if (a.run.plan.chosen < 0 || !a.run.trajectory.trajectory) {
      a.record.detail = a.run.plan.chosen < 0 ? std::string("no path: ") + planner::toString(a.run.plan.status)
                                              : "trajectory generation failed: " + a.run.trajectory.reason;
      return a;
    }
    a.raw = setpoints(a.run, rate_hz);
  }
  a.record.ok = true;
  a.record.chosen_class = a.run.plan.chosen_class;
  for (const planner::Pose4& p : a.run.plan.path) {
    a.record.path.push_back(p.p_WB);
    a.record.path_unknown.push_back(!built.map.isKnown(p.p_WB));
  }
  if (cfg_.look_then_fly && !external_ && planner_ != planner::PlannerKind::kAgnostic &&
      lookFirst(from_here, built.map, clear_m, &a)) {
    if (!a.record.ok) return a;  // no view to look from: the vehicle holds
    a.trajectory = *a.raw;       // its yaws are the views it chose: no look-ahead
    a.chosen_views = true;
    a.map = std::move(built.map);
    return a;
  }
  if (cfg_.stop_before_unknown && !external_ && !stopShort(from_here, built.map, clear_m, &a)) return a;
  // An external planner's yaw is its own: the look-ahead rule is the built-in planners'.
  a.trajectory = external_ ? *a.raw : lookAhead(*a.raw, built.map, *a.run.voxels);
  a.map = std::move(built.map);
  return a;
}

IncrementalMapper::Built OnlinePlanning::planningSnapshot() {
  IncrementalMapper::Built b = mapper_.snapshot();
  const double clear = clearOf(b.map);
  if (cfg_.unknown_space == UnknownSpace::kBlocked) {
    std::vector<Eigen::Vector3d> free = visited_;
    free.push_back(scenario_.scene.goal.p_WB);
    markFree(&b.map.occupancy(), free, clear, clearanceBand(scenario_));
  }
  if (!wedges_.empty()) {
    std::vector<Eigen::Vector3d> keep = visited_;
    keep.push_back(scenario_.scene.goal.p_WB);
    blockWedges(&b.map.occupancy(), wedges_, clearanceBand(scenario_), keep, clear);
  }
  return b;
}

double OnlinePlanning::clearOf(const planner::FeatureMap& map) const {
  return scenario_.planner.perception.robot_radius_m + 2.0 * map.resolution();
}

int OnlinePlanning::addPrior(planner::FeatureMap* map) const {
  const Eigen::Vector3d margin = Eigen::Vector3d::Constant(kPlanningBoxMargin_m);
  return addUnseenPrior(map, scenario_.scene.bounds_min_m - margin, scenario_.scene.bounds_max_m + margin).added;
}

int OnlinePlanning::rateClass(const Scenario& from_here, OnlinePlan* record) {
  const auto t0 = std::chrono::steady_clock::now();
  IncrementalMapper::Built rated = planningSnapshot();
  record->prior_landmarks = addPrior(&rated.map);
  record->snapshot_s += secondsSince(t0);
  const PlanRun choice = solvePlan(from_here, rated.map, planner_, seed_, rrt_samples_, "planner.oracle_class",
                                   cfg_.unknown_space == UnknownSpace::kFree);
  record->voxel_map_s += choice.voxel_map_s;
  record->solve_s += choice.solve_s;
  record->rated_class = choice.plan.chosen_class;
  return record->rated_class;
}

bool OnlinePlanning::stopShort(const Scenario& from_here, const planner::FeatureMap& map, double clear_m, Attempt* a) {
  // Observed: the robot radius and two voxels around the path (as the free places of `blocked`).
  StopRule rule;
  rule.clear_m = clear_m;
  rule.half_fov_rad = lookAheadHalfFov(scenario_.planner.perception);
  std::vector<planner::Pose4> part = stopBeforeUnknown(a->run.plan.path, map, visited_, rule);
  if (part.size() >= a->run.plan.path.size()) return true;
  // The path flown from here on (the record keeps the plan's whole path).
  a->run.plan.path = std::move(part);
  a->stops_short = true;
  if (a->run.plan.path.size() < 2) {  // nowhere to go yet: turn where it is to see the way on
    a->raw = holdTrajectory(a->run.plan.path.front(), cfg_.replan_period_s + cfg_.plan_latency_s, holdRate());
    return true;
  }
  return smoothInto(from_here, "", a);
}

bool OnlinePlanning::smoothInto(const Scenario& from_here, const std::string& detail_prefix, Attempt* a) {
  smoothPath(from_here, a->run.plan.path, nullptr, &a->run);
  a->record.trajectory_s += a->run.trajectory_s;
  if (!a->run.trajectory.trajectory) {
    a->record.ok = false;
    a->record.detail = detail_prefix + "trajectory generation failed: " + a->run.trajectory.reason;
    return false;
  }
  a->raw = setpoints(a->run, holdRate());
  return true;
}

OnlinePlanning::Attempt OnlinePlanning::planClearOf(const planner::Pose4& start, double t_s,
                                                    const std::string& trigger) {
  Attempt a = plan(start, t_s, trigger);
  if (a.record.ok || external_ || a.run.plan.status != planner::PlanStatus::kInvalidStart || !a.run.voxels) return a;
  // The vehicle came within the robot radius of what the map now holds: plan from the nearest point
  // that clears it (two voxels more, for the planners' own discretised checks), no further away than
  // the radius itself; the blend into the new trajectory steps away.
  const double r = scenario_.planner.perception.robot_radius_m;
  const double res = a.run.voxels->resolution();
  const std::optional<Eigen::Vector3d> out = a.run.voxels->nearestClear(start.p_WB, r + 2.0 * res, r);
  if (!out) return a;
  planner::Pose4 moved = start;
  moved.p_WB = *out;
  Attempt b = plan(moved, t_s, trigger);
  b.record.start_shift_m = (*out - start.p_WB).norm();
  return b;
}

bool OnlinePlanning::askExternal(const Scenario& from_here, const planner::FeatureMap& map, Attempt* a) {
  a->run.planner = planner_;
  a->run.seed = seed_;
  buildPlanningVoxels(from_here, map, &a->run, cfg_.unknown_space == UnknownSpace::kFree);
  a->record.voxel_map_s = a->run.voxel_map_s;
  ExternalPlan ext = external_->ask(from_here, map, *a->run.voxels, seed_);
  a->record.solve_s = ext.total_s();
  if (!ext.ok) {
    a->record.detail = ext.detail;
    if (external_->stopped()) planner_failure_ = ext.detail;
    return false;
  }
  a->run.plan.status = planner::PlanStatus::kSolved;
  a->run.plan.chosen_class = ext.homology_class.value_or(-1);
  if (ext.trajectory) {
    // Flown as given, from the switch on; its positions every kBlockedStepS stand for its path.
    a->raw = std::move(ext.trajectory);
    for (double t = a->raw->startTime(); t < a->raw->endTime() + kBlockedStepS; t += kBlockedStepS) {
      const control::TrajectorySetpoint sp = a->raw->sample(std::min(t, a->raw->endTime()));
      a->run.plan.path.push_back(planner::Pose4{sp.p_WB, sp.yaw_rad});
    }
    return true;
  }
  a->run.plan.path = std::move(*ext.path);
  smoothPath(from_here, a->run.plan.path, nullptr, &a->run);
  a->record.trajectory_s = a->run.trajectory_s;
  if (!a->run.trajectory.trajectory) {
    a->record.detail = "external planner " + scenario_.planner.external.name +
                       ": trajectory generation failed: " + a->run.trajectory.reason;
    return false;
  }
  a->raw = setpoints(a->run, scenario_.planner.trajectory.sample_rate_hz);
  return true;
}

bool OnlinePlanning::goalObserved() const {
  const Eigen::Vector3d& g = scenario_.scene.goal.p_WB;
  return mapper_.occupancy().search(static_cast<float>(g.x()), static_cast<float>(g.y()), static_cast<float>(g.z())) !=
         nullptr;
}

Scenario OnlinePlanning::planningScenario(const planner::Pose4& start) const {
  Scenario from_here = scenario_;
  from_here.scene.start = start;
  if (cfg_.plan_look_ahead) {
    from_here.planner.perception.graph.look_unknown_m =
        cfg_.look_ahead_s * scenario_.planner.trajectory.nominal_speed_mps;
  }
  return from_here;
}

control::SetpointTrajectory OnlinePlanning::firstPlan(PlanRun* run) {
  goal_seen_ = goalObserved();  // a prior map may have it
  planner::Pose4 start = scenario_.scene.start;
  Attempt a = plan(start, 0.0, "start");
  next_replan_s_ = cfg_.replan_period_s;
  if (a.trajectory && cfg_.hold_first_plan) a.record.detail = "not flown: trial.hold_first_plan";
  if (a.trajectory && !cfg_.hold_first_plan) {
    a.record.adopted = true;
    stops_short_ = a.stops_short;
    looking_ = a.look.has_value();
    noteLook(a);
    current_ = std::make_unique<control::SetpointTrajectory>(
        limitYawRate(*a.trajectory, a.trajectory->startTime(), scenario_.planner.trajectory.max_yaw_rate_rad_s));
    // Its views are rated as every flown plan's; their times count from the trajectory's start
    // until the take-off's length is known (startFlight).
    rateFlownViews(a.raw ? &*a.raw : nullptr, true, current_->startTime(), 0.0, &a);
  } else {
    // No route yet, or none to fly yet (hold_first_plan): climb to the flight height and look.
    start.p_WB.z() = scenario_.scene.flight_height_m;
    current_ = std::make_unique<control::SetpointTrajectory>(
        holdTrajectory(start, 2.0 * cfg_.replan_period_s + cfg_.plan_latency_s, holdRate()));
    failed_in_a_row_ = a.trajectory ? 0 : 1;
    holding_ = true;
  }
  tau0_ = current_->startTime();
  result_.plans.push_back(a.record);
  *run = std::move(a.run);
  return *current_;
}

void OnlinePlanning::makeGuard(const Intrinsics& camera) {
  constexpr double kGuardMinTurnRad = 5.0 * M_PI / 180.0;
  // Its lead needs the camera (before startFlight() the guard judges by the inliers alone).
  GuardLead lead;
  if (camera.width_px > 0) {
    lead = GuardLead{cfg_.guard_lead_s, camera, static_cast<double>(scenario_.vo.features.edge_threshold_px)};
  }
  guard_.emplace(cfg_.guard_inliers, kGuardMinTurnRad, 0.5 * scenario_.planner.perception.visibility.hfov_rad,
                 cfg_.guard_range_m, lead, cfg_.guard_still);
}

void OnlinePlanning::startFlight(const Intrinsics& camera, double trajectory_start_s) {
  if (flying_ || result_.plans.empty()) throw std::logic_error("OnlinePlanning::startFlight: once, after firstPlan");
  flying_ = true;
  mapper_.setCamera(camera);
  if (guard_) makeGuard(camera);
  OnlinePlan& first = result_.plans.front();
  if (first.flown_min_at_s >= 0.0) first.flown_min_at_s += trajectory_start_s;
}

bool OnlinePlanning::blockedAhead(double tau_from) const {
  const double until = std::min(current_->endTime(), tau_from + kBlockedHorizonS);
  std::vector<Eigen::Vector3d> ahead;
  for (double tau = std::max(tau_from, current_->startTime()); tau <= until + 1e-9; tau += kBlockedStepS) {
    ahead.push_back(current_->sample(tau).p_WB);
  }
  return occupiedWithin(mapper_.occupancy(), ahead, scenario_.planner.perception.robot_radius_m);
}

std::vector<Eigen::Vector3d> OnlinePlanning::positionsAhead(double tau_from) const {
  std::vector<Eigen::Vector3d> ahead;
  for (double tau = tau_from; tau < current_->endTime() + kBlockedStepS; tau += kBlockedStepS) {
    ahead.push_back(current_->sample(std::min(tau, current_->endTime())).p_WB);
  }
  return ahead;
}

void OnlinePlanning::mapFrame(const RgbdFrame& frame, double t_s, double trajectory_start_s) {
  const auto t0 = std::chrono::steady_clock::now();
  mapper_.insertDepth(frame, cfg_.map_stride_px);
  mapper_.observeFeatures(frame);
  ++result_.keyframes;
  if (!blocked_) blocked_ = blockedAhead(tau(t_s, trajectory_start_s));
  if (!goal_seen_) {
    goal_seen_ = goalObserved();
    goal_event_ = goal_seen_;
  }
  result_.map_update_s += secondsSince(t0);
}

OnlineResult OnlinePlanning::finish(const SceneGeometry& truth,
                                    const std::vector<std::pair<double, Eigen::Vector3d>>& flown) {
  OnlineResult out = std::move(result_);
  if (external_) out.planner_stderr = external_->stderrTail();
  out.final_map = mapper_.snapshot().map;
  const octomap::OcTree& tree = out.final_map->occupancy();
  out.coverage = mapCoverage(tree, scenario_);
  const MapError error = mapError(tree, scenario_.scene, truth);
  out.occupied_voxels = error.occupied_voxels;
  out.map_error_mean_m = error.mean_m;
  out.map_error_far_share = error.far_share;
  const MapHoles holes = mapHoles(tree, scenario_, truth);
  out.map_surface_crossings = holes.crossings;
  out.map_hole_share = holes.share();
  out.unknown_share = unknownShare(out.plans, flown);
  return out;
}

}  // namespace tgnav::harness
