#pragma once
// The local backend of `tgnav sweep`: the pending trials of a sweep as `tgnav trial` processes on
// this machine, `jobs` at a time. Each trial dies with the sweep (parent-death signal); Ctrl-C
// reaches the trials too, a SIGTERM for the sweep is passed on to them. On stderr: a progress bar
// with an ETA (on a terminal) and a line per finished or failed trial; the index is rebuilt after
// each finished trial; on stdout: the summary line.
#include "harness/experiments/sweep_folder.h"

namespace tgnav::harness {

// Runs run.todo (not empty; the feature maps already built), `jobs` at a time (0: one per core).
// Returns 0 when every trial ran, 130 when interrupted (SIGINT or SIGTERM), 1 when some failed
// to run (listed on stderr with the last line of each one's log).
int runLocal(const SweepRun& run, int jobs);

// "42s", "3m05s", "1h02m".
std::string formatDuration(double seconds);

}  // namespace tgnav::harness
