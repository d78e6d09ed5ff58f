// tgnav map: the mapping run of a scene -> occlusion-aware feature map on disk.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "harness/cli.h"
#include "harness/errors.h"
#include "harness/map_builder.h"
#include "harness/output.h"
#include "harness/quiet_stderr.h"
#include "harness/topdown.h"

namespace tgnav::cli {

namespace {

struct MapOptions {
  std::string scene;
  std::string out;
  double resolution_m = 0.1;
};

nlohmann::ordered_json summaryJson(const harness::SceneConfig& scene, const harness::MapBuildConfig& c,
                                   const harness::MapBuildStats& s) {
  nlohmann::ordered_json j;
  j["scene"] = scene.source.string();
  j["resolution_m"] = c.resolution_m;
  j["survey_positions"] = s.survey_positions;
  j["frames"] = s.frames;
  j["keypoints"] = s.keypoints;
  j["observations"] = s.observations;
  j["landmarks_merged"] = s.landmarks_merged;
  j["dropped_few_observations"] = s.dropped_few_observations;
  j["dropped_not_embedded"] = s.dropped_not_embedded;
  j["landmarks"] = s.landmarks;
  j["timing"] = {{"render_s", s.render_s}, {"integrate_s", s.integrate_s}, {"features_s", s.features_s},
                 {"total_s", s.total_s}};
  return j;
}

void runMap(const MapOptions& opt) {
  const harness::SceneConfig scene = harness::loadSceneConfig(opt.scene);
  harness::MapBuildConfig config;
  config.resolution_m = opt.resolution_m;
  try {
    config.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--resolution: ") + e.what());
  }
  const std::filesystem::path out = std::filesystem::absolute(opt.out).lexically_normal();
  const std::filesystem::path cwd = std::filesystem::current_path();
  if (out == cwd || out == out.root_path() || !out.has_filename() ||
      std::mismatch(out.begin(), out.end(), cwd.begin(), cwd.end()).first == out.end()) {
    throw InputError("--out: '" + opt.out + "' is the working directory or one of its parents; name a new directory");
  }
  if (std::filesystem::exists(out) && !std::filesystem::is_empty(out) &&
      !std::filesystem::exists(out / "summary.json")) {
    throw InputError(out.string() + ": exists and does not hold a previous map; choose another --out");
  }
  const bool tty = isatty(fileno(stderr)) != 0;
  harness::MapBuildStats stats;
  const planner::FeatureMap map = harness::buildFeatureMap(scene, config, &stats, [&](int done, int total) {
    if (tty && (done % 20 == 0 || done == total)) std::fprintf(stderr, "\rtgnav map: %d/%d frames", done, total);
  });
  if (tty) std::fprintf(stderr, "\n");

  // Everything goes to a sibling temp dir first; it replaces `out` only when complete.
  const std::filesystem::path tmp = out.string() + ".partial";
  std::filesystem::remove_all(tmp);
  harness::makeOutputDir(tmp);
  {
    const harness::QuietStderr quiet;
    map.save(tmp);
  }
  // About 800 pixels across, whatever the scene's size.
  harness::Topdown topdown(scene, (scene.bounds_max_m.x() - scene.bounds_min_m.x()) / 800.0);
  topdown.drawMap(map, 0.3);
  topdown.drawStartGoal();
  harness::writeImageAtomic(tmp / "topdown.png", topdown.image());
  harness::writeFileAtomic(tmp / "summary.json", summaryJson(scene, config, stats).dump(2) + "\n");
  std::filesystem::remove_all(out);
  std::filesystem::rename(tmp, out);
  std::printf("tgnav map: %d frames from %d positions, %d landmarks (%ld keypoints, %d merged, %d seen once, "
              "%d not on a surface), %.1f s -> %s/{map.bt,landmarks.csv,topdown.png,summary.json}\n",
              stats.frames, stats.survey_positions, stats.landmarks, stats.keypoints, stats.landmarks_merged,
              stats.dropped_few_observations, stats.dropped_not_embedded, stats.total_s, out.string().c_str());
}

}  // namespace

void addMapCommand(CLI::App& app) {
  auto opt = std::make_shared<MapOptions>();
  CLI::App* cmd = app.add_subcommand("map", "Survey a scene by rendering and build its occlusion-aware feature map");
  cmd->add_option("--scene", opt->scene, "Scene YAML (configs/scenes/*.yaml) with a survey plan")->required();
  cmd->add_option("--out", opt->out, "Output directory")->required();
  cmd->add_option("--resolution", opt->resolution_m, "OctoMap voxel size in metres")->capture_default_str();
  cmd->callback([opt] { runMap(*opt); });
}

}  // namespace tgnav::cli
