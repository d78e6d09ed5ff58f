// Fixture: builds the storage and gallery feature maps into the tests' shared cache, so that the
// tests needing them (FIXTURES_REQUIRED scene_maps) load them instead of rendering each time.
#include <gtest/gtest.h>

#include <iostream>

#include "test_util.h"

namespace tgnav::harness {
namespace {

TEST(SceneCache, StorageAndGalleryMapsAreCached) {
  for (const char* name : {"storage", "gallery"}) {
    const SceneConfig scene = loadSceneConfig(test::sourceDir() / "configs/scenes" / (std::string(name) + ".yaml"));
    const CachedMap cached = cachedFeatureMap(scene, MapBuildConfig{}, TGNAV_TEST_CACHE);
    std::cout << "[ figure   ] " << name << " map " << (cached.built ? "built" : "found") << " in " << cached.dir
              << "\n";
    EXPECT_TRUE(std::filesystem::is_regular_file(cached.dir / "map.bt"));
    EXPECT_TRUE(std::filesystem::is_regular_file(cached.dir / "landmarks.csv"));
    // The key is a pure function of the inputs: asking again finds the same folder.
    EXPECT_EQ(cachedFeatureMap(scene, MapBuildConfig{}, TGNAV_TEST_CACHE).dir, cached.dir);
  }
}

}  // namespace
}  // namespace tgnav::harness
