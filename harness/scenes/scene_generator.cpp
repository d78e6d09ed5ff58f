#include "harness/scenes/scene_generator.h"

#include <cstdlib>
#include <limits>

#include "harness/base/errors.h"
#include "harness/base/files.h"
#include "harness/config/vehicle_config.h"
#include "harness/io/staged_output.h"
#include "harness/scenes/scene_files.h"

namespace tgnav::harness::scenes {

namespace {

// Streams of a scene seed (harness/scenes/scene_random.h: mixSeed); the layouts use 1-3.
constexpr std::uint64_t kTextureStream = 10;
constexpr std::uint64_t kMaterialStream = 11;

std::string quoted(const std::string& text) { return "'" + text + "'"; }

}  // namespace

SceneKind parseSceneKind(const std::string& text, const std::string& option) {
  if (text == "room") return SceneKind::kRoom;
  if (text == "corridors") return SceneKind::kCorridors;
  if (text == "warehouse") return SceneKind::kWarehouse;
  if (text == "detour") return SceneKind::kDetour;
  throw InputError(option + ": " + quoted(text) +
                   " is not a scene kind; expected room, corridors, warehouse or detour");
}

std::uint64_t parseSceneSeed(const std::string& text, const std::string& option) {
  const std::string expected = " is not a seed; expected an integer in [0, 18446744073709551615]";
  if (text.empty() || text.size() > 20) throw InputError(option + ": " + quoted(text) + expected);
  std::uint64_t value = 0;
  for (char c : text) {
    if (c < '0' || c > '9') throw InputError(option + ": " + quoted(text) + expected);
    const std::uint64_t digit = static_cast<std::uint64_t>(c - '0');
    if (value > (std::numeric_limits<std::uint64_t>::max() - digit) / 10) {
      throw InputError(option + ": " + quoted(text) + expected);
    }
    value = value * 10 + digit;
  }
  return value;
}

std::filesystem::path modelsDir() {
  const char* env = std::getenv("TGNAV_MODELS_DIR");
  return env != nullptr && *env != '\0' ? std::filesystem::path(env)
                                        : std::filesystem::path(TGNAV_SOURCE_DIR "/models");
}

GeneratedScene generateScene(SceneKind kind, std::uint64_t seed) {
  GeneratedScene scene;
  scene.kind = kind;
  scene.seed = seed;
  switch (kind) {
    case SceneKind::kRoom:
      scene.layout = roomLayout(seed);
      break;
    case SceneKind::kCorridors:
      scene.layout = corridorsLayout(seed);
      break;
    case SceneKind::kWarehouse:
      scene.layout = warehouseLayout(seed);
      break;
    case SceneKind::kDetour:
      scene.layout = detourLayout(seed);
      break;
  }
  const std::filesystem::path vehicle = modelsDir() / "quadrotor.xml";
  std::error_code ec;
  const std::filesystem::path description = descriptionBeside(vehicle);
  if (!std::filesystem::is_regular_file(vehicle, ec) || description.empty()) {
    throw InputError(vehicle.string() +
                     ": the vehicle model or its description .yaml is missing (set TGNAV_MODELS_DIR to the models "
                     "folder)");
  }
  SceneRng texture_rng(mixSeed(seed, kTextureStream + static_cast<std::uint64_t>(kind)));
  SceneRng material_rng(mixSeed(seed, kMaterialStream + 16 * static_cast<std::uint64_t>(kind)));
  const std::vector<FaceFiles> faces = addFaceImages(scene.layout, texture_rng, scene.files);
  const std::string name = sceneName(kind, seed);
  scene.files[name + ".xml"] = sceneMjcf(scene.layout, faces, material_rng);
  scene.files[sceneFile(kind, seed)] = sceneYaml(scene.layout, name);
  scene.files[scenarioFile(kind, seed)] = scenarioYaml(scene.layout, name);
  scene.files["generated.json"] = generatedJson(scene.layout, faces);
  // The vehicle by the same reference as the shipped scenes: its MJCF and its description.
  scene.files["quadrotor.xml"] = readTextFile(vehicle);
  scene.files["quadrotor.yaml"] = readTextFile(description);
  return scene;
}

std::string sceneName(SceneKind kind, std::uint64_t seed) {
  return std::string(toString(kind)) + "-" + std::to_string(seed);
}

std::string sceneFile(SceneKind kind, std::uint64_t seed) { return "scenes/" + sceneName(kind, seed) + ".yaml"; }

std::string scenarioFile(SceneKind kind, std::uint64_t seed) { return "scenarios/" + sceneName(kind, seed) + ".yaml"; }

void checkSceneOutput(const std::filesystem::path& dir, const std::string& option) {
  std::error_code ec;
  if (!std::filesystem::exists(dir, ec)) return;
  if (!std::filesystem::is_directory(dir, ec)) {
    throw InputError(option + ": " + dir.string() + " exists and is not a folder; choose a new --out");
  }
  if (!std::filesystem::is_empty(dir, ec)) {
    throw InputError(option + ": " + dir.string() + " exists and is not empty; a scene is written into a new folder");
  }
}

void writeGeneratedScene(const GeneratedScene& scene, const std::filesystem::path& dir) {
  checkSceneOutput(dir);
  const bool existed = std::filesystem::exists(dir);  // empty: the files are moved into it
  StagedDir staged(dir);
  for (const char* sub : {"textures", "scenes", "scenarios"}) {
    std::filesystem::create_directories(staged.staging() / sub);
  }
  for (const auto& [name, bytes] : scene.files) writeFileAtomic(staged.staging() / name, bytes);
  staged.commit(existed ? OnExisting::kMerge : OnExisting::kRefuse, "generating the scene");
}

std::string summaryLine(const GeneratedScene& scene, const std::filesystem::path& dir) {
  const Layout& l = scene.layout;
  int counts[4] = {0, 0, 0, 0};
  for (const Block& b : l.blocks) ++counts[static_cast<int>(b.level)];
  char text[512];
  std::snprintf(text, sizeof text,
                "%s seed %llu: %.1f x %.1f m, %zu obstacles, %zu surfaces (%d rich, %d medium, %d faint, %d plain) "
                "-> %s",
                toString(l.kind), static_cast<unsigned long long>(l.seed), l.xmax - l.xmin, l.ymax - l.ymin,
                l.obstacles.size(), l.blocks.size(), counts[0], counts[1], counts[2], counts[3], dir.c_str());
  return text;
}

}  // namespace tgnav::harness::scenes
