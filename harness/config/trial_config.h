#pragma once
// Settings of a closed-loop trial: a scenario's `trial:` section. Its keys are TrialConfig::visit's;
// configs/trial.yaml lists them all with their defaults and what they mean.
#include <string>
#include <utility>
#include <vector>

#include "control/state_estimator.h"
#include "harness/config/flight_config.h"

namespace tgnav::harness {

// The name of `value` in a table of names such as stateSourceNames() ("?" when absent).
template <typename E>
const char* nameOf(E value, const std::vector<std::pair<std::string, E>>& names) {
  for (const auto& [name, v] : names) {
    if (v == value) return name.c_str();
  }
  return "?";
}

enum class StateSource { kGroundTruth, kVo };
// Every source with its name in configs: {"gt", kGroundTruth}, {"vo", kVo}.
const std::vector<std::pair<std::string, StateSource>>& stateSourceNames();
const char* toString(StateSource source);  // "gt" | "vo"
// False when `text` names no source.
bool parseStateSource(const std::string& text, StateSource* source);

// The simulated IMU: the true specific force and body rates, sampled every physics step, with
// white noise and a constant bias per axis drawn from the trial's seed.
struct ImuConfig {
  double accel_noise_m_s2 = 0.05;  // white noise sigma per sample (about 2.2e-3 m/s^2/sqrt(Hz) at 500 Hz)
  double accel_bias_m_s2 = 0.02;   // sigma of the constant bias per axis
  double gyro_noise_rad_s = 0.005;
  double gyro_bias_rad_s = 0.001;

  // The keys of a trial's `imu:` section (harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a("accel_noise_m_s2", accel_noise_m_s2);
    a("accel_bias_m_s2", accel_bias_m_s2);
    a("gyro_noise_rad_s", gyro_noise_rad_s);
    a("gyro_bias_rad_s", gyro_bias_rad_s);
  }

  void validate() const;  // std::invalid_argument naming the field and value
};

// How a trial plans (trial.mode): `prior` plans once on the scene's survey map before take-off;
// `online` starts with the map of `prior_map`, builds the occupancy and the landmarks from the
// onboard RGB-D frames during flight, at the pose of `map_pose`, and replans on it
// (harness/run/online_planning.h).
enum class TrialMode { kPrior, kOnline };
const std::vector<std::pair<std::string, TrialMode>>& trialModeNames();  // "prior", "online"
// What an online trial knows before take-off: nothing, the survey map, or the survey map within
// prior_radius_m of the start.
enum class PriorMap { kNone, kSurvey, kRadius };
const std::vector<std::pair<std::string, PriorMap>>& priorMapNames();  // "none", "survey", "radius"
// The pose an online trial maps at: its own estimate (the VO fused with the IMU; it flies on it),
// or the truth (the ablation that isolates the VO's drift; it flies on ground truth).
enum class MapPose { kEstimate, kTruth };
const std::vector<std::pair<std::string, MapPose>>& mapPoseNames();  // "estimate", "truth"
// Space never observed, for the planners of an online trial: free (planned through, optimistic)
// or blocked (avoided).
enum class UnknownSpace { kFree, kBlocked };
const std::vector<std::pair<std::string, UnknownSpace>>& unknownSpaceNames();  // "free", "blocked"
// How the perception model rates surfaces an online trial has not seen yet (harness/run/unseen_prior.h):
// blind (no landmarks: a view of them gives the VO nothing), or textured like the surfaces seen so
// far on average (mean: landmarks on the boundary of the observed free space), or, with the
// proposed planner, mean for the choice of route (the homology class) and blind for the path and
// the views flown along it (route_mean; the other planners take it as blind).
enum class UnseenPrior { kBlind, kMean, kRouteMean };
const std::vector<std::pair<std::string, UnseenPrior>>& unseenPriorNames();  // "blind", "mean", "route_mean"

