// tgnav plan: on a scene's feature map (--scenario: proposed, agnostic or rrtstar), or
// topological planning on a 2D occupancy grid (--grid: ROS map_server or MovingAI)
// (harness/run/plan_job.h).
#include <cstdio>
#include <optional>

#include "harness/base/errors.h"
#include "harness/cli/cli.h"
#include "harness/run/plan_job.h"
#include "harness/run/plan_run.h"

namespace tgnav::cli {

namespace {

struct PlanOptions {
  std::string grid;
  std::string scen;
  std::optional<int> bucket;
  std::string scenario;
  std::string start;
  std::string goal;
  std::string planner;
  long long seed = -1;  // -1: the scenario's
  int samples = 0;      // 0: planner.yaml's rrt_star.samples
  std::string map;
  std::string map_cache;
  std::string out;
  double resolution_m = 1.0;
  double robot_radius_m = 0.3;
  int max_classes = 10;
  std::string figure_format = "png";
  std::optional<int> homology_class;
  std::vector<std::string> set;
};

harness::PlanJobResult planGrid(const PlanOptions& opt) {
  if (opt.homology_class) throw InputError("--class: only with --scenario (the oracle of a scene's planners)");
  if (!opt.set.empty()) throw InputError("--set: only with --scenario (overrides of its resolved config)");
  if (!opt.planner.empty() && opt.planner != "agnostic") {
    throw InputError("--planner: '" + opt.planner + "' needs a scene's feature map; with --grid only 'agnostic' runs");
  }
  if (!opt.scen.empty()) {
    if (!opt.start.empty() || !opt.goal.empty()) throw InputError("--start/--goal: with --scen, the rows give them");
    if (opt.bucket && *opt.bucket < 0) throw InputError("--bucket: " + std::to_string(*opt.bucket) + " must be >= 0");
    return harness::runGridScen(
        {opt.grid, opt.scen, opt.bucket, opt.resolution_m, opt.robot_radius_m, opt.max_classes, opt.out});
  }
  if (opt.bucket) throw InputError("--bucket: only with --scen");
  if (opt.start.empty() || opt.goal.empty()) throw InputError("--grid needs --start X,Y and --goal X,Y (or --scen)");
  return harness::runGridPlan({opt.grid, opt.start, opt.goal, opt.resolution_m, opt.robot_radius_m, opt.max_classes,
                               opt.out, harness::parseFigureFormat(opt.figure_format)});
}

harness::PlanJobResult planScenario(const PlanOptions& opt) {
  if (!opt.start.empty() || !opt.goal.empty()) {
    throw InputError("--start/--goal: with --scenario, start and goal come from the scenario or its scene");
  }
  harness::ScenarioPlanJob job;
  job.scenario = opt.scenario;
  job.planner = harness::parsePlannerName(opt.planner.empty() ? "proposed" : opt.planner, "--planner");
  if (opt.samples != 0 && job.planner != planner::PlannerKind::kRrtStar) {
    throw InputError("--samples: only the rrtstar planner takes a sample budget");
  }
  if (opt.samples < 0) throw InputError("--samples: " + std::to_string(opt.samples) + " must be >= 1");
  if (opt.seed < -1) throw InputError("--seed: " + std::to_string(opt.seed) + " must be >= 0");
  job.samples = opt.samples;
  if (opt.seed >= 0) job.seed = static_cast<std::uint64_t>(opt.seed);
  job.map = opt.map;
  job.map_cache = opt.map_cache;
  job.out = opt.out;
  job.figure_format = harness::parseFigureFormat(opt.figure_format);
  job.homology_class = opt.homology_class;
  job.set = opt.set;
  return harness::runScenarioPlan(job);
}

}  // namespace

void addPlanCommand(CLI::App& app) {
  auto opt = std::make_shared<PlanOptions>();
  CLI::App* cmd = app.add_subcommand(
      "plan",
      "Plan on a scene's feature map (--scenario) or on a 2D occupancy grid (--grid); writes plan.json and its figure");
  auto* scenario = cmd->add_option("--scenario", opt->scenario, "Scenario YAML (configs/scenarios/*.yaml)");
  auto* grid = cmd->add_option("--grid", opt->grid, "ROS map_server .yaml (+ .pgm) or MovingAI .map");
  scenario->excludes(grid);
  cmd->add_option("--planner", opt->planner,
                  "proposed | agnostic | rrtstar (default: proposed with --scenario, agnostic with --grid)");
  cmd->add_option("--samples", opt->samples, "rrtstar: iteration budget N (default: planner config)");
  cmd->add_option("--seed", opt->seed, "Random seed (default: the scenario's)");
  cmd->add_option("--map", opt->map, "Feature map folder from `tgnav map` (default: cached by content)");
  cmd->add_option("--map-cache", opt->map_cache,
                  "Cache folder for feature maps (default: $TGNAV_CACHE_DIR or ~/.cache/tgnav)");
  cmd->add_option("--scen", opt->scen, "--grid: a MovingAI .scen file: plan every row, write scen.csv and scen.json");
  auto bucket = std::make_shared<int>(0);
  cmd->add_option("--bucket", *bucket, "--scen: only the rows of this bucket");
  cmd->add_option("--start", opt->start, "--grid: start X,Y in metres (map frame, y up)");
  cmd->add_option("--goal", opt->goal, "--grid: goal X,Y in metres (map frame, y up)");
  cmd->add_option("--resolution", opt->resolution_m, "--grid: metres per cell of a MovingAI map")
      ->capture_default_str();
  cmd->add_option("--robot-radius", opt->robot_radius_m, "--grid: clearance kept from obstacles, metres")
      ->capture_default_str();
  cmd->add_option("--max-classes", opt->max_classes, "--grid: cap on the homology classes searched")
      ->capture_default_str();
  cmd->add_option("--out", opt->out, "Output directory")->required();
  cmd->add_option("--set", opt->set,
                  "--scenario: override a setting of the resolved config, e.g. --set planner.perception.c_p_min=-20 "
                  "(repeatable; keys as in a trial's config.yaml)");
  cmd->add_option("--figure-format", opt->figure_format, "png | pdf | svg")->capture_default_str();
  auto homology_class = std::make_shared<int>(0);
  cmd->add_option("--class", *homology_class, "The oracle: plan homology class K (proposed or agnostic)");
  cmd->callback([opt, cmd, homology_class, bucket] {
    if (cmd->count("--class") > 0) opt->homology_class = *homology_class;
    if (cmd->count("--bucket") > 0) opt->bucket = *bucket;
    if (!opt->scen.empty() && opt->grid.empty()) throw InputError("--scen: needs --grid MAP (its MovingAI map)");
    if (opt->scenario.empty() == opt->grid.empty()) throw InputError("plan: give one of --scenario FILE or --grid MAP");
    const harness::PlanJobResult r = opt->grid.empty() ? planScenario(*opt) : planGrid(*opt);
    harness::reportFigures("tgnav plan", r.figures);
    std::printf("%s\n", r.summary.c_str());
    if (!r.warning.empty() && !r.trajectory_failed) std::fprintf(stderr, "%s\n", r.warning.c_str());
    if (r.trajectory_failed) throw std::runtime_error(r.warning);
  });
}

}  // namespace tgnav::cli
