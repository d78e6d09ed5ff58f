#pragma once
// Closed loop of MuJoCo and the PX4-like cascade: physics every step, rate control and
// allocation at rate_rate_hz, attitude at attitude_rate_hz, position at position_rate_hz.
// The controller flies on ground truth (the paper flew its vehicle on motion capture) unless
// the caller hands it an estimate (FlightHooks::control_state).
#include <mujoco/mujoco.h>

#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "control/cascade.h"
#include "control/trajectory.h"
#include "harness/config/flight_config.h"
#include "harness/sim/mujoco_sim.h"

namespace tgnav::harness {

// Physics steps per tick of a loop running at `rate_hz` (the controller stages, the camera).
// InputError "<what> <rate> Hz does not divide the physics rate of <physics> Hz" when it does not
// divide the physics rate; `what` names the setting, e.g. "--record-rate:".
int stepsPerTick(const mjModel* m, double rate_hz, const std::string& what);

class FlightLoop {
 public:
  // InputError when the loop rates do not divide the physics rate.
  FlightLoop(mjModel* m, mjData* d, const VehicleIds& ids, const control::CascadeConfig& config);

  // One physics step with the controller stages that are due. Returns false when the flight
  // diverged or a command was not finite; motor commands then stay unchanged and divergence()
  // says why. Nothing non-finite ever reaches MuJoCo.
  bool step(const control::TrajectorySetpoint& setpoint);
  // The same, with the controller flying on `control_state` instead of ground truth (divergence
  // is still judged on the true state).
  bool step(const control::TrajectorySetpoint& setpoint, const control::VehicleState& control_state);
  control::VehicleState state() const { return vehicleState(d_, ids_); }
  double time() const { return d_->time; }
  long steps() const { return steps_; }  // physics steps taken by this loop
  // Wall-clock seconds spent so far in the controller stages and in mj_step (not deterministic).
  double controlWallSeconds() const { return control_wall_s_; }
  double physicsWallSeconds() const { return physics_wall_s_; }
  bool positionUpdateDue() const { return steps_ % per_position_ == 0; }
  const std::string& divergence() const { return divergence_; }
  const control::VehicleParams& vehicle() const { return vehicle_; }
  // Sets every rotor's thrust (newtons) as if its motor had settled there: the command, the
  // filter state of filtered actuators and the lag state of direct-thrust ones (e.g. to start a
  // test in hover).
  void setMotorThrusts(const Eigen::VectorXd& thrust_n);
  // Thresholds of the divergence check.
  void setDivergenceLimits(double tilt_rad, double speed_m_s);

 private:
  bool checkDiverged();
  // Writes the motor commands into the model's controls (through the lag of direct-thrust ones).
  void applyMotors();

  mjModel* m_;
  mjData* d_;
  VehicleIds ids_;
  control::VehicleParams vehicle_;
  control::Cascade cascade_;
  Eigen::VectorXd command_n_;  // per rotor, from the allocation
  Eigen::VectorXd thrust_n_;   // per direct-thrust rotor, after its lag
  double direct_alpha_ = 1.0;  // lag filter gain per physics step
  int per_rate_ = 1;
  int per_attitude_ = 2;
  int per_position_ = 5;
  long steps_ = 0;
  double control_wall_s_ = 0.0;
  double physics_wall_s_ = 0.0;
  double max_tilt_rad_ = M_PI / 2;
  double max_speed_m_s_ = 20.0;
  std::string divergence_;
};

enum class FlightStatus { kCompleted, kDiverged, kStopped };

struct FlightSample {
  double t_s = 0.0;
  bool on_trajectory = false;  // false during take-off, settling and the final hold
  control::TrajectorySetpoint setpoint;
  control::VehicleState state;     // true
  control::VehicleState estimate;  // what the controller flew on (= state on ground truth)
};

struct FlightResult {
  FlightStatus status = FlightStatus::kCompleted;
  std::string reason;               // why it diverged or was stopped
  double trajectory_start_s = 0.0;  // sim time at which the trajectory's first setpoint applied
  std::vector<FlightSample> log;    // at the position-loop rate
};

struct FlightHooks {
  // The state the controller flies on, asked before every physics step (unset: ground truth).
  std::function<control::VehicleState(const FlightLoop& loop)> control_state;
  // Called after every physics step that did not diverge (e.g. to render the onboard camera);
  // a non-empty return stops the flight (kStopped) with that reason. It must leave the state
  // the next step reads (qpos, qvel, act, ctrl) alone; recomputing kinematics (mj_kinematics,
  // mj_camlight) is fine, mj_step recomputes them anyway.
  std::function<std::string(const FlightLoop& loop)> after_step;
  // The trajectory to fly, asked before every step (unset: the one given). It may change during
  // the flight (an online planner's); every one keeps the given one's time base, and the flight
  // ends hold_s after the end of the one flown then. The take-off climbs to the given one's first
  // setpoint.
  std::function<const control::SetpointTrajectory&()> trajectory;
};

// When the phases of flyTrajectory begin, from the loop's current time and state.
struct FlightTimeline {
  double takeoff_s = 0.0;  // climb from the current pose to the first setpoint
  double climb_end_s = 0.0;
  double trajectory_start_s = 0.0;  // after the climb and settle_s
  double end_s = 0.0;               // after the trajectory and hold_s
};
FlightTimeline flightTimeline(const FlightLoop& loop, const control::SetpointTrajectory& trajectory,
                              const FlightConfig& config);

// Takes off from the vehicle's current (landed) pose to the trajectory's first setpoint,
// settles, flies the trajectory and holds its end. Hooks that only observe leave the flight
// unchanged.
FlightResult flyTrajectory(FlightLoop& loop, const control::SetpointTrajectory& trajectory, const FlightConfig& config,
                           const FlightHooks& hooks = {});

struct TrackingSummary {
  double duration_s = 0.0;
  double position_rmse_m = 0.0;
  double position_max_m = 0.0;
  double yaw_rmse_rad = 0.0;
  double final_error_m = 0.0;  // at the end of the hold
  int samples = 0;
};
// Errors over the samples on the trajectory.
TrackingSummary summarizeTracking(const FlightResult& result);

}  // namespace tgnav::harness
