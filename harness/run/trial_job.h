#pragma once
// The `tgnav trial` job: load the scenario (with --set overrides) and the scene's feature map,
// run the trial (harness/run/trial.h), score it and write its folder: metrics.json, gt.tum,
// est.tum, vo.csv, plan.json, trajectory.csv, config.yaml, the map layer and the figures
// (topdown, ate), and frames.png with --frames. The folder is staged and appears whole; an
// interrupted trial leaves its partial results marked by an INCOMPLETE file and no metrics.json.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "harness/io/figures.h"
#include "harness/run/trial.h"

namespace tgnav::harness {

struct TrialJob {
  std::filesystem::path scenario;
  planner::PlannerKind planner = planner::PlannerKind::kProposed;
  int samples = 0;                    // RRT*'s budget; 0: the planner config's
  std::optional<std::uint64_t> seed;  // default: the scenario's
  std::vector<std::string> set;       // --set dotted.key=value overrides
  std::filesystem::path out;
  bool force = false;  // replace what --out holds
  int frames = 0;      // frames.png with this many onboard frames (0-64)
  std::string map;     // feature map folder; "" = the cache
  std::string map_cache;
  int threads = 0;                    // > 0: at most this many threads (results do not change)
  std::optional<int> homology_class;  // the oracle: fly this class (planner.oracle_class)
  // Fly this setpoint CSV (the columns `tgnav fly` reads) instead of planning; "" = plan.
  std::filesystem::path trajectory;
  // Or smooth and fly this 4-DoF path CSV (x,y,z,yaw); "" = plan.
  std::filesystem::path path;
  // Ask the scenario's external planner instead (`--planner external`, docs/PLANNER_PROTOCOL.md).
  // `external_command` sets planner.external.command (run in `external_dir`, "" = the current
  // directory) and `external_name` its name, over the scenario's.
  bool external = false;
  std::string external_command;
  std::string external_name;
  std::filesystem::path external_dir;
  bool figures = true;  // draw topdown and ate (a sweep leaves them to its report)
  FigureFormat figure_format = FigureFormat::kPng;
  // Called right before the trial (planning and flight) and right after it, before the results
  // are written: the CLI catches Ctrl-C only in between (a signal while the map is built or the
  // results are written ends the process, and the folder never appears).
  std::function<void()> trial_starting;
  std::function<void()> trial_ended;
};

struct TrialJobResult {
  std::filesystem::path out;
  TrialStatus status = TrialStatus::kPlanFailed;
  std::string summary;  // the line `tgnav trial` prints (a finished trial)
  FigureOutcome figures;
};

// InputError naming the scenario and planner.robot_radius_m when the planners' robot radius is
// less than the reach of the vehicle that flies (harness::vehicleReach): their clearance would not
// keep its rotors off the obstacles.
void checkRobotRadiusBoundsVehicle(const Scenario& scenario);

// InputError for bad input, before anything is written. `interrupt`, when raised, stops the
// flight; the status is then kInterrupted and the folder holds the partial results.
TrialJobResult runTrialJob(const TrialJob& job, const ProgressFn& progress = {},
                           const std::atomic<bool>* interrupt = nullptr);

}  // namespace tgnav::harness