// The keys of an online trial (flat in `trial:`); unused in prior mode.
struct OnlineConfig {
  TrialMode mode = TrialMode::kPrior;
  PriorMap prior_map = PriorMap::kNone;
  double prior_radius_m = 2.0;  // prior_map radius
  MapPose map_pose = MapPose::kEstimate;
  UnknownSpace unknown_space = UnknownSpace::kFree;
  // With proposed and rrtstar (the planners that rate views). Measured: README, online planning.
  UnseenPrior unseen_prior = UnseenPrior::kBlind;
  // A plan takes effect this long (simulated time) after the state it starts from was sampled:
  // the vehicle flies its current trajectory meanwhile. Configured, never measured.
  double plan_latency_s = 0.5;
  double replan_period_s = 2.0;  // a plan every this much simulated time, and on events
  double blend_s = 1.0;          // the new trajectory replaces the old one over this long
  // A plan that changes the route is flown only this long after the last change (unless the path
  // ahead is blocked or the vehicle holds): the vehicle commits to a route long enough to look at
  // it, instead of dithering between two whose unknown parts both look free.
  double commit_s = 6.0;
  // A plan whose choice the proposed planner rates blind for shorter than the current route's class
  // on the same map (by more than planner.selection.blind_tolerance_m) is flown at once, whatever
  // commit_s says: the predicted visibility of the route ahead has dropped.
  bool leave_blind_route = false;
  // Hysteresis on the route (ours): once commit_s has passed, a plan that leaves the current route is
  // flown only where it is worth a restart from rest: no candidate of the plan follows the current
  // route (its class is gone from the map, or left more than kSameRouteM), or the route's candidate is
  // blind for longer than the choice by more than planner.selection.blind_tolerance_m, or longer than
  // it by more than route_margin of the choice's length. false: any other route is flown. On the
  // survey map the vehicle otherwise changed between classes of near-equal cost every commit_s and
  // wandered (gallery: 4/10 reached the goal, 10/10 with it); from no map it gained nothing
  // (docs/results/keep_route).
  bool keep_route = false;
  double route_margin = 0.2;
  // Where the trajectory this far ahead runs through space unknown when planned (or everywhere,
  // with look_ahead_always), the camera turns from the planner's yaw as little as keeps the way
  // there in view (look before flying there); 0: the planner's yaw everywhere.
  double look_ahead_s = 2.0;
  bool look_ahead_always = false;
  // With the perception-aware planners (proposed, rrtstar), the turn toward the way ahead goes
  // only as far as the perception model rates the view trackable on the map the plan was made on
  // (harness/run/look_ahead.h); false: as far as the way ahead needs, as for agnostic. Off: on
  // storage and gallery it changed no outcome (README, online planning).
  bool look_ahead_keeps_tracking = false;
  // With proposed and rrtstar, the look-ahead's yaw keeps the way ahead within the same limit, on
  // whichever side of it the perception model rates the view best on the map the plan was made on
  // (the least turn at a tie; harness/run/look_ahead.h, bestViewOffset). Not with
  // look_ahead_keeps_tracking.
  bool look_ahead_best_view = false;
  // With proposed, its pose graph scores each view where the way ahead is unknown at the yaw the
  // look-ahead flies there (planner.pose_graph.look_unknown_m set to look_ahead_s times the
  // trajectory's nominal speed; planner/pose_graph.h), so that a plan rates the views it flies.
  // false: at the yaws it chose, which the look-ahead then turns. Measured and left off: storage
  // 5/10 and gallery 0/10 against 9/10 and 1/10 (docs/results/first_look); likely because, from no
  // map, a view into unknown space has nothing mapped in it and rates blind.
  bool plan_look_ahead = false;
  // The vehicle climbs and holds its start pose, mapping what its camera sees, until the first
  // replan period, and the first plan it flies is made then; the plan made before take-off, on the
  // prior map alone (from no map: an empty one), is recorded but not flown. false: that plan is flown.
  // Measured on the premise scenes and left off: the VO was still lost in the first turn (median
  // 4.3 s, 0/16; docs/results/first_look).
  bool hold_first_plan = false;
  // The built-in planners' trajectories end at rest before their path first comes within the robot
  // radius and two voxels of space unknown when planned (0.5 m on at least), the camera turned to
  // see the way on; the next plan, made once the map has grown, sends the vehicle on
  // (harness/run/look_ahead.h, stopBeforeUnknown).
  bool stop_before_unknown = false;
  // Look, then fly (harness/run/explore.h; proposed and rrtstar): where the plan's route runs into
  // unknown space, the vehicle flies instead, through observed free space and with every view rated
  // trackable on the map so far (and expecting at least look_min_detections detections), to the place and
  // yaw whose trackable view observes most of the unknown way on, and stops there; the next plan goes
  // on from what it saw (a look is flown to its end: OnlinePlanning::lookInFlight). Where that search
  // reaches the goal, its way there is flown. agnostic ignores
  // it (it has no perception model). Measured and left off: it kept the VO for minutes, but as
  // frozen it reached the goal on none of the development or premise scenes it flew
  // (docs/results/look_then_fly).
  bool look_then_fly = false;
  // The detections (planner::ViewSupport::detections) every view look_then_fly flies must expect,
  // on top of the perception model's rating; 0: the model's alone. 150, the tracking guard's
  // guard_inliers, chosen before any run: the model fitted with the paper's line of sight rated
  // views trackable where the VO found 50-80 features (docs/results/look_then_fly).
  double look_min_detections = 150.0;
  // With look_then_fly, the search rates each view on the landmarks that stay in the image when the
  // camera's yaw errs by up to this either way (the horizontal field of view narrowed by it on each
  // side), not the whole image: its views with texture only at the image's edges were lost to the
  // pose the vehicle really flew (gallery seed 1: a look rated 213-220 detections at its cells, all
  // in strips at the edges, was flown 0.15 m off them, and the VO was lost at 49; the camera saw bare
  // wall). Where the margin leaves nothing to fly, the search is made again on the whole image
  // (OnlinePlanning::searchLook). 0: the whole image. Measured at 7.5 deg, half the search's yaw step
  // (chosen before any run, not fitted), and left off (docs/results/fov_margin).
  double look_fov_margin_deg = 0.0;
  // With look_then_fly: the view a look (or an advance) ends at, where the vehicle stops and holds
  // it while the next plan is made, must expect this much more than the search's floor (detections
  // >= floor x (1 + margin); LookConfig::hold_margin), the views on the way there the floor. On
  // gallery seed 2 (look_guard) a look ended at a view its search rated 157 against 150; on the
  // map 14 s later it rated 142, and the VO was lost there. 0: the floor.
  double look_hold_margin = 0.0;
  // With look_then_fly: of the looks that qualify (LookConfig::along), the one farthest along the
  // planner's route, then the nearest. false: the nearest. On gallery seed 2 the explorer looked
  // again every 0.4 m for 25 s while the views it chose watched the way on 5-10 m ahead.
  bool look_along = false;
  // With look_then_fly (the proposed planner): where the search on the chosen class's route finds
  // neither a view of its way on nor an advance along it, the other classes' routes are searched,
  // in the planner's order of cost, and the first that has either is flown (online.json:
  // look_class), before any look near the way on or at any unknown space. false: the choice's
  // route alone. On gallery the explorer went back and forth for 300-400 s in the east corridor
  // between advances along a class whose way on no trackable view observed and looks at unknown
  // space behind it.
  bool look_classes = false;
  // With look_then_fly, a goal-directed order of looks (LookConfig::advance): a look must observe
  // the robot's footprint of unknown space; where none observes the way on, the vehicle flies along
  // the route's observed part as far as the search reaches, and only then looks near the way on, then
  // anywhere. false: any look that observes the way on, else any unknown space (on the premise scenes,
  // 8 of 16 flights explored until they timed out: docs/results/grazing).
  bool look_advance = false;
  // With look_then_fly: an unknown column that this many adopted look poses were to observe, and
  // that is still unknown, no longer counts for what a view observes (0: never given up). Columns
  // inside obstacles, behind walls and seen through the map's holes stay unknown however often
  // they are looked at: on detour-5002 the explorer flew back 5 m, again and again, to a view of 4.
  int look_give_up = 0;
  // With look_advance: where the way on is the last 2 m (LookConfig::near_m) to the goal, no
  // trackable view observes it and the vehicle cannot advance, it turns to the view of the way on
  // that the model rates least short, trackable or not, and leaves it to the tracking guard
  // (LookConfig::probe; meant with guard_tracking). false: it looks near the way on, then anywhere.
  // Most explorer flights that failed had a route whose first unobserved point lay within 2 m of the
  // goal; measured, not adopted (premise 0/16: docs/results/advance).
  bool look_probe = false;
  // With look_then_fly: where the search finds no trackable view that observes any unknown space and
  // that failed plan would end the trial (the third in a row, holding: no_path; 7 of the 16 premise
  // flights at 7452bb9, docs/results/advance), the plan flies the planner's route instead, as an
  // online trial without look_then_fly does (stop_before_unknown, the look-ahead rule, the tracking
  // guard). Not before: at the start, with nothing mapped, flying the route lost the VO at once where
  // holding and looking went on to the goal (development scene detour-5004).
  bool look_fallback = false;
  // With look_fallback, > 0: before the route is flown as planned, with views nothing rated, the
  // search is made again with this detection floor in place of look_min_detections, and a look (or
  // the way to the goal) it finds is flown instead (online.json: look_lowered). The fallbacks'
  // routes flew views the model rated 76-118 on the map they were planned on, and came just before
  // 2 of the 3 VO losses of docs/results/hold_margin. 0: the route at once.
  double look_fallback_floor = 0.0;
  // With look_then_fly, > 0: where no plan for this long (simulated seconds) has found a route to the
  // goal at least 0.5 m shorter than the shortest before it (RouteProgress), the looks have stalled,
  // and the plan flies the planner's route instead, as look_fallback does. On development scene
  // detour-5002 the vehicle shuttled 100 s between an advance and a look near the way on, 2 m
  // apart, the way on never observed. 0: never. 60 s (a fifth of max_flight_s) was chosen, not fitted.
  // Measured, not adopted: development 3/8 against 4/8 without it, two VO losses where the guard's
  // trips then left only the blind route (docs/results/advance).
  double look_stall_s = 0.0;
  // With look_then_fly (the proposed planner): the explorer keeps the homology class it last flew.
  // A plan whose choice is another class flies the candidate of the class in force instead (its H-
  // signature on the plan's map, from the vehicle's place along the route last adopted), unless that
  // candidate is blind for longer (planner.selection.blind_tolerance_m more) or longer (route_margin
  // of the choice's length), as keep_route judges a route. false: each plan's choice. The explorer's
  // classes cost nearly the same through unknown space, and it went back and forth between them
  // (development detour-5003 for 220 s; gallery seed 1 flew 4 m back along a class it had left,
  // and this did not keep it there). Measured on development scenes only, not adopted: 5/8 against
  // 4/8 (docs/results/advance).
  bool look_keep_class = false;
  // With look_then_fly, flying on the VO: where the last frame kept at least guard_inliers inliers,
  // the detection floor drops to guard_inliers times the detections the model expects of the
  // current view over its inliers, where that is lower (LookConfig::tracked_inliers): the model
  // counts only the landmarks mapped so far. false: look_min_detections as set (on detour-5006 the
  // vehicle never left its start, tracking 700-900 inliers, with no view rated above the floor).
  bool look_calibrate_floor = false;
  // With look_then_fly and guard_lead_s > 0: while a look is flown, each tracked frame rates the
  // view the trajectory holds guard_lead_s ahead, on the map of the latest plan, with the search's
  // floor (the detections it asked of the look's views, LookPlan::floor). Where that view falls
  // below the floor and the view now does not, the vehicle stops where its trajectory is (as the
  // tracking guard does), the view ahead is ruled out for the looks as a trip without a turn
  // (GuardEvent::predicted), and a plan is due. The search rates its grid's cells; the vehicle flies
  // a smoothed path off them: on gallery seed 1 a look rated 213-220 at its cells flew views the
  // model rated 76-118 on the same map, and the VO went from 1000 features to lost in 1 s without a
  // turn, too fast for the guard's inliers (OnlinePlanning::lookGuard). false: looks are flown to
  // their end unless the path is blocked or the tracking guard trips. Measured on development scenes,
  // not adopted: gallery still 0/2, detour 5001-5008 6/8 against 5/8 (docs/results/look_guard).
  bool look_guard = false;
  // With look_guard: every trajectory flown is guarded, not only looks: the search's way to the goal
  // and the route flown as planned (look_fallback, look_stall_s), at look_min_detections where no
  // look's floor applies. On gallery seed 1 with look_guard the flight ended after two look_fallback
  // plans flew the route with the look-ahead's views, unrated, and the VO went from 1000 features to
  // lost in 5 s. With it, both gallery flights kept the VO and timed out 21 m from the goal: the
  // fallback tripped, held, and flew the same route again (docs/results/look_guard). false: looks only.
  bool look_guard_routes = false;
  // A plan along the current route (not flown: a switch restarts from rest) renews the views
  // ahead: the trajectory keeps its positions and takes the new plan's yaw, planned on the map as
  // it is now, from the vehicle's yaw at the switch, then the look-ahead rule on that map
  // (harness/run/look_ahead.h, renewedViews). false: the views of the plan last flown, planned
  // where the way ahead was still unknown. On by default since 7b9d05e: from no map the proposed
  // planner kept the VO to the goal on storage in 9/10 against 1/10 (seeds 1-10) and 6/10 against
  // 3/10 (seeds 21-30, flown only after the fix of 7ca8608 was frozen; docs/results/renew).
  bool renew_views = true;
  // The tracking guard (harness/run/view_guard.h; the built-in planners, flying on the estimate):
  // a frame the VO tracks with fewer than guard_inliers inliers while the camera turns (5 deg or
  // more over the last 0.5 s), stops the vehicle and turns the camera back to the last yaw that
  // tracked enough, and the plans
  // from then on take the unknown space that turn looked toward, within guard_range_m of where it
  // was, as occupied. guard_inliers 150 (5 times vo.min_inliers) and guard_range_m 3 were chosen,
  // not fitted.
  bool guard_tracking = false;
  int guard_inliers = 150;
  double guard_range_m = 3.0;
  // > 0: the guard judges a frame by the inliers that stay in view were its turn to go on this
  // long (harness/run/view_guard.h, GuardLead), and trips before the texture leaves the image.
  // 0: by the inliers alone (docs/results/guard: it tripped 0.15 s before the loss). Measured at
  // 0.6 s and left off: storage never lost the VO, but 8 of 10 flights stalled (docs/results/lead).
  double guard_lead_s = 0.0;
  // true: the guard trips where the camera does not turn as well (ViewGuard's `still`): the texture
  // leaves the image as the vehicle moves (development 5004 and premise 1003 lost the VO so). The
  // wedge is then the view lost. false: only a turn trips it. Probed, not adopted: it saved 5004
  // but not premise 1009, where the estimate drifted before it tripped (docs/results/advance).
  bool guard_still = false;
  // With guard_lead_s > 0: the lead also foresees the turn the trajectory being flown commands over
  // the next guard_lead_s (its yaw then less its yaw now), and takes the larger of that and the turn
  // at the measured rate; a commanded turn of at least the guard's minimum turn counts as a turn,
  // so the guard can trip before the camera starts it. false: the measured rate alone, which is
  // still small when a turn starts (gallery with route_mean: it tripped 0.1 s before the loss;
  // docs/results/no_return).
  bool guard_planned_turn = false;
  int map_every_frames = 4;  // every Nth camera frame goes into the map (a keyframe)
  int map_stride_px = 8;     // ... every Nth pixel of its depth, in both directions
  // Depth within this range goes into the map, and the features there become landmarks: the
  // survey's range (MapBuildConfig::max_range_m, 6 m: RGB-D noise grows as z^2). The VO tracks
  // features up to vo.max_depth_m (10 m) and the planners count them that far
  // (planner.perception.visibility.max_range_m), so texture between the two is tracked but never
  // mapped online: from the premise scenes' starts, a median of 23.5 landmarks mapped in 2 s against
  // 591 at 10 m. Measured at 10 m and left at 6: storage 3/10 against 9/10 (docs/results/first_look).
  double map_range_m = 6.0;
  // The online map's depth rays clear free space only short of the surface they hit
  // (MapBuildConfig::free_short_of_surface).
  bool map_short_of_surface = false;
  // A depth pixel without a return (nothing within the camera's range, camera.max_depth_m) clears
  // the unobserved space along its ray to that range less three sigmas of its depth noise, within
  // map_range_m (MapBuildConfig::no_return_depth_m): down a corridor longer than the camera's
  // range the space at flight height is otherwise never observed, and look_then_fly never flies
  // it. false: such pixels are skipped.
  bool map_clear_no_return = false;
  // Simulated time from take-off; beyond it the flight stops. 300 s: gallery's online flight on
  // the true pose alone took 115 s for its 38 m (docs/results/online10/truth), so 120 s stopped
  // flights that were still tracking and making way.
  double max_flight_s = 300.0;

