#pragma once
// Trajectory generation (paper Sec. VI: the global 4-DoF path goes to a gradient-based B-spline
// optimiser, Zhou et al. 2019, for position and yaw): a smooth, collision-free, dynamically
// feasible position and yaw trajectory that stays in the homology class of the planned path.
//
// 1. Time allocation. Each step of the path takes max(distance / v_nom, |yaw change| / yaw_rate_nom)
//    of "nominal time" (so a turn on the spot gets time too), and the vehicle ramps into and out
//    of that pace with a_nom: the path becomes a reference r(t), yaw included.
// 2. Position: uniform cubic B-spline (C2: position, velocity, acceleration continuous), knots
//    knot_spacing_m / v_nom apart, the first and last three control points pinned to start and
//    goal (rest to rest). L-BFGS (LBFGSpp) minimises
//        int |jerk|^2 dt + w_r int |p(t) - r(t)|^2 dt + w_c int max(0, m - d(p(t)))^2 dt + feasibility,
//    with d the distance field (its gradient pushes the curve away from obstacles), margin
//    m = robot radius + safety margin (relaxed near a start or goal that is itself closer to an
//    obstacle: its clearance + 1/5 of the distance from it), and feasibility penalising velocity
//    and acceleration control points beyond v_max and a_max (by the convex-hull property that
//    bounds the curve).
//    w_r = (2 pi v_nom / smoothing_length)^6: wiggles of the path shorter than the smoothing
//    length (the pose graph's lateral samples) are smoothed out, longer ones are followed.
// 3. Yaw: a second cubic B-spline on the same knots through the unwrapped planned yaws (so it
//    never spins 2 pi across +-pi), smoothed the same way, with yaw-rate control points
//    penalised beyond the limit. Position and yaw share the time line: where the camera looks
//    matches where the planner meant it to look.
// 4. Checks on the result: clearance >= robot radius everywhere (rigorous, 1-Lipschitz), speed,
//    acceleration and yaw rate within limits, and, where obstacle points are given, the same
//    winding angles as the path (H-signature). Limits exceeded -> re-timed (the knot interval
//    stretched: the shape, hence clearance and homology, unchanged). Closer than the robot radius
//    -> re-optimised with a stiffer clearance term (the margin beyond it is a soft target,
//    reported as margin_met). Still failing -> fallback: the path itself,
//    flown point to point with minimum-jerk stops (safe where the path is), with the reason.
#include <Eigen/Core>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "planner/bspline.h"
#include "planner/distance_field.h"
#include "planner/pose4.h"
#include "planner/voxel_map.h"

namespace tgnav::planner {

// Distance to the nearest obstacle and its gradient: what the optimiser and the checks see of the map.
class ClearanceField {
 public:
  virtual ~ClearanceField() = default;
  // Clearance [m] of p (<= 0: in an obstacle or outside the map); `gradient` (may be null) gets
  // its gradient (zero where it is not defined).
  virtual double clearance(const Eigen::Vector3d& p_W, Eigen::Vector3d* gradient) const = 0;

 protected:
  // Copied and moved only as part of a derived field (no slicing).
  ClearanceField() = default;
  ClearanceField(const ClearanceField&) = default;
  ClearanceField& operator=(const ClearanceField&) = default;
  ClearanceField(ClearanceField&&) = default;
  ClearanceField& operator=(ClearanceField&&) = default;
};

// The scene's 3D voxel map (only answers within its clearance band; 0 above and below).
class VoxelClearance final : public ClearanceField {
 public:
  explicit VoxelClearance(const VoxelMap& map) : map_(map) {}
  double clearance(const Eigen::Vector3d& p_W, Eigen::Vector3d* gradient) const override;

 private:
  const VoxelMap& map_;
};

// A 2D occupancy grid's distance field, the same at every height.
class PlanarClearance final : public ClearanceField {
 public:
  explicit PlanarClearance(const DistanceField& field) : field_(field) {}
  double clearance(const Eigen::Vector3d& p_W, Eigen::Vector3d* gradient) const override;

 private:
  const DistanceField& field_;
};

struct TrajectoryConfig {
  double nominal_speed_mps = 0.4;       // time allocation: pace along the path (v_nom, Table I)
  double nominal_accel_mps2 = 0.4;      // ramp into and out of that pace
  double nominal_yaw_rate_rad_s = 0.3;  // pace of turns on the spot (Table I's yaw-rate limit)
  double max_speed_mps = 1.0;           // v_max, held on the result (re-timed otherwise)
  double max_accel_mps2 = 1.0;          // a_max
  double max_yaw_rate_rad_s = 0.6;
  double robot_radius_m = 0.3;        // hard: the trajectory never comes closer to an obstacle
  double safety_margin_m = 0.2;       // target clearance = robot_radius_m + safety_margin_m
  double knot_spacing_m = 0.4;        // B-spline knot interval = this / nominal_speed_mps
  double smoothing_length_m = 2.0;    // path wiggles shorter than this are smoothed out
  double clearance_weight = 1000.0;   // relative to closeness to the path
  double feasibility_weight = 100.0;  // relative to closeness, on (|v|^2 / v_max^2 - 1)^2 (same for a, yaw rate)
  int max_iterations = 300;           // L-BFGS iterations per optimisation
  double sample_rate_hz = 100.0;      // setpoints written out (the position controller's rate)

