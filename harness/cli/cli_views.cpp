// tgnav views: a flown trial's per-frame view features computed again at its true camera poses,
// with other planner settings (harness/run/views_run.h).
#include <cstdio>
#include <memory>

#include "harness/cli/cli.h"
#include "harness/run/views_run.h"

namespace tgnav::cli {

void addViewsCommand(CLI::App& app) {
  auto job = std::make_shared<harness::ViewsJob>();
  CLI::App* cmd = app.add_subcommand(
      "views",
      "A flown trial's per-frame view features (vo.csv's predicted_* columns) again at its true camera poses, with "
      "other settings (--set)");
  cmd->add_option("--trial", job->trial, "A trial folder (config.yaml, gt.tum, vo.csv)")->required();
  cmd->add_option("--out", job->out, "The CSV to write: t, then the predicted_* columns, one row per vo.csv row")
      ->required();
  cmd->add_option("--set", job->set,
                  "Override a setting of the trial's config.yaml, e.g. --set planner.visibility.max_range_m=10 "
                  "(repeatable)");
  cmd->add_option("--map", job->map, "Feature map folder from `tgnav map` (default: cached by content)");
  cmd->add_option("--map-cache", job->map_cache,
                  "Cache folder for feature maps (default: $TGNAV_CACHE_DIR or ~/.cache/tgnav)");
  cmd->add_flag("--force", job->force, "Replace --out if it exists");
  cmd->callback([job] { std::printf("%s\n", harness::runViews(*job).summary.c_str()); });
}

}  // namespace tgnav::cli
