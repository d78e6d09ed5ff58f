// tgnav sweep: many trials, each a separate `tgnav trial` process writing its own folder, locally
// (one per core) or as a Slurm job array. Re-running the same command resumes: finished trials
// are skipped, interrupted or killed ones run again, corrupted ones are moved aside and run again.
// index.csv is rebuilt from the trial folders, so it never loses or repeats a trial.
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include "harness/cli.h"
#include "harness/errors.h"
#include "harness/map_cache.h"
#include "harness/output.h"
#include "harness/scenario.h"
#include "harness/shell.h"
#include "harness/sweep.h"
#include "harness/yaml_util.h"

namespace tgnav::cli {

namespace {

namespace fs = std::filesystem;
using harness::SweepTrial;
using harness::TrialFolder;
using harness::TrialState;

struct SweepCliOptions {
  std::string sweep;
  std::string out;
  int jobs = 0;  // 0: one per core
  std::string backend = "local";
  bool status = false;
  bool wait = false;
  std::string map_cache;
  std::vector<std::string> sbatch_args;
};

std::string readFile(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string duration(double s) {
  char buf[32];
  const long t = static_cast<long>(s + 0.5);
  if (t >= 3600) {
    std::snprintf(buf, sizeof buf, "%ldh%02ldm", t / 3600, (t / 60) % 60);
  } else if (t >= 60) {
    std::snprintf(buf, sizeof buf, "%ldm%02lds", t / 60, t % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%lds", t);
  }
  return buf;
}

// An exclusive flock on a file of the sweep folder, held until destruction. The sweep's lock is
// inherited by its trial processes, so a sweep killed with -9 keeps its folder locked until the
// trials it started (stopped by their parent-death signal) have written their partial results.
class FolderLock {
 public:
  FolderLock(const fs::path& file, bool inherit, double wait_s, const std::string& waiting_message) {
    fd_ = ::open(file.c_str(), O_RDWR | O_CREAT | (inherit ? 0 : O_CLOEXEC), 0644);
    if (fd_ < 0) throw InputError("--out: cannot create " + file.string() + ": " + std::strerror(errno));
    const auto t0 = std::chrono::steady_clock::now();
    bool told = false;
    while (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (waited >= wait_s) {
        ::close(fd_);
        throw InputError("--out: " + file.parent_path().string() +
                         " is in use by another tgnav sweep (or its trials are still stopping): " + file.string() +
                         " is locked");
      }
      if (!told && !waiting_message.empty()) {
        std::fprintf(stderr, "%s\n", waiting_message.c_str());
        told = true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
  }
  ~FolderLock() { ::close(fd_); }
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  int fd_ = -1;
};

// The sweep folder: its trials (from the manifest), their folders' states and the index.
class SweepDir {
 public:
  // Symbolic links resolved: the Slurm job name is a hash of this path, and a task sees DIR as
  // its working directory.
  explicit SweepDir(const fs::path& dir) : dir_(fs::weakly_canonical(fs::absolute(dir))) {
    if (!dir_.has_filename()) dir_ = dir_.parent_path();
  }
  const fs::path& path() const { return dir_; }
  fs::path trialDir(const SweepTrial& t) const { return dir_ / "trials" / t.id; }
  fs::path logFile(const SweepTrial& t) const { return dir_ / "logs" / (t.id + ".log"); }

  // The trials of the sweep held here (trials.csv); InputError when DIR is not a sweep folder.
  std::vector<SweepTrial> manifest() const {
    const fs::path file = dir_ / "trials.csv";
    if (!fs::is_regular_file(file)) {
      throw InputError("--out: " + dir_.string() + " is not a sweep folder (no trials.csv)");
    }
    return harness::parseManifest(readFile(file), file.string());
  }

  std::vector<TrialFolder> inspect(const std::vector<SweepTrial>& trials) const {
    std::vector<TrialFolder> folders;
    for (const SweepTrial& t : trials) folders.push_back(harness::inspectTrialFolder(t, trialDir(t)));
    return folders;
  }

  // Rebuilds index.csv from the trial folders (under its own lock: Slurm tasks rebuild it too).
  std::vector<TrialFolder> writeIndex(const std::vector<SweepTrial>& trials) const {
    const FolderLock lock(dir_ / ".index.lock", false, 60.0, "");
    std::vector<TrialFolder> folders = inspect(trials);
    harness::writeFileAtomic(dir_ / "index.csv", harness::indexCsv(trials, folders));
    return folders;
  }

  // Trials being written now: a trial stages its results in trials/.<id>.tmp-<pid>.
  std::size_t staging() const {
    std::size_t n = 0;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir_ / "trials", ec)) {
      const std::string name = e.path().filename().string();
      if (name.size() > 1 && name[0] == '.' && name.find(".tmp-") != std::string::npos) ++n;
    }
    return n;
  }

 private:
  fs::path dir_;
};

struct Counts {
  std::map<std::string, int> statuses;  // of finished trials
  int done = 0, incomplete = 0, corrupt = 0, absent = 0;
};

Counts count(const std::vector<TrialFolder>& folders) {
  Counts c;
  for (const TrialFolder& f : folders) {
    switch (f.state) {
      case TrialState::kDone:
        ++c.done;
        ++c.statuses[f.metrics["status"].get<std::string>()];
        break;
      case TrialState::kIncomplete:
        ++c.incomplete;
        break;
      case TrialState::kCorrupt:
        ++c.corrupt;
        break;
      case TrialState::kAbsent:
        ++c.absent;
        break;
    }
  }
  return c;
}

std::string statusList(const Counts& c) {
  std::string out;
  for (const auto& [status, n] : c.statuses) out += (out.empty() ? "" : ", ") + std::to_string(n) + " " + status;
  return out.empty() ? "none" : out;
}

// Sets the folder up for `sweep` (first run), or checks that it holds the same sweep (re-run).
void prepareFolder(const SweepDir& dir, const harness::Sweep& sweep) {
  const fs::path commands = dir.path() / "commands.txt";
  const std::string text = harness::commandsText(sweep.trials);
  if (fs::exists(commands)) {
    const std::string held = readFile(commands);
    if (held != text) {
      std::istringstream a(held), b(text);
      std::string la, lb;
      int line = 1;
      while (std::getline(a, la) && std::getline(b, lb) && la == lb) ++line;
      const std::string what = la.substr(0, la.find(' '));
      throw InputError("--out: " + dir.path().string() + " holds another sweep: its commands.txt differs from " +
                       sweep.source.string() + "'s at line " + std::to_string(line) + " (trial " + what +
                       "); use a new --out, or the sweep file it was made from");
    }
  }
  harness::makeOutputDir(dir.path() / "trials");
  harness::makeOutputDir(dir.path() / "logs");
  if (!fs::exists(dir.path() / "sweep.yaml"))
    harness::writeFileAtomic(dir.path() / "sweep.yaml", readFile(sweep.source));
  harness::writeFileAtomic(dir.path() / "trials.csv", harness::manifestCsv(sweep.trials));
  harness::writeFileAtomic(commands, text);
}

// Leftovers of trials that were killed (their staging folders), and corrupted trial folders,
// which are moved to corrupt/ (kept, not deleted) so that the trial runs again.
void tidy(const SweepDir& dir, const std::vector<SweepTrial>& trials, const std::vector<TrialFolder>& folders) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir.path() / "trials", ec)) {
    const std::string name = e.path().filename().string();
    if (name.size() > 1 && name[0] == '.' &&
        (name.find(".tmp-") != std::string::npos || name.find(".old-") != std::string::npos)) {
      fs::remove_all(e.path(), ec);
    }
  }
  for (std::size_t i = 0; i < trials.size(); ++i) {
    if (folders[i].state != TrialState::kCorrupt) continue;
    harness::makeOutputDir(dir.path() / "corrupt");
    fs::path to;
    for (int n = 1; to.empty() || fs::exists(to); ++n)
      to = dir.path() / "corrupt" / (trials[i].id + "." + std::to_string(n));
    fs::rename(dir.trialDir(trials[i]), to);
    std::fprintf(stderr, "tgnav sweep: trials/%s is corrupted (%s); moved to %s, the trial runs again\n",
                 trials[i].id.c_str(), folders[i].problem.c_str(), fs::relative(to, dir.path()).string().c_str());
  }
}

// Builds each scene's feature map once, before the trials that share it start.
void prebuildMaps(const std::vector<SweepTrial>& pending, const std::string& map_cache) {
  std::map<std::string, const SweepTrial*> scenes;  // a trial of each scene
  for (const SweepTrial& t : pending) scenes.emplace(t.scene, &t);
  const fs::path cache = map_cache.empty() ? harness::defaultCacheDir() : fs::path(map_cache);
  for (const auto& [scene, trial] : scenes) {
    std::vector<std::string> set;  // the trial's own settings: one may name another scene
    for (const auto& [key, value] : trial->set) set.push_back(key + "=" + value);
    const harness::YamlDoc overrides = harness::YamlDoc::fromOverrides(set);
    const harness::Scenario s = harness::loadScenario(trial->scenario, &overrides);
    bool told = false;
    harness::cachedFeatureMap(s.scene, harness::MapBuildConfig{}, cache, [&](int done, int total) {
      if (!told) {
        std::fprintf(stderr, "tgnav sweep: building the feature map of %s (once; the trials share it)\n",
                     scene.c_str());
        told = true;
      }
      (void)done;
      (void)total;
    });
  }
}

fs::path selfExe() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot find the tgnav program (/proc/self/exe): " + ec.message());
  return exe;
}

