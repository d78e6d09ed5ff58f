// Configs are strict: unknown keys, bad values and failed validation are errors that name the
// file, the line, the key and the value.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "harness/base/errors.h"
#include "harness/config/config_io.h"
#include "harness/config/planner_config.h"
#include "harness/config/scenario.h"
#include "harness/config/scene_config.h"
#include "harness/config/trial_config.h"
#include "harness/config/yaml_util.h"
#include "test_util.h"

namespace tgnav::harness {
namespace {

using test::inputError;

TEST(CameraConfigFile, ShippedFileEqualsBuiltInDefaults) {
  const CameraConfig file = loadCameraConfig(test::sourceDir() / "configs/camera.yaml");
  const CameraConfig defaults;
  EXPECT_EQ(file.name, defaults.name);
  EXPECT_EQ(defaults.name, kVehicleCamera);
  EXPECT_EQ(file.width_px, defaults.width_px);
  EXPECT_EQ(file.height_px, defaults.height_px);
  EXPECT_EQ(file.near_clip_m, defaults.near_clip_m);
  EXPECT_EQ(file.far_clip_m, defaults.far_clip_m);
  EXPECT_EQ(file.min_depth_m, defaults.min_depth_m);
  EXPECT_EQ(file.max_depth_m, defaults.max_depth_m);
  EXPECT_EQ(file.rgb_noise_sigma, defaults.rgb_noise_sigma);
  EXPECT_EQ(file.depth_noise_sigma_per_m2, defaults.depth_noise_sigma_per_m2);
  EXPECT_EQ(file.offscreen_samples, defaults.offscreen_samples);
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
  // Multisampling: the counts OpenGL offers everywhere, or none.
  const auto samples = test::writeFile(test::tempDir() / "cam3.yaml", "offscreen_samples: 3\n");
  const std::string bad = inputError([&] { loadCameraConfig(samples); });
  EXPECT_NE(bad.find("offscreen_samples = 3: must be 0, 2, 4 or 8"), std::string::npos) << bad;
  const auto none = test::writeFile(test::tempDir() / "cam4.yaml", "offscreen_samples: 0\n");
  EXPECT_EQ(loadCameraConfig(none).offscreen_samples, 0);
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

// --- Writer mode: the visits, run on a writer, emit every key --------------------------------

std::string dump(const YAML::Node& node) {
  YAML::Emitter out;
  out << node;
  return out.c_str();
}

// The dotted paths of all keys of `node`, in order.
std::vector<std::string> keyPaths(const YAML::Node& node, const std::string& context = "") {
  std::vector<std::string> keys;
  for (const auto& kv : node) {
    const std::string key = joinKey(context, kv.first.as<std::string>());
    keys.push_back(key);
    if (kv.second.IsMap()) {
      const std::vector<std::string> inner = keyPaths(kv.second, key);
      keys.insert(keys.end(), inner.begin(), inner.end());
    }
  }
  return keys;
}

TEST(ConfigWriter, WritesExactShortestDecimalsAndTypedScalars) {
  YAML::Node out(YAML::NodeType::Map);
  double tenth = 0.1, micro = 1e-6, twenty = 20.0, third = 1.0 / 3.0, negative = -2.5;
  int count = -7;
  bool flag = true;
  std::string name = "front";
  Eigen::Vector3d v(0.15, 1e-6, -3.0);
  YamlArchive w = YamlArchive::writer(out);
  w("tenth", tenth);
  w("micro", micro);
  w("twenty", twenty);
  w("third", third);
  w("negative", negative);
  w("count", count);
  w("flag", flag);
  w("name", name);
  w("v", v);
  w.group("inner", [](auto& r) {
    double x = 4.0;
    if constexpr (std::is_same_v<std::decay_t<decltype(r)>, YamlArchive>) {
      EXPECT_TRUE(r.writing());
    }
    r("x", x);
  });
  w.finish();
  EXPECT_EQ(out["tenth"].Scalar(), "0.1");
  EXPECT_EQ(out["micro"].Scalar(), "1e-06");
  EXPECT_EQ(out["twenty"].Scalar(), "20");
  EXPECT_EQ(std::stod(out["third"].Scalar()), third);  // exact, not rounded to 6 digits
  EXPECT_EQ(out["negative"].Scalar(), "-2.5");
  EXPECT_EQ(out["count"].Scalar(), "-7");
  EXPECT_EQ(out["flag"].Scalar(), "true");
  EXPECT_EQ(out["name"].Scalar(), "front");
  EXPECT_EQ(out["inner"]["x"].Scalar(), "4");
  EXPECT_NE(dump(out).find("v: [0.15, 1e-06, -3]"), std::string::npos) << dump(out);
  EXPECT_EQ(keyPaths(out), (std::vector<std::string>{"tenth", "micro", "twenty", "third", "negative", "count", "flag",
                                                     "name", "v", "inner", "inner.x"}));
}

// Emits `c`, loads the text back with `load` and emits that: the two texts must be identical.
template <typename Config, typename Load>
Config roundTrip(const Config& c, Load load, const std::filesystem::path& dir) {
  const std::string text = dump(toYaml(c));
  Config back = load(test::writeFile(dir / "config.yaml", text + "\n"));
  EXPECT_EQ(dump(toYaml(back)), text);
  return back;
}

TEST(ConfigRoundTrip, CameraDefaultsAndChangedValues) {
  const auto dir = test::tempDir();
  roundTrip(
      CameraConfig{}, [](const auto& f) { return loadCameraConfig(f); }, dir);
  CameraConfig c;
  c.name = "down";
  c.width_px = 321;
  c.near_clip_m = 0.1 / 3.0;
  c.min_depth_m = 0.1;
  c.depth_noise_sigma_per_m2 = 1e-6;
  const CameraConfig back = roundTrip(
      c, [](const auto& f) { return loadCameraConfig(f); }, dir);
  EXPECT_EQ(back.name, "down");
  EXPECT_EQ(back.width_px, 321);
  EXPECT_EQ(back.near_clip_m, c.near_clip_m);
  EXPECT_EQ(back.depth_noise_sigma_per_m2, 1e-6);
}

TEST(ConfigRoundTrip, CascadeDefaultsAndChangedValues) {
  const auto dir = test::tempDir();
  roundTrip(
      control::CascadeConfig{}, [](const auto& f) { return loadCascadeConfig(f); }, dir);
  control::CascadeConfig c;
  c.rate.p = Eigen::Vector3d(0.1 / 3.0, 0.17, 0.21);
  c.position.tilt_max_rad = M_PI / 5;
  c.attitude_rate_hz = 125.0;
  const control::CascadeConfig back = roundTrip(
      c, [](const auto& f) { return loadCascadeConfig(f); }, dir);
  EXPECT_EQ(back.rate.p, c.rate.p);
  EXPECT_EQ(back.position.tilt_max_rad, c.position.tilt_max_rad);
  EXPECT_EQ(back.attitude_rate_hz, 125.0);
  EXPECT_EQ(keyPaths(toYaml(back)).size(), (1u + 3u) + (1u + 16u) + (1u + 7u) + (1u + 6u));
}

TEST(ConfigRoundTrip, OdometryDefaultsAndChangedValues) {
  const auto dir = test::tempDir();
  roundTrip(
      vo::OdometryConfig{}, [](const auto& f) { return loadOdometryConfig(f); }, dir);
  vo::OdometryConfig c;
  c.features.scale_factor = 1.0 + 1.0 / 7.0;
  c.features.max_features = 777;
  c.ransac_confidence = 0.9999;
  c.reinitialise_after_lost = true;
  const vo::OdometryConfig back = roundTrip(
      c, [](const auto& f) { return loadOdometryConfig(f); }, dir);
  EXPECT_EQ(back.features.scale_factor, c.features.scale_factor);
  EXPECT_EQ(back.features.max_features, 777);
  EXPECT_EQ(back.ransac_confidence, 0.9999);
  EXPECT_TRUE(back.reinitialise_after_lost);
}

TEST(ConfigRoundTrip, TrialDefaultsAndChangedValues) {
  const auto dir = test::tempDir();
  roundTrip(
      TrialConfig{}, [](const auto& f) { return loadTrialConfig(f); }, dir);
  TrialConfig c;
  c.state_source = StateSource::kVo;
  c.pipeline = false;
  c.camera_rate_hz = 25.0;
  c.flight.diverged_tilt_rad = 1.0 / 3.0;
  c.imu.gyro_bias_rad_s = 1e-4;
  c.estimator.attitude_gain = 0.35;
  const TrialConfig back = roundTrip(
      c, [](const auto& f) { return loadTrialConfig(f); }, dir);
  EXPECT_EQ(back.state_source, StateSource::kVo);
  EXPECT_FALSE(back.pipeline);
  EXPECT_EQ(back.camera_rate_hz, 25.0);
  EXPECT_EQ(back.flight.diverged_tilt_rad, c.flight.diverged_tilt_rad);
  EXPECT_EQ(back.imu.gyro_bias_rad_s, 1e-4);
  EXPECT_EQ(back.estimator.attitude_gain, 0.35);
}

TEST(ConfigRoundTrip, PlannerDefaultsAndChangedValues) {
  const auto dir = test::tempDir();
  roundTrip(
      PlannerSettings{}, [](const auto& f) { return loadPlannerSettings(f); }, dir);
  PlannerSettings c;
  c.perception.robot_radius_m = 0.35;
  c.perception.visibility.hfov_rad = M_PI / 3;
  c.rrt_star.samples = 1234;
  c.trajectory.max_iterations = 77;
  const PlannerSettings back = roundTrip(
      c, [](const auto& f) { return loadPlannerSettings(f); }, dir);
  EXPECT_EQ(back.perception.robot_radius_m, 0.35);
  EXPECT_EQ(back.rrt_star.robot_radius_m, 0.35);  // follows perception's
  EXPECT_EQ(back.trajectory.robot_radius_m, 0.35);
  EXPECT_EQ(back.perception.visibility.hfov_rad, M_PI / 3);
  EXPECT_EQ(back.rrt_star.samples, 1234);
  EXPECT_EQ(back.trajectory.max_iterations, 77);
}

// --- Shipped files hold every key at its built-in default -------------------------------------

template <typename Config, typename Load>
void expectShippedDefaults(const std::string& name, Load load) {
  const auto file = test::sourceDir() / "configs" / name;
  EXPECT_EQ(dump(toYaml(load(file))), dump(toYaml(Config{}))) << name << " differs from the built-in defaults";
  EXPECT_EQ(keyPaths(YAML::LoadFile(file.string())), keyPaths(toYaml(Config{})))
      << name << " does not list every key in the order toYaml writes them";
}

TEST(ConfigShippedFiles, VoYamlEqualsBuiltInDefaults) {
  expectShippedDefaults<vo::OdometryConfig>("vo.yaml", [](const auto& f) { return loadOdometryConfig(f); });
}

TEST(ConfigShippedFiles, TrialYamlEqualsBuiltInDefaults) {
  expectShippedDefaults<TrialConfig>("trial.yaml", [](const auto& f) { return loadTrialConfig(f); });
}

TEST(ConfigShippedFiles, CameraYamlListsEveryKey) {
  expectShippedDefaults<CameraConfig>("camera.yaml", [](const auto& f) { return loadCameraConfig(f); });
}

TEST(ConfigShippedFiles, ControllerYamlListsEveryKey) {
  expectShippedDefaults<control::CascadeConfig>("controller.yaml", [](const auto& f) { return loadCascadeConfig(f); });
}

TEST(ConfigShippedFiles, PlannerYamlListsEveryKey) {
  expectShippedDefaults<PlannerSettings>("planner.yaml", [](const auto& f) { return loadPlannerSettings(f); });
}

// --- Trial settings ------------------------------------------------------------------------

TEST(ConfigTrial, StateSourceNames) {
  StateSource s = StateSource::kGroundTruth;
  EXPECT_TRUE(parseStateSource("vo", &s));
  EXPECT_EQ(s, StateSource::kVo);
  EXPECT_TRUE(parseStateSource("gt", &s));
  EXPECT_EQ(s, StateSource::kGroundTruth);
  EXPECT_FALSE(parseStateSource("GT", &s));
  EXPECT_FALSE(parseStateSource("", &s));
  EXPECT_EQ(s, StateSource::kGroundTruth);  // unchanged on failure
  EXPECT_STREQ(toString(StateSource::kVo), "vo");
  EXPECT_STREQ(toString(StateSource::kGroundTruth), "gt");
}

TEST(ConfigTrial, UnknownStateSourceNamesKeyAndValue) {
  const auto file = test::writeFile(test::tempDir() / "trial.yaml", "camera_rate_hz: 10\nstate_source: mocap\n");
  const std::string msg = inputError([&] { loadTrialConfig(file); });
  EXPECT_NE(msg.find(file.string() + ":2: key 'state_source' has value 'mocap', expected one of gt, vo"),
            std::string::npos)
      << msg;
}

template <typename Config>
std::string invalidArgument(const Config& config) {
  try {
    config.validate();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(ConfigTrial, ImuValidationNamesFieldAndValue) {
  EXPECT_EQ(invalidArgument(ImuConfig{}), "");
  ImuConfig imu;
  imu.accel_noise_m_s2 = -1.0;
  EXPECT_EQ(invalidArgument(imu), "accel_noise_m_s2 = -1: must be >= 0");
  imu = ImuConfig{};
  imu.gyro_bias_rad_s = std::nan("");
  EXPECT_EQ(invalidArgument(imu).rfind("gyro_bias_rad_s = ", 0), 0u) << invalidArgument(imu);
  imu = ImuConfig{};
  imu.accel_bias_m_s2 = 0.0;  // a perfect IMU is allowed
  EXPECT_EQ(invalidArgument(imu), "");
}

TEST(ConfigTrial, OnlineKeysAreValidatedWithFieldAndValue) {
  TrialConfig t;
  t.online.plan_latency_s = -0.1;
  EXPECT_EQ(invalidArgument(t), "plan_latency_s = -0.1: must be in [0, 10]");
  t = TrialConfig{};
  t.online.replan_period_s = 0.4;  // not beyond the latency: a plan would be asked before the last took effect
  EXPECT_EQ(invalidArgument(t), "replan_period_s = 0.4: must be > plan_latency_s and <= 60");
  t = TrialConfig{};
  t.online.map_every_frames = 0;
  EXPECT_EQ(invalidArgument(t), "map_every_frames = 0: must be in [1, 100]");
  t = TrialConfig{};
  t.online.prior_radius_m = 0.0;
  EXPECT_EQ(invalidArgument(t), "prior_radius_m = 0: must be > 0");
  t = TrialConfig{};
  t.online.guard_inliers = 0;
  EXPECT_EQ(invalidArgument(t), "guard_inliers = 0: must be in [1, 10000]");
  t = TrialConfig{};
  t.online.guard_range_m = 0.0;
  EXPECT_EQ(invalidArgument(t), "guard_range_m = 0: must be in (0, 100]");
  t = TrialConfig{};
  t.online.map_range_m = 0.0;
  EXPECT_EQ(invalidArgument(t), "map_range_m = 0: must be in (0, 100]");
  t = TrialConfig{};
  t.online.look_ahead_best_view = true;
  EXPECT_EQ(invalidArgument(t), "");
  t.online.look_ahead_keeps_tracking = true;
  EXPECT_EQ(invalidArgument(t),
            "look_ahead_best_view = true: not with look_ahead_keeps_tracking = true (two rules for the same yaw)");
  t = TrialConfig{};
  t.online.look_probe = true;
  EXPECT_EQ(invalidArgument(t),
            "look_probe = true: needs look_advance = true (it probes where the vehicle cannot advance)");
  t.online.look_advance = true;
  EXPECT_EQ(invalidArgument(t), "");
  t = TrialConfig{};
  t.online.look_keep_class = true;
  EXPECT_EQ(invalidArgument(t),
            "look_keep_class = true: needs look_then_fly = true (it keeps the class the explorer flies)");
  t.online.look_then_fly = true;
  EXPECT_EQ(invalidArgument(t), "");
  t = TrialConfig{};
  t.online.look_fallback = true;
  EXPECT_EQ(invalidArgument(t),
            "look_fallback = true: needs look_then_fly = true (it is what a plan does when no look is left)");
  t.online.look_then_fly = true;
  EXPECT_EQ(invalidArgument(t), "");
  t = TrialConfig{};
  t.online.look_fov_margin_deg = 7.5;
  EXPECT_EQ(invalidArgument(t),
            "look_fov_margin_deg > 0: needs look_then_fly = true (it narrows the views the explorer rates)");
  t.online.look_then_fly = true;
  EXPECT_EQ(invalidArgument(t), "");
  t.online.look_fov_margin_deg = -1.0;
  EXPECT_EQ(invalidArgument(t), "look_fov_margin_deg = -1: must be in [0, 45]");
  t = TrialConfig{};
  t.online.look_then_fly = true;
  t.online.look_fallback_floor = 100.0;
  EXPECT_EQ(invalidArgument(t),
            "look_fallback_floor > 0: needs look_fallback = true (the search is made again before the fallback)");
  t.online.look_fallback = true;
  EXPECT_EQ(invalidArgument(t), "");
  t.online.look_fallback_floor = 150.0;
  EXPECT_EQ(invalidArgument(t), "look_fallback_floor = 150: must be below look_min_detections");
  t = TrialConfig{};
  t.online.look_hold_margin = 0.2;
  EXPECT_EQ(invalidArgument(t),
            "look_hold_margin > 0: needs look_then_fly = true (it is asked of the views the explorer stops at)");
  t.online.look_then_fly = true;
  EXPECT_EQ(invalidArgument(t), "");
  t.online.look_hold_margin = std::nan("");
  EXPECT_EQ(invalidArgument(t), "look_hold_margin = nan: must be in [0, 10]");
  t = TrialConfig{};
  t.online.look_along = true;
  EXPECT_EQ(invalidArgument(t), "look_along = true: needs look_then_fly = true (it orders the explorer's looks)");
  t.online.look_then_fly = true;
  EXPECT_EQ(invalidArgument(t), "");
  t = TrialConfig{};
  t.online.look_classes = true;
  EXPECT_EQ(invalidArgument(t), "look_classes = true: needs look_then_fly = true (it widens the explorer's search)");
  t.online.look_then_fly = true;
  EXPECT_EQ(invalidArgument(t), "");
  t = TrialConfig{};
  t.online.look_guard = true;
  const std::string look_guard_needs =
      "look_guard = true: needs look_then_fly = true and guard_lead_s > 0 (it rates the look's view that far ahead)";
  EXPECT_EQ(invalidArgument(t), look_guard_needs);
  t.online.look_then_fly = true;
  EXPECT_EQ(invalidArgument(t), look_guard_needs);  // no lead
  t.online.guard_lead_s = 0.6;
  EXPECT_EQ(invalidArgument(t), "");
  t.online.look_then_fly = false;
  EXPECT_EQ(invalidArgument(t), look_guard_needs);
  t = TrialConfig{};
  t.online.look_guard_routes = true;
  EXPECT_EQ(invalidArgument(t), "look_guard_routes = true: needs look_guard = true (it widens what that guards)");
  t = TrialConfig{};
  t.online.guard_still = true;
  EXPECT_EQ(invalidArgument(t), "guard_still = true: needs guard_tracking = true (it is how the guard trips)");
  t.online.guard_tracking = true;
  EXPECT_EQ(invalidArgument(t), "");
  t = TrialConfig{};
  t.online.guard_planned_turn = true;
  t.online.guard_tracking = true;
  EXPECT_EQ(
      invalidArgument(t),
      "guard_planned_turn = true: needs guard_tracking = true and guard_lead_s > 0 (it is what the lead foresees)");
  t.online.guard_lead_s = 0.6;
  EXPECT_EQ(invalidArgument(t), "");
  t = TrialConfig{};
  t.online.look_stall_s = 60.0;
  EXPECT_EQ(invalidArgument(t), "look_stall_s > 0: needs look_then_fly = true (it is when the looks have stalled)");
  t.online.look_then_fly = true;
  EXPECT_EQ(invalidArgument(t), "");
  t.online.look_stall_s = -1.0;
  EXPECT_EQ(invalidArgument(t), "look_stall_s = -1: must be in [0, 3600]");
  // Online, the vehicle flies on the pose it maps at.
  t = TrialConfig{};
  t.online.mode = TrialMode::kOnline;
  EXPECT_EQ(invalidArgument(t),
            "state_source = gt: must be vo in online mode with map_pose estimate (an online trial flies on the "
            "pose it maps at)");
  t.state_source = StateSource::kVo;
  EXPECT_EQ(invalidArgument(t), "");
  t.online.map_pose = MapPose::kTruth;
  EXPECT_EQ(invalidArgument(t).rfind("state_source = vo: must be gt in online mode with map_pose truth", 0), 0u);
  // Prior mode ignores the online keys' pairing with the state source.
  t.online.mode = TrialMode::kPrior;
  EXPECT_EQ(invalidArgument(t), "");
}

TEST(ConfigTrial, UnknownTrialModeNamesKeyAndValue) {
  const auto file = test::writeFile(test::tempDir() / "trial.yaml", "mode: sideways\n");
  const std::string msg = inputError([&] { loadTrialConfig(file); });
  EXPECT_NE(msg.find(file.string() + ":1: key 'mode' has value 'sideways', expected one of prior, online"),
            std::string::npos)
      << msg;
}

TEST(ConfigTrial, TrialValidationNamesDottedFieldAndValue) {
  EXPECT_EQ(invalidArgument(TrialConfig{}), "");
  TrialConfig t;
  t.camera_rate_hz = 0.0;
  EXPECT_EQ(invalidArgument(t), "camera_rate_hz = 0: must be > 0");
  t = TrialConfig{};
  t.goal_radius_m = -0.5;
  EXPECT_EQ(invalidArgument(t), "goal_radius_m = -0.5: must be > 0");
  t = TrialConfig{};
  t.flight.takeoff_speed_m_s = 0.0;
  EXPECT_EQ(invalidArgument(t).rfind("flight.takeoff_speed_m_s", 0), 0u) << invalidArgument(t);
  t = TrialConfig{};
  t.imu.gyro_noise_rad_s = -2.0;
  EXPECT_EQ(invalidArgument(t), "imu.gyro_noise_rad_s = -2: must be >= 0");
  t = TrialConfig{};
  t.estimator.history_s = 0.0;
  EXPECT_EQ(invalidArgument(t).rfind("estimator.history_s", 0), 0u) << invalidArgument(t);
}

// --- --set overrides -----------------------------------------------------------------------

TEST(ConfigOverrides, NestedKeysListsAndScalars) {
  const YamlDoc doc = YamlDoc::fromOverrides({"start=[1, 2, 1, 0.5]", "trial.state_source=vo", "camera.width_px=320",
                                              "camera.height_px=240", "planner.rrt_star.samples=500",
                                              "vo.features.max_features=800", "trial.imu={gyro_bias_rad_s: 0}"});
  EXPECT_TRUE(doc.isOverrides());
  const YAML::Node& r = doc.root();
  ASSERT_TRUE(r["start"].IsSequence());
  EXPECT_EQ(r["start"].size(), 4u);
  EXPECT_EQ(r["start"][3].Scalar(), "0.5");
  EXPECT_EQ(r["trial"]["state_source"].Scalar(), "vo");
  EXPECT_EQ(r["camera"]["width_px"].Scalar(), "320");
  EXPECT_EQ(r["camera"]["height_px"].Scalar(), "240");
  EXPECT_EQ(r["planner"]["rrt_star"]["samples"].Scalar(), "500");
  EXPECT_EQ(r["vo"]["features"]["max_features"].Scalar(), "800");
  EXPECT_EQ(r["trial"]["imu"]["gyro_bias_rad_s"].Scalar(), "0");
  EXPECT_EQ(keyPaths(r),
            (std::vector<std::string>{"start", "trial", "trial.state_source", "trial.imu", "trial.imu.gyro_bias_rad_s",
                                      "camera", "camera.width_px", "camera.height_px", "planner", "planner.rrt_star",
                                      "planner.rrt_star.samples", "vo", "vo.features", "vo.features.max_features"}));
  EXPECT_EQ(keyPaths(YamlDoc::fromOverrides({}).root()).size(), 0u);
}

TEST(ConfigOverrides, ErrorsAtANodeNameItsAssignment) {
  const YamlDoc doc = YamlDoc::fromOverrides({"seed=2", "camera={width_px: [3]}", "trial.pipeline=maybe"});
  EXPECT_EQ(doc.name(), "--set overrides");
  EXPECT_EQ(inputError([&] { doc.fail(doc.root()["camera"]["width_px"][0], "bad"); }),
            "--set camera={width_px: [3]}: bad");
  EXPECT_EQ(inputError([&] { doc.fail(doc.root()["trial"]["pipeline"], "bad"); }), "--set trial.pipeline=maybe: bad");
  EXPECT_EQ(inputError([&] { doc.fail(doc.root()["trial"], "bad"); }), "--set overrides: bad");
  EXPECT_EQ(doc.assignmentFor("camera.width_px"), "camera={width_px: [3]}");
  EXPECT_EQ(doc.assignmentFor("trial"), "trial.pipeline=maybe");
  EXPECT_EQ(doc.assignmentFor("vo"), "");
}

TEST(ConfigOverrides, MalformedAssignmentsAreNamed) {
  const auto error = [](const std::vector<std::string>& a) { return inputError([&] { YamlDoc::fromOverrides(a); }); };
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"camera.width_px"}, "--set camera.width_px: no '='"},
      {{"=3"}, "--set =3: empty key"},
      {{"a..b=1"}, "--set a..b=1: empty segment in key 'a..b'"},
      {{".a=1"}, "--set .a=1: empty segment"},
      {{"a.=1"}, "--set a.=1: empty segment"},
      {{"a=1", "a.b=2"}, "--set a.b=2: key 'a' is both a value and a mapping"},
      {{"a.b.c=2", "a.b=1"}, "--set a.b=1: key 'a.b' is both a value and a mapping"},
      {{"a.b=1", "a.c=1", "a.b=2"}, "--set a.b=2: key 'a.b' is set twice"},
      {{"seed="}, "--set seed=: no value"},
      {{"start=[1, 2"}, "--set start=[1, 2: YAML syntax error"},
  };
  for (const auto& [assignments, expected] : cases) {
    const std::string msg = error(assignments);
    EXPECT_EQ(msg.rfind(expected, 0), 0u) << "got: " << msg << "\nexpected: " << expected;
  }
}

class ConfigScenario : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::tempDir(); }
  std::filesystem::path scenario(const std::string& body) { return test::smokeScenario(dir_, body); }
  std::string error(const std::filesystem::path& file, const std::vector<std::string>& set) {
    const YamlDoc overrides = YamlDoc::fromOverrides(set);
    return inputError([&] { loadScenario(file, &overrides); });
  }
  std::filesystem::path dir_;
};

