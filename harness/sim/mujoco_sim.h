#pragma once
// RAII ownership of MuJoCo's C objects and the handles of a multirotor in a model.
#include <mujoco/mujoco.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "control/types.h"
#include "control/vehicle.h"
#include "harness/config/vehicle_config.h"
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

// Indices of a vehicle's parts inside a model, as its description names them
// (harness/config/vehicle_config.h).
struct VehicleIds {
  int body = -1;
  int qpos_adr = -1;               // free joint: position (3) then quaternion w, x, y, z (4)
  int qvel_adr = -1;               // free joint: linear velocity in W (3) then angular velocity in B (3)
  std::vector<int> motors;         // actuator ids, in the description's rotor order
  std::vector<int> motor_act;      // their activation (motor-lag filter state) in mjData::act; -1: direct thrust
  std::vector<double> ctrl_per_n;  // actuator control per newton of thrust (1 / (gain |gear force|))
  std::vector<double> max_thrust_n;
  double direct_lag_s = 0.0;  // first-order lag the flight loop applies to direct-thrust actuators
  int gyro_adr = -1;          // sensordata offsets
  int accel_adr = -1;
  int camera = -1;
  // Height of the body frame's origin above the ground when landed: its lowest collision
  // geometry 5 mm above the floor (the vehicle settles onto it).
  double landed_height_m = 0.0;

  int rotorCount() const { return static_cast<int>(motors.size()); }
  // InputError naming the vehicle's MJCF and the element when a part is missing or unusable.
  static VehicleIds find(const mjModel* m, const VehicleDescription& vehicle);
};

// Places the vehicle level at `pose` with zero velocity and recomputes kinematics.
void setVehiclePose(const mjModel* m, mjData* d, const VehicleIds& ids, const planner::Pose4& pose);

// Total mass of the vehicle's body subtree in kg.
double vehicleMass(const mjModel* m, const VehicleIds& ids);

// How far the vehicle's collision geometry reaches from its body origin, at any attitude: the
// largest |geom position| + bounding-sphere radius over the collision geoms of its body. A planner's
// robot radius below it lets the vehicle touch what its paths clear.
double vehicleReach(const mjModel* m, const VehicleIds& ids);

// Mass, inertia and rotor geometry as the model defines them: rotor positions from the
// actuator sites (relative to the centre of mass), thrust axes and yaw-moment ratios from the
// actuator gears, maximum thrust from the control ranges (or the description), motor lag from
// the filter constant (or the description). InputError when the rotors cannot control roll,
// pitch, yaw and thrust independently.
control::VehicleParams vehicleParamsFromModel(const mjModel* m, const VehicleIds& ids);

// True state of the vehicle (free-joint position/velocity, body rates).
control::VehicleState vehicleState(const mjData* d, const VehicleIds& ids);

}  // namespace tgnav::harness
