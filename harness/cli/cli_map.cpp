// tgnav map: the mapping run of a scene -> occlusion-aware feature map on disk
// (harness/run/map_run.h).
#include <unistd.h>

#include <cstdio>

#include "harness/cli/cli.h"
#include "harness/run/map_run.h"

namespace tgnav::cli {

void addMapCommand(CLI::App& app) {
  auto job = std::make_shared<harness::MapJob>();
  auto format = std::make_shared<std::string>("png");
  CLI::App* cmd = app.add_subcommand("map", "Survey a scene by rendering and build its occlusion-aware feature map");
  cmd->add_option("--scene", job->scene, "Scene YAML (configs/scenes/*.yaml) with a survey plan")->required();
  cmd->add_option("--out", job->out, "Output directory")->required();
  cmd->add_option("--resolution", job->resolution_m, "OctoMap voxel size in metres")->capture_default_str();
  cmd->add_option("--figure-format", *format, "png | pdf | svg")->capture_default_str();
  cmd->callback([job, format] {
    job->figure_format = harness::parseFigureFormat(*format);
    job->progress = isatty(fileno(stderr)) != 0;
    const harness::MapRunResult r = harness::runMap(*job);
    harness::reportFigures("tgnav map", r.figures);
    const harness::MapBuildStats& s = r.stats;
    std::printf(
        "tgnav map: %d frames from %d positions, %d landmarks (%ld keypoints, %d merged, %d seen once, "
        "%d not on a surface), %.1f s -> %s/{map.bt,landmarks.csv,topdown.%s,summary.json}\n",
        s.frames, s.survey_positions, s.landmarks, s.keypoints, s.landmarks_merged, s.dropped_few_observations,
        s.dropped_not_embedded, s.total_s, r.out.string().c_str(), format->c_str());
  });
}

}  // namespace tgnav::cli