TEST_F(ConfigScenario, WrongTypeViaSetNamesTheAssignment) {
  const std::string msg = error(scenario(""), {"seed=4", "camera.width_px=abc"});
  EXPECT_EQ(msg, "--set camera.width_px=abc: key 'camera.width_px' has value 'abc', expected an integer");
  EXPECT_EQ(error(scenario(""), {"start=[1, 2, 1]"}),
            "--set start=[1, 2, 1]: key 'start' has value '[1, 2, 1]', expected a list of 4 finite numbers");
  EXPECT_EQ(error(scenario(""), {"trial.state_source=mocap"}),
            "--set trial.state_source=mocap: key 'trial.state_source' has value 'mocap', expected one of gt, vo");
  EXPECT_EQ(error(scenario(""), {"seed=-2"}), "--set seed=-2: key 'seed' has value '-2', expected an integer >= 0");
  EXPECT_EQ(error(scenario(""), {"camera=5"}), "--set camera=5: 'camera' must be a mapping");
  EXPECT_EQ(error(scenario(""), {"goal=[9, 0, 1, 0]"}).rfind("--set goal=[9, 0, 1, 0]: key 'goal' lies outside", 0),
            0u);
}

TEST_F(ConfigScenario, UnknownKeyViaSetNamesTheAssignment) {
  const std::string msg = error(scenario(""), {"camera.widht_px=320"});
  EXPECT_EQ(msg.rfind("--set camera.widht_px=320: unknown key 'camera.widht_px' (allowed: name, width_px,", 0), 0u)
      << msg;
  const std::string top = error(scenario(""), {"camra.width_px=320"});
  EXPECT_EQ(top.rfind("--set camra.width_px=320: unknown key 'camra' (allowed: scene, vehicle, seed, start, goal,", 0),
            0u)
      << top;
  const std::string nested = error(scenario(""), {"vo={features: {max_feature: 3}}"});
  EXPECT_EQ(nested.rfind("--set vo={features: {max_feature: 3}}: unknown key 'vo.features.max_feature'", 0), 0u)
      << nested;
}

