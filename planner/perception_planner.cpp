#include "planner/perception_planner.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "planner/check.h"

namespace tgnav::planner {

namespace {

// SplitMix64: an independent, reproducible seed per class from the plan's seed.
std::uint64_t classSeed(std::uint64_t seed, std::size_t index) {
  std::uint64_t z = seed + 0x9e3779b97f4a7c15ULL * (index + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

std::vector<Eigen::Vector3d> lift(const std::vector<Eigen::Vector2d>& path, double z) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(path.size());
  for (const auto& p : path) out.emplace_back(p.x(), p.y(), z);
  return out;
}

// AP's 4-DoF path: the class's path with the yaw along the direction of travel.
std::vector<Pose4> headingPath(const std::vector<Eigen::Vector3d>& path, double start_yaw) {
  std::vector<Pose4> out;
  double yaw = start_yaw;
  for (std::size_t i = 0; i < path.size(); ++i) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    if (i + 1 < path.size()) {
      d = path[i + 1] - path[i];
    } else if (i > 0) {
      d = path[i] - path[i - 1];
    }
    if (d.head<2>().norm() > 1e-9) yaw = std::atan2(d.y(), d.x());
    out.push_back({path[i], yaw});
  }
  return out;
}

// c_p of every segment (eq. 8 over the chosen poses in it); a segment shorter than the layer
// spacing that holds no layer takes the layer nearest to its middle.
std::vector<ScoredSegment> scoreSegments(const std::vector<PathSegment>& segments, const PoseGraphResult& graph) {
  std::vector<ScoredSegment> out;
  for (std::size_t k = 0; k < segments.size(); ++k) {
    ScoredSegment seg;
    seg.s_begin_m = segments[k].s_begin_m;
    seg.s_end_m = segments[k].s_end_m;
    seg.covisible = segments[k].covisible_landmarks;
    double sum = 0.0;
    int n = 0;
    for (std::size_t j = 0; j < graph.scores.size(); ++j) {
      if (graph.layer_segment[j] == static_cast<int>(k)) {
        sum += graph.scores[j];
        ++n;
      }
    }
    if (n == 0 && !graph.scores.empty()) {
      const double mid = 0.5 * (seg.s_begin_m + seg.s_end_m);
      std::size_t nearest = 0;
      for (std::size_t j = 1; j < graph.layer_s.size(); ++j) {
        if (std::abs(graph.layer_s[j] - mid) < std::abs(graph.layer_s[nearest] - mid)) nearest = j;
      }
      sum = graph.scores[nearest];
      n = 1;
    }
    seg.c_p = n > 0 ? sum / n : std::numeric_limits<double>::quiet_NaN();
    out.push_back(seg);
  }
  return out;
}

// Path length around the chosen poses that score blind (6 ln eps): each layer stands for half the
// interval to either neighbour.
double blindLength(const PoseGraphResult& graph, const InformationConfig& information) {
  const double blind = logDetInformation(Matrix6d::Zero(), information.epsilon);
  const std::size_t n = graph.scores.size();
  double length = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    if (graph.scores[j] > blind + 1e-9) continue;
    if (j > 0) length += 0.5 * (graph.layer_s[j] - graph.layer_s[j - 1]);
    if (j + 1 < n) length += 0.5 * (graph.layer_s[j + 1] - graph.layer_s[j]);
  }
  return length;
}

// The config as the planners use it: one robot radius for the GVD slice and the pose graph.
PerceptionPlannerConfig withRobotRadius(PerceptionPlannerConfig config) {
  config.topo.robot_radius_m = config.robot_radius_m;
  config.graph.robot_radius_m = config.robot_radius_m;
  config.graph.turn_floor = config.selection.c_p_threshold;
  config.validate();
  return config;
}

// What both planners start from (Sec. V-B): the homology classes on the slice at the start's
// height, and one candidate per class with the class's H-signature and reference length.
Plan classCandidates(const VoxelMap& voxels, const PerceptionPlannerConfig& config, const PlanRequest& request) {
  Plan plan;
  const double z = request.start.p_WB.z();
  plan.flight_height_m = z;
  const OccupancyGrid2D grid = voxels.slice(z - config.slice_half_height_m, z + config.slice_half_height_m);
  TopoPlannerConfig topo_config = config.topo;
  topo_config.path_margin_m = voxels.segmentCheckMargin();
  const TopologicalPlanner topo(grid, topo_config);
  plan.topo = topo.solve(request.start.p_WB.head<2>(), request.goal.p_WB.head<2>());
  plan.status = plan.topo.status;
  if (plan.status != PlanStatus::kSolved) return plan;
  plan.candidates.resize(plan.topo.classes.size());
  for (std::size_t i = 0; i < plan.candidates.size(); ++i) {
    plan.candidates[i].h_signature = plan.topo.classes[i].h_signature;
    plan.candidates[i].length_m = plan.topo.classes[i].length_m;
  }
  return plan;
}

}  // namespace

