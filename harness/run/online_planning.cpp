#include "harness/run/online_planning.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "harness/base/clock.h"
#include "harness/base/errors.h"
#include "harness/sim/scene_geometry.h"

namespace tgnav::harness {

namespace {

// Consecutive failed plans after which a vehicle holding without a route stops (`no_path`).
constexpr int kMaxFailedPlans = 3;
// How far ahead (trajectory time) a new occupied voxel near the path asks for a plan.
constexpr double kBlockedHorizonS = 10.0;
constexpr double kBlockedStepS = 0.1;
// A new plan whose every position lies this close (horizontally) to the current trajectory ahead
// follows the current route: it is not flown (a switch starts from rest). Yaw is not compared:
// where the way ahead is unknown it follows the motion (trial.look_ahead_s), not the planner.
constexpr double kSameRouteM = 0.75;
// The box of the planners' voxel map around the scene bounds (plan_run.cpp's margin).
constexpr double kBoxMarginM = 0.5;

MapBuildConfig onlineMapConfig(const planner::FeatureMap& survey) {
  MapBuildConfig config;
  config.resolution_m = survey.resolution();
  return config;
}

// Calls fn(p) with the centre of every map voxel that the leaf at `it` covers (a leaf may be a
// merged cube of many voxels).
template <typename LeafIterator, typename Fn>
void forEachVoxel(const LeafIterator& it, double res, const Fn& fn) {
  const int n = std::max(1, static_cast<int>(std::lround(it.getSize() / res)));
  const Eigen::Vector3d corner =
      Eigen::Vector3d(it.getX(), it.getY(), it.getZ()) - Eigen::Vector3d::Constant(0.5 * it.getSize() - 0.5 * res);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) fn(Eigen::Vector3d(corner + res * Eigen::Vector3d(i, j, k)));
    }
  }
}

// The survey's occupancy within `radius_m` (horizontally) of `centre`, voxel by voxel.
octomap::OcTree cropOccupancy(const octomap::OcTree& tree, const Eigen::Vector3d& centre, double radius_m) {
  const double res = tree.getResolution();
  octomap::OcTree out(res);
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    forEachVoxel(it, res, [&](const Eigen::Vector3d& p) {
      if ((p - centre).head<2>().norm() > radius_m) return;
      out.setNodeValue(
          octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())),
          it->getLogOdds(), /*lazy_eval=*/true);
    });
  }
  out.updateInnerOccupancy();
  return out;
}

// A trajectory that holds `pose` for `duration_s` (a vehicle without a route waits for one).
control::SetpointTrajectory holdTrajectory(const planner::Pose4& pose, double duration_s) {
  control::TrajectorySetpoint sp;
  sp.p_WB = pose.p_WB;
  sp.yaw_rad = pose.yaw_rad;
  return control::SetpointTrajectory({0.0, duration_s}, {sp, sp});
}

// Where `trajectory` look_ahead_s ahead (or half that) runs through space `map` has not observed,
// the yaw turns as little as it must from the planner's for the way there to lie within
// `half_fov_rad` of the camera's axis (the camera looks before the vehicle flies there); the yaws are then smoothed
// over a moving window of kYawWindowS (on the unit circle) and the yaw rates are their differences. Nothing changes
// where the way ahead is known, nor where the vehicle hardly moves.
constexpr double kYawWindowS = 1.0;
control::SetpointTrajectory lookWhereUnknown(const control::SetpointTrajectory& trajectory,
                                             const planner::FeatureMap& map, double look_ahead_s, double half_fov_rad,
                                             bool always) {
  const std::vector<double>& t = trajectory.times();
  std::vector<control::TrajectorySetpoint> sp = trajectory.setpoints();
  if (look_ahead_s <= 0.0 || t.size() < 3) return trajectory;
  std::vector<double> yaw(sp.size());
  bool changed = false;
  for (std::size_t i = 0; i < sp.size(); ++i) {
    yaw[i] = sp[i].yaw_rad;
    const Eigen::Vector3d far = trajectory.sample(t[i] + look_ahead_s).p_WB;
    const Eigen::Vector3d near = trajectory.sample(t[i] + 0.5 * look_ahead_s).p_WB;
    const Eigen::Vector2d way = (far - sp[i].p_WB).head<2>();
    if (way.norm() < 0.1 || (!always && map.isKnown(far) && map.isKnown(near))) continue;
    // The least turn from the planner's yaw that keeps the way ahead in the camera's field of view.
    const double heading = std::atan2(way.y(), way.x());
    yaw[i] = heading + std::clamp(std::remainder(yaw[i] - heading, 2.0 * M_PI), -half_fov_rad, half_fov_rad);
    changed = true;
  }
  if (!changed) return trajectory;
  const double dt = (t.back() - t.front()) / static_cast<double>(t.size() - 1);
  const auto half = static_cast<std::ptrdiff_t>(std::lround(0.5 * kYawWindowS / dt));
  const auto n = static_cast<std::ptrdiff_t>(sp.size());
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (std::ptrdiff_t j = std::max<std::ptrdiff_t>(0, i - half); j <= std::min(n - 1, i + half); ++j) {
      sum += Eigen::Vector2d(std::cos(yaw[static_cast<std::size_t>(j)]), std::sin(yaw[static_cast<std::size_t>(j)]));
    }
    if (sum.norm() > 1e-6) sp[static_cast<std::size_t>(i)].yaw_rad = std::atan2(sum.y(), sum.x());
  }
  for (std::size_t i = 0; i < sp.size(); ++i) {
    const std::size_t lo = i == 0 ? 0 : i - 1;
    const std::size_t hi = std::min(sp.size() - 1, i + 1);
    sp[i].yaw_rate_rad_s = std::remainder(sp[hi].yaw_rad - sp[lo].yaw_rad, 2.0 * M_PI) / (t[hi] - t[lo]);
  }
  return control::SetpointTrajectory(t, std::move(sp));
}

}  // namespace

