#pragma once
// RAII ownership of MuJoCo's C objects and the handles of the tgnav quadrotor in a model.
#include <mujoco/mujoco.h>

#include <array>
#include <filesystem>
#include <memory>
#include <string>

#include "control/types.h"
#include "control/vehicle.h"
#include "planner/pose4.h"

namespace tgnav::harness {

struct MjModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct MjDataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using ModelPtr = std::unique_ptr<mjModel, MjModelDeleter>;
using DataPtr = std::unique_ptr<mjData, MjDataDeleter>;

// Routes MuJoCo errors to C++ exceptions (its default handler exits the process) and its
// warnings to stderr. Idempotent.
void installMujocoHandlers();

// Loads an MJCF file; InputError naming the file and MuJoCo's message when it cannot.
ModelPtr loadModel(const std::filesystem::path& mjcf);
DataPtr makeData(const mjModel* m);

// The warnings MuJoCo counted in `d` (e.g. "mjWARN_BADQACC x3"), "" when there are none.
std::string mujocoWarnings(const mjData* d);

// Indices of the quadrotor of models/quadrotor.xml inside a model.
struct VehicleIds {
  int body = -1;
  int qpos_adr = -1;               // free joint: position (3) then quaternion w, x, y, z (4)
  int qvel_adr = -1;               // free joint: linear velocity in W (3) then angular velocity in B (3)
  std::array<int, 4> motors{};     // actuator ids, PX4 quad-X order
  std::array<int, 4> motor_act{};  // their activation (motor-lag filter state) in mjData::act
  int gyro_adr = -1;               // sensordata offsets
  int accel_adr = -1;

  // InputError naming `source` if the model lacks any part of the vehicle.
  static VehicleIds find(const mjModel* m, const std::string& source);
};

// Height of the centre of mass above the ground when landed: hull half-height 0.03 m of
// models/quadrotor.xml plus 5 mm of clearance; the vehicle settles onto the floor.
constexpr double kLandedHeightM = 0.035;

// Places the vehicle level at `pose` with zero velocity and recomputes kinematics.
void setVehiclePose(const mjModel* m, mjData* d, const VehicleIds& ids, const planner::Pose4& pose);

// Total mass of the vehicle's body subtree in kg.
double vehicleMass(const mjModel* m, const VehicleIds& ids);

// Mass, inertia and rotor geometry as the model defines them: rotor positions from the
// actuator sites (relative to the centre of mass), thrust axes and yaw-moment ratios from the
// actuator gears, maximum thrust from the control ranges, motor lag from the filter constant.
control::VehicleParams vehicleParamsFromModel(const mjModel* m, const VehicleIds& ids);

// True state of the vehicle (free-joint position/velocity, body rates).
control::VehicleState vehicleState(const mjData* d, const VehicleIds& ids);

}  // namespace tgnav::harness
