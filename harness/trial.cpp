#include "harness/trial.h"

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <exception>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include "control/state_estimator.h"
#include "harness/camera.h"
#include "harness/egl_context.h"
#include "harness/errors.h"
#include "harness/imu_sim.h"
#include "harness/mujoco_sim.h"
#include "vo/metrics.h"

namespace tgnav::harness {

const char* toString(TrialStatus status) {
  switch (status) {
    case TrialStatus::kSuccess:
      return "success";
    case TrialStatus::kVoLost:
      return "vo_lost";
    case TrialStatus::kCollision:
      return "collision";
    case TrialStatus::kDiverged:
      return "diverged";
    case TrialStatus::kTimeout:
      return "timeout";
    case TrialStatus::kPlanFailed:
      return "plan_failed";
    case TrialStatus::kInterrupted:
      return "incomplete";
  }
  return "unknown";
}

std::uint64_t trialSeed(std::uint64_t seed, std::uint64_t stream) {
  // splitmix64 of the seed offset by the stream: independent, well-mixed streams.
  std::uint64_t z = seed + stream * 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

std::vector<vo::StampedPose> cameraPoses(const FlightResult& flight, const Eigen::Isometry3d& X_BC) {
  std::vector<vo::StampedPose> poses;
  poses.reserve(flight.log.size());
  for (const FlightSample& f : flight.log) {
    Eigen::Isometry3d X_WB = Eigen::Isometry3d::Identity();
    X_WB.linear() = f.state.q_WB.toRotationMatrix();
    X_WB.translation() = f.state.p_WB;
    poses.push_back(vo::StampedPose{f.t_s, X_WB * X_BC});
  }
  return poses;
}

double peakRssMb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // kB
  }
  return 0.0;
}

namespace {

std::string formatPoint(const Eigen::Vector3d& p) {
  std::ostringstream s;
  s.precision(2);
  s << std::fixed << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return s.str();
}

// The VO stage: camera noise, then tracking, frame after frame in submission order; on a worker
// thread (threaded) or inline. A frame's noise and result do not depend on the mode.
class VoPipeline {
 public:
  struct Done {
    vo::FrameResult vo;
    Eigen::Isometry3d X_WC_true;
    cv::Mat image;  // the noised image, when asked to keep it (and at the first loss)
  };

  VoPipeline(vo::RgbdOdometry& odometry, CameraNoise& noise, bool reinitialises, bool threaded)
      : odometry_(odometry), noise_(noise), reinitialises_(reinitialises) {
    if (threaded) worker_ = std::thread([this] { run(); });
  }
  ~VoPipeline() { stopWorker(); }
  VoPipeline(const VoPipeline&) = delete;
  VoPipeline& operator=(const VoPipeline&) = delete;

  void submit(RgbdFrame frame, bool keep_image) {
    if (!worker_.joinable()) {
      process(Job{std::move(frame), keep_image});
      return;
    }
    std::unique_lock<std::mutex> lock(mutex_);
    // A short queue bounds memory; the simulation runs at most this far ahead of the VO.
    changed_.wait(lock, [&] { return queue_.size() < kQueueCapacity || error_; });
    rethrowLocked();
    queue_.push_back(Job{std::move(frame), keep_image});
    changed_.notify_all();
  }

