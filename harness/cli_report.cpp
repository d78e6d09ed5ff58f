// tgnav report: a sweep folder aggregated into the paper's Table II (table2.csv, table2.md, also
// printed) and figures (fig3_<scene>.png trajectories over the map, fig4_<scene>.png VO error
// against distance travelled, plan_time.png), drawn by scripts/report_plots.py from report.json.
// Bad input (not a sweep, a malformed index) is refused before anything is written; when the
// plots fail the tables are still there and the command exits 1.
#include <cstdio>
#include <set>

#include "harness/cli.h"
#include "harness/errors.h"
#include "harness/output.h"
#include "harness/report.h"

namespace tgnav::cli {

namespace {

namespace fs = std::filesystem;

struct ReportCliOptions {
  std::string dir;
  std::string out;
  std::string map_cache;
  bool no_map = false;
  bool no_plots = false;
};

// The scene backgrounds, each from the first trial of its scene, in order of appearance; with
// --no-map only their names (figure 3 then autoscales and has no start or goal marker).
std::vector<harness::SceneBackground> backgrounds(const harness::SweepIndex& sweep, const fs::path& report_dir,
                                                  const ReportCliOptions& opt) {
  std::vector<harness::SceneBackground> out;
  std::set<std::string> done;
  for (const harness::IndexRow& row : sweep.rows) {
    if (!done.insert(row.scene).second) continue;
    if (opt.no_map) {
      harness::SceneBackground bg;
      bg.scene = row.scene;
      out.push_back(bg);
    } else {
      out.push_back(harness::sceneBackground(row.scene, row.folder, report_dir, opt.map_cache));
    }
  }
  return out;
}

// Writes report.json and the map images and runs the plot script; "" or why it failed.
std::string drawFigures(const harness::SweepIndex& sweep, const std::vector<harness::ReportGroup>& groups,
                        const std::vector<harness::TableRow>& table, const fs::path& report_dir,
                        const ReportCliOptions& opt) {
  try {
    // Before the maps, which may take a while to build.
    const harness::PlotTools tools = harness::findPlotTools(fs::path(TGNAV_SOURCE_DIR) / "scripts");
    const auto scenes = backgrounds(sweep, report_dir, opt);
    harness::writeFileAtomic(report_dir / "report.json",
                             harness::reportJson(sweep, groups, table, scenes).dump(2) + "\n");
    const harness::PlotRun run = harness::runPlotScript(tools, report_dir);
    if (!run.ok) return run.error;
    if (!run.output.empty()) std::fprintf(stderr, "%s", run.output.c_str());  // the script's warnings
    return "";
  } catch (const std::exception& e) {
    return e.what();
  }
}

int runReportCommand(const ReportCliOptions& opt) {
  const harness::SweepIndex sweep = harness::readSweep(opt.dir);
  const fs::path report_dir = opt.out.empty() ? sweep.dir / "report" : fs::absolute(opt.out).lexically_normal();
  std::error_code ec;
  if (fs::exists(report_dir, ec) && !fs::is_directory(report_dir, ec)) {
    throw InputError("--out: " + report_dir.string() + " exists and is not a directory");
  }
  const std::vector<harness::ReportGroup> groups = harness::groupTrials(sweep.rows);
  const std::vector<harness::TableRow> table = harness::tableRows(groups, sweep.rows);
  const std::string markdown = harness::table2Markdown(table, static_cast<int>(sweep.rows.size()),
                                                       sweep.manifest_trials, sweep.dir.filename().string());

  harness::makeOutputDir(report_dir);
  harness::writeFileAtomic(report_dir / "table2.csv", harness::table2Csv(table));
  harness::writeFileAtomic(report_dir / "table2.md", markdown);
  std::printf("%s\n", markdown.c_str());
  std::fflush(stdout);

  const std::string failure = opt.no_plots ? "" : drawFigures(sweep, groups, table, report_dir, opt);
  std::printf("tgnav report: %zu groups, %zu trials -> %s/\n", groups.size(), sweep.rows.size(),
              report_dir.string().c_str());
  if (!failure.empty()) {
    std::fflush(stdout);
    std::fprintf(stderr, "tgnav: error: plots failed: %s\n", oneLine(failure).c_str());
    return 1;
  }
  return 0;
}

}  // namespace

void addReportCommand(CLI::App& app) {
  auto opt = std::make_shared<ReportCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "report", "Aggregate a sweep folder into the paper's Table II (CSV + Markdown) and figures 3 and 4");
  cmd->add_option("DIR", opt->dir, "Sweep folder (from `tgnav sweep`: index.csv, trials.csv, trials/)")->required();
  cmd->add_option("--out", opt->out, "Report folder (default: DIR/report)");
  cmd->add_option("--map-cache", opt->map_cache,
                  "Cache folder for the scenes' feature maps (default: $TGNAV_CACHE_DIR or ~/.cache/tgnav)");
  cmd->add_flag("--no-map", opt->no_map, "Draw the trajectories without the map background");
  cmd->add_flag("--no-plots", opt->no_plots, "Write only the tables (no report.json, no figures)");
  cmd->callback([opt] {
    const int rc = runReportCommand(*opt);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace tgnav::cli
