#pragma once
// Where the camera looks in an online trial (harness/run/online_planning.h): the look-ahead rule
// that turns it toward unknown space before the vehicle flies there, within the trajectory's
// yaw-rate limit.
#include <Eigen/Core>
#include <functional>
#include <optional>
#include <vector>

#include "control/trajectory.h"
#include "planner/feature_map.h"
#include "planner/perception.h"
#include "planner/perception_planner.h"
#include "planner/pose4.h"
#include "planner/voxel_map.h"

namespace tgnav::harness {

// A view as ViewRater rates it.
struct ViewRating {
  double shortfall = 0.0;   // ViewRater::shortfall
  double detections = 0.0;  // ViewRater::detections
};

// Smooths the yaws of `sp` (at times `t`, evenly spaced) over a moving 1 s window on the unit
// circle, then holds the yaw rate within `max_rate` (a backward pass, so that a turn starts early
// enough, then a forward pass from the first setpoint's own yaw, which stays as it was: a
// trajectory that starts where the vehicle is starts with its yaw), and sets the yaw rates to the
// central differences. Without the limit, the look-ahead's switch between the planner's view and
// the way ahead (up to pi) was a 1 s swing of up to 5 rad/s (storage, docs/results/online10).
void smoothYaw(const std::vector<double>& t, double max_rate, std::vector<control::TrajectorySetpoint>* sp);

// Rates views by the planners' perception model on a planner's voxel map (the map a plan was made
// on): how far a view falls short of being trackable (planner::gateShortfall: 0 where the model,
// or the gates, rate it trackable; up to 1).
class ViewRater {
 public:
  // All three must outlive the rater.
  ViewRater(const planner::VoxelMap& voxels, const planner::VisibilityConfig& visibility,
            const planner::InformationConfig& information)
      : voxels_(&voxels), visibility_(&visibility), information_(&information) {}
  // The landmarks a camera with the body at p_WB sees at any yaw (the pose graph's V(p)); the
  // views asked next are from there. With `keep`, only the landmark voxels it accepts (asked before
  // the line of sight; e.g. those seen across observed space only, explore.h).
  void moveTo(const Eigen::Vector3d& p_WB, const std::function<bool(const planner::LandmarkVoxel&)>& keep = {});
  // The shortfall of the view along yaw_rad from where moveTo() put the body.
  double shortfall(double yaw_rad) const;
  // A gate on top of the model's (or the configured gates): a view expecting fewer than this many
  // detections (planner::ViewSupport::detections) falls short by 1 - detections / floor.
  void setDetectionFloor(double detections) { detection_floor_ = detections; }
  double detectionFloor() const { return detection_floor_; }
  // The detections the model expects of the view along yaw_rad (planner::ViewSupport::detections).
  double detections(double yaw_rad) const;
  // Both at once (one evaluation of the model).
  ViewRating rate(double yaw_rad) const;

