// tgnav fly: take off from the scene's start and fly a setpoint trajectory file through the
// PX4-like cascade; write the flown trajectory and a tracking summary.
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "harness/camera.h"
#include "harness/cli.h"
#include "harness/config_io.h"
#include "harness/errors.h"
#include "harness/flight_loop.h"
#include "harness/output.h"
#include "harness/scene_config.h"
#include "harness/trajectory_csv.h"
#include "vo/tum.h"

namespace tgnav::cli {

namespace {

// Height of the centre of mass above the ground when landed: hull half-height 0.03 m of
// models/quadrotor.xml plus 5 mm of clearance; the vehicle settles onto the floor.
constexpr double kLandedHeightM = 0.035;

struct FlyOptions {
  std::string scene;
  std::string trajectory;
  std::string out;
  std::string controller;
};

// Setpoints beyond what the controller can follow are clamped by it; count them for the report.
int countClampedSetpoints(const control::SetpointTrajectory& traj, const control::CascadeConfig& c,
                          double gravity) {
  int n = 0;
  const double max_acc_xy = gravity * std::tan(c.position.tilt_max_rad);
  for (const auto& sp : traj.setpoints()) {
    const bool fast = sp.v_WB.head<2>().norm() > c.position.max_vel_xy_m_s ||
                      sp.v_WB.z() > c.position.max_vel_up_m_s || -sp.v_WB.z() > c.position.max_vel_down_m_s;
    const bool steep = sp.a_WB.head<2>().norm() > max_acc_xy;
    n += (fast || steep) ? 1 : 0;
  }
  return n;
}

void checkAgainstScene(const harness::SceneConfig& scene, const control::SetpointTrajectory& traj,
                       const harness::FlightConfig& flight, const std::string& file) {
  const auto& first = traj.setpoints().front();
  const double offset = (first.p_WB.head<2>() - scene.start.p_WB.head<2>()).norm();
  if (offset > flight.max_start_offset_m) {
    std::ostringstream msg;
    msg << file << ": first setpoint (" << first.p_WB.x() << ", " << first.p_WB.y() << ") is " << offset
        << " m from the scene's start (" << scene.start.p_WB.x() << ", " << scene.start.p_WB.y()
        << "); the vehicle takes off from the start";
    throw InputError(msg.str());
  }
  for (std::size_t i = 0; i < traj.setpoints().size(); ++i) {
    const Eigen::Vector3d& p = traj.setpoints()[i].p_WB;
    if ((p.array() < scene.bounds_min_m.array()).any() || (p.array() > scene.bounds_max_m.array()).any()) {
      std::ostringstream msg;
      msg << file << ": setpoint at t=" << traj.times()[i] << " s (" << p.x() << ", " << p.y() << ", "
          << p.z() << ") lies outside the scene bounds of " << scene.source.string();
      throw InputError(msg.str());
    }
  }
}

std::string flightCsv(const harness::FlightResult& r) {
  std::ostringstream out;
  out.precision(6);
  out << std::fixed;
  out << "t,on_trajectory,x_sp,y_sp,z_sp,yaw_sp,x,y,z,yaw,vx,vy,vz\n";
  for (const auto& f : r.log) {
    const Eigen::Vector3d nose = f.state.q_WB * Eigen::Vector3d::UnitX();
    out << f.t_s << ',' << (f.on_trajectory ? 1 : 0) << ',' << f.setpoint.p_WB.x() << ',' << f.setpoint.p_WB.y()
        << ',' << f.setpoint.p_WB.z() << ',' << std::remainder(f.setpoint.yaw_rad, 2 * M_PI) << ','
        << f.state.p_WB.x() << ',' << f.state.p_WB.y() << ',' << f.state.p_WB.z() << ','
        << std::atan2(nose.y(), nose.x()) << ',' << f.state.v_WB.x() << ',' << f.state.v_WB.y() << ','
        << f.state.v_WB.z() << '\n';
  }
  return out.str();
}

void runFly(const FlyOptions& opt) {
  const harness::SceneConfig scene = harness::loadScene(opt.scene);
  const bool has_scene_yaml = scene.source != scene.mjcf;
  const control::SetpointTrajectory traj = harness::readTrajectoryCsv(opt.trajectory);
  control::CascadeConfig cascade_config;
  if (!opt.controller.empty()) cascade_config = harness::loadCascadeConfig(opt.controller);
  const harness::FlightConfig flight;

  harness::ModelPtr model = harness::loadModel(scene.mjcf);
  harness::DataPtr data = harness::makeData(model.get());
  const auto ids = harness::VehicleIds::find(model.get(), scene.mjcf.string());
  planner::Pose4 landed = scene.start;
  if (has_scene_yaml) {
    checkAgainstScene(scene, traj, flight, opt.trajectory);
    landed.p_WB.z() = scene.bounds_min_m.z() + kLandedHeightM;
  } else {
    // A bare MJCF has no start pose: take off below the first setpoint, from z = 0.
    landed.p_WB = traj.setpoints().front().p_WB;
    landed.p_WB.z() = kLandedHeightM;
    landed.yaw_rad = traj.setpoints().front().yaw_rad;
  }
  harness::setVehiclePose(model.get(), data.get(), ids, landed);
  harness::FlightLoop loop(model.get(), data.get(), ids, cascade_config);
  const int clamped = countClampedSetpoints(traj, cascade_config, loop.vehicle().gravity_m_s2);
  if (clamped > 0) {
    std::fprintf(stderr, "tgnav fly: warning: %d setpoints exceed the controller's speed or tilt "
                         "limits; the controller clamps them\n", clamped);
  }

  const auto wall0 = std::chrono::steady_clock::now();
  const harness::FlightResult result = harness::flyTrajectory(loop, traj, flight);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const harness::TrackingSummary summary = harness::summarizeTracking(result);

  const int cam_id = mj_name2id(model.get(), mjOBJ_CAMERA, "front");
  const Eigen::Isometry3d X_BC = cam_id >= 0 ? harness::cameraInBody(model.get(), cam_id) : Eigen::Isometry3d::Identity();
  std::vector<vo::StampedPose> gt;
  gt.reserve(result.log.size());
  for (const auto& f : result.log) {
    Eigen::Isometry3d X_WB = Eigen::Isometry3d::Identity();
    X_WB.linear() = f.state.q_WB.toRotationMatrix();
    X_WB.translation() = f.state.p_WB;
    gt.push_back(vo::StampedPose{f.t_s, X_WB * X_BC});
  }
  const bool completed = result.status == harness::FlightStatus::kCompleted;
  nlohmann::ordered_json j;
  j["status"] = completed ? "completed" : "diverged";
  j["reason"] = completed ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(result.reason);
  j["trajectory_file"] = opt.trajectory;
  j["scene"] = opt.scene;
  j["trajectory_start_s"] = result.trajectory_start_s;
  j["duration_s"] = summary.duration_s;
  j["position_rmse_m"] = summary.position_rmse_m;
  j["position_max_error_m"] = summary.position_max_m;
  j["yaw_rmse_deg"] = summary.yaw_rmse_rad * 180.0 / M_PI;
  j["final_error_m"] = summary.final_error_m;
  j["clamped_setpoints"] = clamped;
  j["sim_time_s"] = data->time;
  j["wall_time_s"] = wall_s;
  j["real_time_factor"] = wall_s > 0 ? data->time / wall_s : 0.0;

  const std::filesystem::path out(opt.out);
  harness::makeOutputDir(out);
  harness::writeFileAtomic(out / "gt.tum", vo::toTum(gt));
  harness::writeFileAtomic(out / "flight.csv", flightCsv(result));
  harness::writeFileAtomic(out / "tracking.json", j.dump(2) + "\n");
  std::printf("tgnav fly: %s, %.1f s on the trajectory, position rmse %.3f m (max %.3f m), yaw rmse %.2f deg, "
              "final error %.3f m, real-time factor %.0f -> %s/{gt.tum,flight.csv,tracking.json}\n",
              completed ? "completed" : ("DIVERGED (" + result.reason + ")").c_str(), summary.duration_s,
              summary.position_rmse_m, summary.position_max_m, summary.yaw_rmse_rad * 180.0 / M_PI,
              summary.final_error_m, j["real_time_factor"].get<double>(), out.string().c_str());
}

}  // namespace

void addFlyCommand(CLI::App& app) {
  auto opt = std::make_shared<FlyOptions>();
  CLI::App* cmd = app.add_subcommand("fly", "Take off and fly a setpoint trajectory (CSV) in MuJoCo");
  cmd->add_option("--scene", opt->scene, "Scene YAML (start pose, bounds) or MJCF file")->required();
  cmd->add_option("--trajectory", opt->trajectory,
                  "CSV with header: t,x,y,z,yaw[,vx,vy,vz][,ax,ay,az][,yaw_rate] (s, m, rad)")
      ->required();
  cmd->add_option("--out", opt->out, "Output directory")->required();
  cmd->add_option("--controller", opt->controller, "Controller YAML (default: built-in, see configs/controller.yaml)");
  cmd->callback([opt] { runFly(*opt); });
}

}  // namespace tgnav::cli
