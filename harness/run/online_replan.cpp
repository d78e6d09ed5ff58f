// OnlinePlanning (online_planning.h), the half that decides: when a plan is asked, whether the
// plan made is flown (a changed route, a renewal of the views ahead, a hold), and the tracking
// guard's reflex. The plans themselves are made in online_planning.cpp.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "harness/run/frame_prediction.h"
#include "harness/run/look_ahead.h"
#include "harness/run/online_planning.h"
#include "harness/run/view_guard.h"
#include "planner/topological_planner.h"

namespace tgnav::harness {

namespace {

// Consecutive failed plans after which a vehicle holding without a route stops (`no_path`).
constexpr int kMaxFailedPlans = 3;
// A new plan whose every position lies this close (horizontally) to the current trajectory ahead
// follows the current route: it is not flown (a switch starts from rest). Yaw is not compared:
// where the way ahead is unknown it follows the motion (trial.look_ahead_s), not the planner.
constexpr double kSameRouteM = 0.75;
// A flown plan's views are rated this often (OnlinePlan::flown_min_p): twice per camera frame
// period at the default 20 Hz would double the cost for views 2.5 cm apart at the nominal speed.
constexpr double kFlownViewStepS = 0.1;
// The guards' reflex: a hold reached within this (a deceleration of about 1.3 m/s^2 at 0.4 m/s).
constexpr double kGuardBlendS = 0.3;

// Whether every pose of `path` lies within kSameRouteM (horizontally) of some point of `ahead`.
bool followsRoute(const std::vector<planner::Pose4>& path, const std::vector<Eigen::Vector3d>& ahead) {
  for (const planner::Pose4& pose : path) {
    double best = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d& p : ahead) best = std::min(best, (p - pose.p_WB).head<2>().norm());
    if (best > kSameRouteM) return false;
  }
  return true;
}

}  // namespace

bool leavesBlindRoute(const OnlinePlan& plan, double tolerance_m) {
  return plan.chosen_blind_m >= 0.0 && plan.route_blind_m >= 0.0 &&
         plan.chosen_blind_m + tolerance_m < plan.route_blind_m;
}

bool worthLeavingRoute(const OnlinePlan& plan, double blind_tolerance_m, double margin) {
  if (plan.route_blind_m < 0.0 || plan.chosen_blind_m < 0.0) return true;
  return leavesBlindRoute(plan, blind_tolerance_m) || plan.route_length_m > (1.0 + margin) * plan.chosen_length_m;
}

int classInForce(const planner::Plan& plan, const std::vector<Eigen::Vector2d>& route, const Eigen::Vector2d& start) {
  if (route.empty()) return -1;
  std::size_t nearest = 0;
  for (std::size_t i = 1; i < route.size(); ++i) {
    if ((route[i] - start).norm() < (route[nearest] - start).norm()) nearest = i;
  }
  std::vector<Eigen::Vector2d> from_here{start};
  from_here.insert(from_here.end(), route.begin() + static_cast<std::ptrdiff_t>(nearest), route.end());
  const std::vector<double> signature = planner::windingAngles(from_here, plan.topo.obstacle_points);
  const std::size_t n = std::min(plan.topo.classes.size(), plan.candidates.size());
  for (std::size_t k = 0; k < n; ++k) {
    if (!planner::TopologicalPlanner::sameClass(plan.topo.classes[k].h_signature, signature)) continue;
    return plan.candidates[k].feasible ? static_cast<int>(k) : -1;
  }
  return -1;
}

void OnlinePlanning::keepClass(Scenario* from_here, const planner::FeatureMap& map, Attempt* a) {
  if (planner_ != planner::PlannerKind::kProposed || from_here->planner.oracle_class >= 0) return;
  const planner::Plan& plan = a->run.plan;
  if (plan.chosen < 0) return;
  const int k = classInForce(plan, class_route_, from_here->scene.start.p_WB.head<2>());
  a->record.class_in_force = k;
  if (k < 0) return;
  const planner::CandidatePath& kept = plan.candidates[static_cast<std::size_t>(k)];
  a->record.in_force_blind_m = kept.blind_length_m;
  a->record.in_force_length_m = kept.length_m;
  if (k == plan.chosen) return;
  const planner::CandidatePath& choice = plan.candidates[static_cast<std::size_t>(plan.chosen)];
  OnlinePlan judged;
  judged.chosen_blind_m = choice.blind_length_m;
  judged.chosen_length_m = choice.length_m;
  judged.route_blind_m = kept.blind_length_m;
  judged.route_length_m = kept.length_m;
  if (worthLeavingRoute(judged, blindTolerance(), cfg_.route_margin)) return;
  from_here->planner.oracle_class = k;  // the same map and seed: the same classes, in the same order
  PlanRun again = runPlanner(*from_here, map, planner_, seed_, rrt_samples_, "planner.oracle_class",
                             cfg_.unknown_space == UnknownSpace::kFree);
  from_here->planner.oracle_class = -1;
  // Both plans' time counts (the caller adds the one kept).
  const bool kept_ok = again.plan.chosen >= 0 && again.trajectory.trajectory;
  const PlanRun& spent = kept_ok ? a->run : again;
  a->record.voxel_map_s += spent.voxel_map_s;
  a->record.solve_s += spent.solve_s;
  if (!kept_ok) return;  // the choice stays
  a->run = std::move(again);
  a->record.kept_class = true;
}

