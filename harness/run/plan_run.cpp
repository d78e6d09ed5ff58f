#include "harness/run/plan_run.h"

#include <chrono>
#include <cmath>
#include <sstream>

#include "harness/base/clock.h"
#include "harness/base/errors.h"
#include "planner/perception_planner.h"
#include "planner/rrt_star.h"

namespace tgnav::harness {

namespace {

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json poseRows(const std::vector<planner::Pose4>& path) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& p : path) rows.push_back({p.p_WB.x(), p.p_WB.y(), p.p_WB.z(), p.yaw_rad});
  return rows;
}

// The chosen path as a trajectory from the scene's start pose (the vehicle may turn on the spot
// first), kept at the configured clearance and in the path's homology class.
void makeTrajectory(const Scenario& scenario, PlanRun* run) {
  const planner::Plan& plan = run->plan;
  if (plan.chosen < 0 || plan.path.empty()) {
    run->trajectory = {};
    run->trajectory.reason = "no path";
    return;
  }
  smoothPath(scenario, plan.path, &run->plan.topo.obstacle_points, run);
}

}  // namespace

void smoothPath(const Scenario& scenario, const std::vector<planner::Pose4>& path,
                const std::vector<Eigen::Vector2d>* obstacle_points, PlanRun* run) {
  const auto t0 = std::chrono::steady_clock::now();
  planner::TrajectoryRequest request;
  request.path = path;
  request.start_yaw_rad = scenario.scene.start.yaw_rad;
  request.obstacle_points = obstacle_points;
  const planner::VoxelClearance field(*run->voxels);
  run->trajectory = planner::generateTrajectory(request, field, scenario.planner.trajectory);
  run->trajectory_s = secondsSince(t0);
}

control::SetpointTrajectory setpoints(const PlanRun& run, double rate_hz) {
  if (!run.trajectory.trajectory) throw std::logic_error("setpoints: the plan has no trajectory");
  std::vector<double> t;
  std::vector<control::TrajectorySetpoint> sp;
  for (const planner::TrajectorySample& s : planner::sampleTrajectory(*run.trajectory.trajectory, rate_hz)) {
    t.push_back(s.t_s);
    control::TrajectorySetpoint x;
    x.p_WB = s.p_W;
    x.v_WB = s.v_W;
    x.a_WB = s.a_W;
    x.yaw_rad = s.yaw_rad;
    x.yaw_rate_rad_s = s.yaw_rate_rad_s;
    sp.push_back(x);
  }
  return control::SetpointTrajectory(std::move(t), std::move(sp));
}

planner::PlannerKind parsePlannerName(const std::string& text, const std::string& option) {
  planner::PlannerKind kind;
  if (!planner::parsePlannerKind(text, &kind)) {
    throw InputError(option + ": '" + text + "' is not a planner; expected proposed, agnostic or rrtstar");
  }
  return kind;
}

void applyOracleClass(int k, planner::PlannerKind planner, Scenario* scenario) {
  if (k < 0) throw InputError("--class: " + std::to_string(k) + " must be >= 0");
  if (planner == planner::PlannerKind::kRrtStar) {
    throw InputError("--class: the rrtstar planner has no homology class to fly; use proposed or agnostic");
  }
  scenario->planner.oracle_class = k;
}

ClearanceBand clearanceBand(const Scenario& scenario) {
  // Collision checks happen within the pose graph's samples around the flight height.
  const double z = scenario.scene.start.p_WB.z();
  const double reach = scenario.planner.perception.graph.sample_radius_m + scenario.planner.perception.robot_radius_m;
  return {z - reach - 0.2, z + reach + 0.2};
}

void buildPlanningVoxels(const Scenario& scenario, const planner::FeatureMap& map, PlanRun* run, bool unknown_free) {
  const auto t0 = std::chrono::steady_clock::now();
  const SceneConfig& scene = scenario.scene;
  const ClearanceBand band = clearanceBand(scenario);
  run->voxels = std::make_unique<planner::VoxelMap>(
      map, scene.bounds_min_m - Eigen::Vector3d::Constant(kPlanningBoxMargin_m),
      scene.bounds_max_m + Eigen::Vector3d::Constant(kPlanningBoxMargin_m), band.lo_m, band.hi_m, unknown_free);
  run->voxel_map_s = secondsSince(t0);
}

