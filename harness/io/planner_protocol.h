#pragma once
// The external planner protocol, version 1 (docs/PLANNER_PROTOCOL.md): the plan request the
// harness writes and the response it reads, one JSON object per line. Pure text in, values out:
// the process that speaks it is harness/base/child_process.h, the trial's use harness/run/external_plan.h.
#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "control/trajectory.h"
#include "planner/pose4.h"

namespace tgnav::harness {

constexpr int kPlannerProtocolVersion = 1;
constexpr const char* kPlannerProtocolName = "tgnav-planner";
constexpr std::size_t kMaxResponseBytes = std::size_t{64} << 20;  // one response line
constexpr std::size_t kMaxPathPoints = 100000;
constexpr std::size_t kMaxTrajectoryRows = 200000;

// What a plan request tells the planner (every field of docs/PLANNER_PROTOCOL.md's request).
struct PlanRequestMessage {
  int id = 1;
  unsigned long long seed = 0;
  double time_budget_s = 0.0;
  planner::Pose4 start;
  planner::Pose4 goal;
  Eigen::Vector3d bounds_min_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d bounds_max_m = Eigen::Vector3d::Zero();
  double flight_height_m = 0.0;
  double robot_radius_m = 0.0;
  double check_band_lo_m = 0.0;
  double check_band_hi_m = 0.0;
  double nominal_speed_m_s = 0.0;
  double max_speed_m_s = 0.0;
  double max_accel_m_s2 = 0.0;
  double max_yaw_rate_rad_s = 0.0;
  int width_px = 0;
  int height_px = 0;
  double camera_rate_hz = 0.0;
  double hfov_rad = 0.0;
  double vfov_rad = 0.0;
  double min_range_m = 0.0;
  double max_range_m = 0.0;
  double camera_forward_m = 0.0;  // the camera's position on the body (VisibilityConfig)
  double camera_up_m = 0.0;
  std::string octomap;  // absolute paths
  std::string landmarks;
  std::string occupancy_yaml;
  std::string occupancy_pgm;
  std::string classes;  // "" = none (null)
};

// The request as one line (with its '\n').
std::string planRequestLine(const PlanRequestMessage& m);
std::string shutdownLine();

// What a planner answered.
struct PlanResponse {
  bool ok = false;     // status "ok"; false: "no_path"
  std::string reason;  // "" when none given; one line
  std::optional<std::vector<planner::Pose4>> path;
  std::optional<control::SetpointTrajectory> trajectory;
  std::optional<int> homology_class;
  std::vector<double> scores;          // empty when none given
  std::optional<double> solve_time_s;  // the planner's own time
};

// A response that breaks the protocol; what() is one line without the planner's name
// ("invalid response: path[3][1] is not a finite number", "protocol version 2, expected 1").
class ProtocolError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Parses one response line (without its '\n') to request `expected_id`. ProtocolError for
// anything the protocol does not allow: not one JSON object, another protocol or version, another
// id, unknown keys, a status other than ok/no_path, neither or both of path and trajectory, rows
// of the wrong size, non-numbers (NaN and Infinity are not JSON), too few or too many points,
// time not increasing, scores of another length.
PlanResponse parsePlanResponse(const std::string& line, int expected_id);

}  // namespace tgnav::harness