void SelectionConfig::validate() const {
  require(std::isfinite(c_p_threshold), "c_p_threshold", c_p_threshold, "must be finite");
  require(distance_weight >= 0.0, "selection.distance_weight", distance_weight, "must be >= 0");
  require(perception_weight >= 0.0, "selection.perception_weight", perception_weight, "must be >= 0");
  require(perception_tolerance >= 0.0 && std::isfinite(perception_tolerance), "selection.perception_tolerance",
          perception_tolerance, "must be finite and >= 0");
  require(blind_tolerance_m >= 0.0 && std::isfinite(blind_tolerance_m), "selection.blind_tolerance_m",
          blind_tolerance_m, "must be finite and >= 0");
}

void PerceptionPlannerConfig::validate() const {
  require(robot_radius_m >= 0.0, "robot_radius_m", robot_radius_m, "must be >= 0");
  require(slice_half_height_m >= 0.0, "slice_half_height_m", slice_half_height_m, "must be >= 0");
  require(threads >= 0, "threads", threads, "must be >= 0 (0: one per core)");
  topo.validate();
  visibility.validate();
  information.validate();
  segments.validate();
  graph.validate();
  selection.validate();
}

double selectionCost(double length_m, double shortest_m, double c_p_min, const SelectionConfig& config) {
  const double extra = shortest_m > 0.0 ? length_m / shortest_m - 1.0 : 0.0;
  const double f = 1.0 / (1.0 + std::exp(c_p_min - config.c_p_threshold));
  return config.distance_weight * extra + config.perception_weight * f;
}

int selectCandidate(std::vector<CandidatePath>& candidates, const SelectionConfig& config) {
  double shortest = std::numeric_limits<double>::infinity();
  double best_c_p_min = -std::numeric_limits<double>::infinity();
  double least_blind = std::numeric_limits<double>::infinity();
  for (const CandidatePath& c : candidates) {
    if (!c.feasible) continue;
    shortest = std::min(shortest, c.length_m);
    best_c_p_min = std::max(best_c_p_min, c.c_p_min);
    least_blind = std::min(least_blind, c.blind_length_m);
  }
  const bool perception_first = config.perception_first && best_c_p_min < config.c_p_threshold;
  auto least_blind_ones = [&](const CandidatePath& c) {
    return c.blind_length_m <= least_blind + config.blind_tolerance_m;
  };
  if (perception_first) {  // the best c_p,min among the classes with the least blind length
    best_c_p_min = -std::numeric_limits<double>::infinity();
    for (const CandidatePath& c : candidates) {
      if (c.feasible && least_blind_ones(c)) best_c_p_min = std::max(best_c_p_min, c.c_p_min);
    }
  }
  int chosen = -1;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    CandidatePath& c = candidates[i];
    if (!c.feasible) continue;
    c.cost = selectionCost(c.length_m, shortest, c.c_p_min, config);
    if (perception_first && !least_blind_ones(c)) continue;
    if (perception_first && c.c_p_min < best_c_p_min - config.perception_tolerance) continue;
    if (chosen < 0 || c.cost < candidates[static_cast<std::size_t>(chosen)].cost) chosen = static_cast<int>(i);
  }
  return chosen;
}

