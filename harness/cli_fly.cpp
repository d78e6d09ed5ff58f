// tgnav fly: take off from the scene's start and fly a setpoint trajectory file through the
// PX4-like cascade; write the flown trajectory and a tracking summary, and optionally record the
// onboard RGB-D camera as a TUM RGB-D sequence.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "harness/camera.h"
#include "harness/cli.h"
#include "harness/config_io.h"
#include "harness/egl_context.h"
#include "harness/errors.h"
#include "harness/flight_loop.h"
#include "harness/output.h"
#include "harness/scene_config.h"
#include "harness/trajectory_csv.h"
#include "harness/trial.h"
#include "harness/tum_sequence.h"
#include "vo/tum.h"

namespace tgnav::cli {

namespace {

struct FlyOptions {
  std::string scene;
  std::string trajectory;
  std::string out;
  std::string controller;
  // Recording of the onboard camera (--record).
  std::string record;
  double record_rate_hz = 20.0;
  std::string camera_config;
  int width_px = 0;
  int height_px = 0;
  bool width_given = false;
  bool height_given = false;
  std::uint64_t seed = 0;
};

// What --record needs, checked before anything flies or is written.
struct RecordPlan {
  harness::CameraConfig camera;
  int steps_per_frame = 0;
};

RecordPlan planRecording(const FlyOptions& opt, const mjModel* model) {
  RecordPlan plan;
  if (!opt.camera_config.empty()) plan.camera = harness::loadCameraConfig(opt.camera_config);
  if (opt.width_given) plan.camera.width_px = opt.width_px;
  if (opt.height_given) plan.camera.height_px = opt.height_px;
  try {
    plan.camera.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--width/--height: ") + e.what());
  }
  plan.steps_per_frame = harness::stepsPerTick(model, opt.record_rate_hz, "--record-rate:");
  auto normal = [](const std::string& dir) {
    const std::filesystem::path p = std::filesystem::absolute(dir).lexically_normal();
    return p.has_filename() ? p : p.parent_path();  // "seq/" is "seq"
  };
  if (std::filesystem::exists(normal(opt.record))) {
    throw InputError("--record: " + opt.record + " already exists; a sequence is recorded into a new directory");
  }
  if (normal(opt.record) == normal(opt.out)) {
    throw InputError("--record: " + opt.record + " is also --out; record into its own directory");
  }
  return plan;
}

// Setpoints beyond what the controller can follow are clamped by it; count them for the report.
int countClampedSetpoints(const control::SetpointTrajectory& traj, const control::CascadeConfig& c, double gravity) {
  int n = 0;
  const double max_acc_xy = gravity * std::tan(c.position.tilt_max_rad);
  for (const auto& sp : traj.setpoints()) {
    const bool fast = sp.v_WB.head<2>().norm() > c.position.max_vel_xy_m_s || sp.v_WB.z() > c.position.max_vel_up_m_s ||
                      -sp.v_WB.z() > c.position.max_vel_down_m_s;
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
      msg << file << ": setpoint at t=" << traj.times()[i] << " s (" << p.x() << ", " << p.y() << ", " << p.z()
          << ") lies outside the scene bounds of " << scene.source.string();
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
    out << f.t_s << ',' << (f.on_trajectory ? 1 : 0) << ',' << f.setpoint.p_WB.x() << ',' << f.setpoint.p_WB.y() << ','
        << f.setpoint.p_WB.z() << ',' << std::remainder(f.setpoint.yaw_rad, 2 * M_PI) << ',' << f.state.p_WB.x() << ','
        << f.state.p_WB.y() << ',' << f.state.p_WB.z() << ',' << std::atan2(nose.y(), nose.x()) << ','
        << f.state.v_WB.x() << ',' << f.state.v_WB.y() << ',' << f.state.v_WB.z() << '\n';
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
    landed.p_WB.z() = scene.bounds_min_m.z() + harness::kLandedHeightM;
  } else {
    // A bare MJCF has no start pose: take off below the first setpoint, from z = 0.
    landed.p_WB = traj.setpoints().front().p_WB;
    landed.p_WB.z() = harness::kLandedHeightM;
    landed.yaw_rad = traj.setpoints().front().yaw_rad;
  }
  harness::setVehiclePose(model.get(), data.get(), ids, landed);
  harness::FlightLoop loop(model.get(), data.get(), ids, cascade_config);
  const bool recording = !opt.record.empty();
  const RecordPlan record = recording ? planRecording(opt, model.get()) : RecordPlan{};

  // The camera renders the state at the frame's sim time: after mj_step, kinematics still
  // describe the state before the step, so they are recomputed, in a copy of the data (doing it
  // in place changes the flight in its last bits).
  std::unique_ptr<harness::EglContext> gl;
  std::unique_ptr<harness::Camera> camera;
  std::unique_ptr<harness::SequenceWriter> writer;
  harness::DataPtr view;
  harness::FlightHooks hooks;
  auto capture = [&] {
    mj_copyData(view.get(), model.get(), data.get());
    mj_kinematics(model.get(), view.get());
    mj_camlight(model.get(), view.get());
    const harness::RgbdFrame frame = camera->render(view.get());
    writer->add(frame.t_s, frame.bgr, frame.depth_m, frame.X_WC);
  };
  if (recording) {
    view = harness::makeData(model.get());
    gl = std::make_unique<harness::EglContext>();
    camera = std::make_unique<harness::Camera>(model.get(), *gl, record.camera, opt.seed);
    writer = std::make_unique<harness::SequenceWriter>(opt.record, camera->intrinsics());
    hooks.after_step = [&](const harness::FlightLoop& l) {
      if (l.steps() % record.steps_per_frame == 0) capture();
      return std::string();
    };
  }

  const int clamped = countClampedSetpoints(traj, cascade_config, loop.vehicle().gravity_m_s2);
  if (clamped > 0) {
    std::fprintf(stderr,
                 "tgnav fly: warning: %d setpoints exceed the controller's speed or tilt "
                 "limits; the controller clamps them\n",
                 clamped);
  }

  const auto wall0 = std::chrono::steady_clock::now();
  if (recording) capture();  // the first frame, on the ground at t = 0
  const harness::FlightResult result = harness::flyTrajectory(loop, traj, flight, hooks);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const harness::TrackingSummary summary = harness::summarizeTracking(result);

  const int cam_id = mj_name2id(model.get(), mjOBJ_CAMERA, "front");
  const Eigen::Isometry3d X_BC =
      cam_id >= 0 ? harness::cameraInBody(model.get(), cam_id) : Eigen::Isometry3d::Identity();
  const std::vector<vo::StampedPose> gt = harness::cameraPoses(result, X_BC);
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
  if (recording) {
    const harness::Intrinsics& k = camera->intrinsics();
    j["record"] = {{"dir", opt.record},
                   {"frames", writer->frames()},
                   {"rate_hz", opt.record_rate_hz},
                   {"seed", opt.seed},
                   {"camera",
                    {{"name", record.camera.name},
                     {"width_px", k.width_px},
                     {"height_px", k.height_px},
                     {"fx", k.fx},
                     {"fy", k.fy},
                     {"cx", k.cx},
                     {"cy", k.cy},
                     {"min_depth_m", record.camera.min_depth_m},
                     {"max_depth_m", record.camera.max_depth_m},
                     {"rgb_noise_sigma", record.camera.rgb_noise_sigma},
                     {"depth_noise_sigma_per_m2", record.camera.depth_noise_sigma_per_m2}}}};
  } else {
    j["record"] = nullptr;
  }

  // The sequence first: it is complete (renamed into place) or absent.
  if (recording) writer->finish();
  const std::filesystem::path out(opt.out);
  harness::makeOutputDir(out);
  harness::writeFileAtomic(out / "gt.tum", vo::toTum(gt));
  harness::writeFileAtomic(out / "flight.csv", flightCsv(result));
  harness::writeFileAtomic(out / "tracking.json", j.dump(2) + "\n");
  std::printf(
      "tgnav fly: %s, %.1f s on the trajectory, position rmse %.3f m (max %.3f m), yaw rmse %.2f deg, "
      "final error %.3f m, real-time factor %.0f -> %s/{gt.tum,flight.csv,tracking.json}\n",
      completed ? "completed" : ("DIVERGED (" + result.reason + ")").c_str(), summary.duration_s,
      summary.position_rmse_m, summary.position_max_m, summary.yaw_rmse_rad * 180.0 / M_PI, summary.final_error_m,
      j["real_time_factor"].get<double>(), out.string().c_str());
  if (recording) {
    std::printf(
        "tgnav fly: recorded %d RGB-D frames (%dx%d, %g Hz, seed %llu) -> "
        "%s/{rgb.txt,depth.txt,groundtruth.txt,intrinsics.yaml,rgb/,depth/}\n",
        writer->frames(), camera->intrinsics().width_px, camera->intrinsics().height_px, opt.record_rate_hz,
        static_cast<unsigned long long>(opt.seed), writer->dir().string().c_str());
  }
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
  CLI::Option* record = cmd->add_option(
      "--record", opt->record,
      "Record the onboard RGB-D camera into this new directory as a TUM RGB-D sequence (ground truth included)");
  cmd->add_option("--record-rate", opt->record_rate_hz, "Recording rate in Hz; must divide the physics rate")
      ->capture_default_str()
      ->needs(record);
  cmd->add_option("--camera-config", opt->camera_config,
                  "Camera YAML for --record (default: built-in, see configs/camera.yaml)")
      ->needs(record);
  cmd->add_option("--width", opt->width_px, "Recorded image width in pixels (overrides the camera config)")
      ->needs(record);
  cmd->add_option("--height", opt->height_px, "Recorded image height in pixels (overrides the camera config)")
      ->needs(record);
  cmd->add_option("--seed", opt->seed, "Seed of the camera noise for --record")->capture_default_str()->needs(record);
  cmd->callback([opt, cmd] {
    opt->width_given = cmd->count("--width") > 0;
    opt->height_given = cmd->count("--height") > 0;
    runFly(*opt);
  });
}

}  // namespace tgnav::cli
