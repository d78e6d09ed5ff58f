#include "harness/experiments/sweep_local.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <map>
#include <stdexcept>
#include <thread>

#include "harness/base/clock.h"
#include "harness/base/errors.h"
#include "harness/base/shell.h"

namespace tgnav::harness {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::string formatDuration(double s) {
  char buf[32];
  // floor(s + 0.5), not lround(s): the same value as the old (long)(s + 0.5) for every s >= -0.5.
  const long t = static_cast<long>(std::floor(s + 0.5));
  if (t >= 3600) {
    std::snprintf(buf, sizeof buf, "%ldh%02ldm", t / 3600, (t / 60) % 60);
  } else if (t >= 60) {
    std::snprintf(buf, sizeof buf, "%ldm%02lds", t / 60, t % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%lds", t);
  }
  return buf;
}

namespace {

std::atomic<int> g_signal{0};
extern "C" void onSweepSignal(int sig) { g_signal.store(sig); }

// SIGINT and SIGTERM stop the sweep: g_signal says which came.
void catchStopSignals() {
  g_signal.store(0);
  struct sigaction sa {};
  sa.sa_handler = onSweepSignal;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

int defaultJobs() {
  const unsigned n = std::thread::hardware_concurrency();
  return n == 0 ? 1 : static_cast<int>(n);
}

std::vector<std::string> childArguments(const SweepRun& run, const SweepTrial& t) {
  const fs::path folder = run.dir->trialDir(t);
  std::vector<std::string> args = trialArguments(t, folder);
  // One thread per trial; the report draws the figures of all of them.
  args.insert(args.end(), {"--threads", "1", "--no-figures"});
  if (!run.map_cache.empty()) args.insert(args.end(), {"--map-cache", fs::absolute(run.map_cache).string()});
  if (fs::exists(folder)) args.push_back("--force");  // an interrupted trial's partial results
  return args;
}

// "=== <when>: <command line>", before each run's output in a trial's log.
void appendLogHeader(const fs::path& log, const std::vector<std::string>& argv) {
  std::ofstream header(log, std::ios::app);
  const std::time_t now = std::time(nullptr);
  char when[32];
  std::strftime(when, sizeof when, "%Y-%m-%d %H:%M:%S", std::localtime(&now));
  header << "=== " << when << ":";
  for (const std::string& a : argv) header << ' ' << shellWord(a);
  header << '\n';
}

// Starts `tgnav trial ...` with its output appended to `log`. The child dies with the sweep
// (SIGTERM on parent death), so a killed sweep leaves no trials running on.
pid_t spawnTrial(const fs::path& exe, const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> argv_s{exe.string()};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  argv.reserve(argv_s.size() + 1);
  for (std::string& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  appendLogHeader(log, argv_s);
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

// "[##########....] 3/8 done, 2 running, 1m05s elapsed, ETA 2m10s" over the line before.
void printProgress(int done, int total, std::size_t running, double elapsed_s, const std::string& eta) {
  const int width = 30;
  const int filled = total > 0 ? width * done / total : width;
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(width, '.');
  std::fprintf(stderr, "\r\033[Ktgnav sweep: [%s] %d/%d done, %zu running, %s elapsed, ETA %s", bar.c_str(), done,
               total, running, formatDuration(elapsed_s).c_str(), eta.c_str());
}

// The trials of one local run: started `jobs` at a time, waited for, reported.
class LocalPool {
 public:
  LocalPool(const SweepRun& run, int jobs)
      : run_(run),
        dir_(*run.dir),
        jobs_(jobs),
        total_(static_cast<int>(run.trials.size())),
        tty_(isatty(fileno(stderr)) != 0),
        done_(total_ - static_cast<int>(run.todo.size())) {}

  int run() {
    if (done_ > 0) std::fprintf(stderr, "tgnav sweep: resuming: %d of %d trials already done\n", done_, total_);
    std::fprintf(stderr, "tgnav sweep: %zu trials to run, %d at a time -> %s\n", run_.todo.size(), jobs_,
                 dir_.path().c_str());
    catchStopSignals();
    t0_ = Clock::now();
    while (true) {
      const int sig = g_signal.load();
      if (sig == 0) {
        startTrials();
      } else {
        passOn(sig);
      }
      if (running_.empty()) break;
      if (tty_) printProgress(done_, total_, running_.size(), secondsSince(t0_), eta());
      waitForOne();
    }
    return summarise();
  }

 private:
  // A running trial: which, and since when.
  struct Running {
    std::size_t trial;
    Clock::time_point since;
  };

  void startTrials() {
    while (next_ < run_.todo.size() && static_cast<int>(running_.size()) < jobs_) {
      const SweepTrial& t = run_.trials[run_.todo[next_]];
      const pid_t pid = spawnTrial(run_.program, childArguments(run_, t), dir_.logFile(t));
      running_.emplace(pid, Running{run_.todo[next_], Clock::now()});
      ++next_;
    }
  }

  // Ctrl-C reached the trials too (one process group); a SIGTERM for the sweep is passed on.
  void passOn(int sig) {
    if (forwarded_) return;
    if (sig == SIGTERM) {
      for (const auto& [pid, r] : running_) kill(pid, SIGTERM);
    }
    forwarded_ = true;
  }

  // Takes in a trial that has ended, if any (else waits a moment).
  void waitForOne() {
    int wstatus = 0;
    const pid_t pid = waitpid(-1, &wstatus, WNOHANG);
    if (pid <= 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      return;
    }
    const auto it = running_.find(pid);
    if (it == running_.end()) return;
    const Running ended = it->second;
    const double took = secondsSince(ended.since);
    running_.erase(it);
    const SweepTrial& t = run_.trials[ended.trial];
    const TrialFolder folder = inspectTrialFolder(t, dir_.trialDir(t));
    if (folder.state == TrialState::kDone) {
      finished(t, folder.metrics, took);
    } else if (g_signal.load() == 0) {
      failed(t, WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : 128 + WTERMSIG(wstatus));
    }
  }

  void finished(const SweepTrial& t, const nlohmann::json& m, double took) {
    ++done_;
    ++done_now_;
    finished_s_ += took;
    dir_.writeIndex(run_.trials);
    const std::string goal =
        m["goal_error_m"].is_null() ? "n/a" : std::to_string(m["goal_error_m"].get<double>()).substr(0, 5) + " m";
    clearLine();
    std::fprintf(stderr, "tgnav sweep: [%d/%d] %s: %s, goal error %s, %.1f s\n", done_, total_, t.id.c_str(),
                 m["status"].get<std::string>().c_str(), goal.c_str(), m["wall_time_s"].get<double>());
  }

  void failed(const SweepTrial& t, int rc) {
    failures_.push_back(t.id + " (exit " + std::to_string(rc) + "): " + lastLine(dir_.logFile(t)));
    clearLine();
    std::fprintf(stderr, "tgnav sweep: trial %s failed (exit %d); see %s\n", t.id.c_str(), rc, dir_.logFile(t).c_str());
  }

  void clearLine() const {
    if (tty_) std::fprintf(stderr, "\r\033[K");
  }

  // The mean wall time of this run's finished trials for each queued trial, less what the
  // running ones have already spent, shared among the jobs.
  std::string eta() const {
    if (done_now_ == 0) return "--";
    const double mean = finished_s_ / done_now_;
    double left = mean * static_cast<double>(run_.todo.size() - next_);
    for (const auto& [pid, r] : running_) left += std::max(0.0, mean - secondsSince(r.since));
    return formatDuration(left / std::max(1, jobs_));
  }

  // The index rebuilt, the summary line; the exit code.
  int summarise() {
    clearLine();
    const TrialCounts c = countTrials(dir_.writeIndex(run_.trials));
    const double wall = secondsSince(t0_);
    std::printf(
        "tgnav sweep: %d of %d trials done (%s); this run: %d trials in %s (%.2f trials/min, %d at a time) -> "
        "%s/index.csv\n",
        c.done, total_, statusList(c).c_str(), done_now_, formatDuration(wall).c_str(),
        wall > 0 ? 60.0 * done_now_ / wall : 0.0, jobs_, dir_.path().c_str());
    if (g_signal.load() != 0) {
      std::fprintf(stderr, "tgnav sweep: interrupted; run the same command again to resume (%d trials left)\n",
                   total_ - c.done);
      return 130;
    }
    if (failures_.empty()) return 0;
    std::fprintf(stderr, "tgnav sweep: %zu trials failed to run; fix the cause and run the same command again:\n",
                 failures_.size());
    for (const std::string& f : failures_) std::fprintf(stderr, "  %s\n", f.c_str());
    return 1;
  }

  const SweepRun& run_;
  const SweepDir& dir_;
  const int jobs_;
  const int total_;
  const bool tty_;
  int done_;                 // trials done, before this run and in it
  int done_now_ = 0;         // trials done in this run
  double finished_s_ = 0.0;  // wall time of this run's finished trials
  std::size_t next_ = 0;     // run_.todo[next_]: the next trial to start
  bool forwarded_ = false;   // a stop signal was passed on
  std::map<pid_t, Running> running_;
  std::vector<std::string> failures_;
  Clock::time_point t0_;
};

}  // namespace

int runLocal(const SweepRun& run, int jobs) {
  LocalPool pool(run, jobs > 0 ? jobs : defaultJobs());
  return pool.run();
}

}  // namespace tgnav::harness
