// The learned perception model's file (harness/config/track_model_file.h) and the scenario key
// that names it: a good file gives the model the planner evaluates; a missing or malformed one is
// one line naming the file and the key.
#include "harness/config/track_model_file.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>

#include "harness/base/errors.h"
#include "harness/config/scenario.h"
#include "harness/config/yaml_util.h"
#include "planner/perception.h"
#include "test_util.h"

namespace tgnav::harness {
namespace {

using test::inputError;

const char* kGood = R"({"format": "tgnav-track-model", "version": 1, "kind": "logistic",
  "features": ["log_detections", "coverage"], "mean": [3.0, 0.2], "scale": [0.5, 0.1],
  "weights": [2.0, -1.0], "intercept": 0.25, "fitted_on": {"scenes": ["room-501"]}})";

TEST(TrackModelFile, ReadsAGoodFile) {
  const auto file = test::writeFile(test::tempDir() / "model.json", kGood);
  const planner::TrackModel m = loadTrackModel(file);
  ASSERT_EQ(m.terms.size(), 2u);
  EXPECT_EQ(m.terms[0].feature, planner::TrackFeature::kLogDetections);
  EXPECT_EQ(m.terms[1].feature, planner::TrackFeature::kCoverage);
  EXPECT_EQ(m.terms[1].mean, 0.2);
  EXPECT_EQ(m.terms[0].scale, 0.5);
  EXPECT_EQ(m.terms[1].weight, -1.0);
  EXPECT_EQ(m.intercept, 0.25);
  planner::ViewSupport s;
  s.detections = std::exp(3.0) - 1.0;                   // log1p: the mean
  for (int cell = 0; cell < 12; ++cell) s.cover(cell);  // coverage 0.25: half a scale above
  EXPECT_NEAR(m.probability(s), 1.0 / (1.0 + std::exp(-(0.25 - 0.5))), 1e-12);
}

// Version 2: a term may be a ramp of its feature, clamp((f - lo) / (hi - lo), 0, 1); one feature
// may then appear in several terms (a monotone piecewise-linear logit).
const char* kRamps = R"({"format": "tgnav-track-model", "version": 2, "kind": "logistic",
  "features": ["log_inner_detections", "log_inner_detections", "mean_range_m"],
  "ramps": [[1.0, 2.0], [2.0, 4.0], null], "mean": [0.5, 0.25, 3.0], "scale": [0.5, 0.25, 2.0],
  "weights": [1.5, 2.0, -0.5], "intercept": 0.5})";

TEST(TrackModelFile, ReadsAndEvaluatesRamps) {
  const auto file = test::writeFile(test::tempDir() / "ramps.json", kRamps);
  const planner::TrackModel m = loadTrackModel(file);
  ASSERT_EQ(m.terms.size(), 3u);
  EXPECT_TRUE(m.terms[0].ramp);
  EXPECT_EQ(m.terms[1].ramp_lo, 2.0);
  EXPECT_EQ(m.terms[1].ramp_hi, 4.0);
  EXPECT_FALSE(m.terms[2].ramp);
  const auto p = [&](double log_inner, double range_m) {
    planner::ViewSupport s;
    s.inner_detections = std::expm1(log_inner);
    s.detections = s.inner_detections;  // the mean range is detection-weighted
    s.range_detections = range_m * s.detections;
    const double r1 = std::clamp(log_inner - 1.0, 0.0, 1.0);
    const double r2 = std::clamp((log_inner - 2.0) / 2.0, 0.0, 1.0);
    const double z = 0.5 + 1.5 * (r1 - 0.5) / 0.5 + 2.0 * (r2 - 0.25) / 0.25 - 0.5 * (range_m - 3.0) / 2.0;
    EXPECT_NEAR(m.probability(s), 1.0 / (1.0 + std::exp(-z)), 1e-12) << log_inner;
    return m.probability(s);
  };
  // below the first knot and above the last, the ramps are flat: more texture changes nothing there
  EXPECT_NEAR(p(0.2, 3.0), p(0.9, 3.0), 1e-12);
  EXPECT_NEAR(p(4.5, 3.0), p(6.0, 3.0), 1e-12);
  EXPECT_LT(p(1.5, 3.0), p(3.0, 3.0));
}

