#pragma once
// A scenario (configs/scenarios/<name>.yaml): the scene, the seed, and the planner's settings
// layered as  built-in defaults (Table I) < planner_config file < the scenario's `planner:`
// section. Strict keys; paths are relative to the scenario file.
//
//   scene: ../scenes/storage.yaml     # required
//   seed: 1                           # required, >= 0
//   planner_config: ../planner.yaml   # optional
//   planner: {selection: {c_p_threshold: 6.0}}   # optional overrides
//   start: [x, y, z, yaw]             # optional, replaces the scene's
//   goal: [x, y, z, yaw]              # optional
#include <cstdint>
#include <filesystem>

#include "harness/planner_config.h"
#include "harness/scene_config.h"

namespace tgnav::harness {

struct Scenario {
  std::filesystem::path source;
  SceneConfig scene;
  std::uint64_t seed = 0;
  PlannerSettings planner;
};

Scenario loadScenario(const std::filesystem::path& yaml);

}  // namespace tgnav::harness
