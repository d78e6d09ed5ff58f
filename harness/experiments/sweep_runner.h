#pragma once
// `tgnav sweep`, callable without the CLI: many trials, each a separate `tgnav trial` process
// writing its own folder, locally (sweep_local.h) or as a Slurm job array (sweep_slurm.h).
// Running the same sweep into the same folder again resumes it: finished trials are skipped,
// interrupted or killed ones run again, corrupted ones are moved aside and run again. index.csv
// is rebuilt from the trial folders, so it never loses or repeats a trial.
#include <filesystem>
#include <string>
#include <vector>

#include "harness/experiments/sweep_folder.h"
#include "harness/experiments/sweep_slurm.h"

namespace tgnav::harness {

struct SweepOptions {
  std::string sweep;                     // the sweep file (configs/sweeps/*.yaml)
  std::string out;                       // the sweep folder: new, or the one to resume
  int jobs = 0;                          // trials at once (local: 0 one per core; slurm: 0 all)
  std::string backend = "local";         // local | slurm
  bool wait = false;                     // slurm: until the job array has ended
  std::string map_cache;                 // feature map cache ("": $TGNAV_CACHE_DIR or ~/.cache/tgnav)
  std::vector<std::string> sbatch_args;  // slurm: extra sbatch arguments
  std::filesystem::path program;         // the tgnav program that runs the trials ("": this one)
};

// Runs (or resumes) the sweep: checks the options and the sweep file (InputError naming the
// option, or file:line), locks and sets up the folder (waiting for the trials of a killed sweep
// to let go of it), refuses while Slurm tasks of it are still queued or running, tidies it,
// builds each scene's feature map once, then runs the trials that are not done. Progress on
// stderr, the summary on stdout. The exit code: 0 done (or, for Slurm without `wait`,
// submitted), 1 some trials failed, 130 interrupted.
int runSweep(const SweepOptions& options);

// Where a sweep folder stands (`tgnav sweep --status`); refreshes its index.csv.
struct SweepStatus {
  std::filesystem::path dir;  // symbolic links resolved
  std::size_t trials = 0;
  TrialCounts counts;
  std::size_t running = 0;  // trials being written now
  SlurmStatus slurm;
};
// InputError when `dir` is not a sweep folder.
SweepStatus sweepStatus(const std::filesystem::path& dir);

}  // namespace tgnav::harness
