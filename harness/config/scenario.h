#pragma once
// A scenario (configs/scenarios/<name>.yaml): the scene, the seed, and every module's settings.
// Each section is layered as
//   built-in defaults < its *_config file < the scenario's inline section < --set overrides.
// Strict keys; paths are relative to the scenario file.
//
//   scene: ../scenes/storage.yaml        # required
//   seed: 1                              # required, >= 0
//   start: [x, y, z, yaw]                # optional, replaces the scene's
//   goal: [x, y, z, yaw]                 # optional
//   vehicle: ../../models/vehicles/hexarotor.yaml  # optional: flies the scene in place of its own
//   planner_config: ../planner.yaml      # optional files (all keys optional) ...
//   controller_config: ../controller.yaml
//   camera_config: ../camera.yaml
//   vo_config: ../vo.yaml
//   trial_config: ../trial.yaml
//   planner: {selection: {c_p_threshold: 6.0}}   # ... and inline sections over them
//   controller: {position: {vel_p_xy: 2.5}}
//   camera: {width_px: 320, height_px: 240}
//   vo: {min_inliers: 20}
//   trial: {state_source: vo}
//
// Overrides (`--set KEY=VALUE`, YamlDoc::fromOverrides) may set scene and vehicle (paths relative
// to the current directory), seed, start, goal and the keys of planner, controller, camera, vo and
// trial; not the *_config files.
//
// The controller's layers begin with the vehicle's gains file (its description's
// `controller_config`), over the built-in defaults: defaults < vehicle gains < controller_config <
// controller < --set.
#include <cstdint>
#include <filesystem>
#include <string>

#include "control/cascade.h"
#include "harness/config/camera_config.h"
#include "harness/config/planner_config.h"
#include "harness/config/scene_config.h"
#include "harness/config/trial_config.h"
#include "harness/config/yaml_util.h"
#include "vo/odometry.h"

namespace tgnav::harness {

struct Scenario {
  std::filesystem::path source;
  SceneConfig scene;  // start and goal are the scenario's (the scene's unless it replaced them)
  // The vehicle description that flies (absolute): the scenario's `vehicle`, else the scene's,
  // else that of the vehicle the scene's MJCF includes.
  std::filesystem::path vehicle;
  std::uint64_t seed = 0;
  PlannerSettings planner;
  control::CascadeConfig controller;
  CameraConfig camera;
  vo::OdometryConfig vo;
  TrialConfig trial;

  // The sections, each under its key (its file under KEY_config), in config.yaml's order.
  template <typename Archive>
  void visitSections(Archive& a) {
    a("planner", planner);
    a("controller", controller);
    a("camera", camera);
    a("vo", vo);
    a("trial", trial);
  }
};

// InputError naming the file (line, key, value), or the --set assignment an error came from.
Scenario loadScenario(const std::filesystem::path& yaml, const YamlDoc* overrides = nullptr);

// The scenario with everything resolved (absolute scene path, seed, start, goal, and every key of
// every section), as a scenario file: loadScenario() of it gives the same Scenario, and this
// function then gives the same text.
std::string resolvedScenarioYaml(const Scenario& scenario);

// The built-in defaults of every section (planner, controller, camera, vo, trial), every key
// with its value, as one YAML document in the form of config.yaml's sections: appended to a
// scenario's `scene:` and `seed:` it loads as that scenario with the built-in settings.
std::string defaultSectionsYaml();

}  // namespace tgnav::harness
