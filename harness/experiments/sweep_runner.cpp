#include "harness/experiments/sweep_runner.h"

#include <cstdio>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "harness/base/errors.h"
#include "harness/base/files.h"
#include "harness/config/scenario.h"
#include "harness/config/yaml_util.h"
#include "harness/experiments/sweep_local.h"
#include "harness/io/staged_output.h"
#include "harness/run/map_cache.h"

namespace tgnav::harness {

namespace fs = std::filesystem;

namespace {

// The options on their own, before anything is read or written.
void checkOptions(const SweepOptions& opt) {
  if (opt.out.empty()) throw InputError("--out: required");
  if (opt.sweep.empty()) throw InputError("--sweep: required (or --status)");
  if (opt.backend != "local" && opt.backend != "slurm") {
    throw InputError("--backend: '" + opt.backend + "' is not local or slurm");
  }
  if (opt.jobs < 0) throw InputError("--jobs: " + std::to_string(opt.jobs) + " must be >= 1");
  if (opt.backend == "local" && (opt.wait || !opt.sbatch_args.empty())) {
    throw InputError(std::string(opt.wait ? "--wait" : "--sbatch-arg") + ": only for --backend slurm");
  }
}

// True when DIR holds nothing but the generated scenes of a sweep that stopped at a bad sweep file.
bool onlyScenes(const fs::path& dir) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (e.path().filename() != "scenes") return false;
  }
  return !ec;
}

// DIR is new, empty, or a sweep folder (or holds only its generated scenes); InputError otherwise.
void checkSweepFolder(const SweepDir& dir) {
  if (fs::exists(dir.path()) && !fs::is_directory(dir.path())) {
    throw InputError("--out: " + dir.path().string() + " exists and is not a directory");
  }
  if (fs::exists(dir.path()) && !fs::exists(dir.path() / "commands.txt") && !onlyScenes(dir.path())) {
    throw InputError("--out: " + dir.path().string() + " holds files but no sweep; use a new or empty folder");
  }
}

fs::path selfExe() {
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot find the tgnav program (/proc/self/exe): " + ec.message());
  return exe;
}

// Builds each scene's feature map once, before the trials that share it start (only for scenes
// with a trial that needs it: an online trial from no map does not).
void prebuildMaps(const SweepRun& run) {
  std::map<std::string, Scenario> scenes;  // a trial's scenario of each scene that needs its map
  for (std::size_t i : run.todo) {
    const SweepTrial& trial = run.trials[i];
    if (scenes.count(trial.scene) != 0) continue;
    std::vector<std::string> set;  // the trial's own settings: one may name another scene
    set.reserve(trial.set.size());
    for (const auto& [key, value] : trial.set) set.push_back(key + "=" + value);
    const YamlDoc overrides = YamlDoc::fromOverrides(set);
    Scenario s = loadScenario(trial.scenario, &overrides);
    if (s.trial.online.needsSurvey()) scenes.emplace(trial.scene, std::move(s));
  }
  const fs::path cache = run.map_cache.empty() ? defaultCacheDir() : fs::path(run.map_cache);
  for (const auto& [scene, s] : scenes) {
    bool told = false;
    const std::string& name = scene;  // a structured binding cannot be captured (C++17)
    cachedFeatureMap(s.scene, MapBuildConfig{}, cache, [&](int, int) {
      if (!told) {
        std::fprintf(stderr, "tgnav sweep: building the feature map of %s (once; the trials share it)\n", name.c_str());
        told = true;
      }
    });
  }
}

constexpr const char* kSnapshotPrefix = "# tgnav sweep: the resolved scenario of ";
constexpr const char* kSnapshotSuffix = ", as the sweep first ran";