ProposedPlanner::ProposedPlanner(const VoxelMap& voxels, const PerceptionPlannerConfig& config)
    : voxels_(voxels), config_(withRobotRadius(config)) {}

Plan ProposedPlanner::solve(const PlanRequest& request) const {
  Plan plan = classCandidates(voxels_, config_, request);
  if (plan.status != PlanStatus::kSolved) return plan;

  const double z = plan.flight_height_m;
  const std::size_t n = plan.candidates.size();
  plan.details.resize(n);
  auto evaluate = [&](std::size_t i) {
    const std::vector<Eigen::Vector3d> path = lift(plan.topo.classes[i].path, z);
    ClassDetail& detail = plan.details[i];
    detail.segments = extractSegments(
        path, config_.segments, [&](const Eigen::Vector3d& p) { return voxels_.visibleSlots(p, config_.visibility); },
        &detail.visibility_queries, [&](int slot) { return voxels_.landmarksIn(slot); });
    detail.graph = searchPoseGraph(path, detail.segments, voxels_, config_.visibility, config_.information,
                                   config_.graph, config_.keep_start_yaw ? request.start.yaw_rad : std::nan(""),
                                   classSeed(request.seed, i), request.start.yaw_rad);
    CandidatePath& c = plan.candidates[i];
    c.feasible = detail.graph.found;
    c.segments = scoreSegments(detail.segments, detail.graph);
    if (!c.feasible) return;
    c.path = detail.graph.path;
    c.length_m = detail.graph.c_d;
    c.c_p = detail.graph.c_p;
    c.c_p_min = std::numeric_limits<double>::infinity();
    for (const ScoredSegment& s : c.segments) c.c_p_min = std::min(c.c_p_min, s.c_p);
    c.blind_length_m = blindLength(detail.graph, config_.information);
  };
  tbb::task_arena arena(config_.threads > 0 ? config_.threads : tbb::task_arena::automatic);
  // One task per class, longest (slowest) first, so that the threads finish together.
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, n, 1),
        [&](const tbb::blocked_range<std::size_t>& r) {
          for (std::size_t k = r.begin(); k != r.end(); ++k) evaluate(n - 1 - k);
        },
        tbb::simple_partitioner());
  });

  plan.chosen = selectCandidate(plan.candidates, config_.selection);
  if (request.homology_class >= 0) {
    const auto k = static_cast<std::size_t>(request.homology_class);
    plan.chosen = k < n && plan.candidates[k].feasible ? request.homology_class : -1;
  }
  if (plan.chosen < 0) {
    plan.status = PlanStatus::kNoPath;
    return plan;
  }
  plan.path = plan.candidates[static_cast<std::size_t>(plan.chosen)].path;
  // Candidate i is class i's: its pose graph is sampled around that class's path.
  plan.chosen_class = plan.chosen;
  return plan;
}

AgnosticPlanner::AgnosticPlanner(const VoxelMap& voxels, const PerceptionPlannerConfig& config)
    : voxels_(voxels), config_(withRobotRadius(config)) {}

Plan AgnosticPlanner::solve(const PlanRequest& request) const {
  Plan plan = classCandidates(voxels_, config_, request);
  if (plan.status != PlanStatus::kSolved) return plan;
  for (std::size_t i = 0; i < plan.candidates.size(); ++i) {
    plan.candidates[i].path = headingPath(lift(plan.topo.classes[i].path, plan.flight_height_m), request.start.yaw_rad);
  }
  plan.chosen = plan.topo.chosen;
  if (request.homology_class >= 0) {
    if (request.homology_class >= static_cast<int>(plan.candidates.size())) {
      plan.chosen = -1;
      plan.status = PlanStatus::kNoPath;
      return plan;
    }
    plan.chosen = request.homology_class;
  }
  plan.path = plan.candidates[static_cast<std::size_t>(plan.chosen)].path;
  plan.chosen_class = plan.chosen;
  return plan;
}

}  // namespace tgnav::planner
