#pragma once
// Generated scenes in a sweep (harness/scenes/scene_generator.h). A run may name generated scenes
// instead of scenario files:
//
//   runs:
//     - generated: {kind: room, seeds: [101, 102, 103]}    # or a list of such mappings
//       planner: [proposed, agnostic]
//
// Each (kind, seed) becomes DIR/scenes/<kind>-<seed>/ in the sweep folder DIR, written by the
// generator the first time, and checked byte for byte against it on every later run, so that a
// resumed sweep cannot mix trials of two versions of a scene. Its trials fly the scene's own
// scenario (scenarios/<kind>-<seed>.yaml there).
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "harness/config/yaml_util.h"

namespace tgnav::harness {

// The scenes folder of one sweep file's reading, and the scenes already written or checked in
// it (a scene listed by several runs is generated and compared once).
struct GeneratedScenes {
  std::filesystem::path dir;      // empty: no sweep folder
  std::set<std::string> ensured;  // names (<kind>-<seed>)
};

// The scenarios of `run[generated]` (run is a run of the sweep file `doc`, `context` its dotted
// path), each generated into, or checked against, generated->dir. Fails (doc.fail) on a bad kind or
// seed, no scenes folder, or a scene folder that differs from what the generator writes.
std::vector<std::filesystem::path> readGeneratedScenes(const YamlDoc& doc, const YAML::Node& run,
                                                       const std::string& context, GeneratedScenes* generated);

}  // namespace tgnav::harness