TEST_F(ConfigScenario, ConfigFileKeysCannotBeSet) {
  const std::string msg = error(scenario(""), {"camera_config=cam.yaml"});
  EXPECT_EQ(msg.rfind("--set camera_config=cam.yaml: key 'camera_config' names a file and cannot be set with --set", 0),
            0u)
      << msg;
}

TEST_F(ConfigScenario, ValidationFailureNamesTheAssignmentOrTheFile) {
  const auto file = scenario("vo: {weak_inliers: 40}\n");
  const std::string camera = error(file, {"camera.max_depth_m=-1"});
  EXPECT_EQ(camera.rfind("--set camera.max_depth_m=-1: max_depth_m = -1", 0), 0u) << camera;
  // Nested configs name their fields without the nesting; the one --set key of that name is meant.
  EXPECT_EQ(error(file, {"controller.position.pos_p_xy=-1"}),
            "--set controller.position.pos_p_xy=-1: pos_p_xy = -1: must be > 0");
  EXPECT_EQ(error(file, {"trial.imu.accel_bias_m_s2=-1"}),
            "--set trial.imu.accel_bias_m_s2=-1: imu.accel_bias_m_s2 = -1: must be >= 0");
  // The offending key is the file's; the override only made it invalid.
  EXPECT_EQ(error(file, {"vo.min_inliers=50"}),
            file.string() + " (with --set overrides): weak_inliers = 40: must be >= min_inliers");
  // Without overrides the file alone is named.
  EXPECT_EQ(error(scenario("trial: {goal_radius_m: 0}\n"), {}), file.string() + ": goal_radius_m = 0: must be > 0");
}

