#pragma once
// A vehicle description: the YAML beside a multirotor's MJCF (models/quadrotor.yaml beside
// models/quadrotor.xml) that names the parts of the model the harness flies, so that any MJCF
// quad, hexa- or octorotor flies without renaming its elements. The physics itself (mass,
// inertia, rotor positions, thrust axes, spins, yaw-moment ratios, thrust limits) is read from
// the compiled model (harness/sim/vehicle_model.h); nothing here repeats it.
//
//   mjcf: quadrotor.xml            # required: the vehicle's MJCF, relative to this file
//   body: quadrotor                # required: the body holding the rotor sites, IMU and camera
//   root_joint: quadrotor_root     # optional: its free joint (default: the body's one free joint)
//   rotors: [motor0, motor1, motor2, motor3]  # required: actuators on sites of `body` (4, 6 or 8)
//   gyro: gyro                     # required: the IMU's sensors
//   accelerometer: accel
//   camera: front                  # required: the onboard camera, attached to `body`
//   motor:                         # optional
//     time_constant_s: 0.03        # lag of direct-thrust actuators (<motor>, no filter); refused
//                                  # for actuators with filter dynamics (the filter is the lag)
//     max_thrust_n: 13.0           # per rotor; default: the actuator's ctrlrange x gain x gear
//   timestep_s: 0.002              # optional: physics step in place of the MJCF's <option>
//   controller_config: gains.yaml  # optional: the airframe's controller gains (configs/controller.yaml
//                                  # keys), layered under a scenario's `controller` settings
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace tgnav::harness {

struct VehicleDescription {
  std::filesystem::path source;  // the YAML file
  std::filesystem::path mjcf;    // absolute
  std::string body;
  std::string root_joint;           // empty: the body's free joint
  std::vector<std::string> rotors;  // actuator names, in the order the allocation numbers them
  std::string gyro;
  std::string accelerometer;
  std::string camera;
  double motor_time_constant_s = -1.0;      // < 0: not given
  double max_thrust_n = 0.0;                // 0: not given
  double timestep_s = 0.0;                  // 0: the MJCF's
  std::filesystem::path controller_config;  // absolute; empty: none
};

// The rotor counts the harness flies (PX4's quad, hexa and octo geometries).
bool supportedRotorCount(std::size_t n);

// Reads and checks a description: strict keys, the required ones present, names non-empty and
// distinct rotors, positive numbers, `mjcf` and `controller_config` existing files. InputError
// "file:line: ..." naming the key and the value.
VehicleDescription loadVehicleDescription(const std::filesystem::path& yaml);

// A top-level <include file="..."/> of an MJCF text: where its file value lies in the text.
struct IncludeRef {
  std::size_t value_begin = 0;
  std::size_t value_end = 0;
  std::string file;
};
// The <include> elements of an MJCF text, outside comments, in order.
std::vector<IncludeRef> findIncludes(const std::string& text);
// The one <include> of `mjcf` (whose text is `text`) that is a vehicle (a description beside its
// file), with that description in *description; none: nullopt. InputError when it has two.
std::optional<IncludeRef> vehicleInclude(const std::filesystem::path& mjcf, const std::string& text,
                                         std::filesystem::path* description);

// The description of the vehicle a scene MJCF includes: the one top-level <include> whose file
// has a description beside it, or the MJCF's own description when it is a vehicle file itself.
// Empty when there is none; InputError when the MJCF includes more than one vehicle.
std::filesystem::path includedVehicle(const std::filesystem::path& mjcf);

// The description that flies `mjcf`: `vehicle_yaml`, or when that is empty the included
// vehicle's (InputError saying how to name one when there is none).
std::filesystem::path resolveVehicle(const std::filesystem::path& mjcf, const std::filesystem::path& vehicle_yaml);

// The description file beside an MJCF (same name, extension .yaml), or empty when there is none.
std::filesystem::path descriptionBeside(const std::filesystem::path& mjcf);

}  // namespace tgnav::harness