std::vector<std::string> childArguments(const SweepDir& dir, const SweepTrial& t, const std::string& map_cache) {
  std::vector<std::string> args = harness::trialArguments(t, dir.trialDir(t));
  args.insert(args.end(), {"--threads", "1"});
  if (!map_cache.empty()) args.insert(args.end(), {"--map-cache", fs::absolute(map_cache).string()});
  if (fs::exists(dir.trialDir(t))) args.push_back("--force");  // an interrupted trial's partial results
  return args;
}

std::atomic<int> g_signal{0};
extern "C" void onSweepSignal(int sig) { g_signal.store(sig); }

// Starts `tgnav trial ...` with its output appended to `log`. The child dies with the sweep
// (SIGTERM on parent death), so a killed sweep leaves no trials running on.
pid_t spawnTrial(const fs::path& exe, const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> argv_s{exe.string()};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  {
    std::ofstream header(log, std::ios::app);
    const std::time_t now = std::time(nullptr);
    char when[32];
    std::strftime(when, sizeof when, "%Y-%m-%d %H:%M:%S", std::localtime(&now));
    header << "=== " << when << ":";
    for (const std::string& a : argv_s) header << ' ' << harness::shellWord(a);
    header << '\n';
  }
  const int fd = ::open(log.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) throw InputError("--out: cannot write " + log.string() + ": " + std::strerror(errno));
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid == 0) {  // only async-signal-safe calls until exec
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);
    dup2(fd, STDOUT_FILENO);
    dup2(fd, STDERR_FILENO);
    const int devnull = ::open("/dev/null", O_RDONLY);
    if (devnull >= 0) dup2(devnull, STDIN_FILENO);
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    execv(argv[0], argv.data());
    _exit(127);
  }
  ::close(fd);
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  return pid;
}