// trial.map_clear_no_return clears to the camera's max depth less three sigmas of its depth noise:
// a camera whose noise leaves nothing is named with both its settings.
TEST_F(ConfigScenario, ClearingWithoutAReturnNeedsDepthLeftAfterTheNoise) {
  const auto file = scenario("trial: {map_clear_no_return: true}\n");
  EXPECT_EQ(error(file, {}), "");
  EXPECT_EQ(error(file, {"camera.depth_noise_sigma_per_m2=0.002"}), "");  // 10 m less 0.6 m
  EXPECT_EQ(error(file, {"camera.depth_noise_sigma_per_m2=0.05"}),
            file.string() +
                " (with --set overrides): key 'trial.map_clear_no_return' is true, but camera.max_depth_m 10 less "
                "three sigmas of its depth noise (camera.depth_noise_sigma_per_m2 0.05) leaves -5 m to clear "
                "(needs > 0.5)");
  EXPECT_EQ(error(scenario(""), {"camera.depth_noise_sigma_per_m2=0.05"}), "");  // the option off
}

// trial.look_fov_margin_deg narrows the explorer's rated field of view on each side: a margin that
// leaves none of the perception model's horizontal field is named with both settings.
TEST_F(ConfigScenario, TheLooksFieldOfViewMarginMustLeaveAField) {
  const auto file =
      scenario("trial: {mode: online, state_source: vo, look_then_fly: true, look_fov_margin_deg: 7.5}\n");
  EXPECT_EQ(error(file, {}), "");
  EXPECT_EQ(error(file, {"trial.look_fov_margin_deg=37"}), "");  // 74 of the model's 75.2 deg
  EXPECT_EQ(error(file, {"trial.look_fov_margin_deg=40"}),
            file.string() +
                " (with --set overrides): key 'trial.look_fov_margin_deg' is 40, which on each side leaves nothing "
                "of planner.visibility.hfov_rad 1.3125 (needs less than half of it)");
}

