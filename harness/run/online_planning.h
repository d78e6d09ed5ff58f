#pragma once
// Online planning (trial.mode online): the vehicle starts with the map of trial.prior_map, maps
// the onboard camera's keyframes during flight at the pose of trial.map_pose (its own estimate,
// or the truth), and plans again on that map every trial.replan_period_s, when the path ahead
// runs into space newly seen occupied, and when the goal is first observed. Plans are made in the frame the vehicle
// flies in (its estimate); collisions are judged on the true scene by the trial.
//
// Time is simulated: the simulation waits while a plan is made, and the plan takes effect
// trial.plan_latency_s after the state it starts from, while the vehicle flies its current
// trajectory. The new trajectory starts at rest where the current one is at that time, and replaces
// it over trial.blend_s by a smoothstep blend of the two (position, velocity and yaw stay
// continuous). A seed gives the same plans and flight whatever the wall clock.
//
// Unknown space is planned through (unknown_space free) or avoided (blocked). The perception model
// scores the landmarks mapped so far, their detectability counted from the flight's own keyframes;
// a surface not yet seen has no landmarks, so the proposed planner rates views of it blind (the
// prior: an unseen surface gives the VO nothing) and prefers routes past what it has seen textured.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "control/trajectory.h"
#include "harness/config/scenario.h"
#include "harness/run/explore.h"
#include "harness/run/external_plan.h"
#include "harness/run/incremental_map.h"
#include "harness/run/look_columns.h"
#include "harness/run/plan_run.h"
#include "harness/run/view_guard.h"
#include "planner/feature_map.h"
#include "vo/odometry.h"