// The last non-empty line of a trial's log (its error, when it failed).
std::string lastLine(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  return last;
}

int defaultJobs() {
  const unsigned n = std::thread::hardware_concurrency();
  return n == 0 ? 1 : static_cast<int>(n);
}

// A running trial: which, and since when.
struct Running {
  std::size_t trial;
  std::chrono::steady_clock::time_point since;
};

// The ETA: the mean wall time of this run's finished trials for each queued trial, less what the
// running ones have already spent, shared among the jobs.
std::string eta(const std::map<pid_t, Running>& running, std::size_t queued, double finished_s, int finished,
                int jobs) {
  if (finished == 0) return "--";
  const double mean = finished_s / finished;
  double left = mean * static_cast<double>(queued);
  const auto now = std::chrono::steady_clock::now();
  for (const auto& [pid, r] : running) {
    left += std::max(0.0, mean - std::chrono::duration<double>(now - r.since).count());
  }
  return duration(left / std::max(1, jobs));
}

void printProgress(int done, int total, std::size_t running, double elapsed_s, const std::string& eta) {
  const int width = 30;
  const int filled = total > 0 ? width * done / total : width;
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(width, '.');
  std::fprintf(stderr, "\r\033[Ktgnav sweep: [%s] %d/%d done, %zu running, %s elapsed, ETA %s", bar.c_str(), done,
               total, running, duration(elapsed_s).c_str(), eta.c_str());
}