void OnlinePlanning::rateRouteBlindness(const std::vector<Eigen::Vector3d>& ahead, Attempt* a) {
  const planner::Plan& plan = a->run.plan;
  if (plan.chosen < 0 || plan.chosen >= static_cast<int>(plan.candidates.size())) return;
  const planner::CandidatePath& chosen = plan.candidates[static_cast<std::size_t>(plan.chosen)];
  a->record.chosen_blind_m = chosen.blind_length_m;
  a->record.chosen_length_m = chosen.length_m;
  for (const planner::CandidatePath& c : plan.candidates) {
    if (c.feasible && !c.path.empty() && followsRoute(c.path, ahead)) {
      a->record.route_blind_m = c.blind_length_m;
      a->record.route_length_m = c.length_m;
      return;
    }
  }
}

std::optional<control::SetpointTrajectory> OnlinePlanning::renewViews(const Attempt& a, double tau_switch) {
  std::optional<control::SetpointTrajectory> renewed =
      renewedViews(*current_, *a.raw, tau_switch, scenario_.planner.trajectory.max_yaw_rate_rad_s);
  // The search's views stay its own when renewed, as when first flown (plan()); before, the look-ahead
  // turned a renewed way to the goal toward the way ahead: blind, as rated, on detour-1009.
  if (renewed) {
    switchTo(a.chosen_views ? *renewed : lookAhead(*renewed, *a.map, *a.run.voxels), tau_switch, cfg_.blend_s);
  }
  return renewed;
}

void OnlinePlanning::rateFlownViews(const control::SetpointTrajectory* own, bool own_from_start, double tau_switch,
                                    double t_switch, Attempt* a) const {
  if (!a->run.voxels) return;
  const planner::PerceptionPlannerConfig& perception = scenario_.planner.perception;
  // A look is flown to its end (lookInFlight): no later plan takes effect before then.
  const double span_s =
      looking_ ? std::max(cfg_.replan_period_s, current_->endTime() - tau_switch) : cfg_.replan_period_s;
  const RatedView flown = worstView(*current_, tau_switch, span_s, kFlownViewStepS, *a->run.voxels,
                                    perception.visibility, perception.information);
  const double p = flown.prediction.track_probability;
  if (p < 0.0) return;  // no model
  OnlinePlan& r = a->record;
  r.flown_min_p = p;
  r.flown_min_at_s = t_switch + (flown.tau - tau_switch);
  r.flown_min_yaw_rad = flown.yaw_rad;
  r.flown_min_detections = flown.prediction.support.detections;
  if (own == nullptr || p >= perception.information.min_track_probability) return;
  const double from = own_from_start ? own->startTime() : tau_switch;
  r.own_min_p =
      worstView(*own, from, span_s, kFlownViewStepS, *a->run.voxels, perception.visibility, perception.information)
          .prediction.track_probability;
}

void OnlinePlanning::switchTo(const control::SetpointTrajectory& next, double tau_switch, double blend_s) {
  current_ = std::make_unique<control::SetpointTrajectory>(
      limitYawRate(control::spliceTrajectory(*current_, next, tau_switch, blend_s), tau_switch,
                   scenario_.planner.trajectory.max_yaw_rate_rad_s));
}

