#pragma once
// Where the camera looks in an online trial (harness/run/online_planning.h): the look-ahead rule
// that turns it toward unknown space before the vehicle flies there, within the trajectory's
// yaw-rate limit.
#include <vector>

#include "control/trajectory.h"
#include "planner/feature_map.h"

namespace tgnav::harness {

// Smooths the yaws of `sp` (at times `t`, evenly spaced) over a moving 1 s window on the unit
// circle, then holds the yaw rate within `max_rate` (a backward pass, so that a turn starts early
// enough, then a forward pass from the first setpoint's own yaw, which stays as it was: a
// trajectory that starts where the vehicle is starts with its yaw), and sets the yaw rates to the
// central differences. Without the limit, the look-ahead's switch between the planner's view and
// the way ahead (up to pi) was a 1 s swing of up to 5 rad/s (storage, docs/results/online10).
void smoothYaw(const std::vector<double>& t, double max_rate, std::vector<control::TrajectorySetpoint>* sp);

// Where `trajectory` look_ahead_s ahead (or half that) runs through space `map` has not observed
// (or everywhere, with `always`), the yaw turns as little as it must from the planner's for the way
// there to lie within `half_fov_rad` of the camera's axis (the camera looks before the vehicle
// flies there); the yaws are then smoothed and rate-limited (smoothYaw). Nothing changes where the
// way ahead is known, nor where the vehicle hardly moves, nor at the first setpoint (the vehicle's
// own yaw: a first plan that turned it there turned it during take-off, near the ground, and the VO
// was lost in the climb on a generated scene that starts facing away from the goal).
control::SetpointTrajectory lookWhereUnknown(const control::SetpointTrajectory& trajectory,
                                             const planner::FeatureMap& map, double look_ahead_s, double half_fov_rad,
                                             bool always, double max_yaw_rate);

// `trajectory` with its yaw from time `from_s` on held within `max_rate` of the yaw before it (a
// forward pass: a faster turn is spread out and followed late, then joins the trajectory's own yaw
// again), and the yaw rates where it changed their differences. Before `from_s` nothing changes.
// Applied to every spliced trajectory of an online trial: a quintic blend of two trajectories
// whose yaws part is a turn of up to 1.9 rad/s per radian between them.
control::SetpointTrajectory limitYawRate(const control::SetpointTrajectory& trajectory, double from_s, double max_rate);

}  // namespace tgnav::harness
