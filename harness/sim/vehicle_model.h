#pragma once
// A scene's MuJoCo model flown by a chosen vehicle. Scenes include their vehicle's MJCF with
// <include file="..."/> (models/scenes/*.xml include ../quadrotor.xml); a vehicle is an MJCF with
// its description beside it (harness/config/vehicle_config.h). MuJoCo 2.2 cannot edit a
// compiled model, so another vehicle is composed at the XML level: the scene's text with the
// vehicle's <include> pointing at the other MJCF (or one added when the scene includes none),
// compiled from memory under the scene's own path so that its relative paths still resolve.
#include <mujoco/mujoco.h>

#include <filesystem>
#include <string>

#include "harness/config/vehicle_config.h"
#include "harness/sim/mujoco_sim.h"

namespace tgnav::harness {

// The MJCF text of `mjcf` with `vehicle`'s MJCF in place of the vehicle it includes (or added
// after <mujoco> when it includes none): include paths relative to the scene's folder.
std::string composeVehicleScene(const std::filesystem::path& mjcf, const VehicleDescription& vehicle);

struct VehicleModel {
  ModelPtr model;
  VehicleDescription vehicle;
  VehicleIds ids;
};

// Compiles `mjcf` flown by the vehicle described in `vehicle_yaml` (empty: the vehicle it
// includes), applies the description's timestep, and finds the vehicle's parts in it. InputError
// naming the file and element when anything is missing or unusable.
VehicleModel loadVehicleModel(const std::filesystem::path& mjcf, const std::filesystem::path& vehicle_yaml = {});

}  // namespace tgnav::harness
