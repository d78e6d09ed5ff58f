// tgnav eval: ATE and RPE of any trajectory pair (TUM, KITTI, EuRoC) with evo's definitions
// (harness/run/eval_run.h).
#include <cstdio>
#include <string>

#include "harness/cli/cli.h"
#include "harness/run/eval_run.h"

namespace tgnav::cli {

void addEvalCommand(CLI::App& app) {
  auto job = std::make_shared<harness::EvalJob>();
  auto figure_format = std::make_shared<std::string>("png");
  CLI::App* cmd =
      app.add_subcommand("eval", "ATE and RPE of an estimated trajectory against a reference, with evo's definitions");
  cmd->add_option("--ref", job->ref, "Reference (ground-truth) trajectory file")->required();
  cmd->add_option("--est", job->est, "Estimated trajectory file, in the same format")->required();
  cmd->add_option("--format", job->format,
                  "tum (t x y z qx qy qz qw) | kitti (3x4 [R|t] per line, paired by line) | euroc (CSV, ns, qw first)")
      ->capture_default_str();
  cmd->add_option("--align", job->align,
                  "se3 (evo -a) | sim3 (evo -as) | posyaw (4-DoF, rpg) | origin (evo --align_origin) | none")
      ->capture_default_str();
  cmd->add_option("--rpe-delta", job->rpe_delta, "RPE pose distance, in --rpe-unit")->capture_default_str();
  cmd->add_option("--rpe-unit", job->rpe_unit, "m (along the reference) | frames")->capture_default_str();
  cmd->add_option("--max-dt", job->max_dt_s, "Largest time difference of a pair, seconds (not for kitti)")
      ->capture_default_str();
  cmd->add_option("--out", job->out,
                  "New directory for eval.json, eval_pairs.csv and the figure (default: print the summary only)");
  cmd->add_option("--figure-format", *figure_format, "png | pdf | svg")->capture_default_str();
  cmd->callback([job, figure_format] {
    job->figure_format = harness::parseFigureFormat(*figure_format);
    const harness::EvalResult r = harness::runEval(*job);
    for (const std::string& w : r.warnings) std::fprintf(stderr, "%s\n", w.c_str());
    harness::reportFigures("tgnav eval", r.figures);
    std::printf("%s\n", harness::evalSummaryLine(r).c_str());
  });
}

}  // namespace tgnav::cli