namespace tgnav::harness {

class SceneGeometry;

// One plan of an online trial.
struct OnlinePlan {
  double t_s = 0.0;          // simulated time it was asked
  double effective_s = 0.0;  // ... and took (or would have taken) effect
  std::string trigger;       // "start" | "period" | "blocked" | "goal_seen"
  bool ok = false;
  // Flown: it changed the route (a path ahead blocked, a hold, with trial.leave_blind_route a
  // current route rated blind for longer than its choice, or, trial.commit_s after the last
  // change, a path that leaves the current one's route by more than kSameRouteM, with
  // trial.keep_route only where worthLeavingRoute); a plan along the current route is not flown
  // (every switch restarts from rest).
  bool adopted = false;
  // A plan along the current route that was not flown still renews the views ahead: the current
  // trajectory's positions are kept and its yaw ahead becomes the new plan's at the nearest point
  // (then the look-ahead rule on the current map), blended in over trial.blend_s.
  bool views_renewed = false;
  // trial.look_keep_class: the class last flown was planned again in its place (classInForce).
  bool kept_class = false;
  // ... the class in force on this plan's map (-1: none matched, or not asked: nothing adopted yet,
  // or no choice), and its candidate's blind length and length (-1 where none): where it is not
  // kept, what leaving it was judged on (worthLeavingRoute).
  int class_in_force = -1;
  double in_force_blind_m = -1.0;
  double in_force_length_m = -1.0;
  std::string detail;    // why not, when it failed
  planner::Pose4 start;  // where it starts (the estimated frame)
  // > 0: the point on the current trajectory where it would have started lay within the robot
  // radius of a mapped obstacle (the vehicle had come that close), and it started this far from
  // there instead, at the nearest point that clears it (the blend into it steps away)
  double start_shift_m = 0.0;
  std::vector<Eigen::Vector3d> path;  // its chosen path
  std::vector<bool> path_unknown;     // per point of `path`: never observed when planned
  int chosen_class = -1;
  // The blind length (planner::CandidatePath::blind_length_m; only the proposed planner rates it,
  // the others give 0) of its choice, and of its candidate that follows the current route (that
  // route's class on this plan's map); -1: not asked (before take-off, or no route to follow) or no
  // candidate follows it.
  double chosen_blind_m = -1.0;
  double route_blind_m = -1.0;
  double chosen_length_m = -1.0;  // ... and their lengths (planner::CandidatePath::length_m)
  double route_length_m = -1.0;
  // trial.look_then_fly: -1 where the route was flown as planned (not asked, or all observed and
  // the search found no way to the goal with trackable views); else the unknown cells the look
  // pose's view observes (0: none does, and the plan fails: the vehicle holds; or look_goal), of the
  // way on (look_way) or of any unknown space. look_goal: the search's way to the goal was flown.
  int look_seen = -1;
  bool look_way = false;
  bool look_goal = false;
  bool look_advance = false;   // trial.look_advance: it flew along the route instead (LookPlan::advance)
  bool look_near = false;      // ... it looked near the way on (LookPlan::near)
  bool look_probe = false;     // ... it turned to a view of the way on the model rates short (LookPlan::probe)
  bool look_fallback = false;  // trial.look_fallback: no look was left, and the route was flown as planned
                               // (where this failure would have ended the trial)
  // trial.look_fallback_floor: no look was left at look_min_detections where this failure would end
  // the trial, and the search was made again at the lower floor (look_floor: the floor it found
  // the look at; look_fallback: it found none there either)
  bool look_lowered = false;
  bool look_stall = false;   // trial.look_stall_s: the looks had stalled, and the route was flown as planned
  double look_floor = -1.0;  // ... the detection floor its views were rated with (LookPlan::floor)
  // ... trial.look_fov_margin_deg: the search with the margin found nothing to fly, and this one was
  // rated on the whole image (OnlinePlanning::searchLook)
  bool look_whole_fov = false;
  // trial.look_classes: the candidate (index into the plan's classes) whose route the look was found
  // on, where not the planner's choice (path is then that route); -1: the choice's.
  int look_class = -1;
  // ... where its path ends (x, y, z, yaw: the look pose, or the advance's; empty: none) and the
  // unknown columns that view is to observe (LookPlan::watched, their centres)
  std::vector<double> look_pose;
  std::vector<Eigen::Vector2d> look_watched;
  // ... its path (LookPlan::path: x, y, yaw per pose) and the detections the model expects of each
  // pose's view on the plan's map (ViewRater::detections, all its landmarks, in the field of view the
  // search rated: trial.look_fov_margin_deg; the search counted only those seen across observed
  // columns), for reading a look against the VO's inliers where it flew
  std::vector<Eigen::Vector4d> look_path;
  int look_cells = 0;       // cells whose views the search rated
  int landmarks = 0;        // in the map it planned on
  int prior_landmarks = 0;  // ... and those of trial.unseen_prior added to it (route_mean: to the class's map)
  // trial.unseen_prior route_mean: the class the plan on the map with the mean prior chose, which
  // this plan then flies (-1: none, or not asked)
  int rated_class = -1;
  // A flown plan (adopted, or its views renewed): the least trackable view the vehicle then flies
  // until the next plan can take effect (its switch + replan_period_s; a look's end, where later),
  // as this plan's map rates it
  // (worstView, frame_prediction.h, every kFlownViewStepS at the setpoints). The look-ahead and the
  // splice may fly views the plan did not choose: own_min_p is the least probability of the plan's
  // own views over the same time (its trajectory before the look-ahead; with the views renewed, the
  // route's positions with the plan's yaws), asked only where the flown one is blind (below
  // planner.information.min_track_probability). -1: not asked (not flown, no voxel map, no model).
  double flown_min_p = -1.0;
  double flown_min_at_s = -1.0;  // simulated time of that view
  double flown_min_yaw_rad = 0.0;
  double flown_min_detections = -1.0;  // its expected detections (planner::ViewSupport::detections)
  double own_min_p = -1.0;
  double snapshot_s = 0.0;   // wall clock: the map snapshot (copy, opportunities, embedding)
  double voxel_map_s = 0.0;  // wall clock
  double solve_s = 0.0;
  double trajectory_s = 0.0;
};

// What the online part of a trial did, for metrics and figures.
struct OnlineResult {
  std::vector<OnlinePlan> plans;
  int keyframes = 0;          // frames mapped
  double map_update_s = 0.0;  // wall clock of all map updates
  std::optional<planner::FeatureMap> final_map;
  double coverage = 0.0;                      // share of the flight band's voxels in the scene bounds observed
  int occupied_voxels = 0;                    // in the final map, inside the bounds widened by 0.5 m
  double map_error_mean_m = 0.0;              // their centres' mean distance to the true geometry
  double map_error_far_share = 0.0;           // ... share farther than two voxels from it
  int map_surface_crossings = 0;              // observed in the flight band (online_metrics.h, mapHoles)
  double map_hole_share = 0.0;                // ... of them, where the map is free inside the true geometry
  double unknown_share = 0.0;                 // of the flown trajectory: in space unknown when planned
  std::optional<std::string> planner_stderr;  // an external planner's: the last lines it wrote to stderr
  std::vector<GuardEvent> guards;             // trial.guard_tracking: when the guard tripped
};

// Whether a plan's choice is blind for less than its candidate along the current route by more
// than `tolerance_m` (trial.leave_blind_route): both lengths known (>= 0).
bool leavesBlindRoute(const OnlinePlan& plan, double tolerance_m);

// Whether a plan's choice is worth leaving the current route for (trial.keep_route): no candidate
// follows the route (route_blind_m < 0), or the route's candidate is blind for longer than the
// choice by more than `blind_tolerance_m`, or longer than it by more than `margin` times the
// choice's length.
bool worthLeavingRoute(const OnlinePlan& plan, double blind_tolerance_m, double margin);

// trial.look_keep_class: the index into plan.candidates (and plan.topo.classes) of the class that
// `route`, the planner's route last adopted (from where it was planned to the goal), follows from
// `start` on: that route from its point nearest `start`, with `start` before it, has the class's
// H-signature around the plan's obstacles. -1: none does, or its candidate is not feasible.
int classInForce(const planner::Plan& plan, const std::vector<Eigen::Vector2d>& route, const Eigen::Vector2d& start);

class OnlinePlanning {
 public:
  // `survey`: the scene's survey map, for the prior (trial.prior_map). InputError for a planner
  // the online trial does not run (an oracle class).
  // `external`: scenario.planner.external plans (one process, asked at every plan) instead of
  // `planner`.
  OnlinePlanning(const Scenario& scenario, const planner::FeatureMap& survey, planner::PlannerKind planner,
                 std::uint64_t seed, int rrt_samples, bool external = false);
  ~OnlinePlanning();
  OnlinePlanning(const OnlinePlanning&) = delete;
  OnlinePlanning& operator=(const OnlinePlanning&) = delete;
  OnlinePlanning(OnlinePlanning&&) = delete;
  OnlinePlanning& operator=(OnlinePlanning&&) = delete;