PlanRun solvePlan(const Scenario& scenario, const planner::FeatureMap& map, planner::PlannerKind kind,
                  std::uint64_t seed, int rrt_samples, const std::string& oracle_option, bool unknown_free) {
  PlanRun run;
  run.planner = kind;
  run.seed = seed;
  buildPlanningVoxels(scenario, map, &run, unknown_free);

  planner::RrtStarConfig rrt = scenario.planner.rrt_star;
  if (kind == planner::PlannerKind::kRrtStar) {
    if (rrt_samples > 0) rrt.samples = rrt_samples;
    run.rrt_samples = rrt.samples;
    try {
      rrt.validate();
    } catch (const std::invalid_argument& e) {
      throw InputError(std::string("--samples: ") + e.what());
    }
  }
  const int oracle = scenario.planner.oracle_class;
  if (oracle >= 0 && kind == planner::PlannerKind::kRrtStar) {
    throw InputError(oracle_option + " = " + std::to_string(oracle) +
                     ": the rrtstar planner has no homology class to fly; use proposed or agnostic");
  }
  const auto solver = planner::makePlanner(kind, *run.voxels, scenario.planner.perception, rrt);
  planner::PlanRequest request{scenario.scene.start, scenario.scene.goal, seed};
  request.homology_class = oracle;
  const auto t0 = std::chrono::steady_clock::now();
  run.plan = solver->solve(request);
  run.solve_s = secondsSince(t0);
  const auto classes = static_cast<int>(run.plan.topo.classes.size());
  if (oracle >= classes && run.plan.topo.status == planner::PlanStatus::kSolved) {
    throw InputError(oracle_option + " = " + std::to_string(oracle) +
                     ": out of range: " + scenario.scene.source.stem().string() + " has " + std::to_string(classes) +
                     " homology classes (0.." + std::to_string(classes - 1) + ")");
  }
  return run;
}

PlanRun runPlanner(const Scenario& scenario, const planner::FeatureMap& map, planner::PlannerKind kind,
                   std::uint64_t seed, int rrt_samples, const std::string& oracle_option, bool unknown_free) {
  PlanRun run = solvePlan(scenario, map, kind, seed, rrt_samples, oracle_option, unknown_free);
  makeTrajectory(scenario, &run);
  return run;
}

namespace {

// One class of plan.json: its candidate path and, for the proposed planner, how its pose graph went.
nlohmann::ordered_json classJson(const planner::CandidatePath& c, const planner::ClassDetail* detail) {
  nlohmann::ordered_json cj;
  cj["h_signature"] = c.h_signature;
  cj["feasible"] = c.feasible;
  cj["length_m"] = c.length_m;
  cj["c_p"] = number(c.c_p);
  cj["c_p_min"] = number(c.c_p_min);
  cj["blind_length_m"] = number(c.blind_length_m);
  cj["cost"] = number(c.cost);
  if (detail != nullptr) {
    cj["visibility_queries"] = detail->visibility_queries;
    cj["pose_graph"] = {{"nodes", detail->graph.nodes},
                        {"edges", detail->graph.edges},
                        {"rounds", detail->graph.between_rounds},
                        {"moves_checked", detail->graph.between_checked},
                        {"moves_blind", detail->graph.between_blind}};
  }
  cj["segments"] = nlohmann::json::array();
  for (const auto& seg : c.segments) {
    cj["segments"].push_back({{"s_begin_m", seg.s_begin_m},
                              {"s_end_m", seg.s_end_m},
                              {"covisible", seg.covisible},
                              {"c_p", number(seg.c_p)}});
  }
  cj["waypoints"] = poseRows(c.path);
  return cj;
}

}  // namespace