struct OnlinePlanning::Attempt {
  OnlinePlan record;
  PlanRun run;
  std::optional<control::SetpointTrajectory> trajectory;
};

OnlinePlanning::OnlinePlanning(const Scenario& scenario, const planner::FeatureMap& survey,
                               planner::PlannerKind planner, std::uint64_t seed, int rrt_samples)
    : scenario_(scenario),
      cfg_(scenario.trial.online),
      planner_(planner),
      seed_(seed),
      rrt_samples_(rrt_samples),
      mapper_(onlineMapConfig(survey)) {
  if (scenario.planner.oracle_class >= 0) {
    throw InputError("planner.oracle_class = " + std::to_string(scenario.planner.oracle_class) +
                     ": an online trial plans again on the map it builds, whose classes change; use trial.mode prior");
  }
  const planner::Pose4& start = scenario.scene.start;
  switch (cfg_.prior_map) {
    case PriorMap::kNone:
      break;
    case PriorMap::kSurvey:
      mapper_.setPrior(survey.occupancy(), survey.landmarks());
      break;
    case PriorMap::kRadius: {
      std::vector<planner::Landmark> near;
      for (const planner::Landmark& lm : survey.landmarks()) {
        if ((lm.p_W - start.p_WB).head<2>().norm() <= cfg_.prior_radius_m) near.push_back(lm);
      }
      mapper_.setPrior(cropOccupancy(survey.occupancy(), start.p_WB, cfg_.prior_radius_m), std::move(near));
      break;
    }
  }
}

OnlinePlanning::~OnlinePlanning() = default;

OnlinePlanning::Attempt OnlinePlanning::plan(const planner::Pose4& start, double t_s, const std::string& trigger) {
  Attempt a;
  a.record.t_s = t_s;
  a.record.effective_s = t_s + cfg_.plan_latency_s;
  a.record.trigger = trigger;
  a.record.start = start;
  const auto t0 = std::chrono::steady_clock::now();
  IncrementalMapper::Built built = mapper_.snapshot();
  a.record.snapshot_s = secondsSince(t0);
  a.record.landmarks = static_cast<int>(built.map.landmarks().size());
  Scenario from_here = scenario_;
  from_here.scene.start = start;
  a.run = runPlanner(from_here, built.map, planner_, seed_, rrt_samples_, "planner.oracle_class",
                     cfg_.unknown_space == UnknownSpace::kFree);
  a.record.voxel_map_s = a.run.voxel_map_s;
  a.record.solve_s = a.run.solve_s;
  a.record.trajectory_s = a.run.trajectory_s;
  const planner::Plan& plan = a.run.plan;
  if (plan.chosen < 0 || !a.run.trajectory.trajectory) {
    a.record.detail = plan.chosen < 0 ? std::string("no path: ") + planner::toString(plan.status)
                                      : "trajectory generation failed: " + a.run.trajectory.reason;
    return a;
  }
  a.record.ok = true;
  a.record.chosen_class = plan.chosen_class;
  for (const planner::Pose4& p : plan.path) {
    a.record.path.push_back(p.p_WB);
    a.record.path_unknown.push_back(!built.map.isKnown(p.p_WB));
  }
  // The way ahead within the horizontal field of view, 10 deg inside its edge.
  const double half_fov = std::max(0.0, 0.5 * scenario_.planner.perception.visibility.hfov_rad - 10.0 * M_PI / 180.0);
  a.trajectory = lookWhereUnknown(setpoints(a.run, scenario_.planner.trajectory.sample_rate_hz), built.map,
                                  cfg_.look_ahead_s, half_fov, cfg_.look_ahead_always);
  return a;
}