  // The result of the k-th submitted frame, waiting for it.
  Done result(std::size_t k) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return done_.size() > k || error_; });
    rethrowLocked();
    return done_[k];
  }

  // Whether some frame processed so far was lost for good (no re-initialisation).
  bool failedForGood() const { return failed_for_good_.load(); }

  std::vector<Done> finish() {
    stopWorker();
    std::lock_guard<std::mutex> lock(mutex_);
    rethrowLocked();
    return std::move(done_);
  }

 private:
  static constexpr std::size_t kQueueCapacity = 3;
  struct Job {
    RgbdFrame frame;
    bool keep_image;
  };

  void process(Job job) {
    noise_.apply(&job.frame);
    const bool failed_before = odometry_.failed();
    Done d{odometry_.track(job.frame.t_s, job.frame.bgr, job.frame.depth_m), job.frame.X_WC, cv::Mat()};
    const bool first_loss = !failed_before && odometry_.failed();
    if (job.keep_image || first_loss) d.image = job.frame.bgr;
    if (odometry_.failed() && !reinitialises_) failed_for_good_.store(true);
    std::lock_guard<std::mutex> lock(mutex_);
    done_.push_back(std::move(d));
    changed_.notify_all();
  }

  void run() {
    for (;;) {
      Job job;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] { return !queue_.empty() || stop_; });
        if (queue_.empty()) return;  // stopping, all done
        job = std::move(queue_.front());
        queue_.pop_front();
        changed_.notify_all();
      }
      try {
        process(std::move(job));
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex_);
        error_ = std::current_exception();
        changed_.notify_all();
        return;
      }
    }
  }

  void stopWorker() {
    if (!worker_.joinable()) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
      changed_.notify_all();
    }
    worker_.join();
  }

  void rethrowLocked() const {
    if (error_) std::rethrow_exception(error_);
  }

  vo::RgbdOdometry& odometry_;
  CameraNoise& noise_;
  bool reinitialises_;
  std::thread worker_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Job> queue_;
  std::vector<Done> done_;
  bool stop_ = false;
  std::exception_ptr error_;
  std::atomic<bool> failed_for_good_{false};
};

// Height above the landed pose from which a touch of the ground is a crash.
constexpr double kLiftOffM = 0.1;

// The other party of a contact involving the vehicle, or -1 when the contact does not involve it.
int contactPartner(const mjModel* m, const mjContact& c, int vehicle_root) {
  const bool g1 = m->body_rootid[m->geom_bodyid[c.geom1]] == vehicle_root;
  const bool g2 = m->body_rootid[m->geom_bodyid[c.geom2]] == vehicle_root;
  if (g1 == g2) return -1;
  return g1 ? c.geom2 : c.geom1;
}

std::string geomName(const mjModel* m, int geom) {
  const char* name = mj_id2name(m, mjOBJ_GEOM, geom);
  if (name != nullptr && name[0] != '\0') return name;
  const char* body = mj_id2name(m, mjOBJ_BODY, m->geom_bodyid[geom]);
  return "geom " + std::to_string(geom) + (body != nullptr ? std::string(" of body ") + body : std::string());
}

std::string frameCaption(const vo::FrameResult& r) {
  std::ostringstream s;
  s.precision(1);
  s << std::fixed << "t=" << r.t_s << " s " << vo::toString(r.status) << " (" << r.inliers << " inliers)";
  return s.str();
}

Eigen::Vector3d positionAt(const FlightResult& flight, double t_s) {
  Eigen::Vector3d p = flight.log.empty() ? Eigen::Vector3d::Zero() : flight.log.front().state.p_WB;
  for (const FlightSample& f : flight.log) {
    if (f.t_s > t_s + 1e-9) break;
    p = f.state.p_WB;
  }
  return p;
}

}  // namespace

