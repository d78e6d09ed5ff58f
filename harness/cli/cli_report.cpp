// tgnav report: a sweep folder aggregated into the paper's Table II and its figures
// (harness/experiments/report_run.h). When the figures fail the tables are still there and the
// command exits 1.
#include <cstdio>

#include "harness/cli/cli.h"
#include "harness/experiments/report_run.h"

namespace tgnav::cli {

void addReportCommand(CLI::App& app) {
  auto opt = std::make_shared<harness::ReportJob>();
  auto format = std::make_shared<std::string>("png");
  CLI::App* cmd = app.add_subcommand(
      "report", "Aggregate a sweep folder into the paper's Table II (CSV + Markdown) and figures 3 and 4");
  cmd->add_option("DIR", opt->dir, "Sweep folder (from `tgnav sweep`: index.csv, trials.csv, trials/)")->required();
  cmd->add_option("--out", opt->out, "Report folder (default: DIR/report)");
  cmd->add_option("--map-cache", opt->map_cache,
                  "Cache folder for the scenes' feature maps (default: $TGNAV_CACHE_DIR or ~/.cache/tgnav)");
  cmd->add_flag("--no-map", opt->no_map, "Draw the trajectories without the map background");
  cmd->add_flag("--no-plots", opt->no_plots, "Write only the tables (no report.json, no figures)");
  cmd->add_option("--figure-format", *format, "png | pdf | svg")->capture_default_str();
  cmd->callback([opt, format] {
    opt->figure_format = harness::parseFigureFormat(*format);
    const harness::ReportRunResult r = harness::runReport(*opt);
    std::printf("%s\n", r.markdown.c_str());
    std::printf("tgnav report: %zu groups, %zu trials -> %s/\n", r.groups, r.trials, r.out.string().c_str());
    if (!r.figures_failed.empty()) {
      std::fflush(stdout);
      std::fprintf(stderr, "tgnav: error: plots failed: %s\n", oneLine(r.figures_failed).c_str());
      throw CLI::RuntimeError(1);
    }
  });
}

}  // namespace tgnav::cli
