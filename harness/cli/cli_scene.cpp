// tgnav scene generate: a procedurally generated scene from a kind and a seed
// (harness/scenes/scene_generator.h).
#include <cstdio>
#include <memory>
#include <string>

#include "harness/cli/cli.h"
#include "harness/scenes/scene_generator.h"

namespace tgnav::cli {

namespace {

struct SceneGenerateOptions {
  std::string seed;
  std::string kind = "room";
  std::string out;
};

}  // namespace

void addSceneCommand(CLI::App& app) {
  CLI::App* scene = app.add_subcommand("scene", "Scenes: generate one procedurally");
  scene->require_subcommand(1);
  auto opt = std::make_shared<SceneGenerateOptions>();
  CLI::App* cmd = scene->add_subcommand("generate",
                                        "Write a procedurally generated scene (NAME.xml, scenes/NAME.yaml, "
                                        "scenarios/NAME.yaml, textures; NAME = KIND-SEED) into DIR");
  cmd->add_option("--seed", opt->seed, "Seed: an integer in [0, 2^64 - 1]; the same seed gives the same files")
      ->required();
  cmd->add_option("--kind", opt->kind,
                  "room (default), corridors, warehouse or detour (the shortest route blind, issue 38)");
  cmd->add_option("--out", opt->out, "Output folder DIR (new or empty)")->required();
  cmd->callback([opt] {
    namespace scenes = harness::scenes;
    const std::uint64_t seed = scenes::parseSceneSeed(opt->seed, "--seed");
    const scenes::SceneKind kind = scenes::parseSceneKind(opt->kind, "--kind");
    scenes::checkSceneOutput(opt->out, "--out");
    const scenes::GeneratedScene generated = scenes::generateScene(kind, seed);
    scenes::writeGeneratedScene(generated, opt->out);
    std::printf("%s\n", scenes::summaryLine(generated, opt->out).c_str());
  });
}

}  // namespace tgnav::cli
