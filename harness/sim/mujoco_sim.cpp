#include "harness/sim/mujoco_sim.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <mutex>
#include <stdexcept>

#include "harness/base/errors.h"

namespace tgnav::harness {

namespace {
void throwOnMujocoError(const char* msg) { throw std::runtime_error(std::string("MuJoCo: ") + msg); }
void printMujocoWarning(const char* msg) { std::fprintf(stderr, "tgnav: MuJoCo warning: %s\n", msg); }
}  // namespace

void installMujocoHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_error = throwOnMujocoError;
    mju_user_warning = printMujocoWarning;
  });
}

ModelPtr loadModel(const std::filesystem::path& mjcf) {
  installMujocoHandlers();
  if (!std::filesystem::is_regular_file(mjcf)) {
    throw InputError(mjcf.string() + ": MJCF file not found");
  }
  char error[1024] = "";
  ModelPtr m(mj_loadXML(mjcf.c_str(), nullptr, error, sizeof(error)));
  if (!m) throw InputError(mjcf.string() + ": invalid MJCF: " + error);
  return m;
}

DataPtr makeData(const mjModel* m) {
  DataPtr d(mj_makeData(m));
  if (!d) throw std::runtime_error("MuJoCo: mj_makeData failed (out of memory?)");
  return d;
}

std::string mujocoWarnings(const mjData* d) {
  static const char* const kNames[mjNWARNING] = {"INERTIA", "CONTACTFULL", "CNSTRFULL", "VGEOMFULL",
                                                 "BADQPOS", "BADQVEL",     "BADQACC",   "BADCTRL"};
  std::string out;
  for (int i = 0; i < mjNWARNING; ++i) {
    if (d->warning[i].number > 0) {
      out +=
          (out.empty() ? "" : ", ") + std::string("mjWARN_") + kNames[i] + " x" + std::to_string(d->warning[i].number);
    }
  }
  return out;
}

namespace {

// The lowest point of geom `g` below its body's origin, in the body's frame (level body).
double geomBottom(const mjModel* m, int g) {
  const std::ptrdiff_t i = g;
  const Eigen::Vector3d c(m->geom_pos + 3 * i);
  const Eigen::Matrix3d R =
      Eigen::Quaterniond(m->geom_quat[4 * i], m->geom_quat[4 * i + 1], m->geom_quat[4 * i + 2], m->geom_quat[4 * i + 3])
          .toRotationMatrix();
  const Eigen::Vector3d size(m->geom_size + 3 * i);
  const Eigen::Vector3d up = R.row(2).transpose();  // world z in the geom's frame
  switch (m->geom_type[g]) {
    case mjGEOM_SPHERE:
      return c.z() - size[0];
    case mjGEOM_CAPSULE:
      return c.z() - size[0] - size[1] * std::abs(up.z());
    case mjGEOM_CYLINDER:
      return c.z() - size[1] * std::abs(up.z()) - size[0] * std::sqrt(std::max(0.0, 1.0 - up.z() * up.z()));
    case mjGEOM_BOX:
      return c.z() - up.cwiseAbs().dot(size);
    case mjGEOM_ELLIPSOID:
      return c.z() - up.cwiseProduct(size).norm();
    default:  // meshes, height fields: their bounding sphere
      return c.z() - m->geom_rbound[g];
  }
}

// Lowest point of the vehicle's geometry (geoms of `body` itself; collision geoms when it has
// any) below the body's origin.
double vehicleBottom(const mjModel* m, int body) {
  double collision = 0.0;
  double any = 0.0;
  bool has_collision = false;
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_bodyid[g] != body || m->geom_type[g] == mjGEOM_PLANE) continue;
    const double z = geomBottom(m, g);
    any = std::min(any, z);
    if (m->geom_contype[g] != 0 || m->geom_conaffinity[g] != 0) {
      collision = has_collision ? std::min(collision, z) : z;
      has_collision = true;
    }
  }
  return has_collision ? std::min(collision, 0.0) : any;
}

// A named element of the vehicle's model; InputError naming the MJCF and the description if absent.
int need(const mjModel* m, const VehicleDescription& v, mjtObj type, const std::string& name, const char* what) {
  const int id = mj_name2id(m, type, name.c_str());
  if (id < 0) {
    throw InputError(v.mjcf.string() + ": no " + what + " '" + name + "' (vehicle description " + v.source.string() +
                     ")");
  }
  return id;
}