int runLocal(const SweepCliOptions& opt, const SweepDir& dir, const std::vector<SweepTrial>& trials,
             std::vector<TrialFolder> folders) {
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < trials.size(); ++i) {
    if (folders[i].state != TrialState::kDone) todo.push_back(i);
  }
  const int total = static_cast<int>(trials.size());
  int done = total - static_cast<int>(todo.size());
  if (todo.empty()) {
    std::printf("tgnav sweep: all %d trials are done (%s) -> %s/index.csv\n", total, statusList(count(folders)).c_str(),
                dir.path().c_str());
    return 0;
  }
  std::vector<SweepTrial> pending;
  for (std::size_t i : todo) pending.push_back(trials[i]);
  prebuildMaps(pending, opt.map_cache);

  const int jobs = opt.jobs > 0 ? opt.jobs : defaultJobs();
  const bool tty = isatty(fileno(stderr)) != 0;
  if (done > 0) std::fprintf(stderr, "tgnav sweep: resuming: %d of %d trials already done\n", done, total);
  std::fprintf(stderr, "tgnav sweep: %zu trials to run, %d at a time -> %s\n", todo.size(), jobs, dir.path().c_str());
  const fs::path exe = selfExe();
  g_signal.store(0);
  struct sigaction sa {};
  sa.sa_handler = onSweepSignal;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);

  std::map<pid_t, Running> running;
  double finished_s = 0.0;  // wall time of this run's finished trials
  std::vector<std::string> failures;
  std::size_t next = 0;
  int done_now = 0;
  const auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  bool forwarded = false;
  while (true) {
    const int sig = g_signal.load();
    if (sig == 0) {
      while (next < todo.size() && static_cast<int>(running.size()) < jobs) {
        const SweepTrial& t = trials[todo[next]];
        const pid_t pid = spawnTrial(exe, childArguments(dir, t, opt.map_cache), dir.logFile(t));
        running.emplace(pid, Running{todo[next], std::chrono::steady_clock::now()});
        ++next;
      }
    } else if (!forwarded) {
      // Ctrl-C reached the trials too (one process group); a SIGTERM for the sweep is passed on.
      if (sig == SIGTERM) {
        for (const auto& [pid, r] : running) kill(pid, SIGTERM);
      }
      forwarded = true;
    }
    if (running.empty()) break;
    if (tty)
      printProgress(done, total, running.size(), elapsed(),
                    eta(running, todo.size() - next, finished_s, done_now, jobs));
    int wstatus = 0;
    const pid_t pid = waitpid(-1, &wstatus, WNOHANG);
    if (pid <= 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      continue;
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    const std::size_t i = it->second.trial;
    const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - it->second.since).count();
    running.erase(it);
    const SweepTrial& t = trials[i];
    folders[i] = harness::inspectTrialFolder(t, dir.trialDir(t));
    const int rc = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : 128 + WTERMSIG(wstatus);
    if (folders[i].state == TrialState::kDone) {
      ++done;
      ++done_now;
      finished_s += took;
      dir.writeIndex(trials);
      const nlohmann::json& m = folders[i].metrics;
      std::string goal =
          m["goal_error_m"].is_null() ? "n/a" : std::to_string(m["goal_error_m"].get<double>()).substr(0, 5) + " m";
      if (tty) std::fprintf(stderr, "\r\033[K");
      std::fprintf(stderr, "tgnav sweep: [%d/%d] %s: %s, goal error %s, %.1f s\n", done, total, t.id.c_str(),
                   m["status"].get<std::string>().c_str(), goal.c_str(), m["wall_time_s"].get<double>());
    } else if (g_signal.load() == 0) {
      failures.push_back(t.id + " (exit " + std::to_string(rc) + "): " + lastLine(dir.logFile(t)));
      if (tty) std::fprintf(stderr, "\r\033[K");
      std::fprintf(stderr, "tgnav sweep: trial %s failed (exit %d); see %s\n", t.id.c_str(), rc,
                   dir.logFile(t).c_str());
    }
  }
  if (tty) std::fprintf(stderr, "\r\033[K");
  folders = dir.writeIndex(trials);
  const Counts c = count(folders);
  const double wall = elapsed();
  std::printf(
      "tgnav sweep: %d of %d trials done (%s); this run: %d trials in %s (%.2f trials/min, %d at a time) -> "
      "%s/index.csv\n",
      c.done, total, statusList(c).c_str(), done_now, duration(wall).c_str(), wall > 0 ? 60.0 * done_now / wall : 0.0,
      jobs, dir.path().c_str());
  if (g_signal.load() != 0) {
    std::fprintf(stderr, "tgnav sweep: interrupted; run the same command again to resume (%d trials left)\n",
                 total - c.done);
    return 130;
  }
  if (!failures.empty()) {
    std::fprintf(stderr, "tgnav sweep: %zu trials failed to run; fix the cause and run the same command again:\n",
                 failures.size());
    for (const std::string& f : failures) std::fprintf(stderr, "  %s\n", f.c_str());
    return 1;
  }
  return 0;
}

