// tgnav trial: plan, generate the trajectory, fly it closed loop with the onboard camera and the
// VO, and score it. Results appear in --out whole: they are written into a hidden sibling folder
// and renamed into place; an interrupted trial (Ctrl-C, SIGTERM) leaves its partial results
// marked by an INCOMPLETE file and without metrics.json.
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <opencv2/core/utility.hpp>
#include <sstream>

#include "harness/cli.h"
#include "harness/errors.h"
#include "harness/map_cache.h"
#include "harness/output.h"
#include "harness/scenario.h"
#include "harness/trajectory_csv.h"
#include "harness/trial.h"
#include "harness/trial_plots.h"
#include "harness/yaml_util.h"
#include "vo/tum.h"

namespace tgnav::cli {

namespace {

std::atomic<bool> g_interrupted{false};

extern "C" void onInterrupt(int) {
  g_interrupted.store(true);
  // A second signal ends the process at once.
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}

struct TrialCliOptions {
  std::string scenario;
  std::string planner = "proposed";
  int samples = 0;
  long long seed = -1;  // -1: the scenario's
  std::string out;
  std::vector<std::string> set;
  bool force = false;
  int frames = 0;
  std::string map;
  std::string map_cache;
  int threads = 0;  // 0: as configured
};

// The output folder: refused when it holds anything unless --force; results are written into a
// hidden sibling and renamed into place at the end.
class OutputDir {
 public:
  OutputDir(const std::filesystem::path& out, bool force) : out_(std::filesystem::absolute(out).lexically_normal()) {
    if (!out_.has_filename()) out_ = out_.parent_path();  // "dir/" is "dir"
    std::error_code ec;
    if (std::filesystem::exists(out_, ec)) {
      if (!std::filesystem::is_directory(out_, ec)) {
        throw InputError("--out: " + out.string() + " exists and is not a directory");
      }
      if (!std::filesystem::is_empty(out_, ec) && !force) {
        const bool complete = std::filesystem::exists(out_ / "metrics.json", ec);
        throw InputError("--out: " + out.string() + " already holds " +
                         (complete ? "the results of a trial" : "files") + "; use --force to replace them");
      }
    }
    const std::filesystem::path parent = out_.parent_path();
    try {
      std::filesystem::create_directories(parent);
    } catch (const std::filesystem::filesystem_error& e) {
      throw InputError("--out: cannot create " + parent.string() + ": " + e.code().message());
    }
    tmp_ = parent / ("." + out_.filename().string() + ".tmp-" + std::to_string(getpid()));
    std::filesystem::remove_all(tmp_, ec);
    if (!std::filesystem::create_directory(tmp_, ec)) {
      throw InputError("--out: cannot write into " + parent.string() + ": " + ec.message());
    }
  }
  ~OutputDir() {
    std::error_code ec;
    if (!committed_) std::filesystem::remove_all(tmp_, ec);
  }
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

  const std::filesystem::path& staging() const { return tmp_; }
  const std::filesystem::path& path() const { return out_; }

  // Moves the staged results into place, replacing what --out held (only possible with --force).
  void commit() {
    std::error_code ec;
    std::filesystem::path old;
    if (std::filesystem::exists(out_, ec)) {
      old = out_.parent_path() / ("." + out_.filename().string() + ".old-" + std::to_string(getpid()));
      std::filesystem::remove_all(old, ec);
      std::filesystem::rename(out_, old);
    }
    std::filesystem::rename(tmp_, out_);
    committed_ = true;
    if (!old.empty()) std::filesystem::remove_all(old, ec);
  }

