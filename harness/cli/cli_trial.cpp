// tgnav trial: plan, generate the trajectory, fly it closed loop with the onboard camera and the
// VO, and score it (harness/run/trial_job.h). Ctrl-C or SIGTERM stops the flight and leaves the
// partial results marked INCOMPLETE; a second signal ends the process at once.
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <optional>

#include "harness/base/errors.h"
#include "harness/cli/cli.h"
#include "harness/run/plan_run.h"
#include "harness/run/trial_job.h"

namespace tgnav::cli {

namespace {

std::atomic<bool> g_interrupted{false};

extern "C" void onInterrupt(int) {
  g_interrupted.store(true);
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}

struct TrialCliOptions {
  harness::TrialJob job;
  std::string planner = "proposed";
  long long seed = -1;  // -1: the scenario's
  std::string figure_format = "png";
  bool no_figures = false;
  std::optional<int> homology_class;
};

// Percent of the path, sim time and real-time factor on a terminal, four times a second.
harness::ProgressFn terminalProgress() {
  if (isatty(fileno(stderr)) == 0) return {};
  auto last = std::make_shared<std::chrono::steady_clock::time_point>(std::chrono::steady_clock::now() -
                                                                      std::chrono::seconds(1));
  return [last](const harness::TrialProgress& p) {
    const auto now = std::chrono::steady_clock::now();
    if (now - *last < std::chrono::milliseconds(250)) return;
    *last = now;
    std::fprintf(stderr, "\rtgnav trial: %3.0f%% of the path, sim %.1f/%.1f s, real-time factor %.1f   ",
                 100.0 * p.path_fraction, p.sim_s, p.sim_total_s, p.wall_s > 0 ? p.sim_s / p.wall_s : 0.0);
  };
}

int runTrialCommand(TrialCliOptions& opt) {
  harness::TrialJob& job = opt.job;
  // --planner-command implies an external planner; "external" names the scenario's.
  job.external = opt.planner == "external" || !job.external_command.empty();
  if (job.external && opt.planner != "external" && opt.planner != "proposed") {
    throw InputError("--planner-command: runs an external planner; drop --planner " + opt.planner);
  }
  if (!job.external) job.planner = harness::parsePlannerName(opt.planner, "--planner");
  if (opt.seed < -1) throw InputError("--seed: " + std::to_string(opt.seed) + " must be >= 0");
  if (opt.seed >= 0) job.seed = static_cast<std::uint64_t>(opt.seed);
  job.figure_format = harness::parseFigureFormat(opt.figure_format);
  job.figures = !opt.no_figures;
  job.homology_class = opt.homology_class;
  const harness::ProgressFn progress = terminalProgress();
  job.trial_starting = [] {
    g_interrupted.store(false);
    std::signal(SIGINT, onInterrupt);
    std::signal(SIGTERM, onInterrupt);
  };
  job.trial_ended = [&progress] {
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    if (progress) std::fprintf(stderr, "\n");
  };
  const harness::TrialJobResult r = harness::runTrialJob(job, progress, &g_interrupted);
  if (r.status == harness::TrialStatus::kInterrupted) {
    std::fprintf(stderr, "tgnav trial: %s; partial results (marked INCOMPLETE) in %s\n", r.summary.c_str(),
                 r.out.string().c_str());
    return 130;
  }
  harness::reportFigures("tgnav trial", r.figures);
  std::printf("%s\n", r.summary.c_str());
  return 0;
}

// `--online`: trial.mode=online, and the state source the map pose flies on unless `set` names one.
void addOnline(std::vector<std::string>* set) {
  bool source_given = false;
  bool truth = false;
  for (const std::string& s : *set) {
    source_given = source_given || s.rfind("trial.state_source=", 0) == 0;
    truth = truth || s == "trial.map_pose=truth";
  }
  set->insert(set->begin(), "trial.mode=online");
  if (!source_given) set->push_back(truth ? "trial.state_source=gt" : "trial.state_source=vo");
}

}  // namespace

void addTrialCommand(CLI::App& app) {
  auto opt = std::make_shared<TrialCliOptions>();
  harness::TrialJob& job = opt->job;
  CLI::App* cmd = app.add_subcommand(
      "trial", "Plan, fly closed loop with the onboard camera and VO, and score: metrics.json, gt/est.tum, plots");
  cmd->add_option("--scenario", job.scenario, "Scenario YAML (configs/scenarios/*.yaml)")->required();
  cmd->add_option("--planner", opt->planner,
                  "proposed | agnostic | rrtstar | external (the scenario's planner.external; "
                  "docs/PLANNER_PROTOCOL.md)")
      ->capture_default_str();
  cmd->add_option("--planner-command", job.external_command,
                  "Fly the route of this external planner command (run with /bin/sh -c; JSON lines protocol, "
                  "docs/PLANNER_PROTOCOL.md)");
  cmd->add_option("--planner-name", job.external_name,
                  "The external planner's name in results (default: the scenario's, or \"external\")");
  cmd->add_option("--planner-dir", job.external_dir,
                  "The external planner command's working directory (default: the current one)");
  cmd->add_option("--samples", job.samples, "rrtstar: iteration budget N (default: planner config)");
  cmd->add_option("--seed", opt->seed, "Seed of the planner, camera noise and IMU (default: the scenario's)");
  cmd->add_option("--out", job.out, "Results folder (new or empty; see --force)")->required();
  cmd->add_option("--set", job.set,
                  "Override a setting of the resolved config, e.g. --set trial.state_source=vo "
                  "--set camera.width_px=320 (repeatable; keys as in DIR/config.yaml)");
  cmd->add_option("--threads", job.threads,
                  "Use at most N threads (planner, OpenCV, renderer; 1 also renders and tracks in turn); "
                  "results do not change. Default: as configured");
  auto online = std::make_shared<bool>(false);
  cmd->add_flag("--online", *online,
                "Plan online: start without a map, map the onboard frames at the VO's pose and replan "
                "(= --set trial.mode=online, and trial.state_source=vo, or gt with --set trial.map_pose=truth, "
                "unless a --set names it)");
  cmd->add_flag("--force", job.force, "Replace the results already in --out");
  cmd->add_option("--frames", job.frames, "Also write frames.png: a strip of N onboard frames (0-64)");
  cmd->add_option("--map", job.map, "Feature map folder from `tgnav map` (default: cached by content)");
  cmd->add_option("--map-cache", job.map_cache,
                  "Cache folder for feature maps (default: $TGNAV_CACHE_DIR or ~/.cache/tgnav)");
  auto homology_class = std::make_shared<int>(0);
  cmd->add_option("--trajectory", job.trajectory,
                  "Fly this setpoint CSV (t,x,y,z,yaw[,vx,vy,vz,ax,ay,az][,yaw_rate], as `tgnav fly`) instead of "
                  "planning; checked against the map first");
  cmd->add_option("--path", job.path,
                  "Smooth this 4-DoF path CSV (x,y,z,yaw) with the trajectory generator and fly it instead of "
                  "planning; checked against the map first");
  cmd->add_option("--class", *homology_class,
                  "The oracle: fly homology class K of plan.json's classes (proposed: its pose-graph path; "
                  "agnostic: its shortest path); not with rrtstar");
  cmd->add_option("--figure-format", opt->figure_format, "png | pdf | svg")->capture_default_str();
  cmd->add_flag("--no-figures", opt->no_figures, "Write the data only (a sweep's report draws the figures)");
  cmd->callback([opt, cmd, homology_class, online] {
    if (cmd->count("--class") > 0) opt->homology_class = *homology_class;
    if (*online) addOnline(&opt->job.set);
    for (const char* given : {"--trajectory", "--path"}) {
      if (cmd->count(given) > 0 && cmd->count("--planner") > 0) {
        throw InputError(std::string(given) + ": flies what it is given; --planner is for planning one");
      }
    }
    const int rc = runTrialCommand(*opt);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace tgnav::cli