// Points every trial at a snapshot of its scenario in `folder` (DIR/scenarios/, absolute), so that
// editing configs/ under a running or stopped sweep changes none of its trials; returns the
// snapshots still to write (scenario, snapshot), which writeSnapshots() writes once the folder is
// known to hold this sweep. A folder made before snapshots (its commands.txt names no
// DIR/scenarios/) keeps its trials' scenarios as they are.
std::vector<std::pair<fs::path, fs::path>> snapshotScenarios(const SweepDir& dir, const fs::path& folder,
                                                             Sweep* sweep) {
  const fs::path commands = dir.path() / "commands.txt";
  if (fs::exists(commands) && readTextFile(commands).find(folder.string() + "/") == std::string::npos) return {};
  std::map<fs::path, fs::path> held;  // scenario -> its snapshot, from the snapshots' first lines
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(folder, ec)) {
    const std::string text = readTextFile(e.path());
    const std::string first = text.substr(0, text.find('\n'));
    const std::size_t prefix = std::string(kSnapshotPrefix).size();
    const std::size_t end = first.rfind(kSnapshotSuffix);
    if (first.rfind(kSnapshotPrefix, 0) == 0 && end != std::string::npos && end > prefix) {
      held[fs::path(first.substr(prefix, end - prefix))] = e.path();
    }
  }
  std::vector<std::pair<fs::path, fs::path>> to_write;
  std::set<fs::path> taken;
  for (const auto& [scenario, snapshot] : held) taken.insert(snapshot);
  for (SweepTrial& t : sweep->trials) {
    auto it = held.find(t.scenario);
    if (it == held.end()) {
      const std::string stem = t.scenario.stem().string();
      fs::path to = folder / (stem + ".yaml");
      for (int n = 2; taken.count(to) != 0 || fs::exists(to); ++n) {
        to = folder / (stem + "-" + std::to_string(n) + ".yaml");
      }
      taken.insert(to);
      to_write.emplace_back(t.scenario, to);
      it = held.emplace(t.scenario, to).first;
    }
    t.scenario = it->second;
  }
  return to_write;
}

// Each scenario resolved (every setting in force, resolvedScenarioYaml), under a first line that
// names it.
void writeSnapshots(const fs::path& folder, const std::vector<std::pair<fs::path, fs::path>>& snapshots) {
  if (snapshots.empty()) return;
  makeOutputDir(folder);
  for (const auto& [scenario, to] : snapshots) {
    writeFileAtomic(to, std::string(kSnapshotPrefix) + scenario.string() + kSnapshotSuffix + "\n" +
                            resolvedScenarioYaml(loadScenario(scenario)));
  }
}

// The sweep's trials, their states after tidying, and which of them are not done.
SweepRun planRun(const SweepDir& dir, const Sweep& sweep) {
  SweepRun run;
  run.dir = &dir;
  run.trials = sweep.trials;
  dir.tidy(run.trials, dir.inspect(run.trials));
  run.folders = dir.writeIndex(run.trials);
  for (std::size_t i = 0; i < run.trials.size(); ++i) {
    if (run.folders[i].state != TrialState::kDone) run.todo.push_back(i);
  }
  return run;
}

}  // namespace

int runSweep(const SweepOptions& opt) {
  checkOptions(opt);
  const SweepDir dir(opt.out);
  checkSweepFolder(dir);
  // Generated scenes are written here (complete, each on its own) while the sweep file is checked.
  Sweep sweep = loadSweep(opt.sweep, fs::absolute(dir.path()) / "scenes");
  makeOutputDir(dir.path());
  const FolderLock lock(dir.path() / ".lock", /*inherit=*/true, 120.0,
                        "tgnav sweep: " + dir.path().string() +
                            " is locked (another sweep, or the trials of a killed one still stopping); waiting...");
  const fs::path snapshot_dir = fs::absolute(dir.path()).lexically_normal() / "scenarios";
  const std::vector<std::pair<fs::path, fs::path>> snapshots = snapshotScenarios(dir, snapshot_dir, &sweep);
  dir.prepare(sweep);
  writeSnapshots(snapshot_dir, snapshots);
  refuseWhileSlurmRuns(dir);
  SweepRun run = planRun(dir, sweep);
  if (run.todo.empty()) {
    std::printf("tgnav sweep: all %zu trials are done (%s) -> %s/index.csv\n", run.trials.size(),
                statusList(countTrials(run.folders)).c_str(), dir.path().c_str());
    return 0;
  }
  run.map_cache = opt.map_cache;
  prebuildMaps(run);
  run.program = opt.program.empty() ? selfExe() : fs::absolute(opt.program);
  if (opt.backend == "local") return runLocal(run, opt.jobs);
  return runSlurm(run, SlurmOptions{opt.jobs, opt.wait, opt.sbatch_args});
}

SweepStatus sweepStatus(const fs::path& path) {
  if (path.empty()) throw InputError("--out: required");
  const SweepDir dir(path);
  const std::vector<SweepTrial> trials = dir.manifest();
  SweepStatus status;
  status.dir = dir.path();
  status.trials = trials.size();
  status.counts = countTrials(dir.writeIndex(trials));
  status.running = dir.staging();
  status.slurm = slurmStatus(dir);
  return status;
}

}  // namespace tgnav::harness
