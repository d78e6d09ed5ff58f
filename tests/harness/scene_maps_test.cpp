// The paper's scenes say what the paper says, measured on feature maps built from rendering:
// in storage the lower route sees far more landmarks than the upper one; in gallery the two
// texture-poor corridors see far fewer than the textured ones. (The maps come from the tests'
// shared cache, see scene_cache_setup.cpp.)
#include <gtest/gtest.h>

#include <iostream>

#include "harness/run/map_builder.h"
#include "test_util.h"

namespace tgnav::harness {
namespace {

// Mean number of landmarks visible (range, vertical FoV, occlusion; any yaw) from points every
// 0.25 m along the polyline at flight height, to 6 m (the range the scene was designed with).
double meanVisible(const planner::FeatureMap& map, const std::vector<Eigen::Vector2d>& polyline, double z) {
  planner::VisibilityConfig config;
  config.max_range_m = 6.0;
  double sum = 0.0;
  int n = 0;
  for (std::size_t i = 0; i + 1 < polyline.size(); ++i) {
    const Eigen::Vector2d d = polyline[i + 1] - polyline[i];
    const int steps = std::max(1, static_cast<int>(d.norm() / 0.25));
    for (int k = 0; k <= steps; ++k) {
      const Eigen::Vector2d p = polyline[i] + d * (static_cast<double>(k) / steps);
      sum += static_cast<double>(map.visibleFrom(Eigen::Vector3d(p.x(), p.y(), z), config).size());
      ++n;
    }
  }
  return sum / n;
}

TEST(SceneMaps, StorageLowerRouteSeesFiveTimesTheLandmarksOfTheUpperRoute) {
  const SceneConfig scene = loadSceneConfig(test::sourceDir() / "configs/scenes/storage.yaml");
  const planner::FeatureMap map = test::sceneMap("storage");
  const double z = scene.flight_height_m;
  // The middle stretches of the two routes around the partition (the ends are shared).
  const double upper = meanVisible(map, {{-3.6, 3.8}, {3.6, 3.8}}, z);
  const double lower = meanVisible(map, {{-3.6, -3.5}, {3.6, -3.5}}, z);
  std::cout << "[ figure   ] storage: mean visible landmarks along the upper route " << upper << ", lower route "
            << lower << " (" << lower / std::max(upper, 1e-9) << "x)\n";
  EXPECT_GE(lower, 5.0 * upper);
  EXPECT_GT(lower, 500.0);
}

TEST(SceneMaps, GalleryTexturePoorCorridorsSeeFewLandmarks) {
  const SceneConfig scene = loadSceneConfig(test::sourceDir() / "configs/scenes/gallery.yaml");
  const planner::FeatureMap map = test::sceneMap("gallery");
  const double z = scene.flight_height_m;
  // Inside (not at the mouths of) the texture-poor corridors: the horizontal one right of the
  // centre (x 0.8..7.6, y 0..2.4) and the longitudinal one in the upper middle (x -1.7..0.8).
  const double horizontal = meanVisible(map, {{2.0, 1.2}, {5.5, 1.2}}, z);
  const double longitudinal = meanVisible(map, {{-0.45, 2.0}, {-0.45, 6.0}}, z);
  // Inside the textured corridors: lower middle (x -2.8..-0.6) and left middle (y -2.0..0.2).
  const double lower_middle = meanVisible(map, {{-1.7, -6.0}, {-1.7, -3.0}}, z);
  const double left_middle = meanVisible(map, {{-6.5, -0.9}, {-3.5, -0.9}}, z);
  std::cout << "[ figure   ] gallery: mean visible landmarks, texture-poor corridors " << horizontal << " and "
            << longitudinal << ", textured corridors " << lower_middle << " and " << left_middle << "\n";
  const double poor = std::max(horizontal, longitudinal);
  const double rich = std::min(lower_middle, left_middle);
  EXPECT_GE(rich, 5.0 * poor);
}

TEST(SceneMaps, CorridorMiddleIsPoorOuterSidesRich) {
  const SceneConfig scene = loadSceneConfig(test::sourceDir() / "configs/scenes/corridor.yaml");
  const planner::FeatureMap map = buildFeatureMap(scene, MapBuildConfig{}, nullptr);
  const double z = scene.flight_height_m;
  // The middle region between the partitions (x -2.6..2.6, y -0.9..0.9; its two small notices
  // and, near the open ends, the textured corners are visible) vs. outside the partitions.
  const double middle = meanVisible(map, {{-1.0, 0.0}, {1.0, 0.0}}, z);
  const double north = meanVisible(map, {{-1.0, 1.8}, {1.0, 1.8}}, z);
  const double south = meanVisible(map, {{-1.0, -1.8}, {1.0, -1.8}}, z);
  std::cout << "[ figure   ] corridor: mean visible landmarks between the partitions " << middle << ", outside "
            << north << " (north) and " << south << " (south)\n";
  EXPECT_GE(std::min(north, south), 5.0 * middle);
}

}  // namespace
}  // namespace tgnav::harness