TrialResult runTrial(const Scenario& scenario, const planner::FeatureMap& map, const TrialOptions& options,
                     const ProgressFn& progress, const std::atomic<bool>* interrupt) {
  TrialResult result;
  result.plan = runPlanner(scenario, map, options.planner, options.seed, options.rrt_samples);
  const planner::Plan& plan = result.plan.report.plan;
  if (plan.chosen < 0 || !result.plan.trajectory.trajectory) {
    result.status = TrialStatus::kPlanFailed;
    result.detail = plan.chosen < 0 ? std::string("no path: ") + planner::toString(plan.status)
                                    : "trajectory generation failed: " + result.plan.trajectory.reason;
    return result;
  }
  if (interrupt != nullptr && interrupt->load()) {
    result.status = TrialStatus::kInterrupted;
    result.detail = "interrupted after planning";
    return result;
  }
  result.setpoints = setpoints(result.plan, scenario.planner.trajectory.sample_rate_hz);
  const control::SetpointTrajectory& trajectory = *result.setpoints;
  const TrialConfig& cfg = scenario.trial;

  // The vehicle on the ground at the start, facing the start yaw.
  ModelPtr model = loadModel(scenario.scene.mjcf);
  DataPtr data = makeData(model.get());
  DataPtr view = makeData(model.get());
  const VehicleIds ids = VehicleIds::find(model.get(), scenario.scene.mjcf.string());
  planner::Pose4 landed = scenario.scene.start;
  landed.p_WB.z() = scenario.scene.bounds_min_m.z() + kLandedHeightM;
  setVehiclePose(model.get(), data.get(), ids, landed);
  FlightLoop loop(model.get(), data.get(), ids, scenario.controller);
  const int steps_per_frame = stepsPerTick(model.get(), cfg.camera_rate_hz, "trial.camera_rate_hz =");
  const FlightTimeline timeline = flightTimeline(loop, trajectory, cfg.flight);
  result.planned_flight_s = timeline.end_s;

  EglContext gl;
  Camera camera(model.get(), gl, scenario.camera, 0);  // renders noiseless; noise in the VO stage
  CameraNoise noise(scenario.camera, trialSeed(options.seed, 1));
  const int cam_id = mj_name2id(model.get(), mjOBJ_CAMERA, scenario.camera.name.c_str());
  result.X_BC = cameraInBody(model.get(), cam_id);
  const Eigen::Isometry3d X_CB = result.X_BC.inverse();
  const double gravity = loop.vehicle().gravity_m_s2;
  SimulatedImu imu(cfg.imu, ids, trialSeed(options.seed, 2));
  const bool fly_on_vo = cfg.state_source == StateSource::kVo;
  control::StateEstimator estimator(cfg.estimator, gravity);
  estimator.reset(loop.state(), loop.time());

  auto render = [&] {
    mj_copyData(view.get(), model.get(), data.get());
    mj_kinematics(model.get(), view.get());
    mj_camlight(model.get(), view.get());
    return camera.renderNoiseless(view.get());
  };

  // Frames kept for the strip: evenly spread over the planned flight.
  const auto planned_frames = static_cast<long>(std::floor(timeline.end_s * cfg.camera_rate_hz + 1e-9)) + 1;
  std::set<long> strip;
  for (int i = 0; i < options.strip_frames; ++i) {
    strip.insert(options.strip_frames == 1 ? planned_frames / 2
                                           : std::lround(static_cast<double>(i) * (planned_frames - 1) /
                                                         (options.strip_frames - 1)));
  }

  RgbdFrame first = render();
  vo::RgbdOdometry odometry(camera.intrinsics(), scenario.vo, first.X_WC);
  const bool reinitialise = scenario.vo.reinitialise_after_lost;
  VoPipeline pipeline(odometry, noise, reinitialise, cfg.pipeline);
  long frame_index = 0;
  pipeline.submit(std::move(first), strip.count(0) > 0);

  // A VO pose is fused one camera period after its image; rendering stops once tracking is lost
  // for good (the frames after it are not scored).
  long fused_up_to = -1;
  bool vo_failed_known = false;  // among the fused results (deterministic in both modes)
  auto fuseResult = [&](long k) {
    const VoPipeline::Done d = pipeline.result(static_cast<std::size_t>(k));
    fused_up_to = k;
    if (d.vo.status == vo::TrackingStatus::kLost) {
      if (!reinitialise) vo_failed_known = true;
      return;
    }
    estimator.fusePose(d.vo.t_s, d.vo.X_WC * X_CB);
  };

  const int vehicle_root = model->body_rootid[ids.body];
  bool airborne = false;
  bool interrupted = false;
  bool left_bounds = false;
  const auto wall0 = std::chrono::steady_clock::now();
  FlightHooks hooks;
  if (fly_on_vo) hooks.control_state = [&](const FlightLoop&) { return estimator.state(); };
  hooks.after_step = [&](const FlightLoop& l) -> std::string {
    const mjData* d = data.get();
    const control::ImuSample sample = imu.sample(d);
    if (fly_on_vo) estimator.propagate(sample);

    // Contacts: once the vehicle has climbed clear of the ground, any contact is a collision
    // (before, it settles and lifts off on the floor).
    const Eigen::Vector3d p = l.state().p_WB;
    int partner = -1;
    for (int i = 0; i < d->ncon && partner < 0; ++i) partner = contactPartner(model.get(), d->contact[i], vehicle_root);
    if (p.z() > landed.p_WB.z() + kLiftOffM) airborne = true;
    if (partner >= 0 && airborne) {
      result.collision = TrialEvent{l.time(), p, geomName(model.get(), partner)};
      return "collision with " + result.collision->what + " at " + formatPoint(p);
    }
    constexpr double kBoundsSlackM = 1.0;
    if ((p.array() < scenario.scene.bounds_min_m.array() - kBoundsSlackM).any() ||
        (p.array() > scenario.scene.bounds_max_m.array() + kBoundsSlackM).any()) {
      left_bounds = true;
      return "left the scene at " + formatPoint(p);
    }

    if (l.steps() % steps_per_frame == 0) {
      ++frame_index;
      // Render this frame first (the state is settled), then fuse the previous frame's pose,
      // which the controller uses from now on: the VO of frame k-1 overlaps the render of k.
      const bool stop_rendering =
          fly_on_vo ? vo_failed_known : (!reinitialise && pipeline.failedForGood());
      if (!stop_rendering) pipeline.submit(render(), strip.count(frame_index) > 0);
      if (fly_on_vo && fused_up_to < frame_index - 1 && !vo_failed_known) fuseResult(frame_index - 1);
      if (progress) {
        TrialProgress pr;
        pr.sim_s = l.time();
        pr.sim_total_s = timeline.end_s;
        const double on_traj = l.time() - timeline.trajectory_start_s;
        const double traj_s = trajectory.endTime() - trajectory.startTime();
        pr.path_fraction = traj_s > 0 ? std::clamp(on_traj / traj_s, 0.0, 1.0) : 1.0;
        pr.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
        progress(pr);
      }
    }
    if (interrupt != nullptr && interrupt->load()) {
      interrupted = true;
      return "interrupted";
    }
    return std::string();
  };
  result.flight = flyTrajectory(loop, trajectory, cfg.flight, hooks);
  std::vector<VoPipeline::Done> done = pipeline.finish();
  result.flight_wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  result.sim_time_s = data->time;
  result.vo_fused = estimator.fused();
  result.vo_rejected = estimator.rejected();

  // Frames up to the first loss (all of them when the VO re-initialises).
  for (VoPipeline::Done& d : done) {
    const bool lost = d.vo.status == vo::TrackingStatus::kLost;
    if (!d.image.empty()) {
      result.strip_captions.push_back(frameCaption(d.vo));
      result.strip.push_back(d.image);
    }
    result.frames.push_back(TrialFrame{d.vo, d.X_WC_true});
    if (lost && !result.vo_lost) {
      result.vo_lost = TrialEvent{d.vo.t_s, positionAt(result.flight, d.vo.t_s), d.vo.reason};
    }
    if (lost && !reinitialise) break;
  }

  // What decided the outcome, most severe first.
  const Eigen::Vector3d final_p = result.flight.log.empty() ? Eigen::Vector3d::Zero() : loop.state().p_WB;
  result.final_distance_to_goal_m = (final_p - scenario.scene.goal.p_WB).norm();
  const double to_goal = result.final_distance_to_goal_m;
  std::ostringstream why;
  why.precision(2);
  why << std::fixed;
  std::string after_loss;
  if (result.vo_lost) {
    std::ostringstream s;
    s.precision(2);
    s << std::fixed << ", after VO was lost at t = " << result.vo_lost->t_s << " s";
    after_loss = s.str();
  }
  if (interrupted) {
    result.status = TrialStatus::kInterrupted;
    why << "interrupted at t = " << result.sim_time_s << " s of " << timeline.end_s << " s";
  } else if (result.collision) {
    result.status = TrialStatus::kCollision;
    why << "collision with " << result.collision->what << " at t = " << result.collision->t_s << " s at "
        << formatPoint(result.collision->p_WB) << after_loss;
  } else if (result.flight.status != FlightStatus::kCompleted || left_bounds) {
    result.status = TrialStatus::kDiverged;
    why << result.flight.reason << " at t = " << result.sim_time_s << " s" << after_loss;
  } else if (result.vo_lost) {
    result.status = TrialStatus::kVoLost;
    why << "VO lost at t = " << result.vo_lost->t_s << " s at " << formatPoint(result.vo_lost->p_WB) << ": "
        << result.vo_lost->what;
  } else if (to_goal > cfg.goal_radius_m) {
    result.status = TrialStatus::kTimeout;
    why << "the flight ended " << to_goal << " m from the goal (goal radius " << cfg.goal_radius_m << " m)";
  } else {
    result.status = TrialStatus::kSuccess;
    why << "reached the goal (" << to_goal << " m from it) with VO tracking all " << result.frames.size()
        << " frames";
  }
  result.detail = why.str();
  return result;
}

