#pragma once
// A plan from a planner the harness does not ship (scenario.planner.external): the command is
// started as a child process, asked once for a route over the protocol of docs/PLANNER_PROTOCOL.md
// (harness/io/planner_protocol.h), and its answer checked against the map as a given route is
// (given_route.h). Whatever the planner does - hang past its budget, exit, crash, write garbage,
// NaN, a route through a wall - is an outcome with a one-line reason, never an exception: the
// trial then ends in plan_failed. The map files it is sent are the feature map's folder's
// map.bt and landmarks.csv, and an occupancy slice (and the classes, if asked) written into a
// temporary folder that is removed afterwards.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "control/trajectory.h"
#include "harness/config/scenario.h"
#include "planner/feature_map.h"
#include "planner/planner.h"
#include "planner/pose4.h"
#include "planner/voxel_map.h"

namespace tgnav::harness {

struct ExternalPlan {
  bool ok = false;
  std::string detail;  // when !ok: "external planner NAME: ..." (one line)
  // The route (one of them when ok): a path to smooth, or a trajectory to fly.
  std::optional<std::vector<planner::Pose4>> path;
  std::optional<control::SetpointTrajectory> trajectory;
  std::optional<int> homology_class;  // as the planner reported it
  std::vector<double> scores;         // per point, as reported
  std::string reason;                 // as reported ("" when none)
  bool no_path = false;               // the planner answered that it found none (status no_path)
  planner::TopoPlan topo;             // the classes it was sent (planner.external.classes)
  double prepare_s = 0.0;             // writing the map slice (and classes)
  double start_s = 0.0;               // starting the process
  double call_s = 0.0;                // request written to response parsed
  std::optional<double> planner_s;    // the planner's own time (solve_time_s)
  double stop_s = 0.0;                // shutdown: until the process has exited (or was killed)
  double check_s = 0.0;               // the route checked against the map
  std::string ended;                  // how the process ended ("exited with status 0")
  std::string stderr_tail;            // the last lines it wrote to stderr
  double total_s() const { return prepare_s + start_s + call_s + stop_s + check_s; }
};

// Asks scenario.planner.external (configured()) for a route from the scenario's start to its goal.
// `map_dir` holds the feature map (map.bt, landmarks.csv); `voxels` is buildPlanningVoxels() of
// it. `interrupt`, when raised, stops the wait ("interrupted").
ExternalPlan askExternalPlanner(const Scenario& scenario, const std::filesystem::path& map_dir,
                                const planner::VoxelMap& voxels, std::uint64_t seed,
                                const std::atomic<bool>* interrupt = nullptr);

// One external planner process asked again and again, for an online trial's plans (the same
// protocol; request ids count up from 1): started at the first ask, asked to shut down when the
// session ends. Each ask sends the map as it is then (map.bt and landmarks.csv written into the
// session's temporary folder, the occupancy slice, the classes if asked). An answer "no path" or a
// route the map refuses is that plan's failure; a planner that hangs past its budget, exits,
// crashes or writes garbage is stopped and not asked again (ExternalPlan::stopped).
class ExternalPlannerSession {
 public:
  ExternalPlannerSession();
  ~ExternalPlannerSession();
  ExternalPlannerSession(const ExternalPlannerSession&) = delete;
  ExternalPlannerSession& operator=(const ExternalPlannerSession&) = delete;
  ExternalPlannerSession(ExternalPlannerSession&&) = delete;
  ExternalPlannerSession& operator=(ExternalPlannerSession&&) = delete;

  // A route from `from_here`'s start to its goal (its planner.external) on `map` (`voxels`:
  // buildPlanningVoxels of it).
  ExternalPlan ask(const Scenario& from_here, const planner::FeatureMap& map, const planner::VoxelMap& voxels,
                   std::uint64_t seed, const std::atomic<bool>* interrupt = nullptr);
  bool stopped() const;  // it failed: later asks fail at once
  // The last lines the process wrote to stderr so far ("" before it started).
  std::string stderrTail() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tgnav::harness