nlohmann::ordered_json planJson(const Scenario& scenario, const PlanRun& run) {
  const planner::Plan& plan = run.plan;
  nlohmann::ordered_json j;
  j["planner"] = toString(run.planner);
  j["status"] = planner::toString(plan.status);
  j["plan_time_s"] = run.plan_time_s();
  j["seed"] = run.seed;
  if (run.planner == planner::PlannerKind::kRrtStar) j["samples"] = run.rrt_samples;
  j["scenario"] = scenario.source.string();
  j["scene"] = scenario.scene.source.string();
  const auto& s = scenario.scene.start;
  const auto& g = scenario.scene.goal;
  j["start"] = {s.p_WB.x(), s.p_WB.y(), s.p_WB.z(), s.yaw_rad};
  j["goal"] = {g.p_WB.x(), g.p_WB.y(), g.p_WB.z(), g.yaw_rad};
  j["flight_height_m"] = run.plan.flight_height_m;
  j["c_p_threshold"] = scenario.planner.perception.selection.c_p_threshold;
  j["oracle_class"] =
      scenario.planner.oracle_class >= 0 ? nlohmann::json(scenario.planner.oracle_class) : nlohmann::json(nullptr);
  j["timing"] = {{"voxel_map_s", run.voxel_map_s}, {"solve_s", run.solve_s}, {"trajectory_s", run.trajectory_s}};
  j["topology_classes"] = run.plan.topo.classes.size();
  j["classes"] = nlohmann::json::array();
  for (std::size_t i = 0; i < plan.candidates.size(); ++i) {
    j["classes"].push_back(classJson(plan.candidates[i], i < plan.details.size() ? &plan.details[i] : nullptr));
  }
  j["chosen_class"] = plan.chosen >= 0 ? nlohmann::json(plan.chosen) : nlohmann::json(nullptr);
  j["chosen_topology_class"] =
      run.plan.chosen_class >= 0 ? nlohmann::json(run.plan.chosen_class) : nlohmann::json(nullptr);
  double length = 0.0;
  for (std::size_t i = 1; i < plan.path.size(); ++i) length += (plan.path[i].p_WB - plan.path[i - 1].p_WB).norm();
  j["path_length_m"] = length;
  j["path"] = poseRows(plan.path);
  const planner::TrajectoryReport& tr = run.trajectory;
  const planner::TrajectoryConfig& tc = scenario.planner.trajectory;
  nlohmann::ordered_json tj;
  tj["status"] = planner::toString(tr.status);
  tj["reason"] = tr.reason;
  tj["file"] = tr.trajectory ? nlohmann::json("trajectory.csv") : nlohmann::json(nullptr);
  if (tr.trajectory) {
    tj["duration_s"] = tr.duration_s;
    tj["length_m"] = tr.length_m;
    tj["min_clearance_m"] = tr.min_clearance_m;
    tj["clearance_target_m"] = tc.margin_m();
    tj["margin_met"] = tr.margin_met;
    tj["max_speed_mps"] = tr.max_speed_mps;
    tj["max_accel_mps2"] = tr.max_accel_mps2;
    tj["max_yaw_rate_rad_s"] = tr.max_yaw_rate_rad_s;
    tj["limits"] = {
        {"speed_mps", tc.max_speed_mps}, {"accel_mps2", tc.max_accel_mps2}, {"yaw_rate_rad_s", tc.max_yaw_rate_rad_s}};
    tj["same_homology"] = tr.homology_checked ? nlohmann::json(tr.same_homology) : nlohmann::json(nullptr);
    tj["iterations"] = tr.iterations;
    tj["retimes"] = tr.retimes;
    tj["time_scale"] = tr.time_scale;
    tj["sample_rate_hz"] = tc.sample_rate_hz;
  }
  j["trajectory"] = tj;
  return j;
}

std::string runConfigYaml(const std::string& command, const Scenario& scenario, const PlanRun& run) {
  std::ostringstream config;
  config << "# tgnav " << command << " --planner " << planner::toString(run.planner);
  if (run.planner == planner::PlannerKind::kRrtStar) config << " --samples " << run.rrt_samples;
  config << " --seed " << run.seed;
  if (scenario.planner.oracle_class >= 0) config << " --class " << scenario.planner.oracle_class;
  config << "\n" << resolvedScenarioYaml(scenario);
  return config.str();
}

}  // namespace tgnav::harness
