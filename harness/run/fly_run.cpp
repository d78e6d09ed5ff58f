#include "harness/run/fly_run.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>

#include "harness/base/errors.h"
#include "harness/config/config_io.h"
#include "harness/config/scene_config.h"
#include "harness/io/staged_output.h"
#include "harness/io/trajectory_csv.h"
#include "harness/io/tum_sequence.h"
#include "harness/run/trial_metrics.h"
#include "harness/sim/camera.h"
#include "harness/sim/egl_context.h"
#include "harness/sim/flight_loop.h"
#include "harness/sim/vehicle_model.h"
#include "vo/tum.h"

namespace tgnav::harness {

namespace {

// What --record needs, checked before anything flies or is written.
struct RecordPlan {
  CameraConfig camera;
  int steps_per_frame = 0;
};

RecordPlan planRecording(const FlyJob& opt, const mjModel* model, const std::string& vehicle_camera) {
  RecordPlan plan;
  if (!opt.camera_config.empty()) plan.camera = loadCameraConfig(opt.camera_config);
  plan.camera = plan.camera.on(vehicle_camera);
  if (opt.width_px) plan.camera.width_px = *opt.width_px;
  if (opt.height_px) plan.camera.height_px = *opt.height_px;
  try {
    plan.camera.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--width/--height: ") + e.what());
  }
  plan.steps_per_frame = stepsPerTick(model, opt.record_rate_hz, "--record-rate:");
  auto normal = [](const std::filesystem::path& dir) {
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

void checkAgainstScene(const SceneConfig& scene, const control::SetpointTrajectory& traj, const FlightConfig& flight,
                       const std::string& file) {
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

std::string flightCsv(const FlightResult& r) {
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

// The onboard camera recording a TUM RGB-D sequence during the flight. It renders the state at
// the frame's sim time: after mj_step, kinematics still describe the state before the step, so
// they are recomputed, in a copy of the data (doing it in place changes the flight in its last
// bits).
class Recorder {
 public:
  Recorder(mjModel* m, const mjData* d, const FlyJob& job, const RecordPlan& plan)
      : m_(m),
        d_(d),
        view_(makeData(m)),
        camera_(m, gl_, plan.camera, job.seed),
        writer_(job.record, camera_.intrinsics()) {}
  void capture() {
    mj_copyData(view_.get(), m_, d_);
    mj_kinematics(m_, view_.get());
    mj_camlight(m_, view_.get());
    const RgbdFrame frame = camera_.render(view_.get());
    writer_.add(frame.t_s, frame.bgr, frame.depth_m, frame.X_WC);
  }
  void finish() { writer_.finish(); }
  const Intrinsics& intrinsics() const { return camera_.intrinsics(); }
  int frames() const { return writer_.frames(); }
  const std::filesystem::path& dir() const { return writer_.dir(); }

 private:
  mjModel* m_;
  const mjData* d_;
  DataPtr view_;
  EglContext gl_;
  Camera camera_;
  SequenceWriter writer_;
};

// The landed pose: the scene's start, or for a bare MJCF below the first setpoint at z = 0.
planner::Pose4 landedPose(const SceneConfig& scene, const control::SetpointTrajectory& traj, const FlyJob& job,
                          double landed_height_m) {
  planner::Pose4 landed = scene.start;
  if (scene.source != scene.mjcf) {
    checkAgainstScene(scene, traj, FlightConfig{}, job.trajectory.string());
    landed.p_WB.z() = scene.bounds_min_m.z() + landed_height_m;
  } else {
    landed.p_WB = traj.setpoints().front().p_WB;
    landed.p_WB.z() = landed_height_m;
    landed.yaw_rad = traj.setpoints().front().yaw_rad;
  }
  return landed;
}

nlohmann::ordered_json recordJson(const FlyJob& job, const RecordPlan& plan, const Recorder& rec) {
  const Intrinsics& k = rec.intrinsics();
  return {{"dir", job.record},
          {"frames", rec.frames()},
          {"rate_hz", job.record_rate_hz},
          {"seed", job.seed},
          {"camera",
           {{"name", plan.camera.name},
            {"width_px", k.width_px},
            {"height_px", k.height_px},
            {"fx", k.fx},
            {"fy", k.fy},
            {"cx", k.cx},
            {"cy", k.cy},
            {"min_depth_m", plan.camera.min_depth_m},
            {"max_depth_m", plan.camera.max_depth_m},
            {"rgb_noise_sigma", plan.camera.rgb_noise_sigma},
            {"depth_noise_sigma_per_m2", plan.camera.depth_noise_sigma_per_m2}}}};
}

nlohmann::ordered_json trackingJson(const FlyJob& job, const FlightResult& result, int clamped, double sim_s,
                                    double wall_s) {
  const TrackingSummary summary = summarizeTracking(result);
  const bool completed = result.status == FlightStatus::kCompleted;
  nlohmann::ordered_json j;
  j["status"] = completed ? "completed" : "diverged";
  j["reason"] = completed ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(result.reason);
  j["trajectory_file"] = job.trajectory.string();
  j["scene"] = job.scene.string();
  j["trajectory_start_s"] = result.trajectory_start_s;
  j["duration_s"] = summary.duration_s;
  j["position_rmse_m"] = summary.position_rmse_m;
  j["position_max_error_m"] = summary.position_max_m;
  j["yaw_rmse_deg"] = summary.yaw_rmse_rad * 180.0 / M_PI;
  j["final_error_m"] = summary.final_error_m;
  j["clamped_setpoints"] = clamped;
  j["sim_time_s"] = sim_s;
  j["wall_time_s"] = wall_s;
  j["real_time_factor"] = wall_s > 0 ? sim_s / wall_s : 0.0;
  j["record"] = nullptr;
  return j;
}

}  // namespace

FlyRunResult runFly(const FlyJob& job) {
  const SceneConfig scene = loadScene(job.scene);
  const control::SetpointTrajectory traj = readTrajectoryCsv(job.trajectory);
  VehicleModel vehicle = loadVehicleModel(scene.mjcf, job.vehicle.empty() ? scene.vehicle : job.vehicle);
  // Gains: built-in defaults < the vehicle's gains file < --controller.
  control::CascadeConfig cascade_config;
  if (!vehicle.vehicle.controller_config.empty()) {
    cascade_config = loadCascadeConfig(vehicle.vehicle.controller_config);
  }
  if (!job.controller.empty()) cascade_config = loadCascadeConfig(job.controller, cascade_config);

  ModelPtr model = std::move(vehicle.model);
  DataPtr data = makeData(model.get());
  const VehicleIds& ids = vehicle.ids;
  setVehiclePose(model.get(), data.get(), ids, landedPose(scene, traj, job, ids.landed_height_m));
  FlightLoop loop(model.get(), data.get(), ids, cascade_config);
  const bool recording = !job.record.empty();
  const RecordPlan plan = recording ? planRecording(job, model.get(), vehicle.vehicle.camera) : RecordPlan{};
  std::unique_ptr<Recorder> recorder;
  FlightHooks hooks;
  if (recording) {
    recorder = std::make_unique<Recorder>(model.get(), data.get(), job, plan);
    hooks.after_step = [&](const FlightLoop& l) {
      if (l.steps() % plan.steps_per_frame == 0) recorder->capture();
      return std::string();
    };
  }
  FlyRunResult out;
  out.clamped_setpoints = countClampedSetpoints(traj, cascade_config, loop.vehicle().gravity_m_s2);
  if (out.clamped_setpoints > 0) {
    std::fprintf(stderr,
                 "tgnav fly: warning: %d setpoints exceed the controller's speed or tilt limits; the controller "
                 "clamps them\n",
                 out.clamped_setpoints);
  }

  const auto wall0 = std::chrono::steady_clock::now();
  if (recording) recorder->capture();  // the first frame, on the ground at t = 0
  const FlightResult result = flyTrajectory(loop, traj, FlightConfig{}, hooks);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  out.tracking = trackingJson(job, result, out.clamped_setpoints, data->time, wall_s);
  if (recording) {
    out.tracking["record"] = recordJson(job, plan, *recorder);
    recorder->finish();  // the sequence first: it is complete (renamed into place) or absent
    out.tracking["record"]["dir"] = recorder->dir().string();
  }

  const int cam_id = recording ? mj_name2id(model.get(), mjOBJ_CAMERA, plan.camera.name.c_str()) : ids.camera;
  const Eigen::Isometry3d X_BC = cameraInBody(model.get(), cam_id);
  StagedDir staged(job.out);
  writeFileAtomic(staged.staging() / "gt.tum", vo::toTum(cameraPoses(result, X_BC)));
  writeFileAtomic(staged.staging() / "flight.csv", flightCsv(result));
  writeFileAtomic(staged.staging() / "tracking.json", out.tracking.dump(2) + "\n");
  staged.commit(OnExisting::kMerge);
  out.out = staged.target();
  return out;
}

std::string flySummaryLines(const FlyRunResult& r) {
  const nlohmann::ordered_json& j = r.tracking;
  const bool completed = j["status"] == "completed";
  char line[1024];
  std::snprintf(line, sizeof line,
                "tgnav fly: %s, %.1f s on the trajectory, position rmse %.3f m (max %.3f m), yaw rmse %.2f deg, "
                "final error %.3f m, real-time factor %.0f -> %s/{gt.tum,flight.csv,tracking.json}\n",
                completed ? "completed" : ("DIVERGED (" + j["reason"].get<std::string>() + ")").c_str(),
                j["duration_s"].get<double>(), j["position_rmse_m"].get<double>(),
                j["position_max_error_m"].get<double>(), j["yaw_rmse_deg"].get<double>(),
                j["final_error_m"].get<double>(), j["real_time_factor"].get<double>(), r.out.string().c_str());
  std::string text = line;
  if (!j["record"].is_null()) {
    const auto& rec = j["record"];
    std::snprintf(line, sizeof line,
                  "tgnav fly: recorded %d RGB-D frames (%dx%d, %g Hz, seed %llu) -> "
                  "%s/{rgb.txt,depth.txt,groundtruth.txt,intrinsics.yaml,rgb/,depth/}\n",
                  rec["frames"].get<int>(), rec["camera"]["width_px"].get<int>(), rec["camera"]["height_px"].get<int>(),
                  rec["rate_hz"].get<double>(), static_cast<unsigned long long>(rec["seed"].get<std::uint64_t>()),
                  rec["dir"].get<std::string>().c_str());
    text += line;
  }
  return text;
}

}  // namespace tgnav::harness