  // The plan before take-off, from the scene's start on the prior map, into *run (its voxels
  // stay there for the trial's per-frame predictions). Without a route, the vehicle climbs to the
  // start's flight height and holds there for a replan period (the returned trajectory) and
  // replans: it may see one. So it does with trial.hold_first_plan, the plan recorded, not flown.
  control::SetpointTrajectory firstPlan(PlanRun* run);

  // Before the first keyframe: the onboard camera (the map's, and the tracking guard's lead), and
  // when the trajectory starts (simulated time, after the climb): the first plan's flown views were
  // rated before that was known, their flown_min_at_s counted from the trajectory's start. Once.
  void startFlight(const Intrinsics& camera, double trajectory_start_s);

  // The trajectory to fly now (its time base is the first trajectory's).
  const control::SetpointTrajectory& trajectory() const { return *current_; }

  // Maps one keyframe at frame.X_WC, and notes whether the path ahead now runs into occupied space.
  void mapFrame(const RgbdFrame& frame, double t_s, double trajectory_start_s);

  // The VO's result for a frame it tracked (flying on the estimate): its pose and inliers, and
  // where they lie across the image, for the tracking guard (trial.guard_tracking; view_guard.h). When it trips, the
  // vehicle holds where its trajectory is now, the camera turned back, and a plan is due ("blind_view").
  // Before the guard, trial.look_guard rates the look's view ahead, and may stop the vehicle likewise.
  void trackFrame(double t_s, double trajectory_start_s, const vo::FrameResult& frame);