TEST(TrackModelFile, EveryMalformedFileIsOneLineNamingFileAndKey) {
  const auto dir = test::tempDir();
  const std::string good = kGood;
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    text.replace(text.find(from), from.size(), to);
    return text;
  };
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"{", "not JSON"},
      {"[1, 2]", "expected a JSON object"},
      {with("\"tgnav-track-model\"", "\"other\""), "key 'format' has value '\"other\"'"},
      {with("\"version\": 1", "\"version\": 3"), "key 'version' has value '3', expected 1 or 2"},
      {with("\"weights\"", "\"ramps\": [null, [0, 1]], \"weights\""), "key 'ramps' needs version 2"},
      {with("\"version\": 1", "\"version\": 2").replace(good.find("\"weights\""), 0, "\"ramps\": [null], "),
       "key 'ramps' has value '[null]', expected an array of 2 entries"},
      {with("\"version\": 1", "\"version\": 2").replace(good.find("\"weights\""), 0, "\"ramps\": [null, [1, 1]], "),
       "key 'ramps[1]' has value '[1,1]', expected lo < hi"},
      {with("\"version\": 1", "\"version\": 2").replace(good.find("\"weights\""), 0, "\"ramps\": [null, [1]], "),
       "key 'ramps[1]' has value '[1]', expected null or [lo, hi]"},
      {with("\"version\": 1", "\"version\": 2").replace(good.find("\"weights\""), 0, "\"ramps\": [null, [1, \"x\"]], "),
       "key 'ramps[1][1]' has value '\"x\"', expected a number"},
      {with("\"logistic\"", "\"tree\""), "key 'kind' has value '\"tree\"'"},
      {with("\"coverage\"]", "\"colour\"]"),
       "key 'features[1]' has value '\"colour\"', expected one of log_detections"},
      {with("\"features\": [\"log_detections\", \"coverage\"]", "\"features\": []"), "key 'features' has value '[]'"},
      {with("[3.0, 0.2]", "[3.0]"), "key 'mean' has value '[3.0]', expected an array of 2 numbers"},
      {with("[0.5, 0.1]", "[0.5, 0]"), "key 'scale[1]' has value '0.000000', expected > 0"},
      {with("[2.0, -1.0]", "[2.0, \"x\"]"), "key 'weights[1]' has value '\"x\"', expected a number"},
      {with("\"intercept\": 0.25", "\"intercept\": 1e999"), "not JSON"},
      {with("\"intercept\": 0.25,", ""), "key 'intercept' is missing"},
      {with("\"intercept\": 0.25,", "\"intercept\": 0.25, \"view_settings\": 10,"),
       "key 'view_settings' has value '10', expected an object"},
      {with("\"intercept\": 0.25,", "\"intercept\": 0.25, \"view_settings\": {\"hfov_rad\": 1},"),
       "key 'view_settings.vfov_rad' is missing"},
      {with("\"intercept\": 0.25,",
            "\"intercept\": 0.25, \"view_settings\": {\"hfov_rad\": 1, \"vfov_rad\": 1, \"min_range_m\": 0.3, "
            "\"max_range_m\": 10, \"max_incidence_rad\": 1, \"sight_to_face\": 0.5},"),
       "key 'view_settings.sight_to_face' has value '0.5', expected 0 or 1"},
  };
  for (const auto& [text, expected] : cases) {
    const auto file = test::writeFile(dir / "bad.json", text);
    const std::string msg = inputError([&] { loadTrackModel(file); });
    EXPECT_EQ(msg.rfind(file.string() + ": ", 0), 0u) << msg;
    EXPECT_NE(msg.find(expected), std::string::npos) << "got: " << msg << "\nexpected: " << expected;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  EXPECT_EQ(inputError([&] { loadTrackModel(dir / "none.json"); }), (dir / "none.json").string() + ": cannot read");
}

class TrackModelScenario : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::tempDir(); }
  std::filesystem::path scenario(const std::string& body) { return test::smokeScenario(dir_, body); }
  std::filesystem::path dir_;
};

TEST_F(TrackModelScenario, AScenarioNamesItsModelRelativeToItself) {
  test::writeFile(dir_ / "model.json", kGood);
  const Scenario s = loadScenario(scenario("planner: {information: {track_model: model.json}}\n"));
  ASSERT_NE(s.planner.perception.information.model, nullptr);
  EXPECT_EQ(s.planner.perception.information.track_model, (dir_ / "model.json").string());
  EXPECT_EQ(s.planner.rrt_star.information.model, s.planner.perception.information.model);  // one sensor model
  EXPECT_EQ(
      loadScenario(scenario("planner: {information: {track_model: none}}\n")).planner.perception.information.model,
      nullptr);  // none: the gates
}

// The default is configs/track_model.json of the source tree, or of $TGNAV_CONFIGS_DIR; a folder
// without one is one line naming the key and the file.
TEST_F(TrackModelScenario, TheDefaultModelIsTheShippedOne) {
  const Scenario s = loadScenario(scenario(""));
  ASSERT_NE(s.planner.perception.information.model, nullptr);
  EXPECT_EQ(s.planner.perception.information.track_model, (test::sourceDir() / "configs/track_model.json").string());
  EXPECT_EQ(s.planner.perception.information.model->source, s.planner.perception.information.track_model);
  const planner::TrackModel shipped = loadTrackModel(test::sourceDir() / "configs/track_model.json");
  ASSERT_EQ(s.planner.perception.information.model->terms.size(), shipped.terms.size());
  EXPECT_EQ(s.planner.perception.information.model->intercept, shipped.intercept);

  const auto file = scenario("");
  ::setenv("TGNAV_CONFIGS_DIR", dir_.c_str(), 1);
  const std::string msg = inputError([&] { loadScenario(file); });
  ::unsetenv("TGNAV_CONFIGS_DIR");
  EXPECT_EQ(msg, file.string() + ": key 'planner.information.track_model' has value 'default': file " +
                     (dir_ / "track_model.json").string() +
                     " not found (set TGNAV_CONFIGS_DIR, or track_model: none for the gates)");
}