 private:
  std::filesystem::path out_;
  std::filesystem::path tmp_;
  bool committed_ = false;
};

// Caps the threads the trial uses (a sweep runs one trial per core): the planner's, OpenCV's and
// llvmpipe's rasteriser threads (unless LP_NUM_THREADS is set), and one thread renders and
// tracks in turn. The results do not depend on it.
void limitThreads(int threads, harness::Scenario* scenario) {
  scenario->planner.perception.threads = threads;
  if (threads == 1) scenario->trial.pipeline = false;
  cv::setNumThreads(threads);
  setenv("LP_NUM_THREADS", std::to_string(threads).c_str(), /*overwrite=*/0);
}

std::string voCsv(const harness::TrialResult& r) {
  std::ostringstream out;
  out.precision(6);
  out << std::fixed;
  out << "t,status,features,with_depth,matches,inliers,keyframe,x_true,y_true,z_true,x_est,y_est,z_est,reason\n";
  for (const harness::TrialFrame& f : r.frames) {
    const Eigen::Vector3d p = f.X_WC_true.translation();
    const Eigen::Vector3d e = f.vo.X_WC.translation();
    out << f.vo.t_s << ',' << vo::toString(f.vo.status) << ',' << f.vo.features << ',' << f.vo.with_depth << ','
        << f.vo.matches << ',' << f.vo.inliers << ',' << (f.vo.keyframe ? 1 : 0) << ',' << p.x() << ',' << p.y() << ','
        << p.z() << ',';
    if (f.tracked()) {
      out << e.x() << ',' << e.y() << ',' << e.z();
    } else {
      out << ",,";
    }
    std::string reason = f.vo.reason;
    for (char& c : reason) c = (c == ',' || c == '\n') ? ';' : c;
    out << ',' << reason << '\n';
  }
  return out.str();
}

harness::TrialPaths trialPaths(const harness::Scenario& scenario, const harness::TrialOptions& options,
                               const harness::TrialResult& r) {
  harness::TrialPaths paths;
  for (const planner::Pose4& p : r.plan.report.plan.path) paths.planned.push_back(p.p_WB.head<2>());
  if (r.setpoints) {
    for (const auto& sp : r.setpoints->setpoints()) paths.trajectory.push_back(sp.p_WB.head<2>());
  }
  for (const harness::FlightSample& f : r.flight.log) paths.flown.push_back(f.state.p_WB.head<2>());
  for (const harness::TrialFrame& f : r.frames) {
    if (f.tracked()) paths.estimated.push_back(f.vo.X_WC.translation().head<2>());
  }
  if (r.vo_lost) paths.vo_lost_at = r.vo_lost->p_WB.head<2>();
  if (r.collision) paths.collision_at = r.collision->p_WB.head<2>();
  paths.caption = scenario.scene.source.stem().string() + " " + harness::toString(options.planner) + " seed " +
                  std::to_string(options.seed) + ": " + harness::toString(r.status);
  return paths;
}

void writeResults(const OutputDir& dir, const harness::Scenario& scenario, const planner::FeatureMap& map,
                  const harness::TrialOptions& options, const harness::TrialResult& r,
                  const harness::TrialScores& scores, const harness::TrialTiming& timing) {
  const std::filesystem::path& d = dir.staging();
  std::ostringstream config;
  config << "# tgnav trial --planner " << harness::toString(options.planner);
  if (options.planner == harness::PlannerName::kRrtStar) config << " --samples " << r.plan.rrt_samples;
  config << " --seed " << options.seed << "\n" << harness::resolvedScenarioYaml(scenario);
  harness::writeFileAtomic(d / "config.yaml", config.str());
  harness::writeFileAtomic(d / "plan.json", harness::planJson(scenario, r.plan).dump(2) + "\n");
  if (r.setpoints) harness::writeFileAtomic(d / "trajectory.csv", harness::trajectoryCsv(*r.setpoints));
  harness::writeFileAtomic(d / "gt.tum", vo::toTum(harness::cameraPoses(r.flight, r.X_BC)));
  std::vector<vo::StampedPose> est;
  for (const harness::TrialFrame& f : r.frames) {
    if (f.tracked()) est.push_back(vo::StampedPose{f.vo.t_s, f.vo.X_WC});
  }
  harness::writeFileAtomic(d / "est.tum", vo::toTum(est));
  harness::writeFileAtomic(d / "vo.csv", voCsv(r));
  harness::writeImageAtomic(d / "topdown.png",
                            harness::drawTrialTopdown(scenario.scene, map, trialPaths(scenario, options, r)));
  harness::ErrorCurve curve{scores.error_distance_m, scores.error_m,
                            std::string(harness::toString(options.planner)) + " seed " + std::to_string(options.seed),
                            std::nullopt};
  if (r.vo_lost) curve.lost_at_distance_m = scores.distance_tracked_m;
  harness::writeImageAtomic(
      d / "ate.png", harness::drawErrorVsDistance({curve}, "VO position error (VO frame = true frame at take-off)"));
  if (!r.strip.empty()) harness::writeImageAtomic(d / "frames.png", harness::drawFrameStrip(r.strip, r.strip_captions));
  if (r.status == harness::TrialStatus::kInterrupted) {
    harness::writeFileAtomic(d / "INCOMPLETE", "interrupted: " + r.detail + "; these results are partial\n");
  } else {
    // Last: a folder with metrics.json is a finished trial.
    harness::writeFileAtomic(d / "metrics.json",
                             harness::trialMetricsJson(scenario, options, r, scores, timing).dump(2) + "\n");
  }
}

int runTrialCommand(const TrialCliOptions& opt) {
  const auto wall0 = std::chrono::steady_clock::now();
  harness::TrialOptions options;
  options.planner = harness::parsePlannerName(opt.planner, "--planner");
  if (opt.samples != 0 && options.planner != harness::PlannerName::kRrtStar) {
    throw InputError("--samples: only the rrtstar planner takes a sample budget");
  }
  if (opt.samples < 0) throw InputError("--samples: " + std::to_string(opt.samples) + " must be >= 1");
  if (opt.seed < -1) throw InputError("--seed: " + std::to_string(opt.seed) + " must be >= 0");
  if (opt.frames < 0 || opt.frames > 64) {
    throw InputError("--frames: " + std::to_string(opt.frames) + " must be between 0 and 64");
  }
  options.rrt_samples = opt.samples;
  options.strip_frames = opt.frames;
  const harness::YamlDoc overrides = harness::YamlDoc::fromOverrides(opt.set);
  harness::Scenario scenario = harness::loadScenario(opt.scenario, &overrides);
  if (opt.seed >= 0) scenario.seed = static_cast<std::uint64_t>(opt.seed);
  options.seed = scenario.seed;
  if (opt.threads < 0) throw InputError("--threads: " + std::to_string(opt.threads) + " must be >= 1");
  if (opt.threads > 0) limitThreads(opt.threads, &scenario);

  OutputDir dir(opt.out, opt.force);
  const planner::FeatureMap map = harness::loadSceneFeatureMap(scenario.scene, opt.map, opt.map_cache, "tgnav trial");

  g_interrupted.store(false);
  std::signal(SIGINT, onInterrupt);
  std::signal(SIGTERM, onInterrupt);
  const bool tty = isatty(fileno(stderr)) != 0;
  auto last_print = std::chrono::steady_clock::now() - std::chrono::seconds(1);
  harness::ProgressFn progress;
  if (tty) {
    progress = [&](const harness::TrialProgress& p) {
      const auto now = std::chrono::steady_clock::now();
      if (now - last_print < std::chrono::milliseconds(250)) return;
      last_print = now;
      std::fprintf(stderr, "\rtgnav trial: %3.0f%% of the path, sim %.1f/%.1f s, real-time factor %.1f   ",
                   100.0 * p.path_fraction, p.sim_s, p.sim_total_s, p.wall_s > 0 ? p.sim_s / p.wall_s : 0.0);
    };
  }
  const harness::TrialResult result = harness::runTrial(scenario, map, options, progress, &g_interrupted);
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  if (tty) std::fprintf(stderr, "\n");

  const harness::TrialScores scores = harness::scoreTrial(result);
  harness::TrialTiming timing;
  timing.plan_time_s = result.plan.plan_time_s();
  timing.trajectory_s = result.plan.trajectory_s;
  timing.flight_wall_s = result.flight_wall_s;
  timing.peak_rss_mb = harness::peakRssMb();
  timing.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  writeResults(dir, scenario, map, options, result, scores, timing);
  dir.commit();

  const std::string where = dir.path().string();
  if (result.status == harness::TrialStatus::kInterrupted) {
    std::fprintf(stderr, "tgnav trial: %s; partial results (marked INCOMPLETE) in %s\n", result.detail.c_str(),
                 where.c_str());
    return 130;
  }
  std::ostringstream line;
  line.precision(3);
  line << "tgnav trial: " << scenario.scene.source.stem().string() << ' ' << harness::toString(options.planner)
       << " seed " << options.seed << ": " << harness::toString(result.status) << " (" << result.detail << ")";
  if (result.status != harness::TrialStatus::kPlanFailed) {
    line << "; flown " << scores.path_length_m << " m, goal error "
         << (scores.goal_error_m ? std::to_string(*scores.goal_error_m).substr(0, 5) + " m" : std::string("n/a"))
         << ", ATE " << scores.ate_rmse_m << " m over " << scores.vo_frames << " frames, plan " << timing.plan_time_s
         << " s, real-time factor " << (result.flight_wall_s > 0 ? result.sim_time_s / result.flight_wall_s : 0.0);
  }
  line << " -> " << where << "/";
  std::printf("%s\n", line.str().c_str());
  return 0;
}

}  // namespace

void addTrialCommand(CLI::App& app) {
  auto opt = std::make_shared<TrialCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "trial", "Plan, fly closed loop with the onboard camera and VO, and score: metrics.json, gt/est.tum, plots");
  cmd->add_option("--scenario", opt->scenario, "Scenario YAML (configs/scenarios/*.yaml)")->required();
  cmd->add_option("--planner", opt->planner, "proposed | agnostic | rrtstar")->capture_default_str();
  cmd->add_option("--samples", opt->samples, "rrtstar: iteration budget N (default: planner config)");
  cmd->add_option("--seed", opt->seed, "Seed of the planner, camera noise and IMU (default: the scenario's)");
  cmd->add_option("--out", opt->out, "Results folder (new or empty; see --force)")->required();
  cmd->add_option("--set", opt->set,
                  "Override a setting of the resolved config, e.g. --set trial.state_source=vo "
                  "--set camera.width_px=320 (repeatable; keys as in DIR/config.yaml)");
  cmd->add_option("--threads", opt->threads,
                  "Use at most N threads (planner, OpenCV, renderer; 1 also renders and tracks in turn); "
                  "results do not change. Default: as configured");
  cmd->add_flag("--force", opt->force, "Replace the results already in --out");
  cmd->add_option("--frames", opt->frames, "Also write frames.png: a strip of N onboard frames (0-64)");
  cmd->add_option("--map", opt->map, "Feature map folder from `tgnav map` (default: cached by content)");
  cmd->add_option("--map-cache", opt->map_cache,
                  "Cache folder for feature maps (default: $TGNAV_CACHE_DIR or ~/.cache/tgnav)");
  cmd->callback([opt] {
    const int rc = runTrialCommand(*opt);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace tgnav::cli
