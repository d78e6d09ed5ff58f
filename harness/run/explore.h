#pragma once
// Look, then fly (trial.look_then_fly; online trials, the perception-aware planners): where the
// planner's route to the goal runs into space the vehicle has not observed, it does not fly
// toward it looking ahead (that view, into space not yet mapped, is the one the VO lost on the
// premise scenes, storage and gallery: docs/results/route_oracle). Instead it flies, through
// observed free space only, to the place and yaw from which a view that the perception model
// rates trackable on the map so far observes most of the unknown way on, every view on the way
// rated trackable as well, and stops there; the next plan, on the map that view has grown, goes on.
//
// The search is over (cell, yaw) on a grid at the flight height, as scripts/route_oracle.py's
// `explore` is on the true layout: a move keeps its yaw and goes to a neighbouring cell, a turn
// stays and changes the yaw by one step; both end in a view the rater rates trackable.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "harness/run/look_ahead.h"
#include "harness/run/view_guard.h"
#include "planner/pose4.h"
#include "planner/voxel_map.h"

namespace tgnav::harness {

struct LookConfig {
  double cell_m = 0.2;                      // the search's grid (two voxels)
  double yaw_step_rad = 15.0 * M_PI / 180;  // between the yaws it may hold
  double robot_radius_m = 0.38;             // a cell keeps this and a voxel from occupied space ...
  double known_m = 0.38;                    // ... and this from unknown space (online: the robot radius)
  double flight_height_m = 1.0;
  double half_hfov_rad = 0.656;  // a view observes within this of its axis ...
  double observe_range_m = 6.0;  // ... this far (the online mapper's range)
  double turn_m_per_rad = 1.67;  // a turn's cost in metres per radian (online: nominal speed / yaw rate)
  double max_cost_m = 12.0;      // the search goes no farther
  // A visited place counts as observed within this of it, for where the vehicle may go (the forward
  // camera never sees its own place; online, stopBeforeUnknown's clear_m). For lines of sight only
  // the disc of the robot radius does: beyond the disc its body covered, a surface never seen may
  // stand.
  double visited_clear_m = 0.58;
  // The way on is watched within this of its points (stopBeforeUnknown's clear_m).
  double way_clear_m = 0.58;
  // A look pose within this of one already flown to (and within one yaw step) is not chosen again.
  double repeat_m = 0.3;
  // Near where the tracking guard tripped (trial.guard_tracking), the views it turned toward are
  // not trackable, whatever the model rates them: within this of the place, the yaws from halfway
  // between the last good yaw and the one that tripped it on, in the turn's direction, to
  // half_hfov_rad beyond it (where a view no longer shares any bearing with the tripped one).
  double tripped_m = 0.5;
  // trial.look_advance, a goal-directed order of looks. A look must observe at least the robot's
  // footprint of unknown columns (less opens no way for it). Where no view the search reaches
  // observes that much of the way on, it flies along the route first: to the reached state farthest
  // along the route's observed part, at least advance_min_m along it (the search's reach,
  // max_cost_m, is shorter than most routes, and views of the way on lie closer from there). Where
  // it cannot advance, it looks at unknown columns within near_m of the way on before any others.
  // Chosen, not fitted: near_m is a few robot lengths.
  bool advance = false;
  double advance_min_m = 0.5;
  double near_m = 2.0;
  // trial.look_probe (with advance): where the way on is the last stretch to the goal (at most near_m
  // long), no trackable view the search reaches observes it and it cannot advance, it turns, at a
  // reached cell, to the view of the way on (at least the footprint of it) that the model rates least
  // short, trackable or not, where the tracking guard has not tripped. The model counts only
  // landmarks mapped so far, so it rates a view into space not yet mapped bare whatever stands there;
  // the guard (trial.guard_tracking) stops the turn where the VO's inliers say it is not trackable,
  // and that view is then ruled out (tripped_m). Farther from the goal the looks explore instead: at
  // the start, with nothing mapped, probes are all the search finds, and their trips closed the way
  // (detour-5001: no_path at 14 s).
  bool probe = false;
  // trial.look_calibrate_floor: > 0, the inliers the VO tracks the current view with. The rater
  // expects fewer detections than the VO finds inliers (it counts only mapped landmarks, through
  // observed space); a view it expects to give the current view's detections times floor_inliers /
  // tracked_inliers is taken to keep floor_inliers, so the detection floor drops to that, where it
  // is lower (never raised). 0: the floor as set.
  int tracked_inliers = 0;
  int floor_inliers = 150;
  // trial.look_hold_margin: a look pose, or an advance's end, where the vehicle stops and holds
  // its view while the next plan is made, must expect at least the floor in force times (1 +
  // hold_margin) detections; the views on the way there, the floor. 0: the floor.
  double hold_margin = 0.0;
  // trial.look_along: of the looks that qualify (at least half the unknown columns the best one
  // observes), the one whose cell lies farthest along the route (the planner's, up to the way on;
  // by its nearest point, in cells), then the nearest. false: the nearest. The nearest crept: on
  // gallery the explorer looked again every 0.4 m while the way on lay metres ahead.
  bool along = false;
};

struct LookPlan {
  // From the start (as given) to the look pose: cell centres at the flight height, unwrapped yaws;
  // empty where no view observes anything unknown.
  std::vector<planner::Pose4> path;
  int seen = 0;          // unknown cells (voxel columns) the look pose's view observes
  bool way = false;      // ... of the way on (else: of any unknown space)
  bool goal = false;     // the path ends at the goal instead (the search reached its cell)
  bool advance = false;  // ... on the route, short of the way on (LookConfig::advance)
  bool near = false;     // the look pose observes unknown columns near the way on (LookConfig::advance)
  bool probe = false;    // ... of the way on, turned to whatever the model rates it (LookConfig::probe)
  // The centres of the unknown columns the look pose's view observes (the `seen`; empty where the
  // path ends at the goal or advances).
  std::vector<Eigen::Vector2d> watched;
  double cost_m = 0.0;
  int states = 0;      // (cell, yaw) states the search settled
  int cells = 0;       // cells it rated views in
  double floor = 0.0;  // the detection floor the views were rated with (LookConfig::tracked_inliers)
};

// What the flight so far tells the search (OnlinePlanning keeps it).
struct LookMemory {
  std::vector<Eigen::Vector3d> visited;  // places the vehicle has been
  std::vector<planner::Pose4> looked;    // look poses flown to before
  // Points in unknown columns that no longer count as unknown for what a view observes
  // (trial.look_give_up: the looks flown to observe them did not).
  std::vector<Eigen::Vector2d> given_up;
  std::vector<GuardEvent> tripped;  // the tracking guard's trips
};

// The search on `voxels` (the plan's voxel map; its `observed` decides what is unknown), views
// rated by `rater` (moved about by the search) with only the landmarks whose line of sight crosses
// observed columns. Where it reaches the cell of `goal`, the path ends there (at the goal itself);
// the goal counts as a visited place (LookMemory::visited), free as the start is.
// Else: `route` is the planner's route from the start up to where it first runs into unknown
// space, `way_on` the rest of it; `memory`, what the flight so far tells it. Among the states it
// reaches whose view observes unknown cells of the way on, it takes the nearest (by the cost of
// moves and turns) of those that observe at least half as many as the best; ties go to more seen,
// then the first settled. Where none does, the same choice among views of any unknown cells; with
// config.advance, first the advance, the probe (config.probe) and the views near the way on
// (LookConfig::advance).
LookPlan planLook(const planner::VoxelMap& voxels, ViewRater& rater, const planner::Pose4& start,
                  const Eigen::Vector3d& goal, const std::vector<Eigen::Vector3d>& route,
                  const std::vector<Eigen::Vector3d>& way_on, const LookMemory& memory, const LookConfig& config);

}  // namespace tgnav::harness
