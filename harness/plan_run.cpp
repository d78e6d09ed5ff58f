#include "harness/plan_run.h"

#include <chrono>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "harness/errors.h"
#include "harness/topdown.h"
#include "planner/rrt_star.h"

namespace tgnav::harness {

namespace {

constexpr double kBoxMargin_m = 0.5;

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json poseRows(const std::vector<planner::Pose4>& path) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& p : path) rows.push_back({p.p_WB.x(), p.p_WB.y(), p.p_WB.z(), p.yaw_rad});
  return rows;
}

// The topological class with this H-signature (winding angles around the same obstacles).
int classOf(const planner::TopoPlan& plan, const std::vector<double>& h_signature) {
  for (std::size_t i = 0; i < plan.classes.size(); ++i) {
    if (planner::TopologicalPlanner::sameClass(h_signature, plan.classes[i].h_signature)) return static_cast<int>(i);
  }
  return -1;
}

// The chosen path as a trajectory from the scene's start pose (the vehicle may turn on the spot
// first), kept at the configured clearance and in the path's homology class.
void makeTrajectory(const Scenario& scenario, PlanRun* run) {
  const planner::Plan& plan = run->report.plan;
  if (plan.chosen < 0 || plan.path.empty()) {
    run->trajectory = {};
    run->trajectory.reason = "no path";
    return;
  }
  const auto t0 = std::chrono::steady_clock::now();
  planner::TrajectoryRequest request;
  request.path = plan.path;
  request.start_yaw_rad = scenario.scene.start.yaw_rad;
  request.obstacle_points = &run->report.topo.obstacle_points;
  const planner::VoxelClearance field(*run->voxels);
  run->trajectory = planner::generateTrajectory(request, field, scenario.planner.trajectory);
  run->trajectory_s = since(t0);
}

}  // namespace

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

PlannerName parsePlannerName(const std::string& text, const std::string& option) {
  if (text == "proposed") return PlannerName::kProposed;
  if (text == "agnostic") return PlannerName::kAgnostic;
  if (text == "rrtstar") return PlannerName::kRrtStar;
  throw InputError(option + ": '" + text + "' is not a planner; expected proposed, agnostic or rrtstar");
}

const char* toString(PlannerName name) {
  switch (name) {
    case PlannerName::kProposed:
      return "proposed";
    case PlannerName::kAgnostic:
      return "agnostic";
    case PlannerName::kRrtStar:
      return "rrtstar";
  }
  return "?";
}

