// tgnav sweep: many trials, each a separate `tgnav trial` process writing its own folder, locally
// (one per core) or as a Slurm job array; re-running the same command resumes
// (harness/experiments/sweep_runner.h). --status reports where a sweep folder stands.
#include <cstdio>
#include <memory>

#include "harness/base/errors.h"
#include "harness/cli/cli.h"
#include "harness/experiments/sweep_runner.h"

namespace tgnav::cli {

namespace {

struct SweepCliOptions {
  harness::SweepOptions run;
  bool status = false;
};

void printStatus(const harness::SweepStatus& s) {
  const harness::TrialCounts& c = s.counts;
  std::printf("tgnav sweep: %s: %d of %zu trials done (%s)", s.dir.c_str(), c.done, s.trials,
              harness::statusList(c).c_str());
  if (s.running > 0) std::printf(", %zu running", s.running);
  if (c.incomplete > 0) std::printf(", %d interrupted", c.incomplete);
  if (c.corrupt > 0) std::printf(", %d corrupted (moved aside on resume)", c.corrupt);
  std::printf(", %d not started\n", c.absent);
  if (s.slurm.submitted) {
    if (!s.slurm.error.empty()) std::printf("  slurm: %s\n", s.slurm.error.c_str());
    std::string list;
    for (const auto& [state, n] : s.slurm.states) list += (list.empty() ? "" : ", ") + std::to_string(n) + " " + state;
    std::printf("  slurm: %s\n", list.empty() ? "no tasks queued or running" : list.c_str());
  }
  std::printf("  index: %s/index.csv\n", s.dir.c_str());
}

int runSweepCommand(const SweepCliOptions& opt) {
  if (opt.run.out.empty()) throw InputError("--out: required");
  if (!opt.status) return harness::runSweep(opt.run);
  if (!opt.run.sweep.empty()) throw InputError("--status: takes only --out DIR (the sweep is the one in DIR)");
  printStatus(harness::sweepStatus(opt.run.out));
  return 0;
}

}  // namespace

void addSweepCommand(CLI::App& app) {
  auto opt = std::make_shared<SweepCliOptions>();
  harness::SweepOptions& run = opt->run;
  CLI::App* cmd = app.add_subcommand(
      "sweep", "Run many trials (configs/sweeps/*.yaml) locally or on Slurm; resumable; DIR/index.csv");
  cmd->add_option("--sweep", run.sweep, "Sweep YAML (configs/sweeps/*.yaml)");
  cmd->add_option("--out", run.out, "Sweep folder (new, or the one to resume)")->required();
  cmd->add_option("--jobs", run.jobs,
                  "Trials at once (local: default one per core; slurm: the array's limit, default all)");
  cmd->add_option("--backend", run.backend, "local | slurm")->capture_default_str();
  cmd->add_flag("--status", opt->status, "Report the progress of the sweep in --out and refresh its index.csv");
  cmd->add_flag("--wait", run.wait, "slurm: wait until the job array has ended (sbatch --wait)");
  cmd->add_option("--sbatch-arg", run.sbatch_args,
                  "slurm: an extra sbatch argument, e.g. --sbatch-arg=--partition=cpu (repeatable)");
  cmd->add_option("--map-cache", run.map_cache,
                  "Cache folder for feature maps (default: $TGNAV_CACHE_DIR or ~/.cache/tgnav)");
  cmd->callback([opt] {
    const int rc = runSweepCommand(*opt);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace tgnav::cli