control::SetpointTrajectory OnlinePlanning::firstPlan(PlanRun* run) {
  planner::Pose4 start = scenario_.scene.start;
  Attempt a = plan(start, 0.0, "start");
  next_replan_s_ = cfg_.replan_period_s;
  if (a.trajectory) {
    a.record.adopted = true;
    current_ = std::make_unique<control::SetpointTrajectory>(*a.trajectory);
  } else {
    // No route yet: climb to the flight height and look.
    start.p_WB.z() = scenario_.scene.flight_height_m;
    current_ = std::make_unique<control::SetpointTrajectory>(
        holdTrajectory(start, 2.0 * cfg_.replan_period_s + cfg_.plan_latency_s));
    failed_in_a_row_ = 1;
    holding_ = true;
  }
  tau0_ = current_->startTime();
  result_.plans.push_back(a.record);
  *run = std::move(a.run);
  return *current_;
}

bool OnlinePlanning::blockedAhead(double tau_from) const {
  const octomap::OcTree& tree = mapper_.occupancy();
  const double r = scenario_.planner.perception.robot_radius_m;
  const double until = std::min(current_->endTime(), tau_from + kBlockedHorizonS);
  for (double tau = std::max(tau_from, current_->startTime()); tau <= until + 1e-9; tau += kBlockedStepS) {
    const Eigen::Vector3d p = current_->sample(tau).p_WB;
    for (int i = -1; i <= 1; ++i) {
      for (int j = -1; j <= 1; ++j) {
        for (int k = -1; k <= 1; ++k) {
          const Eigen::Vector3d q = p + r * Eigen::Vector3d(i, j, k);
          const octomap::OcTreeNode* node =
              tree.search(static_cast<float>(q.x()), static_cast<float>(q.y()), static_cast<float>(q.z()));
          if (node != nullptr && tree.isNodeOccupied(node)) return true;
        }
      }
    }
  }
  return false;
}

bool OnlinePlanning::sameRoute(const std::vector<planner::Pose4>& path, double tau_from) const {
  std::vector<control::TrajectorySetpoint> ahead;
  for (double tau = tau_from; tau < current_->endTime() + kBlockedStepS; tau += kBlockedStepS) {
    ahead.push_back(current_->sample(std::min(tau, current_->endTime())));
  }
  for (const planner::Pose4& pose : path) {
    double best = std::numeric_limits<double>::infinity();
    for (const control::TrajectorySetpoint& sp : ahead) best = std::min(best, (sp.p_WB - pose.p_WB).head<2>().norm());
    if (best > kSameRouteM) return false;
  }
  return true;
}

void OnlinePlanning::mapFrame(const RgbdFrame& frame, double t_s, double trajectory_start_s) {
  const auto t0 = std::chrono::steady_clock::now();
  mapper_.insertDepth(frame, cfg_.map_stride_px);
  mapper_.observeFeatures(frame);
  ++result_.keyframes;
  if (!blocked_) blocked_ = blockedAhead(tau(t_s, trajectory_start_s));
  result_.map_update_s += secondsSince(t0);
}

std::string OnlinePlanning::replan(double t_s, double trajectory_start_s) {
  if (t_s < pending_until_s_ - 1e-9 || (t_s < next_replan_s_ - 1e-9 && !blocked_)) return std::string();
  const planner::Pose4& goal = scenario_.scene.goal;
  const double t_eff = t_s + cfg_.plan_latency_s;
  const bool before_start = t_eff <= trajectory_start_s;
  planner::Pose4 start = scenario_.scene.start;
  double tau_switch = tau0_;
  if (!before_start) {
    tau_switch = tau(t_eff, trajectory_start_s);
    const control::TrajectorySetpoint sp = current_->sample(tau_switch);
    start.p_WB = Eigen::Vector3d(sp.p_WB.x(), sp.p_WB.y(), scenario_.scene.start.p_WB.z());
    start.yaw_rad = sp.yaw_rad;
  }
  const bool arriving = (start.p_WB - goal.p_WB).head<2>().norm() <= 0.5 * scenario_.trial.goal_radius_m;
  if (arriving && failed_in_a_row_ == 0) {
    next_replan_s_ = std::numeric_limits<double>::infinity();  // the current trajectory ends at the goal
    blocked_ = false;
    return std::string();
  }
  Attempt a = plan(start, t_s, blocked_ ? "blocked" : "period");
  next_replan_s_ = t_s + cfg_.replan_period_s;
  blocked_ = false;
  const bool must_switch = holding_ || a.record.trigger == "blocked";
  const bool committed = t_s < last_change_s_ + cfg_.commit_s;
  if (a.trajectory && !must_switch && (committed || sameRoute(a.run.plan.path, tau_switch))) {
    failed_in_a_row_ = 0;
    result_.plans.push_back(std::move(a.record));
    return std::string();
  }
  if (a.trajectory) {
    a.record.adopted = true;
    last_change_s_ = t_s;
    current_ = std::make_unique<control::SetpointTrajectory>(
        control::spliceTrajectory(*current_, *a.trajectory, tau_switch, before_start ? 0.0 : cfg_.blend_s));
    pending_until_s_ = t_eff;
    failed_in_a_row_ = 0;
    holding_ = false;
    result_.plans.push_back(std::move(a.record));
    return std::string();
  }
  result_.plans.push_back(a.record);
  ++failed_in_a_row_;
  const double tau_now = tau(t_s, trajectory_start_s);
  const bool spent = tau_now >= current_->endTime() - cfg_.plan_latency_s;
  if (failed_in_a_row_ >= kMaxFailedPlans && (spent || holding_)) {
    std::ostringstream why;
    why << failed_in_a_row_ << " plans in a row found no route (last: " << a.record.detail << ")";
    return why.str();
  }
  if (spent || blockedAhead(tau_now)) {
    // Stop where the current trajectory is at the switch, and wait for a route.
    current_ = std::make_unique<control::SetpointTrajectory>(
        control::spliceTrajectory(*current_, holdTrajectory(start, 2.0 * cfg_.replan_period_s + cfg_.plan_latency_s),
                                  tau_switch, before_start ? 0.0 : cfg_.blend_s));
    holding_ = true;
    pending_until_s_ = t_eff;
  }
  return std::string();
}

