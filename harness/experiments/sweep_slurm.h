#pragma once
// The Slurm backend of `tgnav sweep`: the pending trials of a sweep as one Slurm job array (one
// trial per task, DIR/slurm/array-<n>.sh), submitted with sbatch; each task refreshes the index
// when its trial has ended. The arrays of a sweep share a job name unique to its folder, so
// squeue finds the tasks still queued or running (DIR/slurm/jobs.txt lists the submissions).
#include <map>
#include <string>
#include <vector>

#include "harness/experiments/sweep_folder.h"

namespace tgnav::harness {

struct SlurmOptions {
  int jobs = 0;                          // the array's limit of tasks at once (0: all)
  bool wait = false;                     // sbatch --wait: return once every task has ended
  std::vector<std::string> sbatch_args;  // extra sbatch arguments
};

// Submits run.todo (not empty; the feature maps already built) as a job array. Without `wait`:
// 0 once submitted; with it: 0 when every trial of the sweep is done by the end, else 1.
// InputError when sbatch refuses (the job script is removed: the sweep is unchanged).
int runSlurm(const SweepRun& run, const SlurmOptions& options);

// InputError while tasks of the sweep in `dir` are queued or running in Slurm (they write into
// it without the sweep's lock); nothing to check for a sweep never submitted.
void refuseWhileSlurmRuns(const SweepDir& dir);

// The Slurm side of `tgnav sweep --status`.
struct SlurmStatus {
  bool submitted = false;             // DIR/slurm/jobs.txt exists (else nothing below is asked)
  std::string error;                  // squeue failed: why ("" when it answered)
  std::map<std::string, int> states;  // tasks queued or running, by state (PENDING, RUNNING, ...)
};
SlurmStatus slurmStatus(const SweepDir& dir);

}  // namespace tgnav::harness