// ---- Slurm -------------------------------------------------------------------------------------

// The job name of the sweep's arrays: unique to its folder, so squeue finds them by name.
std::string jobName(const SweepDir& dir) {
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a
  for (unsigned char c : dir.path().string()) h = (h ^ c) * 1099511628211ULL;
  char buf[32];
  std::snprintf(buf, sizeof buf, "tgnav-sweep-%08llx", static_cast<unsigned long long>(h & 0xffffffffULL));
  return buf;
}

// Tasks of the sweep's job arrays still queued or running, as "JOBID_TASK STATE" lines.
std::vector<std::string> slurmActive(const SweepDir& dir) {
  const harness::CommandResult q = harness::runCommand("squeue -h -r --name=" + jobName(dir) + " -o '%i %T'");
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

// Refuses to touch a sweep whose Slurm tasks are still queued or running (they write into it
// without the sweep's lock): checked before anything in DIR is tidied, whatever the backend.
void refuseWhileSlurmRuns(const SweepDir& dir) {
  if (!fs::exists(dir.path() / "slurm" / "jobs.txt")) return;
  const std::vector<std::string> active = slurmActive(dir);
  if (!active.empty()) {
    throw InputError("--out: " + dir.path().string() + ": " + std::to_string(active.size()) +
                     " tasks of this sweep are still queued or running in Slurm (job " +
                     active.front().substr(0, active.front().find('_')) +
                     "); wait for them (tgnav sweep --status --out DIR) or cancel them (scancel --name=" +
                     jobName(dir) + ") before running it again");
  }
}

int runSlurm(const SweepCliOptions& opt, const SweepDir& dir, const std::vector<SweepTrial>& trials,
             const std::vector<TrialFolder>& folders) {
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < trials.size(); ++i) {
    if (folders[i].state != TrialState::kDone) todo.push_back(i);
  }
  if (todo.empty()) {
    std::printf("tgnav sweep: all %zu trials are done (%s) -> %s/index.csv\n", trials.size(),
                statusList(count(folders)).c_str(), dir.path().c_str());
    return 0;
  }
  std::vector<SweepTrial> pending;
  for (std::size_t i : todo) pending.push_back(trials[i]);
  prebuildMaps(pending, opt.map_cache);

  // The job script: task k runs the k-th pending trial, then refreshes the index.
  const fs::path exe = selfExe();
  const fs::path slurm = dir.path() / "slurm";
  harness::makeOutputDir(slurm);
  int n = 1;
  while (fs::exists(slurm / ("array-" + std::to_string(n) + ".sh"))) ++n;
  const fs::path script = slurm / ("array-" + std::to_string(n) + ".sh");
  std::ostringstream s;
  s << "#!/bin/bash\n"
    << "# tgnav sweep " << dir.path().string() << ": " << pending.size() << " trials, one per array task\n"
    << "#SBATCH --job-name=" << jobName(dir) << "\n"
    << "#SBATCH --cpus-per-task=1\n"
    << "#SBATCH --output=" << (dir.path() / "logs" / "slurm-%A_%a.out").string() << "\n"
    << "set -u\n"
    << "cd " << harness::shellWord(dir.path().string()) << " || exit 1\n"
    << "case \"$SLURM_ARRAY_TASK_ID\" in\n";
  for (std::size_t k = 0; k < pending.size(); ++k) {
    const SweepTrial& t = pending[k];
    std::vector<std::string> args = harness::trialArguments(t, fs::path("trials") / t.id);
    args.insert(args.end(), {"--threads", "1", "--force"});
    if (!opt.map_cache.empty()) args.insert(args.end(), {"--map-cache", fs::absolute(opt.map_cache).string()});
    s << "  " << k << ") id=" << t.id << "; args=(";
    for (std::size_t a = 0; a < args.size(); ++a) s << (a ? " " : "") << harness::shellWord(args[a]);
    s << ") ;;\n";
  }
  s << "  *) echo \"no trial for array task $SLURM_ARRAY_TASK_ID\" >&2; exit 2 ;;\n"
    << "esac\n"
    << "echo \"=== $(date '+%Y-%m-%d %H:%M:%S'): Slurm job ${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID} on "
       "$(hostname)\" >> \"logs/$id.log\"\n"
    << harness::shellWord(exe.string()) << " \"${args[@]}\" >> \"logs/$id.log\" 2>&1\n"
    << "rc=$?\n"
    << harness::shellWord(exe.string()) << " sweep --status --out . > /dev/null 2>&1\n"
    << "exit $rc\n";
  harness::writeFileAtomic(script, s.str());
  fs::permissions(script, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add);

  const int jobs = opt.jobs > 0 ? opt.jobs : static_cast<int>(pending.size());
  std::string cmd = "sbatch --parsable --array=0-" + std::to_string(pending.size() - 1) + "%" + std::to_string(jobs);
  if (opt.wait) cmd += " --wait";
  for (const std::string& a : opt.sbatch_args) cmd += " " + harness::shellWord(a);
  cmd += " " + harness::shellWord(script.string());
  std::fprintf(stderr, "tgnav sweep: submitting %zu trials (at most %d at once): %s\n", pending.size(), jobs,
               cmd.c_str());
  const harness::CommandResult r = harness::runCommand(cmd);
  // sbatch --parsable prints "JOBID" or "JOBID;CLUSTER" first; with --wait it returns the
  // array's exit code once every task has ended.
  const std::string first = r.output.substr(0, r.output.find('\n'));
  const std::string job = first.substr(0, first.find(';'));
  const bool submitted = !job.empty() && std::all_of(job.begin(), job.end(), ::isdigit);
  if (!submitted) {
    fs::remove(script);
    throw InputError("sbatch failed (exit " + std::to_string(r.rc) + "): " + oneLine(r.output) +
                     "; nothing was submitted, the sweep is unchanged (run the same command to try again)");
  }
  {
    std::ofstream jobs_file(slurm / "jobs.txt", std::ios::app);
    jobs_file << job << ' ' << script.filename().string() << ' ' << pending.size() << '\n';
  }
  if (!opt.wait) {
    std::printf(
        "tgnav sweep: submitted Slurm job array %s (%zu trials, at most %d at once); follow it with: tgnav "
        "sweep --status --out %s\n",
        job.c_str(), pending.size(), jobs, dir.path().c_str());
    return 0;
  }
  const std::vector<TrialFolder> after = dir.writeIndex(trials);
  const Counts c = count(after);
  std::printf("tgnav sweep: Slurm job array %s ended; %d of %zu trials done (%s) -> %s/index.csv\n", job.c_str(),
              c.done, trials.size(), statusList(c).c_str(), dir.path().c_str());
  return c.done == static_cast<int>(trials.size()) ? 0 : 1;
}