// The vehicle body's free joint: the named one, or its only one.
int rootJoint(const mjModel* m, const VehicleDescription& v, int body) {
  const std::string where = v.mjcf.string() + ": ";
  const std::string hint = " (vehicle description " + v.source.string() + ")";
  if (v.root_joint.empty()) {
    for (int j = 0; j < m->njnt; ++j) {
      if (m->jnt_bodyid[j] == body && m->jnt_type[j] == mjJNT_FREE) return j;
    }
    throw InputError(where + "body '" + v.body + "' has no free joint" + hint);
  }
  const int joint = need(m, v, mjOBJ_JOINT, v.root_joint, "joint");
  if (m->jnt_type[joint] != mjJNT_FREE || m->jnt_bodyid[joint] != body) {
    throw InputError(where + "joint '" + v.root_joint + "' must be a free joint of body '" + v.body + "'" + hint);
  }
  return joint;
}

// Rotor actuator `name`: a thrust proportional to its control along its site's gear axis, with
// a thrust limit and a motor lag (its filter, or the description's for direct thrust).
void addRotor(const mjModel* m, const VehicleDescription& v, const std::string& name, VehicleIds* ids) {
  const int a = need(m, v, mjOBJ_ACTUATOR, name, "actuator");
  const std::ptrdiff_t ai = a;
  const std::string element = v.mjcf.string() + ": actuator '" + name + "'";
  const std::string description = v.source.string();
  if (m->actuator_trntype[a] != mjTRN_SITE || m->site_bodyid[m->actuator_trnid[2 * ai]] != ids->body) {
    throw InputError(element + " must act on a site of body '" + v.body + "' (vehicle description " + description +
                     ")");
  }
  if (m->actuator_gaintype[a] != mjGAIN_FIXED || m->actuator_biastype[a] != mjBIAS_NONE ||
      !(m->actuator_gainprm[ai * mjNGAIN] > 0.0)) {
    throw InputError(element + " must produce a force proportional to its control (a fixed gain > 0, no bias)");
  }
  const double force = Eigen::Vector3d(m->actuator_gear + 6 * ai).norm();
  if (!(force > 0.0)) {
    throw InputError(element + " has no thrust axis: the force part of its gear (first three numbers) is zero");
  }
  const double newtons_per_ctrl = m->actuator_gainprm[ai * mjNGAIN] * force;
  const bool limited = m->actuator_ctrllimited[a] != 0;
  const double range_n = limited ? m->actuator_ctrlrange[2 * ai + 1] * newtons_per_ctrl : 0.0;
  double max_n = v.max_thrust_n;
  if (max_n == 0.0) {
    if (!(range_n > 0.0)) {
      throw InputError(element + " has no ctrlrange with a positive upper limit; give its maximum thrust as " +
                       "motor.max_thrust_n in " + description);
    }
    max_n = range_n;
  } else if (limited && max_n > range_n * (1.0 + 1e-9)) {
    throw InputError(description + ": motor.max_thrust_n " + std::to_string(max_n) + " N exceeds what " + element +
                     "'s ctrlrange allows (" + std::to_string(range_n) + " N)");
  }
  int act = -1;
  if (m->actuator_dyntype[a] == mjDYN_FILTER) {
    if (v.motor_time_constant_s >= 0.0) {
      throw InputError(description + ": motor.time_constant_s is for direct-thrust actuators, but " + element +
                       " has its own filter dynamics (its lag); remove the key");
    }
    act = a - (m->nu - m->na);  // MuJoCo 2.2 stores the activations of the last `na` actuators
  } else if (m->actuator_dyntype[a] == mjDYN_NONE) {
    if (v.motor_time_constant_s < 0.0) {
      throw InputError(element + " is a direct-thrust actuator (no filter dynamics): give the motor lag as " +
                       "motor.time_constant_s in " + description + " (0 for none)");
    }
    ids->direct_lag_s = v.motor_time_constant_s;
  } else {
    throw InputError(element + " must have filter dynamics (dyntype=\"filter\", the motor lag) or none");
  }
  ids->motors.push_back(a);
  ids->motor_act.push_back(act);
  ids->ctrl_per_n.push_back(1.0 / newtons_per_ctrl);
  ids->max_thrust_n.push_back(max_n);
}

// The sensordata offset of the sensor `name`, which must be of `type`.
int sensorAdr(const mjModel* m, const VehicleDescription& v, const std::string& name, mjtSensor type,
              const char* element) {
  const int id = need(m, v, mjOBJ_SENSOR, name, "sensor");
  if (m->sensor_type[id] != type) {
    throw InputError(v.mjcf.string() + ": sensor '" + name + "' is not " + element + " (vehicle description " +
                     v.source.string() + ")");
  }
  return m->sensor_adr[id];
}

}  // namespace