  // At simulated time t: replans when one is due. Returns why the flight must stop (no route and
  // the current one blocked or spent), or an empty string.
  std::string replan(double t_s, double trajectory_start_s);

  // Why the external planner was stopped (it hung, crashed, wrote garbage), or "": the trial then
  // ends in plan_failed.
  const std::string& plannerFailure() const { return planner_failure_; }

  // The metrics of the final map against the true scene, and the share of the flight through
  // space unknown when planned (`flown`: estimated positions on the trajectory, with their times).
  OnlineResult finish(const SceneGeometry& truth, const std::vector<std::pair<double, Eigen::Vector3d>>& flown);

 private:
  struct Attempt;
  Attempt plan(const planner::Pose4& start, double t_s, const std::string& trigger);
  // The scenario a plan from `start` is made in (with plan_look_ahead, the pose graph's look_unknown_m).
  Scenario planningScenario(const planner::Pose4& start) const;
  // The map a plan is made on: a snapshot, with the places planned from and the goal free
  // (unknown_space blocked) and the guard's wedges blocked.
  IncrementalMapper::Built planningSnapshot();
  // The robot radius and two voxels of `map`: the clearance kept around visited places and paths.
  double clearOf(const planner::FeatureMap& map) const;
  // Adds trial.unseen_prior's mean landmarks to `map` (unseen_prior.h); returns how many.
  int addPrior(planner::FeatureMap* map) const;
  // unseen_prior route_mean: the homology class the proposed planner chooses from `from_here` on a
  // second snapshot with the mean prior (the same occupancy, so the same classes as the plan's own
  // map); the path and its views are then planned in that class on the map as seen. Records it,
  // the prior's landmarks and the time; -1 where it finds no route.
  int rateClass(const Scenario& from_here, OnlinePlan* record);
  // Why a plan is asked now ("blind_view", "blocked", "goal_seen" or "period"); clears the events.
  std::string takeTrigger();
  // plan(), and where a built-in planner finds `start` within the robot radius of the map
  // (`invalid_start`), plan() again from the nearest point that clears it (record.start_shift_m).
  Attempt planClearOf(const planner::Pose4& start, double t_s, const std::string& trigger);
  // trial.look_then_fly: false where a's route is all observed (flown as planned); else true, and
  // its path becomes the way to the look pose (explore.h), or, where no view observes any unknown
  // space (or that way cannot be flown), it fails (a->record.ok false): the vehicle holds.
  bool lookFirst(const Scenario& from_here, const planner::FeatureMap& map, double clear_m, Attempt* a);
  // The look search's settings for a plan from from_here's start (clear_m: stopBeforeUnknown's).
  LookConfig lookConfig(const Scenario& from_here, double clear_m) const;
  // planLook from `start` on `voxels` with the views rated as trial.look_fov_margin_deg says (the
  // margin dropped where it leaves nothing to fly), at the detection floor min_detections (0: none);
  // record's look_path and look_whole_fov say what it rated.
  LookPlan searchLook(const planner::VoxelMap& voxels, const planner::Pose4& start,
                      const std::vector<Eigen::Vector3d>& route, const std::vector<Eigen::Vector3d>& way_on,
                      bool all_observed, const LookMemory& memory, const LookConfig& look, double min_detections,
                      OnlinePlan* record) const;
  // trial.look_classes: where the search on the chosen class's route (*found) found neither a view
  // of its way on nor an advance along it, the search on the other feasible candidates' routes that
  // run into unknown space, in order of their cost; the first that finds either replaces *found
  // (its cells count in found->cells either way), and the record says which (look_class) and takes
  // its route (path, path_unknown, look_path, look_whole_fov).
  void otherClassLook(const Scenario& from_here, const planner::FeatureMap& map, const StopRule& rule,
                      const LookMemory& memory, const LookConfig& look, LookPlan* found, Attempt* a) const;
  // An adopted plan's look pose: not chosen again, and its columns counted (watch_), and its floor.
  void noteLook(const Attempt& a);
  // trial.look_guard at a tracked frame: true where it tripped (the vehicle holds, a plan is due).
  bool lookGuard(double t_s, double trajectory_start_s);
  // A guard's reflex at simulated time t_s: the trajectory spliced into a hold at `hold` from
  // tau_now over 0.3 s, no look in flight, and a plan due at once ("blind_view").
  void holdForView(const planner::Pose4& hold, double t_s, double tau_now);
  // The columns trial.look_give_up looks were to observe (their centres).
  std::vector<Eigen::Vector2d> givenUp() const;
  // trial.stop_before_unknown: a's path (and trajectory) end before they run into unknown space;
  // false where that trajectory cannot be made (a->record says why).
  bool stopShort(const Scenario& from_here, const planner::FeatureMap& map, double clear_m, Attempt* a);
  // a's trajectory: its path smoothed, into setpoints (a->raw); false, with a->record's detail after
  // `detail_prefix`, where the trajectory cannot be made.
  bool smoothInto(const Scenario& from_here, const std::string& detail_prefix, Attempt* a);
  void makeGuard(const Intrinsics& camera);  // trial.guard_tracking's guard, its lead with `camera`
  bool askExternal(const Scenario& from_here, const planner::FeatureMap& map, Attempt* a);
  bool blockedAhead(double tau_from) const;
  bool goalObserved() const;
  // The current trajectory's positions from tau_from to its end, every kBlockedStepS: a plan's
  // path follows the current route where every pose lies within kSameRouteM of them.
  std::vector<Eigen::Vector3d> positionsAhead(double tau_from) const;
  // a.record's chosen_blind_m and route_blind_m, the route being `ahead` (positionsAhead).
  static void rateRouteBlindness(const std::vector<Eigen::Vector3d>& ahead, Attempt* a);
  // trial.look_keep_class: where the plan's choice leaves the class in force for a candidate not
  // worth it (worthLeavingRoute), plans that class instead (`from_here` as the plan was asked).
  void keepClass(Scenario* from_here, const planner::FeatureMap& map, Attempt* a);
  // trial.look_then_fly: the current trajectory is a look (or an advance) not yet at its end at
  // tau_now. It is flown to its end, where its view is, and a plan asked before then is not flown (its
  // map lacks that view) unless the path ahead is blocked or the guard trips. Before, the commit
  // window ran out as the vehicle arrived and the next plan cut the turn to the view: on development
  // scene detour-5006, 24 of 28 looks never held theirs.
  bool lookInFlight(double tau_now) const { return looking_ && tau_now < current_->endTime(); }
  // Blind lengths this close count as equal (planner.selection.blind_tolerance_m).
  double holdRate() const { return scenario_.planner.trajectory.sample_rate_hz; }
  double blindTolerance() const { return scenario_.planner.perception.selection.blind_tolerance_m; }
  // Flies a (a plan with a trajectory) from tau_switch, simulated time t_switch, on.
  void adopt(Attempt* a, double tau_switch, double t_switch, bool before_start);
  // Renews the views ahead with a's (renewedViews, then the look-ahead unless they are the look
  // search's), and returns the renewed trajectory before the look-ahead: the plan's own views along
  // the route (nothing: not renewed).
  std::optional<control::SetpointTrajectory> renewViews(const Attempt& a, double tau_switch);
  // a's record's flown_* (and own_min_p from `own`, its time base's start at tau_switch when
  // own_from_start): the current trajectory's views from tau_switch on, which is simulated time
  // t_switch.
  void rateFlownViews(const control::SetpointTrajectory* own, bool own_from_start, double tau_switch, double t_switch,
                      Attempt* a) const;
  // The current trajectory becomes `next` from tau_switch on (spliceTrajectory), its yaw rate
  // then held within the trajectory's limit (limitYawRate).
  void switchTo(const control::SetpointTrajectory& next, double tau_switch, double blend_s);
  // The look-ahead rule on `trajectory`, planned on `map` (and `voxels`, its planners' voxel map).
  control::SetpointTrajectory lookAhead(const control::SetpointTrajectory& trajectory, const planner::FeatureMap& map,
                                        const planner::VoxelMap& voxels) const;
  double tau(double t_s, double trajectory_start_s) const { return tau0_ + (t_s - trajectory_start_s); }