 private:
  const planner::VoxelMap* voxels_;
  const planner::VisibilityConfig* visibility_;
  const planner::InformationConfig* information_;
  Eigen::Vector3d p_WB_ = Eigen::Vector3d::Zero();
  std::vector<planner::WeightedPoint> points_;
  double detection_floor_ = 0.0;
};

// The share (0: `planned`, 1: `look`) of the turn from the planner's yaw to the look-ahead's that
// the yaw keeps: of the yaws from `look` back to `planned` (5 deg apart) that keep the heading
// `near` within `near_limit` (the way just ahead stays in the image; `look` itself always may), the
// first the rater rates trackable from where it is, else the one it rates least short (`look` at a
// tie).
double trackableShare(const ViewRater& rater, double planned, double look, double near, double near_limit);

// The offset from `heading` (within +-half_fov) of the yaw that keeps the way ahead in view and
// that the rater rates least short of trackable from where it is: of the plain look-ahead's yaw
// (the least turn from `planned`), then the yaws across the whole window, kYawStepRad apart, from
// the least turn on, the first it rates trackable, else the least short (the least turn at a tie).
// Unlike trackableShare it looks on both sides of the way ahead: past a corner the texture seen on
// the way lies on the far side of it from the planner's yaw.
double bestViewOffset(const ViewRater& rater, double planned, double heading, double half_fov);

// Where `trajectory` look_ahead_s ahead (or half that) runs through space `map` has not observed
// (or everywhere, with `always`), the yaw turns as little as it must from the planner's for the way
// there to lie within `half_fov_rad` of the camera's axis (the camera looks before the vehicle
// flies there); the yaws are then smoothed and rate-limited (smoothYaw). Nothing changes where the
// way ahead is known, nor where the vehicle hardly moves, nor at the first setpoint (the vehicle's
// own yaw: a first plan that turned it there turned it during take-off, near the ground, and the VO
// was lost in the climb on a generated scene that starts facing away from the goal).
// With `rater` (the perception-aware planners), the turn toward the way ahead goes only as far as
// keeps the view trackable on the map as it is: every kRateEveryS the yaws from the way ahead back
// to the planner's are rated, kYawStepRad apart, and the first the rater rates trackable is kept
// (the least shortfall where none is; the way ahead at a tie, as where nothing is mapped). The
// first look into unknown space whose walls are bare was blind for every planner, and the VO was
// lost there (docs/results/online10): the vehicle keeps the mapped texture in view while it turns,
// and sees the new surfaces at the edge of the image before it looks at them. With `best_view`
// (and a rater) the yaw is instead bestViewOffset's: the way ahead stays within half_fov_rad, on
// whichever side of it the view is rated best.
control::SetpointTrajectory lookWhereUnknown(const control::SetpointTrajectory& trajectory,
                                             const planner::FeatureMap& map, double look_ahead_s, double half_fov_rad,
                                             bool always, double max_yaw_rate, ViewRater* rater = nullptr,
                                             bool best_view = false);

// Where a trajectory stops short of unknown space (trial.stop_before_unknown).
struct StopRule {
  // A point of the path is observed where every voxel within clear_m of it (horizontally, at its
  // height) is, or lies within clear_m of a place the vehicle has been (`visited`: the forward
  // camera never sees the vehicle's own place).
  double clear_m = 0.5;
  double min_m = 0.5;   // ... beyond this far along the path (its own voxels: everywhere)
  double look_m = 1.0;  // the way on: the path this far beyond where it stops
  // ... kept this close to the camera's axis at the stop (online trials: the look-ahead's)
  double half_fov_rad = 0.48;
};

// The part of `path` (a plan from where the vehicle is) that ends before it first runs into space
// `map` has not observed: up to the point before the first whose own voxel is unobserved, or,
// beyond rule.min_m along, any voxel within rule.clear_m; voxels within rule.clear_m of a visited
// place count as observed. The last point's yaw turns from the planner's as little as keeps the
// way on within rule.half_fov_rad of the camera's axis: at rest there the camera sees where the
// path goes (and what lies beside it) before the next plan sends the vehicle on. The whole path
// where it stays in observed space; the start alone, turned, where its next point is unobserved.
std::vector<planner::Pose4> stopBeforeUnknown(const std::vector<planner::Pose4>& path, const planner::FeatureMap& map,
                                              const std::vector<Eigen::Vector3d>& visited, const StopRule& rule);

// The look-ahead keeps the way ahead within the horizontal field of view, 10 deg inside its edge.
double lookAheadHalfFov(const planner::PerceptionPlannerConfig& perception);

// A trajectory that holds `pose` for `duration_s` (a vehicle without a route waits for one), with
// a setpoint every 1 / rate_hz: a splice (control::spliceTrajectory) blends at the new trajectory's
// setpoints, and a hold of two setpoints left the current trajectory's velocity and yaw rate as
// feed-forward, fading over the whole hold (the vehicle flew on 0.4 m past the hold and turned 19 deg
// past its yaw).
control::SetpointTrajectory holdTrajectory(const planner::Pose4& pose, double duration_s, double rate_hz);

// A renewal of the views (trial.renew_views): `current` from tau_switch on, each setpoint with the
// yaw of the nearest point of `plan` (a plan along the same route, from where the vehicle will be at
// tau_switch), looked for forward along it (within kRenewWindowS of plan time of the point matched
// last); the first setpoint keeps its own yaw, the vehicle's, and the yaws are smoothed from it
// (smoothYaw). Before, the first took the plan's yaw as well: every renewal (each replan_period_s)
// pulled the camera back toward the planner's view and the look-ahead's turn toward the way ahead
// never got there (storage seed 2: it looked away from a shelf it then flew into). Nothing (nullopt)
// where fewer than 3 setpoints remain.
std::optional<control::SetpointTrajectory> renewedViews(const control::SetpointTrajectory& current,
                                                        const control::SetpointTrajectory& plan, double tau_switch,
                                                        double max_rate);

// `trajectory` with its yaw from time `from_s` on held within `max_rate` of the yaw before it (a
// forward pass: a faster turn is spread out and followed late, then joins the trajectory's own yaw
// again), and the yaw rates where it changed their differences. Before `from_s` nothing changes.
// Applied to every spliced trajectory of an online trial: a quintic blend of two trajectories
// whose yaws part is a turn of up to 1.9 rad/s per radian between them.
control::SetpointTrajectory limitYawRate(const control::SetpointTrajectory& trajectory, double from_s, double max_rate);

}  // namespace tgnav::harness
