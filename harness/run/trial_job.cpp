#include "harness/run/trial_job.h"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <opencv2/core/utility.hpp>
#include <sstream>

#include "harness/base/errors.h"
#include "harness/base/process.h"
#include "harness/config/yaml_util.h"
#include "harness/io/frame_strip.h"
#include "harness/io/staged_output.h"
#include "harness/io/topdown.h"
#include "harness/io/trajectory_csv.h"
#include "harness/run/map_cache.h"
#include "harness/run/trial_metrics.h"
#include "harness/sim/mujoco_sim.h"
#include "harness/sim/vehicle_model.h"
#include "vo/tum.h"

namespace tgnav::harness {

namespace {

namespace fs = std::filesystem;

void checkJob(const TrialJob& job) {
  if (job.samples != 0 && job.planner != planner::PlannerKind::kRrtStar) {
    throw InputError("--samples: only the rrtstar planner takes a sample budget");
  }
  if (job.samples < 0) throw InputError("--samples: " + std::to_string(job.samples) + " must be >= 1");
  if (job.frames < 0 || job.frames > 64) {
    throw InputError("--frames: " + std::to_string(job.frames) + " must be between 0 and 64");
  }
  if (job.threads < 0) throw InputError("--threads: " + std::to_string(job.threads) + " must be >= 1");
  if (!job.trajectory.empty() && !job.path.empty()) {
    throw InputError("--trajectory and --path: give one of them (or neither, to plan)");
  }
  const std::string given = !job.trajectory.empty() ? "--trajectory" : !job.path.empty() ? "--path" : "";
  if (!given.empty() && (job.samples != 0 || job.homology_class || job.external)) {
    throw InputError(given + ": flies what it is given; " +
                     (job.samples != 0     ? "--samples"
                      : job.homology_class ? "--class"
                                           : "--planner external") +
                     " is for a planner");
  }
  if (job.external && (job.samples != 0 || job.homology_class)) {
    throw InputError(std::string(job.samples != 0 ? "--samples" : "--class") + ": not for an external planner");
  }
  if (!job.external && (!job.external_command.empty() || !job.external_name.empty() || !job.external_dir.empty())) {
    throw InputError("--planner-command, --planner-name and --planner-dir are for --planner external");
  }
}

// The command line's external planner over the scenario's (TrialJob::external_command, ...).
void applyExternal(const TrialJob& job, Scenario* scenario) {
  ExternalPlannerConfig& ext = scenario->planner.external;
  if (!job.external_command.empty()) {
    ext.command = job.external_command;
    const fs::path dir = fs::absolute(job.external_dir.empty() ? fs::current_path() : job.external_dir);
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) {
      throw InputError("--planner-dir: '" + job.external_dir.string() + "': folder " + dir.string() + " not found");
    }
    ext.dir = dir.lexically_normal().string();
  } else if (!job.external_dir.empty()) {
    throw InputError("--planner-dir: goes with --planner-command");
  }
  if (!job.external_name.empty()) {
    if (!isExternalPlannerName(job.external_name)) {
      throw InputError("--planner-name: '" + job.external_name +
                       "': 1-40 letters, digits, '_' or '-', and not proposed, agnostic, rrtstar, trajectory or path");
    }
    ext.name = job.external_name;
  }
  if (!ext.configured()) {
    throw InputError("--planner external: " + job.scenario.string() +
                     " sets no planner.external.command; give --planner-command \"...\" or set it");
  }
}

// --out must be new or empty unless --force.
void checkOutput(const fs::path& requested, bool force) {
  fs::path out = fs::absolute(requested).lexically_normal();
  if (!out.has_filename()) out = out.parent_path();
  std::error_code ec;
  if (!fs::exists(out, ec)) return;
  if (!fs::is_directory(out, ec)) throw InputError("--out: " + requested.string() + " exists and is not a directory");
  if (!fs::is_empty(out, ec) && !force) {
    const bool complete = fs::exists(out / "metrics.json", ec);
    throw InputError("--out: " + requested.string() + " already holds " +
                     (complete ? "the results of a trial" : "files") + "; use --force to replace them");
  }
}

// Caps the threads the trial uses (a sweep runs one trial per core): the planner's, OpenCV's and
// llvmpipe's rasteriser threads (unless LP_NUM_THREADS is set), and one thread renders and
// tracks in turn. The results do not depend on it.
void limitThreads(int threads, Scenario* scenario) {
  scenario->planner.perception.threads = threads;
  if (threads == 1) scenario->trial.pipeline = false;
  cv::setNumThreads(threads);
  setenv("LP_NUM_THREADS", std::to_string(threads).c_str(), /*overwrite=*/0);
}

std::string voCsv(const TrialResult& r) {
  std::ostringstream out;
  out.precision(6);
  out << std::fixed;
  out << "t,status,features,with_depth,matches,inliers,keyframe,x_true,y_true,z_true,x_est,y_est,z_est,"
      << kPredictionColumns << ",ba_correction_m,ba_correction_rad,ba_outliers,keyframe_rule,reason\n";
  for (const TrialFrame& f : r.frames) {
    const Eigen::Vector3d p = f.X_WC_true.translation();
    const Eigen::Vector3d e = f.vo.X_WC.translation();
    out << f.vo.t_s << ',' << vo::toString(f.vo.status) << ',' << f.vo.features << ',' << f.vo.with_depth << ','
        << f.vo.matches << ',' << f.vo.inliers << ',' << (f.vo.keyframe ? 1 : 0) << ',' << p.x() << ',' << p.y() << ','
        << p.z() << ',';
    if (f.tracked()) {
      out << e.x() << ',' << e.y() << ',' << e.z();
    } else {
      out << ",,";
    }
    out << ',';
    writePredictionColumns(out, f.predicted);
    out << ',';
    if (std::isfinite(f.vo.ba_correction_m)) {  // keyframes that bundle adjustment refined
      out << f.vo.ba_correction_m << ',' << f.vo.ba_correction_rad << ',' << f.vo.ba_outliers;
    } else {
      out << ",,";
    }
    std::string reason = f.vo.reason;
    for (char& c : reason) c = (c == ',' || c == '\n') ? ';' : c;
    out << ',' << f.vo.keyframe_rule << ',' << reason << '\n';
  }
  return out.str();
}

// The route fields every plan.json of a given or external route has: the smoothed trajectory's
// report (when a path was smoothed) and the setpoints flown.
void addRouteFields(const TrialResult& r, bool smoothed, nlohmann::ordered_json* plan) {
  if (smoothed) {
    const planner::TrajectoryReport& tr = r.plan.trajectory;
    (*plan)["trajectory"] = {{"status", planner::toString(tr.status)},
                             {"reason", tr.reason},
                             {"duration_s", tr.duration_s},
                             {"length_m", tr.length_m},
                             {"min_clearance_m", tr.min_clearance_m}};
  }
  if (r.setpoints) {
    (*plan)["setpoints"] = r.setpoints->setpoints().size();
    (*plan)["duration_s"] = r.setpoints->endTime() - r.setpoints->startTime();
  }
}

// plan.json of a trial flown on an external planner's route: what it was asked, what it said and
// how long the protocol took besides the planner's own time.
nlohmann::ordered_json externalPlanJson(const Scenario& scenario, const TrialOptions& options, const TrialResult& r) {
  using nlohmann::ordered_json;
  const ExternalPlannerConfig& cfg = scenario.planner.external;
  ordered_json plan;
  plan["planner"] = cfg.name;
  plan["seed"] = options.seed;
  plan["scenario"] = scenario.source.string();
  plan["scene"] = scenario.scene.source.string();
  ordered_json ext;
  ext["command"] = cfg.command;
  ext["dir"] = cfg.dir;
  ext["timeout_s"] = cfg.timeout_s;
  if (r.external) {
    const ExternalPlan& e = *r.external;
    ext["status"] = e.ok ? "ok" : "failed";
    ext["detail"] = e.detail;
    ext["reason"] = e.reason;
    ext["ended"] = e.ended;
    ext["homology_class"] = e.homology_class ? ordered_json(*e.homology_class) : ordered_json(nullptr);
    ext["prepare_s"] = e.prepare_s;
    ext["start_s"] = e.start_s;
    ext["call_s"] = e.call_s;
    ext["planner_s"] = e.planner_s ? ordered_json(*e.planner_s) : ordered_json(nullptr);
    ext["stop_s"] = e.stop_s;
    ext["check_s"] = e.check_s;
    ext["total_s"] = e.total_s();
    ext["overhead_s"] = e.total_s() - e.planner_s.value_or(0.0);
    if (!e.scores.empty()) ext["scores"] = e.scores;
  }
  plan["external"] = ext;
  ordered_json classes = ordered_json::array();
  for (const planner::HomologyClass& c : r.plan.plan.topo.classes) classes.push_back({{"length_m", c.length_m}});
  plan["classes"] = classes;
  ordered_json path = ordered_json::array();
  for (const planner::Pose4& p : r.plan.plan.path) path.push_back({p.p_WB.x(), p.p_WB.y(), p.p_WB.z(), p.yaw_rad});
  plan["path"] = path;
  addRouteFields(r, !r.plan.plan.path.empty(), &plan);
  return plan;
}

// online.json: every plan of an online trial, for the figures (harness/run/online_planning.h).
nlohmann::ordered_json onlinePlansJson(const OnlineResult& online) {
  nlohmann::ordered_json plans = nlohmann::ordered_json::array();
  for (const OnlinePlan& p : online.plans) {
    nlohmann::ordered_json j;
    j["t_s"] = p.t_s;
    j["effective_s"] = p.effective_s;
    j["trigger"] = p.trigger;
    j["ok"] = p.ok;
    j["adopted"] = p.adopted;
    j["views_renewed"] = p.views_renewed;
    j["kept_class"] = p.kept_class;
    j["class_in_force"] = p.class_in_force;
    j["in_force_blind_m"] = p.in_force_blind_m;
    j["in_force_length_m"] = p.in_force_length_m;
    j["detail"] = p.detail;
    j["start"] = {p.start.p_WB.x(), p.start.p_WB.y(), p.start.p_WB.z(), p.start.yaw_rad};
    j["start_shift_m"] = p.start_shift_m;
    j["chosen_class"] = p.chosen_class;
    j["chosen_blind_m"] = p.chosen_blind_m;
    j["route_blind_m"] = p.route_blind_m;
    j["chosen_length_m"] = p.chosen_length_m;
    j["route_length_m"] = p.route_length_m;
    j["look_seen"] = p.look_seen;
    j["look_way"] = p.look_way;
    j["look_goal"] = p.look_goal;
    j["look_advance"] = p.look_advance;
    j["look_probe"] = p.look_probe;
    j["look_fallback"] = p.look_fallback;
    j["look_lowered"] = p.look_lowered;
    j["look_stall"] = p.look_stall;
    j["look_near"] = p.look_near;
    j["look_floor"] = p.look_floor;
    j["look_whole_fov"] = p.look_whole_fov;
    j["look_class"] = p.look_class;
    j["look_pose"] = p.look_pose;
    nlohmann::ordered_json watched = nlohmann::ordered_json::array();
    for (const Eigen::Vector2d& c : p.look_watched) watched.push_back({c.x(), c.y()});
    j["look_watched"] = watched;
    nlohmann::ordered_json look_path = nlohmann::ordered_json::array();
    for (const Eigen::Vector4d& q : p.look_path) look_path.push_back({q.x(), q.y(), q.z(), q.w()});
    j["look_path"] = look_path;  // x, y, yaw, expected detections
    j["look_cells"] = p.look_cells;
    j["landmarks"] = p.landmarks;
    j["prior_landmarks"] = p.prior_landmarks;
    j["rated_class"] = p.rated_class;
    j["flown_min_p"] = p.flown_min_p;
    j["flown_min_at_s"] = p.flown_min_at_s;
    j["flown_min_yaw_rad"] = p.flown_min_yaw_rad;
    j["flown_min_detections"] = p.flown_min_detections;
    j["own_min_p"] = p.own_min_p;
    nlohmann::ordered_json path = nlohmann::ordered_json::array();
    for (std::size_t i = 0; i < p.path.size(); ++i) {
      path.push_back({p.path[i].x(), p.path[i].y(), p.path[i].z(), p.path_unknown[i] ? 1 : 0});
    }
    j["path"] = path;  // x, y, z, unknown when planned (0/1)
    plans.push_back(j);
  }
  nlohmann::ordered_json guards = nlohmann::ordered_json::array();
  for (const GuardEvent& g : online.guards) {
    guards.push_back({{"t_s", g.t_s},
                      {"p", {g.wedge.apex.x(), g.wedge.apex.y(), g.wedge.apex.z()}},
                      {"yaw_rad", g.yaw_rad},
                      {"good_yaw_rad", g.good_yaw_rad},
                      {"inliers", g.inliers},
                      {"turning", g.turning},
                      {"planned_rad", g.planned_rad},
                      {"predicted", g.predicted()},
                      {"predicted_detections", g.predicted_detections},
                      {"wedge_from_rad", g.wedge.from_rad},
                      {"wedge_width_rad", g.wedge.width_rad},
                      {"wedge_range_m", g.wedge.range_m}});
  }
  return {{"plans", plans}, {"guards", guards}};
}

void writeData(const fs::path& d, const Scenario& scenario, const TrialOptions& options, const TrialResult& r) {
  if (options.given()) {
    const char* kind = options.givenKind();
    writeFileAtomic(d / "config.yaml", std::string("# tgnav trial --") + kind + " " + options.given_file + " --seed " +
                                           std::to_string(options.seed) + "\n" + resolvedScenarioYaml(scenario));
    nlohmann::ordered_json plan;
    plan["planner"] = kind;
    plan["given_file"] = options.given_file;
    plan["seed"] = options.seed;
    plan["scenario"] = scenario.source.string();
    plan["scene"] = scenario.scene.source.string();
    if (options.given_path) plan["waypoints"] = options.given_path->size();
    addRouteFields(r, options.given_path.has_value(), &plan);
    writeFileAtomic(d / "plan.json", plan.dump(2) + "\n");
  } else if (options.external) {
    const ExternalPlannerConfig& ext = scenario.planner.external;
    writeFileAtomic(d / "config.yaml", "# tgnav trial --planner external (" + ext.name + ": " + ext.command +
                                           ") --seed " + std::to_string(options.seed) + "\n" +
                                           resolvedScenarioYaml(scenario));
    writeFileAtomic(d / "plan.json", externalPlanJson(scenario, options, r).dump(2) + "\n");
    // Online, the session's (it was asked at every plan); else the single ask's.
    const std::optional<std::string>& online_tail = r.online ? r.online->planner_stderr : std::nullopt;
    writeFileAtomic(d / "planner_stderr.txt", online_tail  ? *online_tail
                                              : r.external ? r.external->stderr_tail
                                                           : std::string());
  } else {
    writeFileAtomic(d / "config.yaml", runConfigYaml("trial", scenario, r.plan));
    writeFileAtomic(d / "plan.json", planJson(scenario, r.plan).dump(2) + "\n");
  }
  if (r.setpoints) writeFileAtomic(d / "trajectory.csv", trajectoryCsv(*r.setpoints));
  writeFileAtomic(d / "gt.tum", vo::toTum(cameraPoses(r.flight, r.X_BC)));
  std::vector<vo::StampedPose> est;
  for (const TrialFrame& f : r.frames) {
    if (f.tracked()) est.push_back(vo::StampedPose{f.vo.t_s, f.vo.X_WC});
  }
  writeFileAtomic(d / "est.tum", vo::toTum(est));
  writeFileAtomic(d / "vo.csv", voCsv(r));
  if (!r.strip.empty()) writeImageAtomic(d / "frames.png", drawFrameStrip(r.strip, r.strip_captions));
  if (r.online) writeFileAtomic(d / "online.json", onlinePlansJson(*r.online).dump(1) + "\n");
}

std::string summaryLine(const Scenario& scenario, const TrialOptions& options, const TrialResult& r,
                        const TrialScores& scores, const TrialTiming& timing, const fs::path& out) {
  std::ostringstream line;
  line.precision(3);
  line << "tgnav trial: " << scenario.scene.source.stem().string() << ' '
       << (options.given() ? std::string(options.givenKind()) + " " + options.given_file
                           : plannerLabel(scenario, options))
       << " seed " << options.seed << ": " << toString(r.status) << " (" << r.detail << ")";
  if (r.status != TrialStatus::kPlanFailed) {
    line << "; flown " << scores.path_length_m << " m, goal error "
         << (scores.goal_error_m ? std::to_string(*scores.goal_error_m).substr(0, 5) + " m" : std::string("n/a"))
         << ", ATE " << scores.ate_rmse_m << " m over " << scores.vo_frames << " frames, plan " << timing.plan_time_s
         << " s, real-time factor " << (r.flight_wall_s > 0 ? r.sim_time_s / r.flight_wall_s : 0.0);
    if (r.online) line << ", online: " << r.online->plans.size() << " plans";
  }
  line << " -> " << out.string() << "/";
  return line.str();
}

}  // namespace