VehicleIds VehicleIds::find(const mjModel* m, const VehicleDescription& v) {
  VehicleIds ids;
  ids.body = need(m, v, mjOBJ_BODY, v.body, "body");
  const int joint = rootJoint(m, v, ids.body);
  ids.qpos_adr = m->jnt_qposadr[joint];
  ids.qvel_adr = m->jnt_dofadr[joint];
  for (const std::string& name : v.rotors) addRotor(m, v, name, &ids);
  ids.gyro_adr = sensorAdr(m, v, v.gyro, mjSENS_GYRO, "a <gyro>");
  ids.accel_adr = sensorAdr(m, v, v.accelerometer, mjSENS_ACCELEROMETER, "an <accelerometer>");
  ids.camera = need(m, v, mjOBJ_CAMERA, v.camera, "camera");
  if (m->cam_bodyid[ids.camera] != ids.body) {
    throw InputError(v.mjcf.string() + ": camera '" + v.camera + "' must be attached to body '" + v.body +
                     "' (vehicle description " + v.source.string() + ")");
  }
  constexpr double kGroundClearanceM = 0.005;
  // To the micrometre: the height does not depend on the last bits of the geometry's sums.
  ids.landed_height_m = std::round((kGroundClearanceM - vehicleBottom(m, ids.body)) * 1e6) / 1e6;
  return ids;
}

void setVehiclePose(const mjModel* m, mjData* d, const VehicleIds& ids, const planner::Pose4& pose) {
  mjtNum* q = d->qpos + ids.qpos_adr;
  for (int i = 0; i < 3; ++i) q[i] = pose.p_WB[i];
  q[3] = std::cos(0.5 * pose.yaw_rad);
  q[4] = 0.0;
  q[5] = 0.0;
  q[6] = std::sin(0.5 * pose.yaw_rad);
  for (int i = 0; i < 6; ++i) d->qvel[ids.qvel_adr + i] = 0.0;
  mj_forward(m, d);
}

double vehicleMass(const mjModel* m, const VehicleIds& ids) { return m->body_subtreemass[ids.body]; }

double vehicleReach(const mjModel* m, const VehicleIds& ids) {
  double reach = 0.0;
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_bodyid[g] != ids.body || (m->geom_contype[g] == 0 && m->geom_conaffinity[g] == 0)) continue;
    const mjtNum* p = m->geom_pos + 3 * static_cast<std::ptrdiff_t>(g);
    reach = std::max(reach, std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) + m->geom_rbound[g]);
  }
  return reach;
}

control::VehicleParams vehicleParamsFromModel(const mjModel* m, const VehicleIds& ids) {
  control::VehicleParams v;
  v.mass_kg = vehicleMass(m, ids);
  const std::ptrdiff_t body = ids.body;  // pointer offsets below in ptrdiff_t
  v.inertia_diag_kg_m2 = Eigen::Vector3d(m->body_inertia + 3 * body);
  v.gravity_m_s2 = -m->opt.gravity[2];
  const Eigen::Vector3d com_B(m->body_ipos + 3 * body);
  for (int i = 0; i < ids.rotorCount(); ++i) {
    const std::ptrdiff_t a = ids.motors[i];
    const std::ptrdiff_t site = m->actuator_trnid[2 * a];
    const Eigen::Quaterniond q_BS(m->site_quat[4 * site], m->site_quat[4 * site + 1], m->site_quat[4 * site + 2],
                                  m->site_quat[4 * site + 3]);
    const Eigen::Vector3d force = q_BS * Eigen::Vector3d(m->actuator_gear + 6 * a);
    const Eigen::Vector3d moment = q_BS * Eigen::Vector3d(m->actuator_gear + 6 * a + 3);
    control::Rotor r;
    r.p_B = Eigen::Vector3d(m->site_pos + 3 * site) - com_B;
    r.axis_B = force.normalized();
    r.spin = moment.dot(r.axis_B) <= 0.0 ? 1 : -1;  // drag reacts against the spin
    r.yaw_moment_ratio_m = moment.norm() / force.norm();
    r.max_thrust_n = ids.max_thrust_n[i];
    v.rotors.push_back(r);
    const double lag = ids.motor_act[i] >= 0 ? m->actuator_dynprm[a * mjNDYN] : ids.direct_lag_s;
    v.motor_time_constant_s = std::max(v.motor_time_constant_s, lag);
  }
  try {
    v.validate();
    v.checkControllable();
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("vehicle model: ") + e.what());
  }
  return v;
}

control::VehicleState vehicleState(const mjData* d, const VehicleIds& ids) {
  control::VehicleState s;
  const mjtNum* q = d->qpos + ids.qpos_adr;
  const mjtNum* v = d->qvel + ids.qvel_adr;
  s.p_WB = Eigen::Vector3d(q[0], q[1], q[2]);
  s.q_WB = Eigen::Quaterniond(q[3], q[4], q[5], q[6]).normalized();
  s.v_WB = Eigen::Vector3d(v[0], v[1], v[2]);
  s.w_B = Eigen::Vector3d(v[3], v[4], v[5]);
  return s;
}

}  // namespace tgnav::harness
