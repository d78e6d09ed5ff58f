#include "harness/sim/mujoco_sim.h"

#include <Eigen/Geometry>
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

VehicleIds VehicleIds::find(const mjModel* m, const std::string& source) {
  auto need = [&](int id, const std::string& what) {
    if (id < 0) throw InputError(source + ": model has no " + what + " (include models/quadrotor.xml)");
    return id;
  };
  VehicleIds ids;
  ids.body = need(mj_name2id(m, mjOBJ_BODY, "quadrotor"), "body 'quadrotor'");
  const int joint = need(mj_name2id(m, mjOBJ_JOINT, "quadrotor_root"), "joint 'quadrotor_root'");
  if (m->jnt_type[joint] != mjJNT_FREE) throw InputError(source + ": joint 'quadrotor_root' is not a free joint");
  ids.qpos_adr = m->jnt_qposadr[joint];
  ids.qvel_adr = m->jnt_dofadr[joint];
  for (int i = 0; i < 4; ++i) {
    const std::string name = "motor" + std::to_string(i);
    ids.motors[i] = need(mj_name2id(m, mjOBJ_ACTUATOR, name.c_str()), "actuator '" + name + "'");
    if (m->actuator_dyntype[ids.motors[i]] != mjDYN_FILTER) {
      throw InputError(source + ": actuator '" + name + "' needs filter dynamics (motor lag)");
    }
    // MuJoCo 2.2 stores activations of the last `na` actuators, in actuator order.
    ids.motor_act[i] = ids.motors[i] - (m->nu - m->na);
  }
  ids.gyro_adr = m->sensor_adr[need(mj_name2id(m, mjOBJ_SENSOR, "gyro"), "sensor 'gyro'")];
  ids.accel_adr = m->sensor_adr[need(mj_name2id(m, mjOBJ_SENSOR, "accel"), "sensor 'accel'")];
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

control::VehicleParams vehicleParamsFromModel(const mjModel* m, const VehicleIds& ids) {
  control::VehicleParams v;
  v.mass_kg = vehicleMass(m, ids);
  const std::ptrdiff_t body = ids.body;  // pointer offsets below in ptrdiff_t
  v.inertia_diag_kg_m2 = Eigen::Vector3d(m->body_inertia + 3 * body);
  v.gravity_m_s2 = -m->opt.gravity[2];
  const Eigen::Vector3d com_B(m->body_ipos + 3 * body);
  for (int i = 0; i < 4; ++i) {
    const std::ptrdiff_t a = ids.motors[i];
    const std::ptrdiff_t site = m->actuator_trnid[2 * a];
    if (m->actuator_trntype[a] != mjTRN_SITE || m->site_bodyid[site] != ids.body) {
      throw InputError("actuator 'motor" + std::to_string(i) + "' must act on a site of body 'quadrotor'");
    }
    const Eigen::Quaterniond q_BS(m->site_quat[4 * site], m->site_quat[4 * site + 1], m->site_quat[4 * site + 2],
                                  m->site_quat[4 * site + 3]);
    const Eigen::Vector3d force = q_BS * Eigen::Vector3d(m->actuator_gear + 6 * a);
    const Eigen::Vector3d moment = q_BS * Eigen::Vector3d(m->actuator_gear + 6 * a + 3);
    control::Rotor r;
    r.p_B = Eigen::Vector3d(m->site_pos + 3 * site) - com_B;
    r.axis_B = force.normalized();
    r.spin = moment.dot(r.axis_B) <= 0.0 ? 1 : -1;  // drag reacts against the spin
    r.yaw_moment_ratio_m = moment.norm() / force.norm();
    r.max_thrust_n = m->actuator_ctrlrange[2 * a + 1] * m->actuator_gainprm[a * mjNGAIN] * force.norm();
    v.rotors.push_back(r);
    v.motor_time_constant_s = m->actuator_dynprm[a * mjNDYN];
  }
  try {
    v.validate();
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