TEST_F(TrackModelScenario, AMissingModelIsNamedWithItsKey) {
  const auto file = scenario("planner: {information: {track_model: nowhere.json}}\n");
  EXPECT_EQ(inputError([&] { loadScenario(file); }),
            file.string() + ": key 'planner.information.track_model' has value 'nowhere.json': file " +
                (dir_ / "nowhere.json").string() + " not found");
  const YamlDoc overrides = YamlDoc::fromOverrides({"planner.information.track_model=/no/such/model.json"});
  EXPECT_EQ(inputError([&] { loadScenario(scenario(""), &overrides); }),
            "--set: key 'planner.information.track_model' has value '/no/such/model.json': file /no/such/model.json "
            "not found");
  test::writeFile(dir_ / "bad.json", "{}");
  const YamlDoc bad = YamlDoc::fromOverrides({"planner.information.track_model=" + (dir_ / "bad.json").string()});
  EXPECT_EQ(inputError([&] { loadScenario(scenario(""), &bad); }),
            (dir_ / "bad.json").string() + ": key 'format' is missing");
  const YamlDoc p = YamlDoc::fromOverrides({"planner.information.min_track_probability=1"});
  EXPECT_EQ(inputError([&] { loadScenario(scenario(""), &p); }),
            "--set planner.information.min_track_probability=1: min_track_probability = 1: must be in (0, 1)");
}

// A model records the view settings its features were counted with; a scenario that plans with
// others is refused, naming the setting and both values.
TEST_F(TrackModelScenario, AModelFittedForOtherViewSettingsIsRefused) {
  const planner::PerceptionPlannerConfig defaults;
  const auto model = [&](double max_range_m, const char* face = "") {
    std::ostringstream text;
    text.precision(17);
    text << R"({"format": "tgnav-track-model", "version": 1, "kind": "logistic", "features": ["coverage"],
      "mean": [0.2], "scale": [0.1], "weights": [1.0], "intercept": 0.0, "view_settings": {"hfov_rad": )"
         << defaults.visibility.hfov_rad << ", \"vfov_rad\": " << defaults.visibility.vfov_rad
         << ", \"min_range_m\": " << defaults.visibility.min_range_m << ", \"max_range_m\": " << max_range_m
         << ", \"max_incidence_rad\": " << defaults.information.max_incidence_rad << face << "}}";
    return text.str();
  };
  test::writeFile(dir_ / "same.json", model(defaults.visibility.max_range_m));
  const Scenario s = loadScenario(scenario("planner: {information: {track_model: same.json}}\n"));
  ASSERT_NE(s.planner.perception.information.model, nullptr);
  EXPECT_TRUE(s.planner.perception.information.model->has_view_settings);
  EXPECT_EQ(s.planner.perception.information.model->view_settings.max_range_m, defaults.visibility.max_range_m);

  test::writeFile(dir_ / "far.json", model(defaults.visibility.max_range_m + 4.0));
  const auto file = scenario("planner: {information: {track_model: far.json}}\n");
  const std::string msg = inputError([&] { loadScenario(file); });
  EXPECT_EQ(msg.rfind(file.string() + ": key 'planner.information.track_model' has value '" +
                          (dir_ / "far.json").string() + "': it was fitted with planner.visibility.max_range_m = ",
                      0),
            0u)
      << msg;
  EXPECT_NE(msg.find("this config has " + std::to_string(static_cast<int>(defaults.visibility.max_range_m))),
            std::string::npos)
      << msg;
  // The same planner settings as the model's: accepted.
  const YamlDoc far = YamlDoc::fromOverrides(
      {"planner.visibility.max_range_m=" + std::to_string(defaults.visibility.max_range_m + 4.0)});
  EXPECT_NE(loadScenario(file, &far).planner.perception.information.model, nullptr);

  // Counted to the landmarks' faces (VisibilityConfig::sight_to_face), planned to their centres: refused.
  test::writeFile(dir_ / "face.json", model(defaults.visibility.max_range_m, ", \"sight_to_face\": 1"));
  const auto face_file = scenario("planner: {information: {track_model: face.json}}\n");
  EXPECT_NE(inputError([&] {
              loadScenario(face_file);
            }).find("it was fitted with planner.visibility.sight_to_face = 1, this config has 0"),
            std::string::npos);
  const YamlDoc face = YamlDoc::fromOverrides({"planner.visibility.sight_to_face=true"});
  EXPECT_NE(loadScenario(face_file, &face).planner.perception.information.model, nullptr);
}

}  // namespace
}  // namespace tgnav::harness