bool OnlinePlanning::lookGuard(double t_s, double trajectory_start_s) {
  if (!cfg_.look_guard || !rated_map_ || t_s < trajectory_start_s) return false;
  const double tau_now = tau(t_s, trajectory_start_s);
  const bool look = lookInFlight(tau_now);
  if (!look && !cfg_.look_guard_routes) return false;
  const double floor = look ? look_floor_ : cfg_.look_min_detections;
  const planner::PerceptionPlannerConfig& perception = scenario_.planner.perception;
  // (A view below the floor already is not one the look flies into: the search starts where the
  // vehicle is, whatever its view.)
  const std::optional<RatedView> short_view = viewAheadFallsShort(
      *current_, tau_now, cfg_.guard_lead_s, floor, *rated_map_, perception.visibility, perception.information);
  if (!short_view) return false;
  const RatedView& ahead = *short_view;
  const control::TrajectorySetpoint now = current_->sample(tau_now);
  GuardEvent e;
  e.t_s = t_s;
  e.yaw_rad = ahead.yaw_rad;
  e.good_yaw_rad = now.yaw_rad;
  e.inliers = last_inliers_;
  e.turning = false;  // the search rules out that view near the apex, at its yaw (trippedView)
  e.predicted_detections = ahead.prediction.support.detections;
  const double half_fov = 0.5 * perception.visibility.hfov_rad;
  e.wedge.apex = current_->sample(ahead.tau).p_WB;
  e.wedge.from_rad = std::remainder(ahead.yaw_rad - half_fov, 2.0 * M_PI);
  e.wedge.width_rad = 2.0 * half_fov;
  e.wedge.range_m = cfg_.guard_range_m;
  result_.guards.push_back(e);
  // Not a wedge of unknown space planned occupied (wedges_): what makes the view poor is mapped.
  holdForView(planner::Pose4{now.p_WB, now.yaw_rad}, t_s, tau_now);
  return true;
}

void OnlinePlanning::holdForView(const planner::Pose4& hold, double t_s, double tau_now) {
  // A reflex, not a plan: it stops within kGuardBlendS.
  switchTo(holdTrajectory(hold, 2.0 * cfg_.replan_period_s + cfg_.plan_latency_s, holdRate()), tau_now, kGuardBlendS);
  holding_ = true;
  stops_short_ = false;
  looking_ = false;
  blind_view_ = true;
  pending_until_s_ = t_s;
}

void OnlinePlanning::trackFrame(double t_s, double trajectory_start_s, const vo::FrameResult& frame) {
  last_inliers_ = frame.inliers;
  if (lookGuard(t_s, trajectory_start_s)) return;
  if (!guard_ || t_s < trajectory_start_s) return;
  const Eigen::Isometry3d& X_WC = frame.X_WC;
  const int inliers = frame.inliers;
  const Eigen::Vector3d axis = X_WC.linear().col(2);  // the optical axis
  const double yaw = std::atan2(axis.y(), axis.x());
  const double good = guard_->goodYaw();
  const double tau_now = tau(t_s, trajectory_start_s);
  // trial.guard_planned_turn: the turn the trajectory commands over the lead.
  const double planned =
      cfg_.guard_planned_turn
          ? std::remainder(current_->sample(tau_now + cfg_.guard_lead_s).yaw_rad - current_->sample(tau_now).yaw_rad,
                           2.0 * M_PI)
          : 0.0;
  const std::optional<BlindWedge> wedge =
      guard_->observe(t_s, X_WC.translation(), yaw, inliers, &frame.inlier_columns, planned);
  if (!wedge) return;
  wedges_.push_back(*wedge);
  result_.guards.push_back(
      GuardEvent{t_s, yaw, good, inliers, guard_->lastTripTurned(), *wedge, guard_->lastTripPlannedRad()});
  holdForView(planner::Pose4{current_->sample(tau_now).p_WB, good}, t_s, tau_now);
}

std::string OnlinePlanning::takeTrigger() {
  const char* why = blind_view_ ? "blind_view" : blocked_ ? "blocked" : goal_event_ ? "goal_seen" : "period";
  blind_view_ = blocked_ = goal_event_ = false;
  return why;
}

void OnlinePlanning::adopt(Attempt* a, double tau_switch, double t_switch, bool before_start) {
  a->record.adopted = true;
  stops_short_ = a->stops_short;
  looking_ = a->look.has_value();
  noteLook(*a);
  last_change_s_ = a->record.t_s;
  switchTo(*a->trajectory, tau_switch, before_start ? 0.0 : cfg_.blend_s);
  rateFlownViews(a->raw ? &*a->raw : nullptr, true, tau_switch, t_switch, a);
  if (cfg_.look_keep_class) {
    class_route_.clear();
    for (const Eigen::Vector3d& p : a->record.path) class_route_.push_back(p.head<2>());
  }
  failed_in_a_row_ = 0;
  holding_ = false;
  if (guard_) guard_->rearm();
  if (cfg_.look_guard) rated_map_ = std::move(a->run.voxels);
  result_.plans.push_back(std::move(a->record));
}