TEST_F(ConfigScenario, LayersDefaultsFileInlineAndOverrides) {
  test::writeFile(dir_ / "cam.yaml", "width_px: 400\nheight_px: 300\nnear_clip_m: 0.06\nrgb_noise_sigma: 1\n");
  test::writeFile(dir_ / "trial.yaml", "state_source: vo\ncamera_rate_hz: 25\nflight: {hold_s: 3}\n");
  test::writeFile(dir_ / "vo.yaml", "min_inliers: 20\nweak_inliers: 40\n");
  test::writeFile(dir_ / "ctl.yaml", "position: {vel_p_xy: 2.5}\n");
  const auto file = scenario(
      "camera_config: cam.yaml\ncamera: {height_px: 320, rgb_noise_sigma: 2}\n"
      "trial_config: trial.yaml\ntrial: {camera_rate_hz: 50, flight: {settle_s: 0.5}}\n"
      "vo_config: vo.yaml\ncontroller_config: ctl.yaml\ncontroller: {rates_hz: {position: 50}}\n"
      "planner: {rrt_star: {samples: 300}}\nstart: [-2, 0, 1, 0]\n");
  const YamlDoc overrides =
      YamlDoc::fromOverrides({"camera.rgb_noise_sigma=3", "trial.flight.settle_s=0.25", "vo.features.max_features=600",
                              "seed=9", "goal=[2, 1, 1.5, 0.1]", "controller.position.vel_p_xy=2"});
  const Scenario s = loadScenario(file, &overrides);
  const CameraConfig defaults;
  EXPECT_EQ(s.camera.width_px, 400);                    // file
  EXPECT_EQ(s.camera.near_clip_m, 0.06);                // file
  EXPECT_EQ(s.camera.height_px, 320);                   // inline over file
  EXPECT_EQ(s.camera.rgb_noise_sigma, 3.0);             // --set over inline over file
  EXPECT_EQ(s.camera.far_clip_m, defaults.far_clip_m);  // default
  EXPECT_EQ(s.trial.state_source, StateSource::kVo);    // file
  EXPECT_EQ(s.trial.camera_rate_hz, 50.0);              // inline
  EXPECT_EQ(s.trial.flight.hold_s, 3.0);                // file, in a section
  EXPECT_EQ(s.trial.flight.settle_s, 0.25);             // --set
  EXPECT_EQ(s.trial.goal_radius_m, TrialConfig{}.goal_radius_m);
  EXPECT_EQ(s.vo.min_inliers, 20);
  EXPECT_EQ(s.vo.features.max_features, 600);
  EXPECT_EQ(s.vo.features.grid_cols, vo::FeatureConfig{}.grid_cols);
  EXPECT_EQ(s.controller.position.vel_p_xy, 2.0);
  EXPECT_EQ(s.controller.position_rate_hz, 50.0);
  EXPECT_EQ(s.controller.attitude_rate_hz, control::CascadeConfig{}.attitude_rate_hz);
  EXPECT_EQ(s.planner.rrt_star.samples, 300);
  EXPECT_EQ(s.seed, 9u);
  EXPECT_EQ(s.scene.start.p_WB, Eigen::Vector3d(-2, 0, 1));  // scenario over scene
  EXPECT_EQ(s.scene.goal.p_WB, Eigen::Vector3d(2, 1, 1.5));  // --set
  EXPECT_EQ(s.scene.goal.yaw_rad, 0.1);

  // Without the overrides, the file and inline layers alone.
  const Scenario plain = loadScenario(file);
  EXPECT_EQ(plain.camera.rgb_noise_sigma, 2.0);
  EXPECT_EQ(plain.trial.flight.settle_s, 0.5);
  EXPECT_EQ(plain.seed, 3u);
  EXPECT_EQ(plain.scene.goal.p_WB, Eigen::Vector3d(3, 0, 1));  // the scene's
}

