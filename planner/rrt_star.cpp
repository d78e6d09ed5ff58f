#include "planner/rrt_star.h"

#include <ompl/base/MotionValidator.h>
#include <ompl/base/OptimizationObjective.h>
#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/StateSampler.h>
#include <ompl/base/goals/GoalSampleableRegion.h>
#include <ompl/base/spaces/SE2StateSpace.h>
#include <ompl/base/terminationconditions/IterationTerminationCondition.h>
#include <ompl/datastructures/NearestNeighborsLinear.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/planners/rrt/RRTstar.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <memory>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include "planner/check.h"
#include "planner/fisher.h"

namespace tgnav::planner {

namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace {

using Se2State = ob::SE2StateSpace::StateType;

// OMPL's RNG seeds a 32-bit Mersenne twister: mix the 64-bit seed (splitmix64) so that seeds
// differing only in their high bits still give different streams, one per consumer.
std::uint32_t streamSeed(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (stream + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return static_cast<std::uint32_t>(z ^ (z >> 31));
}

Eigen::Vector3d position(const ob::State* state, double z) {
  const auto* s = state->as<Se2State>();
  return {s->getX(), s->getY(), z};
}

double planarDistance(const ob::State* a, const ob::State* b) {
  const auto* sa = a->as<Se2State>();
  const auto* sb = b->as<Se2State>();
  return std::hypot(sb->getX() - sa->getX(), sb->getY() - sa->getY());
}

// Uniform (x, y, yaw) samples from a generator of its own, seeded per solve: OMPL's default
// samplers draw their seeds from a process-wide sequence, so two solves would differ.
class SeededSe2Sampler : public ob::StateSampler {
 public:
  SeededSe2Sampler(const ob::StateSpace* space, std::uint32_t seed) : StateSampler(space) { rng_.setLocalSeed(seed); }

  void sampleUniform(ob::State* state) override {
    const ob::RealVectorBounds& b = space_->as<ob::SE2StateSpace>()->getBounds();
    auto* s = state->as<Se2State>();
    s->setXY(rng_.uniformReal(b.low[0], b.high[0]), rng_.uniformReal(b.low[1], b.high[1]));
    s->setYaw(rng_.uniformReal(-M_PI, M_PI));
  }
  void sampleUniformNear(ob::State* state, const ob::State* near, double distance) override {
    const auto* n = near->as<Se2State>();
    auto* s = state->as<Se2State>();
    s->setXY(n->getX() + rng_.uniformReal(-distance, distance), n->getY() + rng_.uniformReal(-distance, distance));
    s->setYaw(n->getYaw() + rng_.uniformReal(-distance, distance));
    space_->enforceBounds(state);
  }
  void sampleGaussian(ob::State* state, const ob::State* mean, double std_dev) override {
    const auto* m = mean->as<Se2State>();
    auto* s = state->as<Se2State>();
    s->setXY(rng_.gaussian(m->getX(), std_dev), rng_.gaussian(m->getY(), std_dev));
    s->setYaw(rng_.gaussian(m->getYaw(), std_dev));
    space_->enforceBounds(state);
  }
};

// RRT* with its goal-bias generator seeded per solve, and two changes that leave the tree as it
// is but make each sample cheaper:
// - r-disc neighbours (radius min(range, r_RRT* (log n / n)^(1/3))) instead of OMPL's default
//   k-nearest, whose k = 2^(d+1) e (1 + 1/d) log n is about 400 here: RRT* evaluates the edge cost
//   to every such neighbour although only those within `range` may connect, ~50x more co-visibility
//   information matrices per sample. While the radius is capped at `range` (up to ~10^4 samples on
//   a 100 m^2 map) both variants build the same tree.
// - linear nearest-neighbour search: the default GNAT picks pivots with a generator seeded from
//   the process-wide sequence, which can reorder equidistant neighbours. O(n) per query is small
//   next to the edge costs.
class SeededRrtStar : public og::RRTstar {
 public:
  SeededRrtStar(const ob::SpaceInformationPtr& si, std::uint32_t seed) : RRTstar(si) {
    rng_.setLocalSeed(seed);
    nn_ = std::make_shared<ompl::NearestNeighborsLinear<Motion*>>();
    setKNearest(false);
  }
};

// Edge validity by the voxel map's exact clearance check, not by OMPL's sampled states.
class ClearanceMotionValidator : public ob::MotionValidator {
 public:
  ClearanceMotionValidator(const ob::SpaceInformationPtr& si, const VoxelMap& voxels, double z, double radius)
      : MotionValidator(si), voxels_(voxels), z_(z), radius_(radius) {}

  bool checkMotion(const ob::State* s1, const ob::State* s2) const override {
    const bool ok = voxels_.segmentClear(position(s1, z_), position(s2, z_), radius_);
    ok ? ++valid_ : ++invalid_;
    return ok;
  }
  // Not used by RRT*; walks the segment in half-voxel steps to the last clear point.
  bool checkMotion(const ob::State* s1, const ob::State* s2, std::pair<ob::State*, double>& last_valid) const override {
    if (checkMotion(s1, s2)) return true;
    const double len = planarDistance(s1, s2);
    const int steps = std::max(1, static_cast<int>(std::ceil(len / (0.5 * voxels_.resolution()))));
    const Eigen::Vector3d a = position(s1, z_);
    const Eigen::Vector3d b = position(s2, z_);
    double t = 0.0;
    for (int i = 1; i <= steps; ++i) {
      const double ti = static_cast<double>(i) / steps;
      if (!voxels_.segmentClear(a, a + (b - a) * ti, radius_)) break;
      t = ti;
    }
    if (last_valid.first != nullptr) si_->getStateSpace()->interpolate(s1, s2, t, last_valid.first);
    last_valid.second = t;
    return false;
  }

 private:
  const VoxelMap& voxels_;
  double z_;
  double radius_;
};

// Goal region in xy only (any yaw); sampling it returns the goal pose itself, so goal bias works.
class XyGoal : public ob::GoalSampleableRegion {
 public:
  XyGoal(const ob::SpaceInformationPtr& si, const ob::State* goal, double tolerance)
      : GoalSampleableRegion(si), goal_(si->cloneState(goal)) {
    setThreshold(tolerance);
  }
  ~XyGoal() override { si_->freeState(goal_); }
  XyGoal(const XyGoal&) = delete;  // owns goal_
  XyGoal& operator=(const XyGoal&) = delete;
  XyGoal(XyGoal&&) = delete;
  XyGoal& operator=(XyGoal&&) = delete;

  double distanceGoal(const ob::State* st) const override { return planarDistance(st, goal_); }
  void sampleGoal(ob::State* st) const override { si_->copyState(st, goal_); }
  // One goal sample at most in the tree: RRT* stops goal biasing once a node reaches the region.
  unsigned int maxSampleCount() const override { return 1; }

 private:
  ob::State* goal_;
};

// Perception score of poses and edges, with V(p) cached per state: RRT* asks for the cost of an
// edge into every neighbour of each new sample, and V(p) (one ray per landmark voxel) is the
// expensive part. Owned by one solve() only, so the cache needs no locking.
class CovisibilityScorer {
 public:
  CovisibilityScorer(const VoxelMap& voxels, const RrtStarConfig& config, double z)
      : voxels_(voxels),
        config_(config),
        z_(z),
        cells_(config.information.usesImageCells()),
        inner_(config.information.usesInnerDetections()) {}

  // The landmark voxels of V(p) whose landmarks (aggregated at their mean, as aggregateByVoxel)
  // lie in the field of view at the state's yaw. V(p) is a union of whole landmark voxels, so
  // intersecting two views voxel by voxel and weighting each common voxel by its landmark count
  // is the same as intersecting V(p1) and V(p2) and aggregating the common ids by voxel.
  struct View {
    std::vector<int> slots;  // into VoxelMap::landmarkVoxels(), ascending
  };

  const View& view(const ob::State* state) const {
    const auto* s = state->as<Se2State>();
    const Key key{bits(s->getX()), bits(s->getY()), bits(s->getYaw())};
    auto it = cache_.find(key);
    if (it != cache_.end()) return it->second;
    // V(p) restricted to the field of view, with the cheap FoV test first: only about a fifth of
    // the voxels in range survive it, and the ray of each survivor is most of the planner's time.
    // The range and vertical-FoV test on the voxel centre is VoxelMap::visibleFrom's own.
    const VisibilityConfig& vis = config_.visibility;
    const Eigen::Vector3d p = cameraPosition(position(state, z_), s->getYaw(), vis);
    const double tan_half_vfov = std::tan(0.5 * vis.vfov_rad);
    View v;
    const std::vector<LandmarkVoxel>& all = voxels_.landmarkVoxels();
    for (std::size_t slot = 0; slot < all.size(); ++slot) {
      if (!inFieldOfView(p, s->getYaw(), all[slot].mean_W, vis)) continue;
      if (!withinIncidence(p, {all[slot].mean_W, 1.0, all[slot].normal_W}, config_.information)) continue;
      const Eigen::Vector3d d = all[slot].centre_W - p;
      const double r = d.norm();
      if (r < vis.min_range_m || r > vis.max_range_m || std::abs(d.z()) > tan_half_vfov * d.head<2>().norm()) continue;
      if (voxels_.sees(p, all[slot].index, vis)) v.slots.push_back(static_cast<int>(slot));
    }
    return cache_.emplace(key, std::move(v)).first->second;
  }

  // c of an edge: log det of the information at s2 from the landmarks co-visible from both poses
  // and in both fields of view.
  double edgeScore(const ob::State* s1, const ob::State* s2) const {
    const View& a = view(s1);
    const View& b = view(s2);
    const double yaw2 = s2->as<Se2State>()->getYaw();
    const Eigen::Vector3d p2 = cameraPosition(position(s2, z_), yaw2, config_.visibility);
    Matrix6d info = Matrix6d::Zero();
    ViewSupport support;
    const ImageCells cells(yaw2, config_.visibility);
    std::size_t i = 0;
    std::size_t j = 0;
    while (i < a.slots.size() && j < b.slots.size()) {
      if (a.slots[i] < b.slots[j]) {
        ++i;
      } else if (b.slots[j] < a.slots[i]) {
        ++j;
      } else {
        const LandmarkVoxel& l = voxels_.landmarkVoxels()[static_cast<std::size_t>(a.slots[i])];
        const WeightedPoint point{l.mean_W, static_cast<double>(l.ids.size()), l.normal_W, l.detections};
        addCentredInformation(p2, point.p_W, point.weight, config_.information.bearing_noise_rad, &info);
        support.count(point, (point.p_W - p2).norm(), inner_ && cells.inner(p2, point.p_W));
        ++i;
        ++j;
      }
    }
    // The image coverage is the camera's at s2: all of its view, not only the common part.
    if (cells_) {
      for (int slot : b.slots) {
        support.cover(cells(p2, voxels_.landmarkVoxels()[static_cast<std::size_t>(slot)].mean_W));
      }
    }
    return scoreInformation(info, support, config_.information);
  }

  // Cost per metre of an edge with score c: lambda_d + lambda_p f(c - c_p,thr) (eq. 9's sigmoid:
  // information beyond the threshold hardly helps, a blind edge pays lambda_p in full).
  double costRate(double c) const {
    return config_.distance_weight + config_.perception_weight / (1.0 + std::exp(c - config_.c_p_threshold));
  }

  double edgeCost(const ob::State* s1, const ob::State* s2) const {
    const double length = planarDistance(s1, s2);
    if (length == 0.0) return 0.0;
    // Without a perception term, skip the rays: lambda_p = 0 is the distance-only RRT*.
    if (config_.perception_weight == 0.0) return length * config_.distance_weight;
    return length * costRate(edgeScore(s1, s2));
  }

 private:
  struct Key {
    std::uint64_t x, y, yaw;
    bool operator==(const Key& o) const { return x == o.x && y == o.y && yaw == o.yaw; }
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      std::size_t h = std::hash<std::uint64_t>()(k.x);
      h = h * 1000003u ^ std::hash<std::uint64_t>()(k.y);
      return h * 1000003u ^ std::hash<std::uint64_t>()(k.yaw);
    }
  };
  static std::uint64_t bits(double v) {
    std::uint64_t b;
    std::memcpy(&b, &v, sizeof b);
    return b;
  }

  const VoxelMap& voxels_;
  const RrtStarConfig& config_;
  double z_;
  bool cells_;  // the score needs the image cells (InformationConfig::usesImageCells)
  bool inner_;  // ... and the inner detections (usesInnerDetections)
  mutable std::unordered_map<Key, View, KeyHash> cache_;
};

class CovisibilityObjective : public ob::OptimizationObjective {
 public:
  CovisibilityObjective(const ob::SpaceInformationPtr& si, const CovisibilityScorer& scorer, double distance_weight)
      : OptimizationObjective(si), scorer_(scorer), distance_weight_(distance_weight) {
    description_ = "perception-aware (co-visible Fisher information)";
  }

  ob::Cost stateCost(const ob::State*) const override { return identityCost(); }
  ob::Cost motionCost(const ob::State* s1, const ob::State* s2) const override {
    return ob::Cost(scorer_.edgeCost(s1, s2));
  }
  // The distance term alone bounds any edge's cost from below.
  ob::Cost motionCostHeuristic(const ob::State* s1, const ob::State* s2) const override {
    return ob::Cost(distance_weight_ * planarDistance(s1, s2));
  }
  // The score is taken at the edge's end pose: the reverse edge costs differently, and RRT*
  // must not reuse the cost of p -> q for q -> p when rewiring.
  bool isSymmetric() const override { return false; }

 private:
  const CovisibilityScorer& scorer_;
  double distance_weight_;
};

}  // namespace

void RrtStarConfig::validate() const {
  require(samples >= 1, "samples", samples, "must be >= 1");
  require(range_m > 0.0, "range_m", range_m, "must be > 0");
  require(goal_bias >= 0.0 && goal_bias <= 1.0, "goal_bias", goal_bias, "must be in [0, 1]");
  require(goal_tolerance_m > 0.0, "goal_tolerance_m", goal_tolerance_m, "must be > 0");
  require(robot_radius_m >= 0.0, "robot_radius_m", robot_radius_m, "must be >= 0");
  require(distance_weight >= 0.0, "distance_weight", distance_weight, "must be >= 0");
  require(perception_weight >= 0.0, "perception_weight", perception_weight, "must be >= 0");
  require(distance_weight + perception_weight > 0.0, "distance_weight", distance_weight,
          "distance_weight + perception_weight must be > 0");
  require(std::isfinite(c_p_threshold), "c_p_threshold", c_p_threshold, "must be finite");
  require(slice_half_height_m >= 0.0, "slice_half_height_m", slice_half_height_m, "must be >= 0");
  visibility.validate();
  information.validate();
  topo.validate();
}

PerceptionRrtStar::PerceptionRrtStar(const VoxelMap& voxels, const RrtStarConfig& config)
    : voxels_(voxels), config_(config) {
  config_.topo.robot_radius_m = config_.robot_radius_m;
  config_.validate();
}

Plan PerceptionRrtStar::solve(const PlanRequest& request) const {
  if (request.homology_class >= 0) {
    throw std::invalid_argument("PerceptionRrtStar: RRT* has no homology class to fly (homology_class = " +
                                std::to_string(request.homology_class) + ")");
  }
  Plan plan = searchTree(request.start, request.goal, request.seed);
  // The classes after the search, which never sees them: the tree and its path are the same as
  // without the labelling.
  const double z = request.start.p_WB.z();
  plan.flight_height_m = z;
  TopoPlannerConfig topo_config = config_.topo;
  topo_config.path_margin_m = voxels_.segmentCheckMargin();
  const TopologicalPlanner topo(voxels_.slice(z - config_.slice_half_height_m, z + config_.slice_half_height_m),
                                topo_config);
  plan.topo = topo.solve(request.start.p_WB.head<2>(), request.goal.p_WB.head<2>());
  for (CandidatePath& c : plan.candidates) {
    std::vector<Eigen::Vector2d> xy;
    for (const Pose4& p : c.path) xy.push_back(p.p_WB.head<2>());
    c.h_signature = topo.hSignature(xy);
  }
  if (plan.chosen < 0) return plan;
  const std::vector<double>& h = plan.candidates[static_cast<std::size_t>(plan.chosen)].h_signature;
  for (std::size_t i = 0; i < plan.topo.classes.size() && plan.chosen_class < 0; ++i) {
    if (TopologicalPlanner::sameClass(h, plan.topo.classes[i].h_signature)) plan.chosen_class = static_cast<int>(i);
  }
  return plan;
}

Plan PerceptionRrtStar::searchTree(const Pose4& start, const Pose4& goal, std::uint64_t seed) const {
  // OMPL logs every solve at info level; keep warnings and errors only (process-wide, set once
  // so that concurrent solves do not race on it).
  static const bool quiet = (ompl::msg::setLogLevel(ompl::msg::LOG_WARN), true);
  (void)quiet;
  const double z = start.p_WB.z();

  auto space = std::make_shared<ob::SE2StateSpace>();
  ob::RealVectorBounds bounds(2);
  const Eigen::Vector3d lo = voxels_.origin();
  const Eigen::Vector3d hi = lo + voxels_.size().cast<double>() * voxels_.resolution();
  bounds.setLow(0, lo.x());
  bounds.setLow(1, lo.y());
  bounds.setHigh(0, hi.x());
  bounds.setHigh(1, hi.y());
  space->setBounds(bounds);
  const std::uint32_t sampler_seed = streamSeed(seed, 0);
  space->setStateSamplerAllocator([sampler_seed](const ob::StateSpace* s) -> ob::StateSamplerPtr {
    return std::make_shared<SeededSe2Sampler>(s, sampler_seed);
  });

  auto si = std::make_shared<ob::SpaceInformation>(space);
  const double radius = config_.robot_radius_m;
  const VoxelMap& voxels = voxels_;
  si->setStateValidityChecker([&voxels, si_raw = si.get(), z, radius](const ob::State* s) {
    return si_raw->satisfiesBounds(s) && voxels.clearance(position(s, z)) >= radius;
  });
  si->setMotionValidator(std::make_shared<ClearanceMotionValidator>(si, voxels_, z, radius));
  si->setup();

  ob::ScopedState<ob::SE2StateSpace> s0(space);
  s0->setXY(start.p_WB.x(), start.p_WB.y());
  s0->setYaw(std::remainder(start.yaw_rad, 2.0 * M_PI));
  ob::ScopedState<ob::SE2StateSpace> g0(space);
  g0->setXY(goal.p_WB.x(), goal.p_WB.y());
  g0->setYaw(std::remainder(goal.yaw_rad, 2.0 * M_PI));

  Plan plan;
  if (!si->isValid(s0.get())) {
    plan.status = PlanStatus::kInvalidStart;
    return plan;
  }
  if (!si->isValid(g0.get())) {
    plan.status = PlanStatus::kInvalidGoal;
    return plan;
  }

  const CovisibilityScorer scorer(voxels_, config_, z);
  auto pdef = std::make_shared<ob::ProblemDefinition>(si);
  pdef->addStartState(s0);
  pdef->setGoal(std::make_shared<XyGoal>(si, g0.get(), config_.goal_tolerance_m));
  pdef->setOptimizationObjective(std::make_shared<CovisibilityObjective>(si, scorer, config_.distance_weight));

  auto planner = std::make_shared<SeededRrtStar>(si, streamSeed(seed, 1));
  planner->setRange(config_.range_m);
  planner->setGoalBias(config_.goal_bias);
  planner->setProblemDefinition(pdef);
  planner->setup();
  ob::IterationTerminationCondition iterations(static_cast<unsigned int>(config_.samples));
  const ob::PlannerStatus status = planner->solve(iterations);
  if (status != ob::PlannerStatus::EXACT_SOLUTION) return plan;  // kNoPath: none, or only approximate

  std::vector<const ob::State*> states;
  auto* solution = pdef->getSolutionPath()->as<og::PathGeometric>();
  for (std::size_t i = 0; i < solution->getStateCount(); ++i) states.push_back(solution->getState(i));
  // The tree ends within the tolerance of the goal; finish at the goal position when that last
  // step is clear, keeping the heading the tree arrived with: the goal region leaves yaw free (as
  // the pose graph of the proposed planner does), so no final turn on the spot is added.
  ob::ScopedState<ob::SE2StateSpace> finish(space);
  finish->setXY(goal.p_WB.x(), goal.p_WB.y());
  finish->setYaw(states.back()->as<Se2State>()->getYaw());
  if (!space->equalStates(states.back(), finish.get()) && si->checkMotion(states.back(), finish.get())) {
    states.push_back(finish.get());
  }

  CandidatePath candidate;
  candidate.cost = planner->bestCost().value();  // of the tree's path: without the final step added above
  std::vector<std::vector<int>> visible;
  double score_sum = 0.0;
  candidate.c_p_min = std::numeric_limits<double>::infinity();
  for (const ob::State* state : states) {
    const Eigen::Vector3d p = position(state, z);
    const double yaw = state->as<Se2State>()->getYaw();
    const Eigen::Vector3d camera = cameraPosition(p, yaw, config_.visibility);
    visible.push_back(voxels_.visibleFrom(camera, config_.visibility));
    const double score =
        poseScore(camera, yaw, aggregateByVoxel(voxels_, visible.back()), config_.visibility, config_.information);
    score_sum += score;
    candidate.c_p_min = std::min(candidate.c_p_min, score);
    if (!candidate.path.empty()) candidate.length_m += (p - candidate.path.back().p_WB).norm();
    candidate.path.push_back({p, yaw});
  }
  candidate.c_p = score_sum / static_cast<double>(states.size());
  double s = 0.0;
  for (std::size_t i = 1; i < states.size(); ++i) {
    ScoredSegment segment;
    segment.s_begin_m = s;
    s += (candidate.path[i].p_WB - candidate.path[i - 1].p_WB).norm();
    segment.s_end_m = s;
    std::vector<int> common;
    std::set_intersection(visible[i - 1].begin(), visible[i - 1].end(), visible[i].begin(), visible[i].end(),
                          std::back_inserter(common));
    segment.covisible = static_cast<int>(common.size());
    segment.c_p = scorer.edgeScore(states[i - 1], states[i]);
    candidate.segments.push_back(segment);
  }

  plan.status = PlanStatus::kSolved;
  plan.candidates.push_back(std::move(candidate));
  plan.chosen = 0;
  plan.path = plan.candidates[0].path;
  return plan;
}

}  // namespace tgnav::planner
