#include "harness/run/map_run.h"

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "harness/base/errors.h"
#include "harness/io/staged_output.h"
#include "harness/io/topdown.h"
#include "harness/run/map_cache.h"

namespace tgnav::harness {

namespace {

namespace fs = std::filesystem;

// The map's height band drawn in the top-down raster, about the flight height.
constexpr double kRasterBandM = 0.3;

nlohmann::ordered_json summaryJson(const SceneConfig& scene, const MapBuildConfig& c, const MapBuildStats& s) {
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
  j["mean_detectability"] = s.mean_detectability;
  j["timing"] = {{"render_s", s.render_s},
                 {"integrate_s", s.integrate_s},
                 {"features_s", s.features_s},
                 {"opportunities_s", s.opportunities_s},
                 {"total_s", s.total_s}};
  return j;
}

// A new folder, or one holding an earlier map; never the working directory or a parent of it.
fs::path checkedOutput(const fs::path& requested) {
  fs::path out = fs::absolute(requested).lexically_normal();
  const fs::path cwd = fs::current_path();
  if (out == cwd || out == out.root_path() || !out.has_filename() ||
      std::mismatch(out.begin(), out.end(), cwd.begin(), cwd.end()).first == out.end()) {
    throw InputError("--out: '" + requested.string() +
                     "' is the working directory or one of its parents; name a new directory");
  }
  if (fs::exists(out) && !fs::is_empty(out) && !fs::exists(out / "summary.json")) {
    throw InputError(out.string() + ": exists and does not hold a previous map; choose another --out");
  }
  return out;
}

}  // namespace

MapRunResult runMap(const MapJob& job) {
  const SceneConfig scene = loadSceneConfig(job.scene);
  MapBuildConfig config;
  config.resolution_m = job.resolution_m;
  try {
    config.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--resolution: ") + e.what());
  }
  MapRunResult result;
  result.out = checkedOutput(job.out);
  const planner::FeatureMap map = buildFeatureMap(scene, config, &result.stats, [&](int done, int total) {
    if (job.progress && (done % 20 == 0 || done == total)) {
      std::fprintf(stderr, "\rtgnav map: %d/%d frames", done, total);
    }
  });
  if (job.progress) std::fprintf(stderr, "\n");

  StagedDir staged(result.out);
  saveFeatureMap(map, staged.staging());
  writeMapLayer(staged.staging(), sceneMapLayer(scene, map, kRasterBandM));
  writeFileAtomic(staged.staging() / "summary.json", summaryJson(scene, config, result.stats).dump(2) + "\n");
  result.figures = drawFigures("map", staged.staging(), job.figure_format);
  staged.commit(OnExisting::kReplace);
  return result;
}

}  // namespace tgnav::harness
