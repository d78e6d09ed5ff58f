#pragma once
// Helpers shared by the harness tests.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/base/errors.h"
#include "harness/base/quiet_stderr.h"
#include "harness/base/shell.h"
#include "harness/io/staged_output.h"
#include "harness/run/map_cache.h"
#include "planner/feature_map.h"

namespace tgnav::test {

inline std::filesystem::path sourceDir() { return TGNAV_SOURCE_DIR; }

// A fresh directory under the system temp dir, unique per test.
inline std::filesystem::path tempDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  auto dir =
      std::filesystem::temp_directory_path() / ("tgnav_" + std::string(info->test_suite_name()) + "_" + info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// Staging folders (StagedDir) left in `dir`: none once a command has finished or failed.
inline int stagingLeftIn(const std::filesystem::path& dir) {
  int n = 0;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) n += harness::isStagingName(e.path().filename());
  return n;
}

inline std::filesystem::path writeFile(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

// dir/scenario.yaml on the smoke scene with seed 3, then `body` (more scenario keys).
inline std::filesystem::path smokeScenario(const std::filesystem::path& dir, const std::string& body) {
  return writeFile(dir / "scenario.yaml",
                   "scene: " + (sourceDir() / "configs/scenes/smoke.yaml").string() + "\nseed: 3\n" + body);
}

// DIR/metrics.json as text to compare, without its wall-clock figures (plan_time_s, wall_time_s,
// real_time_factor, peak_rss_mb, timing) and the keys in `also`.
inline std::string metricsWithout(const std::filesystem::path& dir, std::initializer_list<const char*> also = {}) {
  std::ifstream in(dir / "metrics.json");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  nlohmann::ordered_json j = nlohmann::ordered_json::parse(text);
  for (const char* key : {"plan_time_s", "wall_time_s", "real_time_factor", "peak_rss_mb", "timing"}) j.erase(key);
  for (const char* key : also) j.erase(key);
  return j.dump(2);
}

// Runs a shell command line; its output (stderr included) and exit code.
using CmdResult = harness::CommandResult;
inline CmdResult runShell(const std::string& command) { return harness::runCommand(command); }

// The message of the InputError that `fn` throws ("" when it throws none).
template <typename Fn>
std::string inputError(Fn fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// The feature map of configs/scenes/<name>.yaml from the tests' shared cache (built by the
// scene_maps fixture, or here on first use).
inline planner::FeatureMap sceneMap(const std::string& name) {
  const harness::SceneConfig scene = harness::loadSceneConfig(sourceDir() / "configs/scenes" / (name + ".yaml"));
  const harness::CachedMap cached = harness::cachedFeatureMap(scene, harness::MapBuildConfig{}, TGNAV_TEST_CACHE);
  const harness::QuietStderr quiet;
  return planner::FeatureMap::load(cached.dir);
}

// A textured wall 3.55 m east of the origin (y -1.45 to 1.0 m, z 0.55 to 1.5 m; 0.1 m voxels), two
// landmarks per voxel on its face unless `landmarks` is false, the space from x = 0 to `free_to`
// observed free in front of it.
inline planner::FeatureMap texturedWall(double free_to = 0.0, bool landmarks = true) {
  planner::FeatureMap map(0.1);
  for (double x = 0.05; x < free_to; x += 0.1) {
    for (double y = -1.45; y < 1.0; y += 0.1) {
      for (double z = 0.55; z < 1.5; z += 0.1) {
        map.occupancy().updateNode(
            octomap::point3d(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)), false);
      }
    }
  }
  std::vector<planner::Landmark> seen;
  for (double y = -1.45; y < 1.0; y += 0.1) {
    for (double z = 0.55; z < 1.5; z += 0.1) {
      map.occupancy().updateNode(octomap::point3d(3.55F, static_cast<float>(y), static_cast<float>(z)), true);
      for (double dz : {-0.02, 0.02}) {
        planner::Landmark lm;
        lm.p_W = Eigen::Vector3d(3.5, y, z + dz);
        lm.observations = lm.opportunities = 1;
        lm.ref_kf_p_W = Eigen::Vector3d(0.0, y, z);
        seen.push_back(lm);
      }
    }
  }
  if (landmarks) map.setLandmarks(seen);
  EXPECT_EQ(map.embedLandmarks(0.15), 0);
  return map;
}

}  // namespace tgnav::test
