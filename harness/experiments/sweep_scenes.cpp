#include "harness/experiments/sweep_scenes.h"

#include <algorithm>
#include <map>
#include <utility>

#include "harness/base/errors.h"
#include "harness/base/files.h"
#include "harness/scenes/scene_generator.h"

namespace fs = std::filesystem;

namespace tgnav::harness {

namespace {

using scenes::SceneKind;

std::vector<YAML::Node> items(const YAML::Node& node) {
  std::vector<YAML::Node> out;
  if (node.IsSequence()) {
    for (const YAML::Node& n : node) out.push_back(n);
  } else {
    out.push_back(node);
  }
  return out;
}

// The first file of the folder that differs from the generated scene ("" when none does; files
// the generator does not write are ignored).
std::string firstDifference(const scenes::GeneratedScene& scene, const fs::path& dir) {
  for (const auto& [name, bytes] : scene.files) {
    const fs::path file = dir / name;
    std::error_code ec;
    if (!fs::is_regular_file(file, ec) || readTextFile(file) != bytes) return name;
  }
  return "";
}

// DIR/<kind>-<seed>: written when absent, checked when present (once per reading). Returns its
// scenario file.
fs::path ensureScene(const YamlDoc& doc, const YAML::Node& where, const std::string& key, SceneKind kind,
                     std::uint64_t seed, GeneratedScenes* generated) {
  const std::string name = scenes::sceneName(kind, seed);
  fs::path scenario = generated->dir / name / scenes::scenarioFile(kind, seed);
  if (!generated->ensured.insert(name).second) return scenario;
  const scenes::GeneratedScene scene = scenes::generateScene(kind, seed);
  const fs::path dir = generated->dir / name;
  std::error_code ec;
  if (!fs::exists(dir, ec)) {
    fs::create_directories(generated->dir);
    scenes::writeGeneratedScene(scene, dir);
  } else {
    const std::string differs = firstDifference(scene, dir);
    if (!differs.empty()) {
      doc.fail(where, key + ": " + (dir / differs).string() + " is not what this tgnav generates for " +
                          scenes::sceneName(kind, seed) +
                          " (the generator changed since the sweep began?): continue with the tgnav that "
                          "began it, or start a new sweep folder");
    }
  }
  return scenario;
}

}  // namespace

std::vector<fs::path> readGeneratedScenes(const YamlDoc& doc, const YAML::Node& run, const std::string& context,
                                          GeneratedScenes* generated) {
  const std::string key = joinKey(context, "generated");
  const YAML::Node node = run["generated"];
  if (generated->dir.empty()) {
    doc.fail(node, key + ": generated scenes are written into the sweep folder, and there is none here");
  }
  std::vector<fs::path> scenarios;
  for (const YAML::Node& entry : items(node)) {
    if (!entry.IsMap()) {
      doc.fail(entry, key + ": expected a mapping {kind: room|corridors|warehouse|detour, seeds: [...]}");
    }
    doc.requireKeys(entry, {"kind", "seeds"}, key);
    for (const char* k : {"kind", "seeds"}) {
      if (!entry[k]) doc.fail(entry, key + ": key '" + k + "' is missing");
    }
    const YAML::Node kind_node = entry["kind"];
    SceneKind kind = SceneKind::kRoom;
    try {
      kind = scenes::parseSceneKind(kind_node.IsScalar() ? kind_node.Scalar() : "?", joinKey(key, "kind"));
    } catch (const InputError& e) {
      doc.fail(kind_node, e.what());
    }
    const YAML::Node seeds = entry["seeds"];
    if (!seeds.IsSequence() || seeds.size() == 0) {
      doc.fail(seeds, joinKey(key, "seeds") + ": expected a non-empty list");
    }
    for (const YAML::Node& s : seeds) {
      std::uint64_t seed = 0;
      try {
        seed = scenes::parseSceneSeed(s.IsScalar() ? s.Scalar() : "?", joinKey(key, "seeds"));
      } catch (const InputError& e) {
        doc.fail(s, e.what());
      }
      const fs::path scenario = ensureScene(doc, s, key, kind, seed, generated);
      if (std::find(scenarios.begin(), scenarios.end(), scenario) != scenarios.end()) {
        doc.fail(s, joinKey(key, "seeds") + ": " + scenes::sceneName(kind, seed) + " is listed twice");
      }
      scenarios.push_back(scenario);
    }
  }
  return scenarios;
}

}  // namespace tgnav::harness