std::string OnlinePlanning::replan(double t_s, double trajectory_start_s) {
  if (!planner_failure_.empty()) return planner_failure_;
  const bool event = blocked_ || goal_event_ || blind_view_;
  if (t_s < pending_until_s_ - 1e-9 || (t_s < next_replan_s_ - 1e-9 && !event)) return std::string();
  const planner::Pose4& goal = scenario_.scene.goal;
  const double t_eff = t_s + cfg_.plan_latency_s;
  const bool before_start = t_eff <= trajectory_start_s;
  planner::Pose4 start = scenario_.scene.start;
  double tau_switch = tau0_;
  if (!before_start) {
    tau_switch = tau(t_eff, trajectory_start_s);
    const control::TrajectorySetpoint sp = current_->sample(tau_switch);
    start.p_WB = Eigen::Vector3d(sp.p_WB.x(), sp.p_WB.y(), scenario_.scene.start.p_WB.z());
    start.yaw_rad = sp.yaw_rad;
  }
  const bool arriving = (start.p_WB - goal.p_WB).head<2>().norm() <= 0.5 * scenario_.trial.goal_radius_m;
  if (arriving && failed_in_a_row_ == 0) {
    next_replan_s_ = std::numeric_limits<double>::infinity();  // the current trajectory ends at the goal
    takeTrigger();
    return std::string();
  }
  const double tau_now = tau(t_s, trajectory_start_s);
  const bool spent = tau_now >= current_->endTime() - cfg_.plan_latency_s;
  // Failed plans this many in a row end the trial (no_path); one more is the last chance.
  const auto ends_trial = [&](int failed) { return failed >= kMaxFailedPlans && (spent || holding_); };
  last_chance_ = ends_trial(failed_in_a_row_ + 1);
  Attempt a = planClearOf(start, t_s, takeTrigger());
  next_replan_s_ = t_s + cfg_.replan_period_s;
  // A trajectory that stops short of unknown space and ends before the next plan is asked gives way
  // to this one.
  const bool stopping = stops_short_ && !before_start && tau_switch + cfg_.replan_period_s >= current_->endTime();
  const bool looking = !before_start && lookInFlight(tau_now);
  const bool in_flight = a.trajectory && !before_start;  // its paths are compared with the route ahead
  const std::vector<Eigen::Vector3d> ahead = in_flight ? positionsAhead(tau_switch) : std::vector<Eigen::Vector3d>{};
  if (in_flight) rateRouteBlindness(ahead, &a);
  // A plan that rates the current route blind for longer than its choice leaves it at once.
  const bool leave_blind = cfg_.leave_blind_route && leavesBlindRoute(a.record, blindTolerance());
  const bool must_switch = holding_ || (stopping && !looking) || a.record.trigger == "blocked" || leave_blind;
  // (A plan exactly commit_s after the last change is not committed, whatever the rounding.)
  const bool committed = t_s < last_change_s_ + cfg_.commit_s - 1e-9 || looking;
  // Whether the plan follows the current route: asked only where it decides something.
  // Renewing the views is the built-in planners' (as the look-ahead): an external planner's yaw is its own.
  const bool renew = cfg_.renew_views && !external_;
  const bool same =
      in_flight && !must_switch && !looking && (!committed || renew) && followsRoute(a.run.plan.path, ahead);
  const bool keep = cfg_.keep_route && in_flight && !worthLeavingRoute(a.record, blindTolerance(), cfg_.route_margin);
  if (a.trajectory && !must_switch && (committed || same || keep)) {
    failed_in_a_row_ = 0;
    if (renew && same) {
      const std::optional<control::SetpointTrajectory> own = renewViews(a, tau_switch);
      rateFlownViews(own ? &*own : nullptr, false, tau_switch, t_eff, &a);
      a.record.views_renewed = true;
      pending_until_s_ = t_eff;
    }
    if (cfg_.look_guard) rated_map_ = std::move(a.run.voxels);
    result_.plans.push_back(std::move(a.record));
    return std::string();
  }
  if (a.trajectory) {
    adopt(&a, tau_switch, before_start ? trajectory_start_s : t_eff, before_start);
    pending_until_s_ = t_eff;
    return std::string();
  }
  result_.plans.push_back(a.record);
  ++failed_in_a_row_;
  if (ends_trial(failed_in_a_row_)) {
    std::ostringstream why;
    why << failed_in_a_row_ << " plans in a row found no route (last: " << a.record.detail << ")";
    return why.str();
  }
  if (spent || blockedAhead(tau_now)) {
    // Stop where the current trajectory is at the switch, and wait for a route.
    switchTo(holdTrajectory(start, 2.0 * cfg_.replan_period_s + cfg_.plan_latency_s, holdRate()), tau_switch,
             before_start ? 0.0 : cfg_.blend_s);
    holding_ = true;
    looking_ = false;
    pending_until_s_ = t_eff;
  }
  return std::string();
}

}  // namespace tgnav::harness