TEST_F(ConfigScenario, SceneOverrideIsRelativeToTheCurrentDirectory) {
  const auto file = scenario("");
  const std::filesystem::path cwd = std::filesystem::current_path();
  std::filesystem::current_path(test::sourceDir() / "configs");
  const YamlDoc good = YamlDoc::fromOverrides({"scene=scenes/corridor.yaml"});
  std::string msg;
  Scenario s;
  try {
    s = loadScenario(file, &good);
    msg = error(file, {"scene=scenes/nowhere.yaml"});
  } catch (...) {
    std::filesystem::current_path(cwd);
    throw;
  }
  std::filesystem::current_path(cwd);
  EXPECT_EQ(s.scene.source, test::sourceDir() / "configs/scenes/corridor.yaml");
  EXPECT_EQ(msg.rfind("--set scene=scenes/nowhere.yaml: key 'scene' has value 'scenes/nowhere.yaml': file ", 0), 0u)
      << msg;
}

TEST_F(ConfigScenario, SectionsDefaultAndMessagesStay) {
  for (const char* name : {"smoke", "storage", "gallery", "corridor"}) {
    EXPECT_EQ(
        inputError([&] { loadScenario(test::sourceDir() / "configs/scenarios" / (std::string(name) + ".yaml")); }), "")
        << name;
  }
  const Scenario s = loadScenario(scenario(""));
  EXPECT_EQ(s.seed, 3u);
  PlannerSettings planner;  // the default model resolved to its file
  planner.perception.information.track_model = (test::sourceDir() / "configs/track_model.json").string();
  EXPECT_EQ(dump(toYaml(s.planner)), dump(toYaml(planner)));
  EXPECT_EQ(dump(toYaml(s.camera)), dump(toYaml(CameraConfig{})));
  EXPECT_EQ(dump(toYaml(s.controller)), dump(toYaml(control::CascadeConfig{})));
  EXPECT_EQ(dump(toYaml(s.vo)), dump(toYaml(vo::OdometryConfig{})));
  EXPECT_EQ(dump(toYaml(s.trial)), dump(toYaml(TrialConfig{})));
  const auto bad_seed = test::writeFile(
      dir_ / "bad.yaml", "scene: " + (test::sourceDir() / "configs/scenes/smoke.yaml").string() + "\nseed: -1\n");
  EXPECT_EQ(inputError([&] { loadScenario(bad_seed); }),
            bad_seed.string() + ":2: key 'seed' has value '-1', expected an integer >= 0");
  const auto unknown = scenario("cammera: {}\n");
  EXPECT_NE(inputError([&] { loadScenario(unknown); }).find(unknown.string() + ":3: unknown key 'cammera'"),
            std::string::npos);
  const auto missing = scenario("camera_config: nowhere.yaml\n");
  EXPECT_NE(inputError([&] { loadScenario(missing); }).find("key 'camera_config' has value 'nowhere.yaml': file"),
            std::string::npos);
}

// --- The resolved scenario loads back to itself ----------------------------------------------

void expectSameScenario(const Scenario& a, const Scenario& b) {
  EXPECT_EQ(a.scene.source, b.scene.source);
  EXPECT_EQ(a.scene.mjcf, b.scene.mjcf);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.scene.start.p_WB, b.scene.start.p_WB);
  EXPECT_EQ(a.scene.start.yaw_rad, b.scene.start.yaw_rad);
  EXPECT_EQ(a.scene.goal.p_WB, b.scene.goal.p_WB);
  EXPECT_EQ(a.scene.goal.yaw_rad, b.scene.goal.yaw_rad);
  EXPECT_EQ(dump(toYaml(a.planner)), dump(toYaml(b.planner)));
  EXPECT_EQ(dump(toYaml(a.controller)), dump(toYaml(b.controller)));
  EXPECT_EQ(dump(toYaml(a.camera)), dump(toYaml(b.camera)));
  EXPECT_EQ(dump(toYaml(a.vo)), dump(toYaml(b.vo)));
  EXPECT_EQ(dump(toYaml(a.trial)), dump(toYaml(b.trial)));
}

TEST_F(ConfigScenario, ResolvedStorageScenarioLoadsBackIdentically) {
  const Scenario s = loadScenario(test::sourceDir() / "configs/scenarios/storage.yaml");
  const std::string text = resolvedScenarioYaml(s);
  const Scenario back = loadScenario(test::writeFile(dir_ / "resolved.yaml", text));
  expectSameScenario(s, back);
  EXPECT_EQ(resolvedScenarioYaml(back), text);
  EXPECT_EQ(text.rfind("# ", 0), 0u);
  EXPECT_NE(text.find("\nscene: " + (test::sourceDir() / "configs/scenes/storage.yaml").lexically_normal().string() +
                      "\nvehicle: " + (test::sourceDir() / "models/quadrotor.yaml").lexically_normal().string() +
                      "\nseed: 1\nstart: ["),
            std::string::npos)
      << text;
  for (const char* key : {"\nplanner:\n", "\ncontroller:\n", "\ncamera:\n", "\nvo:\n", "\ntrial:\n"}) {
    EXPECT_NE(text.find(key), std::string::npos) << key;
  }
}

TEST_F(ConfigScenario, ResolvedScenarioWithOverridesLoadsBackIdentically) {
  const auto file = scenario("camera: {width_px: 320, height_px: 240}\ntrial: {state_source: vo}\n");
  const YamlDoc overrides = YamlDoc::fromOverrides(
      {"start=[-2.9, 0.1, 1.1, 0.1]", "goal=[2.7, -0.3, 1.3, 0.7853981633974483]", "seed=12",
       "camera.depth_noise_sigma_per_m2=0.002", "vo.ratio_test=0.7", "trial.imu.gyro_bias_rad_s=1e-4",
       "controller.rate.p=[0.1, 0.1, 0.3]", "planner.selection.c_p_threshold=5.5"});
  const Scenario s = loadScenario(file, &overrides);
  const std::string text = resolvedScenarioYaml(s);
  EXPECT_NE(text.find("start: [-2.9, 0.1, 1.1, 0.1]"), std::string::npos) << text;
  EXPECT_NE(text.find("gyro_bias_rad_s: 1e-04"), std::string::npos) << text;
  const Scenario back = loadScenario(test::writeFile(dir_ / "resolved.yaml", text));
  expectSameScenario(s, back);
  EXPECT_EQ(back.camera.width_px, 320);
  EXPECT_EQ(back.trial.state_source, StateSource::kVo);
  EXPECT_EQ(back.controller.rate.p, Eigen::Vector3d(0.1, 0.1, 0.3));
  EXPECT_EQ(resolvedScenarioYaml(back), text);
}

// --- Every key is named once, in a visit ---------------------------------------------------------