  template <typename Archive>
  void visit(Archive& a) {
    a.choice("mode", mode, trialModeNames());
    a.choice("prior_map", prior_map, priorMapNames());
    a("prior_radius_m", prior_radius_m);
    a.choice("map_pose", map_pose, mapPoseNames());
    a.choice("unknown_space", unknown_space, unknownSpaceNames());
    a.choice("unseen_prior", unseen_prior, unseenPriorNames());
    a("plan_latency_s", plan_latency_s);
    a("replan_period_s", replan_period_s);
    a("blend_s", blend_s);
    a("commit_s", commit_s);
    a("leave_blind_route", leave_blind_route);
    a("keep_route", keep_route);
    a("route_margin", route_margin);
    a("look_ahead_s", look_ahead_s);
    a("look_ahead_always", look_ahead_always);
    a("look_ahead_keeps_tracking", look_ahead_keeps_tracking);
    a("look_ahead_best_view", look_ahead_best_view);
    a("plan_look_ahead", plan_look_ahead);
    a("hold_first_plan", hold_first_plan);
    a("stop_before_unknown", stop_before_unknown);
    a("look_then_fly", look_then_fly);
    a("look_min_detections", look_min_detections);
    a("look_fov_margin_deg", look_fov_margin_deg);
    a("look_hold_margin", look_hold_margin);
    a("look_along", look_along);
    a("look_classes", look_classes);
    a("look_advance", look_advance);
    a("look_give_up", look_give_up);
    a("look_probe", look_probe);
    a("look_fallback", look_fallback);
    a("look_fallback_floor", look_fallback_floor);
    a("look_stall_s", look_stall_s);
    a("look_keep_class", look_keep_class);
    a("look_calibrate_floor", look_calibrate_floor);
    a("look_guard", look_guard);
    a("look_guard_routes", look_guard_routes);
    a("renew_views", renew_views);
    a("guard_tracking", guard_tracking);
    a("guard_inliers", guard_inliers);
    a("guard_range_m", guard_range_m);
    a("guard_lead_s", guard_lead_s);
    a("guard_still", guard_still);
    a("guard_planned_turn", guard_planned_turn);
    a("map_every_frames", map_every_frames);
    a("map_stride_px", map_stride_px);
    a("map_range_m", map_range_m);
    a("map_short_of_surface", map_short_of_surface);
    a("map_clear_no_return", map_clear_no_return);
    a("max_flight_s", max_flight_s);
  }