namespace {

// The plan in effect at time t: the last that took effect by then (the first before any).
const OnlinePlan* planAt(const std::vector<OnlinePlan>& plans, double t_s) {
  const OnlinePlan* in_effect = nullptr;
  for (const OnlinePlan& p : plans) {
    if (!p.adopted) continue;
    if (in_effect == nullptr || p.effective_s <= t_s) in_effect = &p;
  }
  return in_effect;
}

}  // namespace

OnlineResult OnlinePlanning::finish(const SceneGeometry& truth,
                                    const std::vector<std::pair<double, Eigen::Vector3d>>& flown) {
  OnlineResult out = std::move(result_);
  out.final_map = mapper_.snapshot().map;
  const octomap::OcTree& tree = out.final_map->occupancy();
  const double res = tree.getResolution();
  const SceneConfig& scene = scenario_.scene;
  // Coverage: the voxels of the bounds in the flight band that were observed.
  const ClearanceBand band = clearanceBand(scenario_);
  long known = 0;
  long total = 0;
  for (double z = band.lo_m + 0.5 * res; z < band.hi_m; z += res) {
    for (double y = scene.bounds_min_m.y() + 0.5 * res; y < scene.bounds_max_m.y(); y += res) {
      for (double x = scene.bounds_min_m.x() + 0.5 * res; x < scene.bounds_max_m.x(); x += res) {
        ++total;
        known += tree.search(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)) != nullptr ? 1 : 0;
      }
    }
  }
  out.coverage = total > 0 ? static_cast<double>(known) / static_cast<double>(total) : 0.0;
  // Map error: each occupied voxel's centre against the true surfaces.
  const Eigen::Vector3d lo = scene.bounds_min_m - Eigen::Vector3d::Constant(kBoxMarginM);
  const Eigen::Vector3d hi = scene.bounds_max_m + Eigen::Vector3d::Constant(kBoxMarginM);
  double sum = 0.0;
  long far = 0;
  long n = 0;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    forEachVoxel(it, res, [&](const Eigen::Vector3d& p) {
      if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) return;
      const double d = std::max(0.0, truth.signedDistance(p));
      sum += d;
      far += d > 2.0 * res ? 1 : 0;
      ++n;
    });
  }
  out.occupied_voxels = static_cast<int>(n);
  out.map_error_mean_m = n > 0 ? sum / static_cast<double>(n) : 0.0;
  out.map_error_far_share = n > 0 ? static_cast<double>(far) / static_cast<double>(n) : 0.0;
  // The flight through space unknown when planned: per flown point, the nearest point of the
  // plan in effect.
  long unknown = 0;
  for (const auto& [t, p] : flown) {
    const OnlinePlan* plan = planAt(out.plans, t);
    if (plan == nullptr || plan->path.empty()) continue;
    std::size_t best = 0;
    for (std::size_t i = 1; i < plan->path.size(); ++i) {
      if ((plan->path[i] - p).squaredNorm() < (plan->path[best] - p).squaredNorm()) best = i;
    }
    unknown += plan->path_unknown[best] ? 1 : 0;
  }
  out.unknown_share = flown.empty() ? 0.0 : static_cast<double>(unknown) / static_cast<double>(flown.size());
  return out;
}

}  // namespace tgnav::harness