// An archive that gives every field it visits a value different from the one it had (and, field
// after field, different from each other).
class Perturber {
 public:
  Perturber& operator()(const std::string&, double& v) {
    v = v * 1.5 + 0.25 + 0.001 * ++n_;
    return *this;
  }
  Perturber& operator()(const std::string&, int& v) {
    v += 3 + ++n_;
    return *this;
  }
  Perturber& operator()(const std::string&, bool& v) {
    v = !v;
    return *this;
  }
  Perturber& operator()(const std::string&, std::string& v) {
    v += "_" + std::to_string(++n_);
    return *this;
  }
  Perturber& operator()(const std::string&, Eigen::Vector3d& v) {
    v = v * 1.5 + Eigen::Vector3d(0.1, 0.2, 0.3) / 3.0 + Eigen::Vector3d::Constant(0.001 * ++n_);
    return *this;
  }
  Perturber& operator()(const std::string&, std::vector<double>& v) {
    for (double& x : v) x = x * 1.5 + 0.125;
    v.push_back(0.001 * ++n_);
    return *this;
  }
  Perturber& operator()(const std::string&, planner::Pose4& v) {
    v.p_WB += Eigen::Vector3d(0.5, -0.25, 0.125);
    v.yaw_rad += 0.001 * ++n_;
    return *this;
  }
  Perturber& operator()(const std::string&, std::filesystem::path& v) {
    v /= "x" + std::to_string(++n_);
    return *this;
  }
  template <typename Config>
  Perturber& operator()(const std::string&, Config& c) {
    c.visit(*this);
    return *this;
  }
  template <typename Fn>
  Perturber& group(const std::string&, Fn&& visit_group) {
    visit_group(*this);
    return *this;
  }
  template <typename E>
  Perturber& choice(const std::string&, E& v, const std::vector<std::pair<std::string, E>>& names) {
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (names[i].second == v) {
        v = names[(i + 1) % names.size()].second;
        return *this;
      }
    }
    return *this;
  }

 private:
  int n_ = 0;
};

// The dotted paths of the scalar (or list) values of `node`, with their text.
void leaves(const YAML::Node& node, const std::string& context, std::map<std::string, std::string>* out) {
  for (const auto& kv : node) {
    const std::string key = joinKey(context, kv.first.as<std::string>());
    if (kv.second.IsMap()) {
      leaves(kv.second, key, out);
    } else {
      (*out)[key] = dump(kv.second);
    }
  }
}

template <typename Config>
class ConfigVisit : public ::testing::Test {};

using VisitedConfigs =
    ::testing::Types<control::PositionControlConfig, control::AttitudeControlConfig, control::RateControlConfig,
                     control::CascadeConfig, control::EstimatorConfig, vo::FeatureConfig, vo::OdometryConfig,
                     planner::TopoPlannerConfig, planner::VisibilityConfig, planner::InformationConfig,
                     planner::SegmentConfig, planner::PoseGraphConfig, planner::SelectionConfig,
                     planner::PerceptionPlannerConfig, planner::RrtStarConfig, planner::TrajectoryConfig, CameraConfig,
                     FlightConfig, ImuConfig, TrialConfig, PlannerSettings, SurveyPlan, SceneConfig>;
// Each type's tests named by its place in the list, as gtest's default does; named here so that the
// macro's variadic argument is given (clang: -Wgnu-zero-variadic-macro-arguments).
struct VisitedName {
  template <typename T>
  static std::string GetName(int i) {
    return std::to_string(i);
  }
};
TYPED_TEST_SUITE(ConfigVisit, VisitedConfigs, VisitedName);

// Written with every value changed, read back over the defaults, written again: the same text,
// and every key's value differs from its default (so every key was read into its field).
TYPED_TEST(ConfigVisit, RoundTripsChangedValues) {
  TypeParam c;
  Perturber perturb;
  c.visit(perturb);
  const YAML::Node written = toYaml(c);
  const std::string text = dump(written);
  const auto file = test::writeFile(test::tempDir() / "config.yaml", text + "\n");
  const YamlDoc doc = YamlDoc::load(file);
  TypeParam back;
  readConfig(YamlArchive(doc, doc.root(), ""), &back);
  EXPECT_EQ(dump(toYaml(back)), text);

  std::map<std::string, std::string> changed, defaults;
  leaves(written, "", &changed);
  leaves(toYaml(TypeParam{}), "", &defaults);
  ASSERT_EQ(changed.size(), defaults.size());
  EXPECT_FALSE(changed.empty());
  for (const auto& [key, value] : changed) EXPECT_NE(value, defaults[key]) << key;
}

// No mapping names a key twice; toYaml writes exactly the keys the visit names, in its order.
TYPED_TEST(ConfigVisit, NamesEachKeyOnce) {
  TypeParam c;
  KeyLister keys(/*nested=*/true);
  c.visit(keys);
  std::map<std::string, int> count;
  for (const std::string& k : keys.keys()) ++count[k];
  for (const auto& [key, n] : count) EXPECT_EQ(n, 1) << "key '" << key << "' is named " << n << " times";
  EXPECT_EQ(keys.keys(), keyPaths(toYaml(c)));
}

TEST(ConfigVisitKeys, ScenarioSectionsAreNamedOnce) {
  Scenario s;
  KeyLister keys(/*nested=*/true);
  s.visitSections(keys);
  std::map<std::string, int> count;
  for (const std::string& k : keys.keys()) ++count[k];
  for (const auto& [key, n] : count) EXPECT_EQ(n, 1) << key;
  KeyLister flat;
  s.visitSections(flat);
  EXPECT_EQ(flat.keys(), (std::vector<std::string>{"planner", "controller", "camera", "vo", "trial"}));
}

// The fields that follow perception's are keys of their structs' own visits, and have none in
// planner.yaml: a file that sets one is refused.
TEST(ConfigVisitKeys, PlannerSharedFieldsHaveNoKeys) {
  PlannerSettings p;
  KeyLister all(/*nested=*/true);
  p.perception.visit(all);
  all("rrt_star", p.rrt_star);
  all("trajectory", p.trajectory);
  const std::vector<std::string> written = keyPaths(toYaml(p));
  for (const std::string& key : PlannerSettings::sharedKeys()) {
    EXPECT_NE(std::find(all.keys().begin(), all.keys().end(), key), all.keys().end()) << key;
    EXPECT_EQ(std::find(written.begin(), written.end(), key), written.end()) << key;
  }
  const auto dir = test::tempDir();
  const auto rrt =
      test::writeFile(dir / "rrt.yaml", "robot_radius_m: 0.4\nrrt_star: {samples: 5, robot_radius_m: 1}\n");
  EXPECT_EQ(inputError([&] { loadPlannerSettings(rrt); }),
            rrt.string() +
                ":2: unknown key 'rrt_star.robot_radius_m' (allowed: samples, range_m, goal_bias, goal_tolerance_m, "
                "distance_weight, perception_weight, c_p_threshold)");
  const auto topo = test::writeFile(dir / "topo.yaml", "topology: {robot_radius_m: 1}\n");
  EXPECT_NE(inputError([&] { loadPlannerSettings(topo); })
                .find("unknown key 'topology.robot_radius_m' (allowed: max_classes, max_expansions, max_length_ratio, "
                      "min_spur_length_m)"),
            std::string::npos);
  const auto traj = test::writeFile(dir / "traj.yaml", "trajectory: {robot_radius_m: 1}\n");
  EXPECT_NE(inputError([&] { loadPlannerSettings(traj); }).find("unknown key 'trajectory.robot_radius_m'"),
            std::string::npos);
  // What they follow.
  const auto shared = test::writeFile(dir / "shared.yaml",
                                      "robot_radius_m: 0.4\nslice_half_height_m: 0.2\nvisibility: {max_range_m: 5}\n"
                                      "information: {epsilon: 0.02}\ntopology: {max_classes: 4}\n");
  const PlannerSettings s = loadPlannerSettings(shared);
  EXPECT_EQ(s.rrt_star.robot_radius_m, 0.4);
  EXPECT_EQ(s.trajectory.robot_radius_m, 0.4);
  EXPECT_EQ(s.perception.topo.robot_radius_m, 0.4);
  EXPECT_EQ(s.perception.graph.robot_radius_m, 0.4);
  EXPECT_EQ(s.rrt_star.slice_half_height_m, 0.2);
  EXPECT_EQ(s.rrt_star.visibility.max_range_m, 5.0);
  EXPECT_EQ(s.rrt_star.information.epsilon, 0.02);
  EXPECT_EQ(s.rrt_star.topo.max_classes, 4);
}

