#include "harness/run/trial.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <opencv2/core/utility.hpp>
#include <set>
#include <sstream>

#include "control/state_estimator.h"
#include "harness/base/errors.h"
#include "harness/base/process.h"
#include "harness/run/online_planning.h"
#include "harness/run/trial_metrics.h"
#include "harness/run/trial_route.h"
#include "harness/run/vo_pipeline.h"
#include "harness/sim/camera.h"
#include "harness/sim/egl_context.h"
#include "harness/sim/imu_sim.h"
#include "harness/sim/mujoco_sim.h"
#include "harness/sim/scene_geometry.h"
#include "harness/sim/vehicle_model.h"
#include "vo/stage_clock.h"

namespace tgnav::harness {

std::uint64_t trialSeed(std::uint64_t seed, std::uint64_t stream) {
  // splitmix64 of the seed offset by the stream: independent, well-mixed streams.
  std::uint64_t z = seed + stream * 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

namespace {

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

// Frames kept for the strip: `count` evenly spread over the planned flight's frames.
std::set<long> stripFrames(int count, double end_s, double camera_rate_hz) {
  const auto planned_frames = static_cast<long>(std::floor(end_s * camera_rate_hz + 1e-9)) + 1;
  std::set<long> strip;
  for (int i = 0; i < count; ++i) {
    strip.insert(count == 1 ? planned_frames / 2
                            : std::lround(static_cast<double>(i) * (planned_frames - 1) / (count - 1)));
  }
  return strip;
}

// The flight of a trial with everything that runs beside the controller: the onboard camera and
// the VO pipeline, the IMU and the estimator (state source vo), contact and bounds checks, progress.
class ClosedLoop {
  using Clock = std::chrono::steady_clock;

 public:
  // `online`: the online planner that maps the keyframes and replans (none: fly `trajectory`).
  ClosedLoop(const Scenario& scenario, const TrialOptions& options, const control::SetpointTrajectory& trajectory,
             TrialResult* result, OnlinePlanning* online)
      : scenario_(scenario),
        cfg_(scenario.trial),
        trajectory_(trajectory),
        result_(result),
        vehicle_(loadVehicleModel(scenario.scene.mjcf, scenario.vehicle)),
        model_(std::move(vehicle_.model)),
        data_(makeData(model_.get())),
        view_(makeData(model_.get())),
        ids_(vehicle_.ids),
        landed_(placeOnGround(scenario.scene, model_.get(), data_.get(), ids_)),
        loop_(model_.get(), data_.get(), ids_, scenario.controller),
        steps_per_frame_(stepsPerTick(model_.get(), cfg_.camera_rate_hz, "trial.camera_rate_hz =")),
        timeline_(flightTimeline(loop_, trajectory, cfg_.flight)),
        camera_(model_.get(), gl_, scenario.camera.on(vehicle_.vehicle.camera), 0),  // noise: in the VO stage
        noise_(scenario.camera, trialSeed(options.seed, 1)),
        imu_(cfg_.imu, ids_, trialSeed(options.seed, 2)),
        estimator_(cfg_.estimator, loop_.vehicle().gravity_m_s2),
        strip_(stripFrames(options.strip_frames, timeline_.end_s, cfg_.camera_rate_hz)),
        fly_on_vo_(cfg_.state_source == StateSource::kVo),
        reinitialise_(scenario.vo.reinitialise_after_lost),
        vehicle_root_(model_->body_rootid[ids_.body]),
        online_(online) {
    if (online_ != nullptr) online_->startFlight(camera_.intrinsics(), timeline_.trajectory_start_s);
    result_->planned_flight_s = timeline_.end_s;
    result_->X_BC = cameraInBody(model_.get(), camera_.id());
    X_CB_ = result_->X_BC.inverse();
    estimator_.reset(loop_.state(), loop_.time());
  }

  TrialEvents fly(const ProgressFn& progress, const std::atomic<bool>* interrupt) {
    progress_ = progress;
    interrupt_ = interrupt;
    RgbdFrame first = render();
    odometry_ = std::make_unique<vo::RgbdOdometry>(camera_.intrinsics(), scenario_.vo, first.X_WC);
    pipeline_ = std::make_unique<VoPipeline>(*odometry_, noise_, reinitialise_, cfg_.pipeline);
    keepForMap(0, first);
    pipeline_->submit(std::move(first), strip_.count(0) > 0);
    FlightHooks hooks;
    if (online_ != nullptr) {
      hooks.trajectory = [this]() -> const control::SetpointTrajectory& { return online_->trajectory(); };
    }
    if (fly_on_vo_) hooks.control_state = [this](const FlightLoop&) { return estimator_.state(); };
    hooks.after_step = [this](const FlightLoop& l) { return afterStep(l); };
    const double process_cpu0 = vo::processCpuSeconds();
    const double renderer_cpu0 = threadsCpuSeconds("llvmpipe-");
    wall0_ = Clock::now();
    tick_mark_ = wall0_;
    cpu_mark_ = vo::threadCpuSeconds();
    ticks_.emplace_back();  // frame 0, rendered before the clock started
    ticks_.back().rendered = true;
    result_->flight = flyTrajectory(loop_, trajectory_, cfg_.flight, hooks);
    // The physics after the last tick counts with it, and so does waiting for the VO to finish.
    const Clock::time_point flown = Clock::now();
    ticks_.back().sim_busy_s += seconds(flown - tick_mark_);
    ticks_.back().sim_busy_cpu_s += vo::threadCpuSeconds() - cpu_mark_;
    std::vector<VoPipeline::Done> done = pipeline_->finish();
    const Clock::time_point end = Clock::now();
    ticks_.back().sim_wait_s += seconds(end - flown);
    result_->flight_wall_s = seconds(end - wall0_);
    result_->profile.process_cpu_s = vo::processCpuSeconds() - process_cpu0;
    const double renderer_cpu1 = threadsCpuSeconds("llvmpipe-");
    result_->profile.renderer_cpu_s =
        renderer_cpu0 >= 0.0 && renderer_cpu1 >= 0.0 ? renderer_cpu1 - renderer_cpu0 : -1.0;
    result_->sim_time_s = data_->time;
    collectFrames(std::move(done));
    fillProfile();
    result_->vo_fusion = estimator_.tally();
    if (online_ != nullptr) finishOnline();
    return events();
  }

 private:
  // Puts the vehicle on the ground at the start, facing the start yaw, and returns that pose.
  static planner::Pose4 placeOnGround(const SceneConfig& scene, const mjModel* m, mjData* d, const VehicleIds& ids) {
    planner::Pose4 landed = scene.start;
    landed.p_WB.z() = scene.bounds_min_m.z() + ids.landed_height_m;
    setVehiclePose(m, d, ids, landed);
    return landed;
  }

  // Renders the state after the step on a copy of what the scene is made of (mj_step leaves
  // bodies, geoms, cameras and lights at the state before its integration, and the physics must
  // not see them recomputed): the positions, the mocap bodies and the time, from which the
  // kinematics, the centres of mass and the cameras and lights follow. Copying the whole mjData
  // (its arena) every frame cost more than drawing at 320x240.
  RgbdFrame render() {
    const mjModel* m = model_.get();
    const mjData* d = data_.get();
    mjData* v = view_.get();
    v->time = d->time;
    mju_copy(v->qpos, d->qpos, m->nq);
    mju_copy(v->mocap_pos, d->mocap_pos, 3 * m->nmocap);
    mju_copy(v->mocap_quat, d->mocap_quat, 4 * m->nmocap);
    mj_kinematics(m, v);
    mj_comPos(m, v);
    mj_camlight(m, v);
    return camera_.renderNoiseless(v);
  }

  std::string afterStep(const FlightLoop& l) {
    const control::ImuSample sample = imu_.sample(data_.get());
    if (fly_on_vo_) estimator_.propagate(sample);
    if (std::string stop = checkContactsAndBounds(l); !stop.empty()) return stop;
    if (l.steps() % steps_per_frame_ == 0) {
      if (std::string stop = cameraTick(l); !stop.empty()) return stop;
    }
    if (interrupt_ != nullptr && interrupt_->load()) {
      interrupted_ = true;
      return "interrupted";
    }
    return std::string();
  }

  // Once the vehicle has climbed clear of the ground, any contact is a collision (before, it
  // settles and lifts off on the floor).
  std::string checkContactsAndBounds(const FlightLoop& l) {
    const mjData* d = data_.get();
    const Eigen::Vector3d p = l.state().p_WB;
    int partner = -1;
    for (int i = 0; i < d->ncon && partner < 0; ++i) {
      partner = contactPartner(model_.get(), d->contact[i], vehicle_root_);
    }
    if (p.z() > landed_.p_WB.z() + kLiftOffM) airborne_ = true;
    if (partner >= 0 && airborne_) {
      result_->collision = TrialEvent{l.time(), p, geomName(model_.get(), partner)};
      return "collision with " + result_->collision->what + " at " + formatPoint(p);
    }
    constexpr double kBoundsSlackM = 1.0;
    const SceneConfig& scene = scenario_.scene;
    if ((p.array() < scene.bounds_min_m.array() - kBoundsSlackM).any() ||
        (p.array() > scene.bounds_max_m.array() + kBoundsSlackM).any()) {
      left_bounds_ = true;
      return "left the scene at " + formatPoint(p);
    }
    return std::string();
  }

  // Renders this frame first (the state is settled), then fuses the previous frame's pose, which
  // the controller uses from now on: the VO of frame k-1 overlaps the render of k. A VO pose is
  // fused one camera period after its image; rendering stops once tracking is lost for good (the
  // frames after it are not scored).
  std::string cameraTick(const FlightLoop& l) {
    ++frame_index_;
    // Online at the true pose, the map needs every frame whatever the VO does (and when the VO
    // stage noticed its loss depends on the wall clock).
    const bool map_at_truth = online_ != nullptr && !fly_on_vo_;
    const bool stop_rendering = fly_on_vo_     ? vo_failed_known_
                                : map_at_truth ? false
                                               : (!reinitialise_ && pipeline_->failedForGood());
    TickProfile tick;
    double blocked_s = 0.0;  // waiting for the VO stage
    if (!stop_rendering) {
      RgbdFrame frame = render();
      keepForMap(frame_index_, frame);
      blocked_s += pipeline_->submit(std::move(frame), strip_.count(frame_index_) > 0);
      tick.rendered = true;
    }
    if (fly_on_vo_ && fused_up_to_ < frame_index_ - 1 && !vo_failed_known_) {
      const Clock::time_point t = Clock::now();
      fuseResult(frame_index_ - 1);
      blocked_s += seconds(Clock::now() - t);
    }
    std::string stop = online_ != nullptr ? planOnline(l) : std::string();
    if (progress_) reportProgress(l);
    const Clock::time_point now = Clock::now();
    const double cpu_now = vo::threadCpuSeconds();
    tick.sim_busy_s = seconds(now - tick_mark_) - blocked_s;
    tick.sim_wait_s = blocked_s;
    tick.sim_busy_cpu_s = cpu_now - cpu_mark_;
    tick_mark_ = now;
    cpu_mark_ = cpu_now;
    ticks_.push_back(tick);
    return stop;
  }

  // Online: a copy of every trial.map_every_frames-th frame, mapped once its pose is known.
  void keepForMap(long k, const RgbdFrame& frame) {
    if (online_ == nullptr || k % cfg_.online.map_every_frames != 0) return;
    RgbdFrame copy;
    copy.t_s = frame.t_s;
    copy.bgr = frame.bgr.clone();
    copy.depth_m = frame.depth_m.clone();
    copy.X_WC = frame.X_WC;
    map_frames_.emplace(k, std::move(copy));
  }

  // Online, at a camera tick: maps the previous frame (at the VO's pose, or the true one), then
  // replans when due. Returns why the flight stops (no route), or "".
  std::string planOnline(const FlightLoop& l) {
    const auto kept = map_frames_.find(frame_index_ - 1);
    if (kept != map_frames_.end()) {
      RgbdFrame frame = std::move(kept->second);
      map_frames_.erase(kept);
      const bool truth = cfg_.online.map_pose == MapPose::kTruth;
      const bool tracked = truth || (fused_pose_index_ == frame_index_ - 1 && fused_pose_);
      if (tracked) {
        if (!truth) frame.X_WC = *fused_pose_;
        online_->mapFrame(frame, l.time(), timeline_.trajectory_start_s);
      }
    }
    if (l.time() >= cfg_.online.max_flight_s) {
      time_limit_ = true;
      return "the flight time limit trial.max_flight_s";
    }
    std::string why = online_->replan(l.time(), timeline_.trajectory_start_s);
    if (why.empty()) return why;
    result_->no_path = TrialEvent{l.time(), l.state().p_WB, why};
    return "no path: " + why;
  }

  // The online part's metrics: the final map against the scene, the flight against the plans.
  void finishOnline() {
    std::vector<std::pair<double, Eigen::Vector3d>> flown;
    for (const FlightSample& f : result_->flight.log) {
      if (f.on_trajectory) flown.emplace_back(f.t_s, f.estimate.p_WB);
    }
    mj_forward(model_.get(), view_.get());
    result_->online = online_->finish(SceneGeometry(model_.get(), view_.get()), flown);
  }

  static double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

  void fillProfile() {
    TrialProfile& p = result_->profile;
    p.pipelined = cfg_.pipeline;
    p.queue_capacity = static_cast<int>(VoPipeline::kQueueCapacity);
    p.waits_for_pose = fly_on_vo_;
    const char* lp = std::getenv("LP_NUM_THREADS");
    p.llvmpipe_threads = lp != nullptr ? std::atoi(lp) : 0;
    p.gl_renderer = gl_.renderer();
    p.opencv_threads = cv::getNumThreads();
    p.flight_wall_s = result_->flight_wall_s;
    p.sim_time_s = result_->sim_time_s;
    p.physics_s = loop_.physicsWallSeconds();
    p.control_s = loop_.controlWallSeconds();
    p.ticks = std::move(ticks_);
  }

  void fuseResult(long k) {
    const VoPipeline::Done d = pipeline_->result(static_cast<std::size_t>(k));
    fused_up_to_ = k;
    fused_pose_index_ = k;
    fused_pose_.reset();
    if (d.vo.status == vo::TrackingStatus::kLost) {
      if (!reinitialise_) vo_failed_known_ = true;  // among the fused results: the same in both modes
      return;
    }
    estimator_.fusePose(d.vo.t_s, d.vo.X_WC * X_CB_);
    vo::FrameResult frame = d.vo;  // the map and the guard take it as the estimate did: less the jumps found
    fused_pose_ = frame.X_WC = Eigen::Translation3d(-estimator_.voOffset()) * d.vo.X_WC;
    if (online_ != nullptr) online_->trackFrame(data_->time, timeline_.trajectory_start_s, frame);
  }

  void reportProgress(const FlightLoop& l) const {
    TrialProgress pr;
    pr.sim_s = l.time();
    pr.sim_total_s = timeline_.end_s;
    const double on_traj = l.time() - timeline_.trajectory_start_s;
    const double traj_s = trajectory_.endTime() - trajectory_.startTime();
    pr.path_fraction = traj_s > 0 ? std::clamp(on_traj / traj_s, 0.0, 1.0) : 1.0;
    pr.wall_s = seconds(Clock::now() - wall0_);
    progress_(pr);
  }

  // Frames up to the first loss (all of them when the VO re-initialises).
  void collectFrames(std::vector<VoPipeline::Done> done) {
    for (std::size_t k = 0; k < done.size() && k < ticks_.size(); ++k) {
      TickProfile& tick = ticks_[k];
      tick.frame = done[k].frame_timing;
      tick.vo = done[k].vo.timing;
      tick.frame_cpu = done[k].frame_cpu;
      tick.vo_cpu = done[k].vo.cpu;
      // Sequential: the simulation thread noised and tracked the frame itself; that counts as the VO's.
      if (!cfg_.pipeline) {
        tick.sim_busy_s = std::max(0.0, tick.sim_busy_s - tick.featuresBusy() - tick.trackingBusy());
        const double vo_cpu = tick.frame_cpu.noise_s + tick.vo_cpu.total();
        tick.sim_busy_cpu_s = std::max(0.0, tick.sim_busy_cpu_s - vo_cpu);
      }
    }
    for (VoPipeline::Done& d : done) {
      const bool lost = d.vo.status == vo::TrackingStatus::kLost;
      if (!d.image.empty()) {
        result_->strip_captions.push_back(frameCaption(d.vo));
        result_->strip.push_back(d.image);
      }
      result_->frames.push_back(TrialFrame{d.vo, d.X_WC_true, FramePrediction{}});
      if (lost && !result_->vo_lost) {
        result_->vo_lost = TrialEvent{d.vo.t_s, positionAt(result_->flight, d.vo.t_s), d.vo.reason};
      }
      if (lost && !reinitialise_) break;
    }
  }

  TrialEvents events() {
    const Eigen::Vector3d final_p = result_->flight.log.empty() ? Eigen::Vector3d::Zero() : loop_.state().p_WB;
    result_->final_distance_to_goal_m = (final_p - scenario_.scene.goal.p_WB).norm();
    TrialEvents e;
    e.interrupted = interrupted_;
    e.collision = result_->collision;
    e.flight_completed = result_->flight.status == FlightStatus::kCompleted;
    e.flight_reason = result_->flight.reason;
    e.left_bounds = left_bounds_;
    e.vo_lost = result_->vo_lost;
    e.no_path = result_->no_path;
    // An online flight stopped for want of a route ended as planned, without one.
    // ... and so did one stopped at its time limit (a timeout unless it is at the goal).
    if (result_->no_path || time_limit_) e.flight_completed = true;
    e.final_distance_to_goal_m = result_->final_distance_to_goal_m;
    e.goal_radius_m = cfg_.goal_radius_m;
    e.sim_time_s = result_->sim_time_s;
    e.planned_end_s = timeline_.end_s;
    e.frames = static_cast<int>(result_->frames.size());
    return e;
  }

  const Scenario& scenario_;
  const TrialConfig& cfg_;
  const control::SetpointTrajectory& trajectory_;
  TrialResult* result_;
  VehicleModel vehicle_;  // its model moves to model_
  ModelPtr model_;
  DataPtr data_;
  DataPtr view_;  // what the camera renders (render())
  VehicleIds ids_;
  planner::Pose4 landed_;
  FlightLoop loop_;
  int steps_per_frame_;
  FlightTimeline timeline_;
  EglContext gl_;
  Camera camera_;
  CameraNoise noise_;
  SimulatedImu imu_;
  control::StateEstimator estimator_;
  std::set<long> strip_;
  bool fly_on_vo_;
  bool reinitialise_;
  int vehicle_root_;
  Eigen::Isometry3d X_CB_ = Eigen::Isometry3d::Identity();
  std::unique_ptr<vo::RgbdOdometry> odometry_;
  std::unique_ptr<VoPipeline> pipeline_;
  ProgressFn progress_;
  const std::atomic<bool>* interrupt_ = nullptr;
  Clock::time_point wall0_;
  Clock::time_point tick_mark_;  // end of the last camera tick
  double cpu_mark_ = 0.0;        // ... and the simulation thread's CPU seconds then
  std::vector<TickProfile> ticks_;
  long frame_index_ = 0;
  long fused_up_to_ = -1;
  bool vo_failed_known_ = false;
  bool airborne_ = false;
  bool interrupted_ = false;
  bool left_bounds_ = false;
  OnlinePlanning* online_ = nullptr;
  bool time_limit_ = false;               // online: stopped at trial.max_flight_s
  std::map<long, RgbdFrame> map_frames_;  // online: frames waiting for their pose
  long fused_pose_index_ = -1;            // the last VO result fused, and its pose when tracked
  std::optional<Eigen::Isometry3d> fused_pose_;
};

}  // namespace

std::string plannerLabel(const Scenario& scenario, const TrialOptions& options) {
  if (options.given()) return options.givenKind();
  if (options.external) return scenario.planner.external.name;
  return planner::toString(options.planner);
}

TrialResult runTrial(const Scenario& scenario, const planner::FeatureMap& map, const TrialOptions& options,
                     const ProgressFn& progress, const std::atomic<bool>* interrupt) {
  TrialResult result;
  std::unique_ptr<OnlinePlanning> online;
  if (scenario.trial.online.online()) {
    if (options.given()) throw InputError("trial.mode = online: plans again on the map it builds, not a given route");
    online = std::make_unique<OnlinePlanning>(scenario, map, options.planner, options.seed, options.rrt_samples,
                                              options.external);
    result.setpoints = online->firstPlan(&result.plan);
  } else if (!makeRoute(scenario, map, options, interrupt, &result)) {
    return result;
  }
  if (interrupt != nullptr && interrupt->load()) {
    result.status = TrialStatus::kInterrupted;
    result.detail = "interrupted after planning";
    return result;
  }
  ClosedLoop closed_loop(scenario, options, *result.setpoints, &result, online.get());
  TrialEvents events = closed_loop.fly(progress, interrupt);
  if (online) result.setpoints = online->trajectory();  // what was flown in the end: every plan spliced
  events.goal_error_m = trackedGoalError(result.frames);
  events.path_length_m = flownLength(result.flight);
  events.max_drift_ratio = scenario.trial.max_drift_ratio;
  const TrialVerdict verdict = decideStatus(events);
  result.status = verdict.status;
  result.detail = verdict.detail;
  if (online && !online->plannerFailure().empty() && result.status == TrialStatus::kNoPath) {
    result.status = TrialStatus::kPlanFailed;  // the external planner failed, not the map
    result.detail = online->plannerFailure();
  }
  const planner::PerceptionPlannerConfig& model = scenario.planner.perception;
  // Online: the frames are predicted, and the map drawn, from the map the flight built.
  if (result.online && result.online->final_map) buildPlanningVoxels(scenario, *result.online->final_map, &result.plan);
  for (TrialFrame& f : result.frames) {
    f.predicted = predictFrame(*result.plan.voxels, f.X_WC_true, model.visibility, model.information);
  }
  return result;
}

}  // namespace tgnav::harness