TrialScores scoreTrial(const TrialResult& result) {
  TrialScores s;
  const planner::Plan& plan = result.plan.report.plan;
  if (plan.chosen >= 0) s.planned_length_m = plan.candidates[static_cast<std::size_t>(plan.chosen)].length_m;
  s.trajectory_length_m = result.plan.trajectory.length_m;
  for (std::size_t i = 1; i < result.flight.log.size(); ++i) {
    s.path_length_m += (result.flight.log[i].state.p_WB - result.flight.log[i - 1].state.p_WB).norm();
  }

  std::vector<vo::PosePair> pairs;
  double distance = 0.0;
  for (std::size_t i = 0; i < result.frames.size(); ++i) {
    const TrialFrame& f = result.frames[i];
    if (i > 0) distance += (f.X_WC_true.translation() - result.frames[i - 1].X_WC_true.translation()).norm();
    switch (f.vo.status) {
      case vo::TrackingStatus::kOk:
        ++s.vo_ok;
        break;
      case vo::TrackingStatus::kWeak:
        ++s.vo_weak;
        break;
      case vo::TrackingStatus::kLost:
        ++s.vo_lost;
        break;
    }
    if (!f.tracked()) continue;
    pairs.push_back(vo::PosePair{f.vo.t_s, f.vo.X_WC, f.X_WC_true});
    s.error_distance_m.push_back(distance);
    s.distance_tracked_m = distance;
  }
  s.vo_frames = static_cast<int>(result.frames.size());
  if (!pairs.empty()) {
    const vo::AteResult anchored = vo::absoluteTrajectoryError(pairs, false);
    s.ate_anchored_rmse_m = anchored.rmse_m;
    s.ate_max_m = anchored.max_m;
    s.ate_rmse_m = vo::absoluteTrajectoryError(pairs, true).rmse_m;
    const Eigen::Isometry3d T = pairs.front().X_WC_gt * pairs.front().X_WC_est.inverse();
    for (const vo::PosePair& p : pairs) {
      s.error_m.push_back(((T * p.X_WC_est).translation() - p.X_WC_gt.translation()).norm());
    }
    // The goal error needs an estimate at the end of the flight.
    if (result.frames.back().tracked() && result.status != TrialStatus::kInterrupted) {
      s.goal_error_m = vo::goalError(pairs);
    }
  }
  return s;
}

