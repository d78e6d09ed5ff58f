#pragma once
// The files of a generated scene from its layout (harness/scenes/scene_generator.h).
#include <map>
#include <string>
#include <vector>

#include "harness/scenes/scene_layout.h"
#include "harness/scenes/scene_random.h"

namespace tgnav::harness::scenes {

// The images of a block's cube texture, as file names under textures/ (MuJoCo's cube faces:
// left -x, right +x, up +y, down -y; top and bottom show `down`). Empty for a plain block.
struct FaceFiles {
  std::string left, right, up, down;
  bool empty() const { return down.empty(); }
};

// Draws the face images of every block that is not plain into `files` (textures/NAME.png), each
// pre-rotated so that it shows upright on its face (scripts/make_textures.py's convention).
std::vector<FaceFiles> addFaceImages(const Layout& layout, SceneRng& rng, std::map<std::string, std::string>& files);

std::string sceneMjcf(const Layout& layout, const std::vector<FaceFiles>& faces, SceneRng& rng);
std::string sceneYaml(const Layout& layout, const std::string& name);
std::string scenarioYaml(const Layout& layout, const std::string& name);
std::string generatedJson(const Layout& layout, const std::vector<FaceFiles>& faces);

}  // namespace tgnav::harness::scenes
