#pragma once
// Sweeps: many trials (planners x scenarios x seeds x settings) run by `tgnav sweep`.
//
// A sweep file (configs/sweeps/*.yaml) lists runs; each run is the cartesian product of its axes,
// and the sweep is the union of its runs:
//
//   seeds: 10                       # 1..10, or a list [1, 4, 7]; a run may give its own
//   set: {camera.width_px: 320}     # optional: --set overrides for every trial
//   runs:
//     - scenario: ../scenarios/storage.yaml      # one path or a list (relative to this file)
//       planner: [proposed, agnostic]            # one name or a list; an external planner as
//                                                # {external: COMMAND, name: NAME} (sweep_planners.h)
//     - scenario: ../scenarios/storage.yaml
//       planner: rrtstar
//       samples: [300, 1000, 2000]               # rrtstar's sample budget (rrtstar only)
//       set: {vo.min_inliers: 25}                # optional: fixed overrides of this run
//       axes: {vo.max_features: [300, 600]}      # optional: any config key, one value each
//                                                # (a `vehicle` file relative to this file)
//     - generated: {kind: room, seeds: [101, 102]}  # instead of scenario: generated scenes, written
//       planner: proposed                           # into DIR/scenes/ (harness/experiments/sweep_scenes.h)
//
// A trial's id names what distinguishes it, e.g. storage__rrtstar-300__s01 or
// storage__proposed__vo.max_features=300__s01; its results go to DIR/trials/<id>.
//
// The sweep folder DIR:
//   sweep.yaml     the sweep file as first run (a copy)
//   trials.csv     the manifest: every trial of the sweep (id,scenario,scene,planner,samples,seed,params)
//   commands.txt   each trial's `tgnav trial` arguments (run in DIR)
//   scenarios/     each scenario resolved when the sweep first ran (its first line names it); the
//                  trials run these, so editing configs/ later changes none of them (sweep_runner.cpp)
//   index.csv      the finished trials with their headline metrics, in manifest order; rebuilt
//                  from the trial folders, so it never loses or repeats a trial
//   trials/<id>/   one `tgnav trial` folder each; finished when it holds a valid metrics.json
//   logs/<id>.log  each trial's output
//   scenes/        generated scenes (runs with `generated:`), one folder each
//   slurm/         job scripts and submitted job ids (--backend slurm)
//   corrupt/       trial folders that were found corrupted, moved aside before re-running
//
// This file: the sweep file and what it expands into. The folder's trial states, index and lock:
// sweep_folder.h; running a sweep (runSweep, sweepStatus): sweep_runner.h, with the backends in
// sweep_local.h and sweep_slurm.h.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace tgnav::harness {

struct SweepTrial {
  std::string id;
  std::filesystem::path scenario;  // absolute
  std::string scene;               // the scenario's scene (its file's stem)
  std::string planner;             // proposed | agnostic | rrtstar | an external planner's name
  // An external planner's command and working directory (sweep_planners.h); "" for a built-in one.
  // Not in the manifest: commands.txt holds them.
  std::string external_command;
  std::filesystem::path external_dir;
  int samples = 0;  // rrtstar's sample budget; 0 for the others
  std::uint64_t seed = 0;
  // --set overrides, in order: the sweep's, the run's, then the run's axes.
  std::vector<std::pair<std::string, std::string>> set;
  // What distinguishes the trial beyond scenario, planner, samples and seed: the run's own set and
  // axis assignments as "key=value;key=value" ("" when none).
  std::string params;
};

struct Sweep {
  std::filesystem::path source;
  std::vector<SweepTrial> trials;
};

// Reads and expands a sweep file, and checks every trial's configuration (scenario, planner,
// every --set key) by loading it. InputError naming file:line, the key and the value. Generated
// scenes are written into (or checked against) `scenes_dir`, the sweep folder's scenes/; a sweep
// file with generated scenes and no scenes_dir is an InputError.
Sweep loadSweep(const std::filesystem::path& yaml, const std::filesystem::path& scenes_dir = {});

// The arguments of `tgnav trial` for one trial (without the program), writing into `out`.
std::vector<std::string> trialArguments(const SweepTrial& trial, const std::filesystem::path& out);

// The manifest (trials.csv) and back (without `set`). parseManifest: InputError naming file:line
// on a bad row.
std::string manifestCsv(const std::vector<SweepTrial>& trials);
std::vector<SweepTrial> parseManifest(const std::string& text, const std::string& file);

// commands.txt: per trial a line "<id> trial --scenario ... --out trials/<id>", shell-quoted, to
// be run in DIR. It pins the sweep down: a re-run must expand to the same commands.
std::string commandsText(const std::vector<SweepTrial>& trials);

// A trial's params ("key=value;key=value") as trial ids and report labels show them: a
// `vehicle` file by its name ("vehicle=hexarotor").
std::string paramsLabel(const std::string& params);

}  // namespace tgnav::harness