nlohmann::ordered_json trialMetricsJson(const Scenario& scenario, const TrialOptions& options,
                                        const TrialResult& result, const TrialScores& scores,
                                        const TrialTiming& timing) {
  using nlohmann::ordered_json;
  auto orNull = [](const std::optional<double>& v) { return v ? ordered_json(*v) : ordered_json(nullptr); };
  auto point = [](const Eigen::Vector3d& p) { return ordered_json::array({p.x(), p.y(), p.z()}); };
  ordered_json j;
  j["scenario"] = scenario.source.string();
  j["scene"] = scenario.scene.source.stem().string();
  j["planner"] = toString(options.planner);
  j["samples"] = options.planner == PlannerName::kRrtStar ? ordered_json(result.plan.rrt_samples) : ordered_json(nullptr);
  j["seed"] = options.seed;
  j["state_source"] = toString(scenario.trial.state_source);
  j["status"] = toString(result.status);
  j["detail"] = result.detail;
  j["path_length_m"] = scores.path_length_m;
  j["planned_length_m"] = scores.planned_length_m;
  j["trajectory_length_m"] = scores.trajectory_length_m;
  j["goal_error_m"] = orNull(scores.goal_error_m);
  j["final_distance_to_goal_m"] = result.final_distance_to_goal_m;
  j["ate_rmse_m"] = scores.ate_rmse_m;
  j["ate_anchored_rmse_m"] = scores.ate_anchored_rmse_m;
  j["ate_max_m"] = scores.ate_max_m;
  j["vo_frames"] = scores.vo_frames;
  j["vo_ok"] = scores.vo_ok;
  j["vo_weak"] = scores.vo_weak;
  j["vo_lost_frames"] = scores.vo_lost;
  j["vo_lost_at_s"] = result.vo_lost ? ordered_json(result.vo_lost->t_s) : ordered_json(nullptr);
  j["vo_lost_position"] = result.vo_lost ? point(result.vo_lost->p_WB) : ordered_json(nullptr);
  j["vo_lost_reason"] = result.vo_lost ? ordered_json(result.vo_lost->what) : ordered_json(nullptr);
  j["distance_tracked_m"] = scores.distance_tracked_m;
  j["collision"] = result.collision ? ordered_json{{"t_s", result.collision->t_s},
                                                   {"position", point(result.collision->p_WB)},
                                                   {"with", result.collision->what}}
                                    : ordered_json(nullptr);
  const planner::Plan& plan = result.plan.report.plan;
  j["plan_status"] = planner::toString(plan.status);
  j["classes"] = result.plan.report.topo.classes.size();
  j["chosen_class"] = result.plan.chosen_topology_class >= 0 ? ordered_json(result.plan.chosen_topology_class)
                                                             : ordered_json(nullptr);
  j["c_p_min"] = plan.chosen >= 0 && std::isfinite(plan.candidates[static_cast<std::size_t>(plan.chosen)].c_p_min)
                     ? ordered_json(plan.candidates[static_cast<std::size_t>(plan.chosen)].c_p_min)
                     : ordered_json(nullptr);
  j["trajectory_status"] = planner::toString(result.plan.trajectory.status);
  const TrackingSummary tracking = summarizeTracking(result.flight);
  j["tracking_rmse_m"] = tracking.position_rmse_m;
  j["vo_poses_fused"] = result.vo_fused;
  j["vo_poses_rejected"] = result.vo_rejected;
  j["camera"] = {{"width_px", scenario.camera.width_px},
                 {"height_px", scenario.camera.height_px},
                 {"rate_hz", scenario.trial.camera_rate_hz}};
  j["sim_time_s"] = result.sim_time_s;
  const double rtf = result.flight_wall_s > 0 ? result.sim_time_s / result.flight_wall_s : 0.0;
  // Wall-clock figures: DESIGN.md's names at the top level, and all of them under `timing`.
  j["plan_time_s"] = timing.plan_time_s;
  j["wall_time_s"] = timing.wall_time_s;
  j["real_time_factor"] = rtf;
  j["peak_rss_mb"] = timing.peak_rss_mb;
  j["timing"] = {{"plan_time_s", timing.plan_time_s},
                 {"trajectory_s", timing.trajectory_s},
                 {"flight_wall_s", timing.flight_wall_s},
                 {"wall_time_s", timing.wall_time_s},
                 {"real_time_factor", rtf},
                 {"peak_rss_mb", timing.peak_rss_mb}};
  return j;
}

}  // namespace tgnav::harness