void checkRobotRadiusBoundsVehicle(const Scenario& scenario) {
  const VehicleModel vehicle = loadVehicleModel(scenario.scene.mjcf, scenario.vehicle);
  const double reach = vehicleReach(vehicle.model.get(), vehicle.ids);
  const double radius = scenario.planner.perception.robot_radius_m;
  if (radius >= reach) return;
  std::ostringstream msg;
  msg << scenario.source.string() << ": planner.robot_radius_m = " << radius
      << " is less than the reach of the vehicle " << vehicle.vehicle.source.string() << " ("
      << std::round(reach * 1000.0) / 1000.0 << " m from its body origin); set it to at least "
      << std::ceil(reach * 100.0) / 100.0;
  throw InputError(msg.str());
}

TrialJobResult runTrialJob(const TrialJob& job, const ProgressFn& progress, const std::atomic<bool>* interrupt) {
  const auto wall0 = std::chrono::steady_clock::now();
  checkJob(job);
  const YamlDoc overrides = YamlDoc::fromOverrides(job.set);
  Scenario scenario = loadScenario(job.scenario, &overrides);
  if (job.seed) scenario.seed = *job.seed;
  if (job.threads > 0) limitThreads(job.threads, &scenario);
  TrialOptions options;
  options.planner = job.planner;
  options.rrt_samples = job.samples;
  options.seed = scenario.seed;
  options.strip_frames = job.frames;
  if (!job.trajectory.empty()) {
    options.given_trajectory = readTrajectoryCsv(job.trajectory);
    options.given_file = job.trajectory.string();
  } else if (!job.path.empty()) {
    options.given_path = readPathCsv(job.path);
    options.given_file = job.path.string();
  }
  options.external = job.external;
  if (job.external) applyExternal(job, &scenario);
  if (job.homology_class) {
    applyOracleClass(*job.homology_class, job.planner, &scenario);
    options.oracle_option = "--class";
  }
  checkRobotRadiusBoundsVehicle(scenario);
  checkOutput(job.out, job.force);
  StagedDir staged(job.out);
  const planner::FeatureMap map =
      scenario.trial.online.needsSurvey() || !job.map.empty()
          ? loadSceneFeatureMap(scenario.scene, job.map, job.map_cache, "tgnav trial", &options.map_dir)
          : planner::FeatureMap(MapBuildConfig{}.resolution_m);

  if (job.trial_starting) job.trial_starting();
  const TrialResult r = runTrial(scenario, map, options, progress, interrupt);
  if (job.trial_ended) job.trial_ended();
  const TrialScores scores = scoreTrial(r);
  TrialTiming timing;
  timing.plan_time_s = r.plan.plan_time_s();
  timing.trajectory_s = r.plan.trajectory_s;
  timing.flight_wall_s = r.flight_wall_s;
  timing.peak_rss_mb = peakRssMb();
  timing.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();

  const fs::path& d = staged.staging();
  writeData(d, scenario, options, r);
  // Online: the map the flight built (planned on in the estimated frame).
  const planner::FeatureMap& drawn = r.online && r.online->final_map ? *r.online->final_map : map;
  writeMapLayer(d, sceneMapLayer(scenario.scene, drawn, scenario.planner.perception.slice_half_height_m));
  TrialJobResult result;
  if (r.status == TrialStatus::kInterrupted) {
    writeFileAtomic(d / "INCOMPLETE", "interrupted: " + r.detail + "; these results are partial\n");
  } else {
    // A folder with metrics.json is a finished trial (the folder appears whole when committed).
    writeFileAtomic(d / "metrics.json", trialMetricsJson(scenario, options, r, scores, timing).dump(2) + "\n");
  }
  // Partial results get their figures too; they read metrics.json where there is one.
  if (job.figures) result.figures = drawFigures("trial", d, job.figure_format);
  staged.commit(OnExisting::kReplace);
  result.out = staged.target();
  result.status = r.status;
  result.summary =
      r.status == TrialStatus::kInterrupted ? r.detail : summaryLine(scenario, options, r, scores, timing, result.out);
  return result;
}

}  // namespace tgnav::harness