PlanRun runPlanner(const Scenario& scenario, const planner::FeatureMap& map, PlannerName name, std::uint64_t seed,
                   int rrt_samples) {
  PlanRun run;
  run.planner = name;
  run.seed = seed;
  const SceneConfig& scene = scenario.scene;
  auto t0 = std::chrono::steady_clock::now();
  // Collision checks happen within the pose graph's samples around the flight height.
  const double z = scene.start.p_WB.z();
  const double reach = scenario.planner.perception.graph.sample_radius_m + scenario.planner.perception.robot_radius_m;
  run.voxels = std::make_unique<planner::VoxelMap>(map, scene.bounds_min_m - Eigen::Vector3d::Constant(kBoxMargin_m),
                                                   scene.bounds_max_m + Eigen::Vector3d::Constant(kBoxMargin_m),
                                                   z - reach - 0.2, z + reach + 0.2);
  run.voxel_map_s = since(t0);

  const planner::PerceptionPlanner perception(*run.voxels, scenario.planner.perception);
  t0 = std::chrono::steady_clock::now();
  if (name == PlannerName::kRrtStar) {
    planner::RrtStarConfig config = scenario.planner.rrt_star;
    if (rrt_samples > 0) config.samples = rrt_samples;
    run.rrt_samples = config.samples;
    try {
      config.validate();
    } catch (const std::invalid_argument& e) {
      throw InputError(std::string("--samples: ") + e.what());
    }
    const planner::PerceptionRrtStar rrt(*run.voxels, config);
    run.report.plan = rrt.solve(scene.start, scene.goal, seed);
    run.solve_s = since(t0);
    // The topological classes only to say which class RRT* ended up in (not timed).
    const double band = scenario.planner.perception.slice_half_height_m;
    planner::TopoPlannerConfig topo_config = scenario.planner.perception.topo;
    topo_config.robot_radius_m = scenario.planner.perception.robot_radius_m;
    const planner::TopologicalPlanner topo(run.voxels->slice(z - band, z + band), topo_config);
    run.report.topo = topo.solve(scene.start.p_WB.head<2>(), scene.goal.p_WB.head<2>());
    run.report.flight_height_m = z;
    if (run.report.plan.chosen >= 0) {
      for (auto& c : run.report.plan.candidates) {
        std::vector<Eigen::Vector2d> xy;
        for (const auto& p : c.path) xy.push_back(p.p_WB.head<2>());
        c.h_signature = topo.hSignature(xy);
      }
      run.chosen_topology_class = classOf(
          run.report.topo, run.report.plan.candidates[static_cast<std::size_t>(run.report.plan.chosen)].h_signature);
    }
    makeTrajectory(scenario, &run);
    return run;
  }
  run.report = perception.solve(
      scene.start, scene.goal,
      name == PlannerName::kProposed ? planner::PlannerKind::kProposed : planner::PlannerKind::kAgnostic, seed);
  run.solve_s = since(t0);
  run.chosen_topology_class = run.report.plan.chosen;
  makeTrajectory(scenario, &run);
  return run;
}

