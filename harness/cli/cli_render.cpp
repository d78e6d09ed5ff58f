// tgnav render: one RGB-D frame of a scene from a vehicle pose (harness/run/render_run.h).
#include <cstdio>
#include <utility>

#include "harness/cli/cli.h"
#include "harness/run/render_run.h"

namespace tgnav::cli {

void addRenderCommand(CLI::App& app) {
  auto opt = std::make_shared<harness::RenderJob>();
  auto size = std::make_shared<std::pair<int, int>>(0, 0);
  CLI::App* cmd = app.add_subcommand("render", "Render one RGB-D frame of a scene from a vehicle pose");
  cmd->add_option("--scene", opt->scene, "Scene YAML (configs/scenes/*.yaml) or MJCF file")->required();
  cmd->add_option("--pose", opt->pose, "Vehicle pose x,y,z,yaw in metres and radians (default: the scene's start)");
  cmd->add_option("--out", opt->out, "Output directory")->required();
  cmd->add_option("--vehicle", opt->vehicle, "Vehicle description YAML whose camera renders (default: the scene's)");
  cmd->add_option("--camera-config", opt->camera_config, "Camera YAML (default: built-in, see configs/camera.yaml)");
  cmd->add_option("--width", size->first, "Image width in pixels (overrides the camera config)");
  cmd->add_option("--height", size->second, "Image height in pixels (overrides the camera config)");
  cmd->add_option("--seed", opt->seed, "Seed of the camera noise");
  cmd->callback([opt, size, cmd] {
    if (cmd->count("--width") > 0) opt->width_px = size->first;
    if (cmd->count("--height") > 0) opt->height_px = size->second;
    std::printf("%s\n", harness::runRender(*opt).c_str());
  });
}

}  // namespace tgnav::cli