int runStatus(const SweepDir& dir) {
  const std::vector<SweepTrial> trials = dir.manifest();
  const std::vector<TrialFolder> folders = dir.writeIndex(trials);
  const Counts c = count(folders);
  std::printf("tgnav sweep: %s: %d of %zu trials done (%s)", dir.path().c_str(), c.done, trials.size(),
              statusList(c).c_str());
  if (const std::size_t writing = dir.staging()) std::printf(", %zu running", writing);
  if (c.incomplete > 0) std::printf(", %d interrupted", c.incomplete);
  if (c.corrupt > 0) std::printf(", %d corrupted (moved aside on resume)", c.corrupt);
  std::printf(", %d not started\n", c.absent);
  if (fs::exists(dir.path() / "slurm" / "jobs.txt")) {
    std::vector<std::string> active;
    try {
      active = slurmActive(dir);
    } catch (const InputError& e) {
      std::printf("  slurm: %s\n", e.what());
    }
    std::map<std::string, int> states;
    for (const std::string& line : active) ++states[line.substr(line.find(' ') + 1)];
    std::string list;
    for (const auto& [state, n] : states) list += (list.empty() ? "" : ", ") + std::to_string(n) + " " + state;
    std::printf("  slurm: %s\n", active.empty() ? "no tasks queued or running" : list.c_str());
  }
  std::printf("  index: %s/index.csv\n", dir.path().c_str());
  return 0;
}