TEST(ConfigArchive, ChoiceWritesNamesAndRejectsOthers) {
  TrialConfig t;
  t.state_source = StateSource::kVo;
  EXPECT_EQ(toYaml(t)["state_source"].Scalar(), "vo");
  const auto file = test::writeFile(test::tempDir() / "trial.yaml", "state_source: \"\"\n");
  EXPECT_NE(
      inputError([&] { loadTrialConfig(file); }).find("key 'state_source' has value '', expected a non-empty string"),
      std::string::npos);
}

TEST(ConfigArchive, RequiredKeysAndUnknownKeysFirst) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "world.xml", "<mujoco/>");
  // A misspelt key is reported as unknown, not as the missing key it was meant to be.
  const auto typo = test::writeFile(dir / "scene.yaml",
                                    "mjcf: world.xml\nflight_height_m: 1.0\nstrat: [0, 0, 1, 0]\ngoal: [1, 1, 1, 0]\n"
                                    "bounds: {min: [-1, -1, 0], max: [2, 2, 3]}\n"
                                    "survey: {spacing_m: 1.0, heights_m: [0.8], yaw_count: 8, clearance_m: 0.4}\n");
  EXPECT_EQ(inputError([&] { loadSceneConfig(typo); })
                .rfind(typo.string() + ":3: unknown key 'strat' (allowed: mjcf, "
                                       "flight_height_m, start, goal, bounds, survey, vehicle)",
                       0),
            0u);
  const auto nested = test::writeFile(dir / "scene2.yaml",
                                      "mjcf: world.xml\nflight_height_m: 1.0\nstart: [0, 0, 1, 0]\ngoal: [1, 1, 1, 0]\n"
                                      "bounds: {min: [-1, -1, 0]}\n"
                                      "survey: {spacing_m: 1.0, heights_m: [0.8], yaw_count: 8, clearance_m: 0.4}\n");
  EXPECT_NE(inputError([&] { loadSceneConfig(nested); }).find(":5: missing required key 'bounds.max'"),
            std::string::npos)
      << inputError([&] { loadSceneConfig(nested); });
  const auto empty = test::writeFile(dir / "scene3.yaml",
                                     "mjcf: world.xml\nflight_height_m: 1.0\nstart: [0, 0, 1, 0]\ngoal: [1, 1, 1, 0]\n"
                                     "bounds: {min: [-1, -1, 0], max: [2, 2, 3]}\n"
                                     "survey: {spacing_m: 1.0, heights_m: [], yaw_count: 8, clearance_m: 0.4}\n");
  EXPECT_NE(inputError([&] { loadSceneConfig(empty); }).find("key 'survey.heights_m' must be a non-empty list"),
            std::string::npos);
}

// --- The built-in defaults of every section -------------------------------------------------

TEST(ConfigDefaults, LoadBackAsTheScenariosSections) {
  const std::string text = defaultSectionsYaml();
  EXPECT_EQ(text.rfind("# ", 0), 0u);
  const YAML::Node doc = YAML::Load(text);
  EXPECT_EQ(keyPaths(doc).size(),
            keyPaths(toYaml(PlannerSettings{})).size() + keyPaths(toYaml(control::CascadeConfig{})).size() +
                keyPaths(toYaml(CameraConfig{})).size() + keyPaths(toYaml(vo::OdometryConfig{})).size() +
                keyPaths(toYaml(TrialConfig{})).size() + 5u);
  EXPECT_EQ(dump(doc["planner"]), dump(toYaml(PlannerSettings{})));
  EXPECT_EQ(dump(doc["controller"]), dump(toYaml(control::CascadeConfig{})));
  EXPECT_EQ(dump(doc["camera"]), dump(toYaml(CameraConfig{})));
  EXPECT_EQ(dump(doc["vo"]), dump(toYaml(vo::OdometryConfig{})));
  EXPECT_EQ(dump(doc["trial"]), dump(toYaml(TrialConfig{})));

  // A scenario of a scene, a seed and these sections is the scenario with the built-in settings.
  const auto dir = test::tempDir();
  const auto file =
      test::writeFile(dir / "defaults.yaml",
                      "scene: " + (test::sourceDir() / "configs/scenes/smoke.yaml").string() + "\nseed: 3\n" + text);
  const Scenario s = loadScenario(file);
  const Scenario plain = loadScenario(test::writeFile(
      dir / "plain.yaml", "scene: " + (test::sourceDir() / "configs/scenes/smoke.yaml").string() + "\nseed: 3\n"));
  expectSameScenario(s, plain);
  EXPECT_EQ(resolvedScenarioYaml(s), resolvedScenarioYaml(plain));
  // ... and the resolved config.yaml holds them, byte for byte, the default model named by its file.
  std::string body = text.substr(text.find("\nplanner:\n") + 1);
  const std::string model_key = "track_model: default\n";
  ASSERT_NE(body.find(model_key), std::string::npos);
  body.replace(body.find(model_key), model_key.size(),
               "track_model: " + (test::sourceDir() / "configs/track_model.json").string() + "\n");
  EXPECT_NE(resolvedScenarioYaml(s).find(body), std::string::npos);
}

TEST(ConfigDefaults, ListEveryKeyOfTheShippedFiles) {
  const YAML::Node defaults = YAML::Load(defaultSectionsYaml());
  for (const auto& [section, file] : std::vector<std::pair<std::string, std::string>>{{"trial", "trial.yaml"},
                                                                                      {"vo", "vo.yaml"},
                                                                                      {"camera", "camera.yaml"},
                                                                                      {"controller", "controller.yaml"},
                                                                                      {"planner", "planner.yaml"}}) {
    const std::vector<std::string> listed = keyPaths(defaults[section]);
    const YAML::Node shipped = YAML::LoadFile((test::sourceDir() / "configs" / file).string());
    std::map<std::string, std::string> shipped_leaves, listed_leaves;
    leaves(shipped, "", &shipped_leaves);
    leaves(defaults[section], "", &listed_leaves);
    for (const std::string& key : keyPaths(shipped)) {
      EXPECT_NE(std::find(listed.begin(), listed.end(), key), listed.end()) << file << ": " << key;
      // A mapping in the file is a mapping in the defaults, a value a value.
      EXPECT_EQ(shipped_leaves.count(key), listed_leaves.count(key)) << file << ": " << key;
    }
  }
}

}  // namespace
}  // namespace tgnav::harness
