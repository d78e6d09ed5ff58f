// tgnav vo: the RGB-D visual odometry over a TUM RGB-D sequence folder, scored against its
// ground truth (harness/run/vo_run.h).
#include <unistd.h>

#include <cstdio>

#include "harness/cli/cli.h"
#include "harness/run/vo_run.h"

namespace tgnav::cli {

void addVoCommand(CLI::App& app) {
  auto job = std::make_shared<harness::VoJob>();
  CLI::App* cmd = app.add_subcommand("vo", "Run the RGB-D visual odometry over a TUM RGB-D sequence and score it");
  cmd->add_option("--sequence", job->sequence,
                  "TUM RGB-D sequence folder (rgb.txt, depth.txt, rgb/, depth/, optional groundtruth.txt and "
                  "intrinsics.yaml), e.g. from tgnav fly --record")
      ->required();
  cmd->add_option("--out", job->out, "Output directory (must not exist)")->required();
  cmd->add_option("--config", job->config,
                  "Odometry YAML: fields of vo::OdometryConfig (features: vo::FeatureConfig); default built-in");
  cmd->add_option("--intrinsics", job->intrinsics,
                  "fx,fy,cx,cy in pixels, for sequences without intrinsics.yaml (overrides it otherwise)");
  cmd->add_flag("--reinitialise", job->reinitialise, "Restart the odometry after it is lost (default: stay lost)");
  cmd->callback([job] {
    job->progress = isatty(fileno(stderr)) != 0;
    std::printf("%s\n", harness::voSummaryLine(harness::runVo(*job)).c_str());
  });
}

}  // namespace tgnav::cli
