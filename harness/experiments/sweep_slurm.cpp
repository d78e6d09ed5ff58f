#include "harness/experiments/sweep_slurm.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "harness/base/errors.h"
#include "harness/base/shell.h"
#include "harness/io/staged_output.h"

namespace tgnav::harness {

namespace fs = std::filesystem;

namespace {

// The job name of the sweep's arrays: unique to its folder, so squeue finds them by name.
std::string jobName(const SweepDir& dir) {
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a
  for (unsigned char c : dir.path().string()) h = (h ^ c) * 1099511628211ULL;
  char buf[32];
  std::snprintf(buf, sizeof buf, "tgnav-sweep-%08llx", static_cast<unsigned long long>(h & 0xffffffffULL));
  return buf;
}

bool submitted(const SweepDir& dir) { return fs::exists(dir.path() / "slurm" / "jobs.txt"); }

// Tasks of the sweep's job arrays still queued or running, as "JOBID_TASK STATE" lines.
std::vector<std::string> activeTasks(const SweepDir& dir) {
  const CommandResult q = runCommand("squeue -h -r --name=" + jobName(dir) + " -o '%i %T'");
  if (q.rc != 0) {
    throw InputError("squeue failed (exit " + std::to_string(q.rc) + "): " + oneLine(q.output) +
                     "; is Slurm reachable from here (SLURM_CONF)?");
  }
  std::vector<std::string> lines;
  std::istringstream in(q.output);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

// A new job script in DIR/slurm: array-<n>.sh, n one more than the last.
fs::path newScriptPath(const SweepDir& dir) {
  const fs::path slurm = dir.path() / "slurm";
  makeOutputDir(slurm);
  int n = 1;
  while (fs::exists(slurm / ("array-" + std::to_string(n) + ".sh"))) ++n;
  return slurm / ("array-" + std::to_string(n) + ".sh");
}

// The job script: task k runs the k-th pending trial, then refreshes the index.
std::string jobScript(const SweepRun& run) {
  const SweepDir& dir = *run.dir;
  std::ostringstream s;
  s << "#!/bin/bash\n"
    << "# tgnav sweep " << dir.path().string() << ": " << run.todo.size() << " trials, one per array task\n"
    << "#SBATCH --job-name=" << jobName(dir) << "\n"
    << "#SBATCH --cpus-per-task=1\n"
    << "#SBATCH --output=" << (dir.path() / "logs" / "slurm-%A_%a.out").string() << "\n"
    << "set -u\n"
    << "cd " << shellWord(dir.path().string()) << " || exit 1\n"
    << "case \"$SLURM_ARRAY_TASK_ID\" in\n";
  for (std::size_t k = 0; k < run.todo.size(); ++k) {
    const SweepTrial& t = run.trials[run.todo[k]];
    std::vector<std::string> args = trialArguments(t, fs::path("trials") / t.id);
    args.insert(args.end(), {"--threads", "1", "--no-figures", "--force"});
    if (!run.map_cache.empty()) args.insert(args.end(), {"--map-cache", fs::absolute(run.map_cache).string()});
    s << "  " << k << ") id=" << t.id << "; args=(";
    for (std::size_t a = 0; a < args.size(); ++a) s << (a ? " " : "") << shellWord(args[a]);
    s << ") ;;\n";
  }
  const std::string exe = shellWord(run.program.string());
  s << "  *) echo \"no trial for array task $SLURM_ARRAY_TASK_ID\" >&2; exit 2 ;;\n"
    << "esac\n"
    << "echo \"=== $(date '+%Y-%m-%d %H:%M:%S'): Slurm job ${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID} on "
       "$(hostname)\" >> \"logs/$id.log\"\n"
    << exe << " \"${args[@]}\" >> \"logs/$id.log\" 2>&1\n"
    << "rc=$?\n"
    << exe << " sweep --status --out . > /dev/null 2>&1\n"
    << "exit $rc\n";
  return s.str();
}

std::string sbatchCommand(const fs::path& script, std::size_t tasks, int jobs, const SlurmOptions& options) {
  std::string cmd = "sbatch --parsable --array=0-" + std::to_string(tasks - 1) + "%" + std::to_string(jobs);
  if (options.wait) cmd += " --wait";
  for (const std::string& a : options.sbatch_args) cmd += " " + shellWord(a);
  return cmd + " " + shellWord(script.string());
}

// Runs sbatch; the job id. When nothing was submitted: InputError, the script removed.
std::string submit(const std::string& cmd, const fs::path& script) {
  const CommandResult r = runCommand(cmd);
  // sbatch --parsable prints "JOBID" or "JOBID;CLUSTER" first; with --wait it returns the
  // array's exit code once every task has ended.
  const std::string first = r.output.substr(0, r.output.find('\n'));
  std::string job = first.substr(0, first.find(';'));
  if (job.empty() || !std::all_of(job.begin(), job.end(), ::isdigit)) {
    fs::remove(script);
    throw InputError("sbatch failed (exit " + std::to_string(r.rc) + "): " + oneLine(r.output) +
                     "; nothing was submitted, the sweep is unchanged (run the same command to try again)");
  }
  return job;
}

}  // namespace

int runSlurm(const SweepRun& run, const SlurmOptions& options) {
  const SweepDir& dir = *run.dir;
  const std::size_t tasks = run.todo.size();
  const fs::path script = newScriptPath(dir);
  writeFileAtomic(script, jobScript(run));
  fs::permissions(script, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add);

  const int jobs = options.jobs > 0 ? options.jobs : static_cast<int>(tasks);
  const std::string cmd = sbatchCommand(script, tasks, jobs, options);
  std::fprintf(stderr, "tgnav sweep: submitting %zu trials (at most %d at once): %s\n", tasks, jobs, cmd.c_str());
  const std::string job = submit(cmd, script);
  std::ofstream(dir.path() / "slurm" / "jobs.txt", std::ios::app)
      << job << ' ' << script.filename().string() << ' ' << tasks << '\n';
  if (!options.wait) {
    std::printf(
        "tgnav sweep: submitted Slurm job array %s (%zu trials, at most %d at once); follow it with: tgnav "
        "sweep --status --out %s\n",
        job.c_str(), tasks, jobs, dir.path().c_str());
    return 0;
  }
  const TrialCounts c = countTrials(dir.writeIndex(run.trials));
  std::printf("tgnav sweep: Slurm job array %s ended; %d of %zu trials done (%s) -> %s/index.csv\n", job.c_str(),
              c.done, run.trials.size(), statusList(c).c_str(), dir.path().c_str());
  return c.done == static_cast<int>(run.trials.size()) ? 0 : 1;
}

void refuseWhileSlurmRuns(const SweepDir& dir) {
  if (!submitted(dir)) return;
  const std::vector<std::string> active = activeTasks(dir);
  if (!active.empty()) {
    throw InputError("--out: " + dir.path().string() + ": " + std::to_string(active.size()) +
                     " tasks of this sweep are still queued or running in Slurm (job " +
                     active.front().substr(0, active.front().find('_')) +
                     "); wait for them (tgnav sweep --status --out DIR) or cancel them (scancel --name=" +
                     jobName(dir) + ") before running it again");
  }
}

SlurmStatus slurmStatus(const SweepDir& dir) {
  SlurmStatus status;
  status.submitted = submitted(dir);
  if (!status.submitted) return status;
  std::vector<std::string> active;
  try {
    active = activeTasks(dir);
  } catch (const InputError& e) {
    status.error = e.what();
  }
  for (const std::string& line : active) ++status.states[line.substr(line.find(' ') + 1)];
  return status;
}

}  // namespace tgnav::harness
