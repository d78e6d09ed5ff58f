// Configs are strict: unknown keys, bad values and failed validation are errors that name the
// file, the line, the key and the value.
#include <gtest/gtest.h>

#include "harness/config_io.h"
#include "harness/errors.h"
#include "harness/scene_config.h"
#include "test_util.h"

namespace tgnav::harness {
namespace {

using test::inputError;

TEST(CameraConfigFile, ShippedFileEqualsBuiltInDefaults) {
  const CameraConfig file = loadCameraConfig(test::sourceDir() / "configs/camera.yaml");
  const CameraConfig defaults;
  EXPECT_EQ(file.name, defaults.name);
  EXPECT_EQ(file.width_px, defaults.width_px);
  EXPECT_EQ(file.height_px, defaults.height_px);
  EXPECT_EQ(file.near_clip_m, defaults.near_clip_m);
  EXPECT_EQ(file.far_clip_m, defaults.far_clip_m);
  EXPECT_EQ(file.min_depth_m, defaults.min_depth_m);
  EXPECT_EQ(file.max_depth_m, defaults.max_depth_m);
  EXPECT_EQ(file.rgb_noise_sigma, defaults.rgb_noise_sigma);
  EXPECT_EQ(file.depth_noise_sigma_per_m2, defaults.depth_noise_sigma_per_m2);
}

TEST(CameraConfigFile, UnknownKeyNamesFileLineAndKey) {
  const auto file = test::writeFile(test::tempDir() / "cam.yaml", "width_px: 320\nwidht_px: 3\n");
  const std::string msg = inputError([&] { loadCameraConfig(file); });
  EXPECT_NE(msg.find(file.string() + ":2:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("unknown key 'widht_px'"), std::string::npos) << msg;
}

TEST(CameraConfigFile, BadValueNamesKeyAndValue) {
  const auto file = test::writeFile(test::tempDir() / "cam.yaml", "height_px: tall\n");
  const std::string msg = inputError([&] { loadCameraConfig(file); });
  EXPECT_NE(msg.find("height_px"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'tall'"), std::string::npos) << msg;
  const auto frac = test::writeFile(test::tempDir() / "cam2.yaml", "height_px: 240.5\n");
  EXPECT_NE(inputError([&] { loadCameraConfig(frac); }).find("integer"), std::string::npos);
}

TEST(CameraConfigFile, ValidationFailureNamesFileKeyAndValue) {
  const auto file = test::writeFile(test::tempDir() / "cam.yaml", "max_depth_m: -1\n");
  const std::string msg = inputError([&] { loadCameraConfig(file); });
  EXPECT_NE(msg.find(file.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("max_depth_m = -1"), std::string::npos) << msg;
}

TEST(CameraConfigFile, SyntaxErrorNamesLine) {
  const auto file = test::writeFile(test::tempDir() / "cam.yaml", "width_px: 320\nheight_px: [1, 2\n");
  const std::string msg = inputError([&] { loadCameraConfig(file); });
  EXPECT_NE(msg.find("YAML syntax error"), std::string::npos) << msg;
  EXPECT_NE(msg.find(file.string() + ":"), std::string::npos) << msg;
}

TEST(SceneConfigFile, SmokeSceneLoads) {
  const SceneConfig s = loadSceneConfig(test::sourceDir() / "configs/scenes/smoke.yaml");
  EXPECT_TRUE(std::filesystem::is_regular_file(s.mjcf));
  EXPECT_DOUBLE_EQ(s.flight_height_m, 1.0);
  EXPECT_DOUBLE_EQ(s.start.p_WB.x(), -3.0);
  EXPECT_DOUBLE_EQ(s.goal.p_WB.x(), 3.0);
}

class SceneErrors : public ::testing::Test {
 protected:
  std::string load(const std::string& text) {
    const auto dir = test::tempDir();
    test::writeFile(dir / "world.xml", "<mujoco/>");
    const auto file = test::writeFile(dir / "scene.yaml", text);
    return inputError([&] { loadSceneConfig(file); });
  }
  const std::string valid_ =
      "mjcf: world.xml\nflight_height_m: 1.0\nstart: [0, 0, 1, 0]\ngoal: [1, 1, 1, 0]\n"
      "bounds: {min: [-1, -1, 0], max: [2, 2, 3]}\n"
      "survey: {spacing_m: 1.0, heights_m: [0.8, 1.2], yaw_count: 8, clearance_m: 0.4}\n";
};

TEST_F(SceneErrors, ValidSceneHasNoError) { EXPECT_EQ(load(valid_), ""); }

TEST_F(SceneErrors, MissingMjcfNamesKeyAndValue) {
  const std::string msg = load("mjcf: nowhere.xml\n" + valid_.substr(valid_.find('\n') + 1));
  EXPECT_NE(msg.find("'mjcf'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("nowhere.xml"), std::string::npos) << msg;
}

TEST_F(SceneErrors, MissingKeyIsNamed) {
  const std::string msg = load("mjcf: world.xml\nflight_height_m: 1.0\n");
  EXPECT_NE(msg.find("missing required key 'start'"), std::string::npos) << msg;
}

TEST_F(SceneErrors, ShortPoseIsRejected) {
  std::string text = valid_;
  text.replace(text.find("start: [0, 0, 1, 0]"), 19, "start: [0, 0, 1]");
  const std::string msg = load(text);
  EXPECT_NE(msg.find("'start'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("4 finite numbers"), std::string::npos) << msg;
}

TEST_F(SceneErrors, GoalOutsideBoundsIsRejected) {
  std::string text = valid_;
  text.replace(text.find("goal: [1, 1, 1, 0]"), 18, "goal: [9, 1, 1, 0]");
  EXPECT_NE(load(text).find("'goal' lies outside 'bounds'"), std::string::npos);
}

TEST_F(SceneErrors, NestedUnknownKeyHasDottedName) {
  std::string text = valid_;
  text.replace(text.find("max: [2, 2, 3]"), 14, "max: [2, 2, 3], mid: [0, 0, 0]");
  EXPECT_NE(load(text).find("unknown key 'bounds.mid'"), std::string::npos);
}

TEST_F(SceneErrors, SurveyHeightOutsideBoundsIsRejected) {
  std::string text = valid_;
  text.replace(text.find("heights_m: [0.8, 1.2]"), 21, "heights_m: [0.8, 3.5]");
  EXPECT_NE(load(text).find("'survey.heights_m' has value '3.5'"), std::string::npos) << load(text);
}

TEST_F(SceneErrors, SurveyYawCountMustBeAnInteger) {
  std::string text = valid_;
  text.replace(text.find("yaw_count: 8"), 12, "yaw_count: 2.5");
  EXPECT_NE(load(text).find("'survey.yaw_count' has value '2.5'"), std::string::npos) << load(text);
}

TEST(SceneFile, UnknownExtensionIsRejected) {
  const auto file = test::writeFile(test::tempDir() / "scene.txt", "x");
  EXPECT_NE(inputError([&] { loadScene(file); }).find("unknown scene file type"), std::string::npos);
}

}  // namespace
}  // namespace tgnav::harness
