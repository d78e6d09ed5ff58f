// tgnav fly: fly a setpoint trajectory file through the cascade, optionally recording the
// onboard camera (harness/run/fly_run.h).
#include <cstdio>
#include <utility>

#include "harness/cli/cli.h"
#include "harness/run/fly_run.h"

namespace tgnav::cli {

void addFlyCommand(CLI::App& app) {
  auto opt = std::make_shared<harness::FlyJob>();
  auto size = std::make_shared<std::pair<int, int>>(0, 0);
  CLI::App* cmd = app.add_subcommand("fly", "Take off and fly a setpoint trajectory (CSV) in MuJoCo");
  cmd->add_option("--scene", opt->scene, "Scene YAML (start pose, bounds) or MJCF file")->required();
  cmd->add_option("--trajectory", opt->trajectory,
                  "CSV with header: t,x,y,z,yaw[,vx,vy,vz][,ax,ay,az][,yaw_rate] (s, m, rad)")
      ->required();
  cmd->add_option("--out", opt->out, "Output directory")->required();
  cmd->add_option("--vehicle", opt->vehicle,
                  "Vehicle description YAML (default: the scene's, e.g. models/quadrotor.yaml; see models/vehicles/)");
  cmd->add_option("--controller", opt->controller,
                  "Controller YAML over the vehicle's gains (default: the vehicle's gains file, else the built-in "
                  "defaults of configs/controller.yaml)");
  CLI::Option* record = cmd->add_option(
      "--record", opt->record,
      "Record the onboard RGB-D camera into this new directory as a TUM RGB-D sequence (ground truth included)");
  cmd->add_option("--record-rate", opt->record_rate_hz, "Recording rate in Hz; must divide the physics rate")
      ->capture_default_str()
      ->needs(record);
  cmd->add_option("--camera-config", opt->camera_config,
                  "Camera YAML for --record (default: built-in, see configs/camera.yaml)")
      ->needs(record);
  cmd->add_option("--width", size->first, "Recorded image width in pixels (overrides the camera config)")
      ->needs(record);
  cmd->add_option("--height", size->second, "Recorded image height in pixels (overrides the camera config)")
      ->needs(record);
  cmd->add_option("--seed", opt->seed, "Seed of the camera noise for --record")->capture_default_str()->needs(record);
  cmd->callback([opt, size, cmd] {
    if (cmd->count("--width") > 0) opt->width_px = size->first;
    if (cmd->count("--height") > 0) opt->height_px = size->second;
    std::fputs(harness::flySummaryLines(harness::runFly(*opt)).c_str(), stdout);
  });
}

}  // namespace tgnav::cli