nlohmann::ordered_json planJson(const Scenario& scenario, const PlanRun& run) {
  const planner::Plan& plan = run.report.plan;
  nlohmann::ordered_json j;
  j["planner"] = toString(run.planner);
  j["status"] = planner::toString(plan.status);
  j["plan_time_s"] = run.plan_time_s();
  j["seed"] = run.seed;
  if (run.planner == PlannerName::kRrtStar) j["samples"] = run.rrt_samples;
  j["scenario"] = scenario.source.string();
  j["scene"] = scenario.scene.source.string();
  const auto& s = scenario.scene.start;
  const auto& g = scenario.scene.goal;
  j["start"] = {s.p_WB.x(), s.p_WB.y(), s.p_WB.z(), s.yaw_rad};
  j["goal"] = {g.p_WB.x(), g.p_WB.y(), g.p_WB.z(), g.yaw_rad};
  j["flight_height_m"] = run.report.flight_height_m;
  j["timing"] = {{"voxel_map_s", run.voxel_map_s}, {"solve_s", run.solve_s}, {"trajectory_s", run.trajectory_s}};
  j["topology_classes"] = run.report.topo.classes.size();
  j["classes"] = nlohmann::json::array();
  for (std::size_t i = 0; i < plan.candidates.size(); ++i) {
    const planner::CandidatePath& c = plan.candidates[i];
    nlohmann::ordered_json cj;
    cj["h_signature"] = c.h_signature;
    cj["feasible"] = c.feasible;
    cj["length_m"] = c.length_m;
    cj["c_p"] = number(c.c_p);
    cj["c_p_min"] = number(c.c_p_min);
    cj["cost"] = number(c.cost);
    if (i < run.report.details.size()) cj["visibility_queries"] = run.report.details[i].visibility_queries;
    cj["segments"] = nlohmann::json::array();
    for (const auto& seg : c.segments) {
      cj["segments"].push_back({{"s_begin_m", seg.s_begin_m},
                                {"s_end_m", seg.s_end_m},
                                {"covisible", seg.covisible},
                                {"c_p", number(seg.c_p)}});
    }
    cj["waypoints"] = poseRows(c.path);
    j["classes"].push_back(cj);
  }
  j["chosen_class"] = plan.chosen >= 0 ? nlohmann::json(plan.chosen) : nlohmann::json(nullptr);
  j["chosen_topology_class"] =
      run.chosen_topology_class >= 0 ? nlohmann::json(run.chosen_topology_class) : nlohmann::json(nullptr);
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

cv::Mat drawPlanImage(const Scenario& scenario, const planner::FeatureMap& map, const PlanRun& run) {
  const SceneConfig& scene = scenario.scene;
  Topdown top(scene, (scene.bounds_max_m.x() - scene.bounds_min_m.x()) / 800.0);
  top.drawMap(map, scenario.planner.perception.slice_half_height_m);
  cv::Mat img = top.image().clone();
  const planner::Plan& plan = run.report.plan;
  const double thr = scenario.planner.perception.selection.c_p_threshold;
  auto polyline = [&](const std::vector<planner::Pose4>& path, const cv::Scalar& colour, int width) {
    for (std::size_t i = 1; i < path.size(); ++i) {
      cv::line(img, top.toPixel(path[i - 1].p_WB.head<2>()), top.toPixel(path[i].p_WB.head<2>()), colour, width,
               cv::LINE_AA);
    }
  };
  // Perception quality of a class: red (weakest segment far below c_p,thr) to green (far above).
  for (std::size_t i = 0; i < plan.candidates.size(); ++i) {
    if (static_cast<int>(i) == plan.chosen) continue;
    const planner::CandidatePath& c = plan.candidates[i];
    cv::Scalar colour(150, 150, 150);
    if (std::isfinite(c.c_p_min)) {
      const double q = 1.0 / (1.0 + std::exp(-(c.c_p_min - thr) / 4.0));
      colour = cv::Scalar(40, 200 * q, 220 * (1.0 - q));
    }
    polyline(c.path, colour, 2);
  }
  // The topological classes (thin) for the baselines that do not draw them as candidates.
  if (plan.candidates.size() <= 1) {
    for (const auto& c : run.report.topo.classes) {
      for (std::size_t i = 1; i < c.path.size(); ++i) {
        cv::line(img, top.toPixel(c.path[i - 1]), top.toPixel(c.path[i]), cv::Scalar(170, 170, 170), 1, cv::LINE_AA);
      }
    }
  }
  if (plan.chosen >= 0) {
    polyline(plan.path, cv::Scalar(200, 60, 0), 3);
    if (run.trajectory.trajectory) {  // the smooth trajectory over the path (thin, dark)
      const auto samples = planner::sampleTrajectory(*run.trajectory.trajectory, 10.0);
      for (std::size_t i = 1; i < samples.size(); ++i) {
        cv::line(img, top.toPixel(samples[i - 1].p_W.head<2>()), top.toPixel(samples[i].p_W.head<2>()),
                 cv::Scalar(20, 20, 20), 2, cv::LINE_AA);
      }
    }
    double since_arrow = 1e9;
    for (std::size_t i = 0; i < plan.path.size(); ++i) {
      if (i > 0) since_arrow += (plan.path[i].p_WB - plan.path[i - 1].p_WB).norm();
      if (since_arrow < 0.8) continue;
      since_arrow = 0.0;
      const Eigen::Vector2d p = plan.path[i].p_WB.head<2>();
      const Eigen::Vector2d tip =
          p + 0.5 * Eigen::Vector2d(std::cos(plan.path[i].yaw_rad), std::sin(plan.path[i].yaw_rad));
      cv::arrowedLine(img, top.toPixel(p), top.toPixel(tip), cv::Scalar(120, 0, 120), 2, cv::LINE_AA, 0, 0.35);
    }
  }
  const cv::Point s = top.toPixel(scene.start.p_WB.head<2>());
  const cv::Point g = top.toPixel(scene.goal.p_WB.head<2>());
  cv::circle(img, s, 8, cv::Scalar(0, 170, 0), cv::FILLED);
  cv::circle(img, g, 8, cv::Scalar(0, 0, 220), cv::FILLED);
  return img;
}

}  // namespace tgnav::harness
