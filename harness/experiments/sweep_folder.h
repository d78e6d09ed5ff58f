#pragma once
// The sweep folder DIR (its layout: sweep.h): how its trial folders are judged (absent,
// interrupted, corrupted, done), its index.csv, the lock that keeps two sweeps out of one
// folder, and what a run does to the folder before its trials start (set up, checked, tidied).
#include <cstddef>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/experiments/sweep.h"

namespace tgnav::harness {

// What a trial folder holds.
enum class TrialState { kAbsent, kIncomplete, kCorrupt, kDone };
// False positive: clang-tidy 14 takes the implicit default constructor for noexcept (it is not: json's can throw).
// NOLINTNEXTLINE(bugprone-exception-escape)
struct TrialFolder {
  TrialState state = TrialState::kAbsent;
  std::string problem;     // kIncomplete / kCorrupt: what is wrong, one line
  nlohmann::json metrics;  // kDone: metrics.json
};
// kDone needs a metrics.json that parses, has the fields index.csv takes, and is this trial's
// (scenario's scene, planner, samples, seed). A folder with INCOMPLETE or without metrics.json
// is kIncomplete (an interrupted or killed trial); anything else is kCorrupt.
TrialFolder inspectTrialFolder(const SweepTrial& trial, const std::filesystem::path& folder);

// index.csv: one row per finished trial (states[i] for trials[i]), in manifest order.
extern const char* const kIndexHeader;
std::string indexCsv(const std::vector<SweepTrial>& trials, const std::vector<TrialFolder>& folders);

// Names in DIR/trials that `tgnav trial` stages its results under: `.<id>.tmp-<pid>` while it
// writes them (isTrialStaging), and also `.<id>.old-<pid>` while it replaces a folder
// (isTrialLeftover: what a killed trial may leave behind).
bool isTrialStaging(const std::string& file_name);
bool isTrialLeftover(const std::string& file_name);

// How many trials are in each state, and the statuses of the finished ones.
struct TrialCounts {
  std::map<std::string, int> statuses;  // of finished trials
  int done = 0, incomplete = 0, corrupt = 0, absent = 0;
};
TrialCounts countTrials(const std::vector<TrialFolder>& folders);
// "3 success, 1 vo_lost" ("none" when no trial is done).
std::string statusList(const TrialCounts& counts);

// An exclusive flock on a file of the sweep folder, held until destruction; waits up to wait_s
// (saying `waiting_message` once on stderr, when not empty), then InputError. With `inherit`
// the lock passes to the trial processes, so a sweep killed with -9 keeps its folder locked
// until the trials it started (stopped by their parent-death signal) have written their partial
// results.
class FolderLock {
 public:
  FolderLock(const std::filesystem::path& file, bool inherit, double wait_s, const std::string& waiting_message);
  ~FolderLock();
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;
  FolderLock(FolderLock&&) = delete;  // owns the lock's fd
  FolderLock& operator=(FolderLock&&) = delete;

 private:
  int fd_ = -1;
};

// The sweep folder: its trials (from the manifest), their folders' states and the index.
class SweepDir {
 public:
  // Symbolic links resolved: the Slurm job name is a hash of this path, and a task sees DIR as
  // its working directory.
  explicit SweepDir(const std::filesystem::path& dir);
  const std::filesystem::path& path() const { return dir_; }
  std::filesystem::path trialDir(const SweepTrial& t) const { return dir_ / "trials" / t.id; }
  std::filesystem::path logFile(const SweepTrial& t) const { return dir_ / "logs" / (t.id + ".log"); }

  // The trials of the sweep held here (trials.csv); InputError when DIR is not a sweep folder.
  std::vector<SweepTrial> manifest() const;
  std::vector<TrialFolder> inspect(const std::vector<SweepTrial>& trials) const;
  // Rebuilds index.csv from the trial folders (under its own lock: Slurm tasks rebuild it too).
  std::vector<TrialFolder> writeIndex(const std::vector<SweepTrial>& trials) const;
  // Trials being written now (their staging folders in trials/).
  std::size_t staging() const;

  // Sets the folder up for `sweep` (first run), or checks that it holds the same sweep (re-run:
  // InputError naming the first line where commands.txt differs).
  void prepare(const Sweep& sweep) const;
  // Removes the leftovers of killed trials (their staging folders) and moves corrupted trial
  // folders to corrupt/ (kept, not deleted, and said on stderr) so that those trials run again.
  void tidy(const std::vector<SweepTrial>& trials, const std::vector<TrialFolder>& folders) const;

 private:
  std::filesystem::path dir_;
};

// One run of a sweep, for a backend: the sweep in `dir`, its trials' states, which to run.
struct SweepRun {
  const SweepDir* dir = nullptr;
  std::vector<SweepTrial> trials;    // all of them, in manifest order
  std::vector<TrialFolder> folders;  // folders[i]: the state of trials[i] before this run
  std::vector<std::size_t> todo;     // indexes of the trials to run (not done)
  std::filesystem::path program;     // the tgnav program that runs each trial
  std::string map_cache;             // --map-cache for the trials ("" for the default)
};

}  // namespace tgnav::harness