  bool online() const { return mode == TrialMode::kOnline; }
  // Whether a trial needs the scene's survey feature map: an online trial from no map does not (it
  // takes only the map resolution, the survey's default).
  bool needsSurvey() const { return !online() || prior_map != PriorMap::kNone; }
  void validate() const;
  void validateLooks() const;  // validate()'s checks of the look_* keys
};

struct TrialConfig {
  StateSource state_source = StateSource::kGroundTruth;
  double camera_rate_hz = 20.0;
  double goal_radius_m = 0.5;
  // A trial whose VO tracked to the end but whose goal error exceeds this fraction of the
  // distance flown is `drifted`, not `success` (harness/run/trial_status.h).
  double max_drift_ratio = 0.01;
  bool pipeline = true;
  FlightConfig flight;
  ImuConfig imu;
  control::EstimatorConfig estimator;
  OnlineConfig online;  // its keys are flat in `trial:` (trial.mode, trial.plan_latency_s, ...)

  // The keys of configs/trial.yaml (harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a.choice("state_source", state_source, stateSourceNames());
    a("camera_rate_hz", camera_rate_hz);
    a("goal_radius_m", goal_radius_m);
    a("max_drift_ratio", max_drift_ratio);
    a("pipeline", pipeline);
    a("flight", flight);
    a("imu", imu);
    a("estimator", estimator);
    online.visit(a);
  }

  void validate() const;  // std::invalid_argument naming the field (dotted within trial) and value
};

}  // namespace tgnav::harness