  // trial.look_stall_s: a route to the goal this much shorter than the shortest before it is progress
  // (LookConfig::advance_min_m, the least advance).
  static constexpr double kStallProgressM = 0.5;

  const Scenario& scenario_;
  const OnlineConfig& cfg_;
  planner::PlannerKind planner_;
  std::uint64_t seed_;
  int rrt_samples_;
  IncrementalMapper mapper_;
  std::unique_ptr<ExternalPlannerSession> external_;
  std::string planner_failure_;  // the external planner's, when it was stopped
  std::unique_ptr<control::SetpointTrajectory> current_;
  double tau0_ = 0.0;  // the first trajectory's start: the time base of every later one
  double next_replan_s_ = 0.0;
  double pending_until_s_ = -1.0;  // a plan takes effect then; none is asked before
  double last_change_s_ = -1e9;    // when the last plan that changed the route was asked
  bool blocked_ = false;
  bool goal_seen_ = false;                   // the goal's voxel has been observed
  bool goal_event_ = false;                  // ... by the last keyframe: a plan is due
  bool holding_ = false;                     // flying a hold: no route, or the guard tripped
  bool flying_ = false;                      // startFlight has been called
  std::optional<ViewGuard> guard_;           // trial.guard_tracking, built-in planners
  std::vector<BlindWedge> wedges_;           // ... where it tripped: unknown space there is planned occupied
  bool blind_view_ = false;                  // ... it tripped: a plan is due
  bool stops_short_ = false;                 // the trajectory flown stops short of unknown space
  bool looking_ = false;                     // ... at a look pose (trial.look_then_fly): flown to its end
  int failed_in_a_row_ = 0;                  // plans without a route since the last one with
  bool last_chance_ = false;                 // one more failed plan ends the trial (trial.look_fallback)
  RouteProgress progress_{kStallProgressM};  // trial.look_stall_s: the looks' progress to the goal
  std::vector<Eigen::Vector3d> visited_;     // where plans started: free, seen or not
  std::vector<planner::Pose4> looked_;       // trial.look_then_fly: the look poses flown to
  LookWatch watch_;       // ... the looks adopted per unknown column they were to observe (trial.look_give_up)
  int last_inliers_ = 0;  // the VO's inliers in the last frame it tracked
  // trial.look_guard: the voxel map of the latest plan flown or recorded along the route (from the
  // first replan on; not of a plan that failed), and the detections the look being flown asked of its views
  std::unique_ptr<planner::VoxelMap> rated_map_;
  double look_floor_ = 0.0;
  // trial.look_keep_class: the planner's route last adopted (2D)
  std::vector<Eigen::Vector2d> class_route_;
  OnlineResult result_;
};

// One plan being made (online_planning.cpp) and decided on (online_replan.cpp).
struct OnlinePlanning::Attempt {
  OnlinePlan record;
  PlanRun run;
  std::optional<control::SetpointTrajectory> trajectory;  // the planner's, after the look-ahead rule
  std::optional<control::SetpointTrajectory> raw;         // the planner's
  std::optional<planner::FeatureMap> map;                 // the snapshot it planned on
  bool stops_short = false;            // its trajectory ends before the path does (stop_before_unknown)
  std::optional<planner::Pose4> look;  // trial.look_then_fly: its trajectory ends at this look pose
  // ... its yaws are the search's views (a look or its way to the goal): no look-ahead, also renewed
  bool chosen_views = false;
  std::vector<Eigen::Vector2d> watched;  // ... whose view is to observe these unknown columns (centres)
};

}  // namespace tgnav::harness