  // Names every field once, for the harness's config files (a(key, field); harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a("nominal_speed_mps", nominal_speed_mps);
    a("nominal_accel_mps2", nominal_accel_mps2);
    a("nominal_yaw_rate_rad_s", nominal_yaw_rate_rad_s);
    a("max_speed_mps", max_speed_mps);
    a("max_accel_mps2", max_accel_mps2);
    a("max_yaw_rate_rad_s", max_yaw_rate_rad_s);
    a("robot_radius_m", robot_radius_m);
    a("safety_margin_m", safety_margin_m);
    a("knot_spacing_m", knot_spacing_m);
    a("smoothing_length_m", smoothing_length_m);
    a("clearance_weight", clearance_weight);
    a("feasibility_weight", feasibility_weight);
    a("max_iterations", max_iterations);
    a("sample_rate_hz", sample_rate_hz);
  }

  double margin_m() const { return robot_radius_m + safety_margin_m; }
  void validate() const;  // std::invalid_argument naming the field and value
};

struct TrajectorySample {
  double t_s = 0.0;
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_W = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_W = Eigen::Vector3d::Zero();
  double yaw_rad = 0.0;  // continuous (unwrapped) from Trajectory::at; wrapped by sampleTrajectory
  double yaw_rate_rad_s = 0.0;
};

// A continuous-time 4-DoF trajectory on [0, duration()], from rest to rest.
class Trajectory {
 public:
  virtual ~Trajectory() = default;
  virtual double duration() const = 0;
  virtual TrajectorySample at(double t_s) const = 0;  // clamped to [0, duration()]

 protected:
  // Copied and moved only as part of a derived trajectory (no slicing).
  Trajectory() = default;
  Trajectory(const Trajectory&) = default;
  Trajectory& operator=(const Trajectory&) = default;
  Trajectory(Trajectory&&) = default;
  Trajectory& operator=(Trajectory&&) = default;
};

// Optimised: position and yaw B-splines on the same knots.
class BSplineTrajectory final : public Trajectory {
 public:
  BSplineTrajectory(UniformBSpline position, UniformBSpline yaw);
  double duration() const override { return position_.duration(); }
  TrajectorySample at(double t_s) const override;
  const UniformBSpline& position() const { return position_; }
  const UniformBSpline& yaw() const { return yaw_; }
  void setKnotInterval(double dt);

 private:
  UniformBSpline position_;
  UniformBSpline yaw_;
};

enum class TrajectoryStatus { kOptimised, kFallback, kFailed };
const char* toString(TrajectoryStatus status);

struct TrajectoryRequest {
  std::vector<Pose4> path;                                          // the planner's 4-DoF path, start to goal
  double start_yaw_rad = std::numeric_limits<double>::quiet_NaN();  // vehicle's yaw before it sets
                                                                    // off (NaN: the path's first)
  const std::vector<Eigen::Vector2d>* obstacle_points = nullptr;    // H-signature check if given
};

struct TrajectoryReport {
  TrajectoryStatus status = TrajectoryStatus::kFailed;
  std::string reason;                            // why not optimised (empty when it was)
  std::shared_ptr<const Trajectory> trajectory;  // null only when failed
  double duration_s = 0.0;
  double length_m = 0.0;         // of the trajectory, sampled
  double min_clearance_m = 0.0;  // sampled at 1 kHz
  bool margin_met = false;       // clearance >= robot radius + safety margin everywhere
                                 // (near a start or goal closer than that to an
                                 // obstacle: >= that end's own clearance)
  double max_speed_mps = 0.0;
  double max_accel_mps2 = 0.0;
  double max_yaw_rate_rad_s = 0.0;
  bool homology_checked = false;
  bool same_homology = false;
  int iterations = 0;  // L-BFGS iterations, position and yaw, all rounds
  int retimes = 0;
  double time_scale = 1.0;  // final duration / allocated duration
};

// std::invalid_argument for an empty path or non-finite values. Otherwise always a report: a
// trajectory (optimised or fallback) or kFailed with the reason (the path itself collides).
TrajectoryReport generateTrajectory(const TrajectoryRequest& request, const ClearanceField& field,
                                    const TrajectoryConfig& config);

// Samples at `rate_hz` from 0, the last exactly at duration(); yaw wrapped to [-pi, pi).
std::vector<TrajectorySample> sampleTrajectory(const Trajectory& trajectory, double rate_hz);

}  // namespace tgnav::planner