int runSweepCommand(const SweepCliOptions& opt) {
  if (opt.out.empty()) throw InputError("--out: required");
  const SweepDir dir(opt.out);
  if (opt.status) {
    if (!opt.sweep.empty()) throw InputError("--status: takes only --out DIR (the sweep is the one in DIR)");
    return runStatus(dir);
  }
  if (opt.sweep.empty()) throw InputError("--sweep: required (or --status)");
  if (opt.backend != "local" && opt.backend != "slurm") {
    throw InputError("--backend: '" + opt.backend + "' is not local or slurm");
  }
  if (opt.jobs < 0) throw InputError("--jobs: " + std::to_string(opt.jobs) + " must be >= 1");
  if (opt.backend == "local" && (opt.wait || !opt.sbatch_args.empty())) {
    throw InputError(std::string(opt.wait ? "--wait" : "--sbatch-arg") + ": only for --backend slurm");
  }
  const harness::Sweep sweep = harness::loadSweep(opt.sweep);
  if (fs::exists(dir.path()) && !fs::is_directory(dir.path())) {
    throw InputError("--out: " + dir.path().string() + " exists and is not a directory");
  }
  if (fs::exists(dir.path()) && !fs::is_empty(dir.path()) && !fs::exists(dir.path() / "commands.txt")) {
    throw InputError("--out: " + dir.path().string() + " holds files but no sweep; use a new or empty folder");
  }
  harness::makeOutputDir(dir.path());
  const FolderLock lock(dir.path() / ".lock", /*inherit=*/true, 120.0,
                        "tgnav sweep: " + dir.path().string() +
                            " is locked (another sweep, or the trials of a killed one still stopping); waiting...");
  prepareFolder(dir, sweep);
  refuseWhileSlurmRuns(dir);
  std::vector<TrialFolder> folders = dir.inspect(sweep.trials);
  tidy(dir, sweep.trials, folders);
  folders = dir.writeIndex(sweep.trials);
  return opt.backend == "local" ? runLocal(opt, dir, sweep.trials, folders) : runSlurm(opt, dir, sweep.trials, folders);
}

}  // namespace

void addSweepCommand(CLI::App& app) {
  auto opt = std::make_shared<SweepCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "sweep", "Run many trials (configs/sweeps/*.yaml) locally or on Slurm; resumable; DIR/index.csv");
  cmd->add_option("--sweep", opt->sweep, "Sweep YAML (configs/sweeps/*.yaml)");
  cmd->add_option("--out", opt->out, "Sweep folder (new, or the one to resume)")->required();
  cmd->add_option("--jobs", opt->jobs,
                  "Trials at once (local: default one per core; slurm: the array's limit, default all)");
  cmd->add_option("--backend", opt->backend, "local | slurm")->capture_default_str();
  cmd->add_flag("--status", opt->status, "Report the progress of the sweep in --out and refresh its index.csv");
  cmd->add_flag("--wait", opt->wait, "slurm: wait until the job array has ended (sbatch --wait)");
  cmd->add_option("--sbatch-arg", opt->sbatch_args,
                  "slurm: an extra sbatch argument, e.g. --sbatch-arg=--partition=cpu (repeatable)");
  cmd->add_option("--map-cache", opt->map_cache,
                  "Cache folder for feature maps (default: $TGNAV_CACHE_DIR or ~/.cache/tgnav)");
  cmd->callback([opt] {
    const int rc = runSweepCommand(*opt);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace tgnav::cli
