// The perception-aware planner (paper Alg. 1, Sec. V-E): the selection cost (eq. 9 with the
// intended sign) and its breakeven, and end-to-end choices on generated two-class scenes where
// one class runs along densely textured walls and the other through a blind gap, at length
// ratios 1.2, ~4 and ~10; determinism across thread counts; no landmarks at all; bad configs.
#include "planner/perception_planner.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>

#include "planner/rrt_star.h"
#include "tests/planner/synthetic_world.h"

namespace tgnav::planner {
namespace {

constexpr double kFlightZ = 1.0;

// ---------------------------------------------------------------------------------------------
// Selection cost.

TEST(SelectionCost, FeatureRichBeatsFeaturePoorUpToTheBreakeven) {
  const SelectionConfig table1;                                     // c_p,thr 6, eta_d 0.2, eta_p 1.5
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

CandidatePath candidate(double length_m, double c_p_min) {
  CandidatePath c;
  c.feasible = true;
  c.length_m = length_m;
  c.c_p_min = c_p_min;
  return c;
}

TEST(SelectCandidate, BelowTheThresholdPerceptionComesFirst) {
  const double blind = 6.0 * std::log(InformationConfig{}.epsilon);
  SelectionConfig config;  // perception_first, tolerance 1.0
  // No class reaches c_p,thr = 6: the weak-but-seeing class wins over the shorter blind one,
  // though eq. 9 alone prefers the shorter (both pay ~eta_p).
  std::vector<CandidatePath> weak{candidate(14.0, blind), candidate(17.0, 0.5), candidate(15.0, blind)};
  EXPECT_EQ(selectCandidate(weak, config), 1);
  EXPECT_LT(weak[0].cost, weak[1].cost);
  SelectionConfig paper = config;
  paper.perception_first = false;
  EXPECT_EQ(selectCandidate(weak, paper), 0);
  // Within the tolerance of the best c_p,min, eq. 9 decides: the shorter of 0.5 and 0.2 wins.
  std::vector<CandidatePath> close{candidate(20.0, 0.5), candidate(16.0, 0.2), candidate(14.0, blind)};
  EXPECT_EQ(selectCandidate(close, config), 1);
  // All blind: the shortest, as before.
  std::vector<CandidatePath> all_blind{candidate(18.0, blind), candidate(14.0, blind)};
  EXPECT_EQ(selectCandidate(all_blind, config), 1);
  // Some class reaches c_p,thr: eq. 9 alone, as in the paper (a much longer rich class can lose
  // to a shorter class just under the threshold).
  std::vector<CandidatePath> above{candidate(100.0, 30.0), candidate(14.0, 5.9)};
  EXPECT_EQ(selectCandidate(above, config), 1);
  EXPECT_EQ(selectCandidate(above, paper), 1);
  // Every class blind somewhere (c_p,min ties at the blind score): the least blind length decides,
  // within blind_tolerance_m (0.5), then eq. 9 (the shorter of the two least blind).
  auto blind_for = [&](double length_m, double blind_m) {
    CandidatePath c = candidate(length_m, blind);
    c.blind_length_m = blind_m;
    return c;
  };
  std::vector<CandidatePath> masked{blind_for(14.0, 14.0), blind_for(17.0, 0.6), blind_for(16.0, 0.8),
                                    blind_for(15.0, 1.4)};
  EXPECT_EQ(selectCandidate(masked, config), 2);
  EXPECT_EQ(selectCandidate(masked, paper), 0);
  // Blind lengths within the tolerance count as equal: c_p,min decides between them.
  std::vector<CandidatePath> mixed{blind_for(14.0, 0.0), blind_for(15.0, 0.3)};
  mixed[0].c_p_min = -20.0;
  mixed[1].c_p_min = 3.0;
  EXPECT_EQ(selectCandidate(mixed, config), 1);
  // Infeasible candidates are never chosen; none feasible: -1.
  std::vector<CandidatePath> none{candidate(10.0, 20.0)};
  none[0].feasible = false;
  EXPECT_EQ(selectCandidate(none, config), -1);
  SelectionConfig bad = config;
  bad.perception_tolerance = -1.0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Generated scenes, each with one free-standing solid in a box, so exactly two homology classes.
// Landmarks every 0.1 m on faces along the longer class; the shorter class passes a stretch from
// which none can be seen (checked by expectScenePremise: its weakest segment scores 6 ln eps).
// Start and goal are shared, so the short class does see texture near its ends; only its
// weakest segment (eq. 10) matters. Keyframes are put 0.5 m in front of the faces (1 m could land
// inside another solid, and embedLandmarks() would drop the landmark).
//
// VoxelMap's (and FeatureMap's) line of sight reaches a face voxel only when the ray enters the
// solid through that voxel, i.e. within 45 degrees of the face normal on each axis: a wall at
// distance d shows a band +-d wide. The scenes are laid out with that in mind.

struct Scene {
  std::unique_ptr<VoxelMap> voxels;
  int landmarks = 0;
  Pose4 start, goal;
};

std::unique_ptr<Scene> buildScene(testing::SyntheticWorld& w, const Eigen::Vector2d& start,
                                  const Eigen::Vector2d& goal) {
  for (Landmark& lm : w.landmarks) lm.ref_kf_p_W = lm.p_W + 0.5 * (lm.ref_kf_p_W - lm.p_W);
  const FeatureMap map = w.build();
  auto scene = std::make_unique<Scene>();
  scene->voxels = std::make_unique<VoxelMap>(map, w.min_W, w.max_W);
  scene->landmarks = static_cast<int>(map.landmarks().size());
  EXPECT_EQ(scene->landmarks, static_cast<int>(w.landmarks.size())) << "every landmark embeds";
  scene->start.p_WB = Eigen::Vector3d(start.x(), start.y(), kFlightZ);
  scene->goal.p_WB = Eigen::Vector3d(goal.x(), goal.y(), kFlightZ);
  return scene;
}

// Block scenes: box W x H x 2 m, wall slabs 0.3 m thick on its left, right and top sides, and a
// block x in [x0, x1], y in [1.6, top]. Start and goal at the same height either side of it: one
// class dips through the gap under the block, the other climbs over it. Textured: the block's
// sides above y = 1.7 and its top, the top slab and the side slabs above `side_from`. The middle
// of the gap sees none of it: the block's faces point away from it, and the side slabs' texture
// lies above the sight lines (and the 45 degrees) that reach them under the block's corners.
struct BlockSpec {
  double width, height, x0, x1, top, start_x, goal_x, ends_y, side_from;
};

std::unique_ptr<Scene> buildBlockScene(const BlockSpec& s, bool textured) {
  testing::SyntheticWorld w;
  w.min_W = {0.0, 0.0, 0.0};
  w.max_W = {s.width, s.height, 2.0};
  const double W = s.width;
  const double H = s.height;
  const Eigen::AlignedBox3d block(Eigen::Vector3d(s.x0, 1.6, 0.0), Eigen::Vector3d(s.x1, s.top, 2.0));
  const Eigen::AlignedBox3d top(Eigen::Vector3d(0.0, H - 0.3, 0.0), Eigen::Vector3d(W, H, 2.0));
  const Eigen::AlignedBox3d left(Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(0.3, H - 0.3, 2.0));
  const Eigen::AlignedBox3d right(Eigen::Vector3d(W - 0.3, 0.0, 0.0), Eigen::Vector3d(W, H - 0.3, 2.0));
  w.solids = {block, top, left, right};
  if (textured) {
    const Eigen::AlignedBox3d sides(Eigen::Vector3d(s.x0, 1.7, 0.0), Eigen::Vector3d(s.x1, s.top, 2.0));
    w.texture(sides, Eigen::Vector3d(-1, 0, 0), 0.1);
    w.texture(sides, Eigen::Vector3d(1, 0, 0), 0.1);
    w.texture(block, Eigen::Vector3d(0, 1, 0), 0.1);
    w.texture(Eigen::AlignedBox3d(Eigen::Vector3d(0.3, H - 0.3, 0.0), Eigen::Vector3d(W - 0.3, H, 2.0)),
              Eigen::Vector3d(0, -1, 0), 0.1);
    w.texture(Eigen::AlignedBox3d(Eigen::Vector3d(0.0, s.side_from, 0.0), Eigen::Vector3d(0.3, H - 0.3, 2.0)),
              Eigen::Vector3d(1, 0, 0), 0.1);
    w.texture(Eigen::AlignedBox3d(Eigen::Vector3d(W - 0.3, s.side_from, 0.0), Eigen::Vector3d(W, H - 0.3, 2.0)),
              Eigen::Vector3d(-1, 0, 0), 0.1);
  }
  return buildScene(w, {s.start_x, s.ends_y}, {s.goal_x, s.ends_y});
}

// Scene A: a block 6 m wide and 2.2 m tall in a 14 x 6.5 m box: over it is ~20 % longer.
constexpr BlockSpec kSceneA{14.0, 6.5, 4.0, 10.0, 3.8, 1.5, 12.5, 2.0, 2.5};
// Scene B: a tower 1 m wide and 8.9 m tall in a 5 x 12 m box, the ends beside it 1 m above the
// gap: over it is ~4x longer.
constexpr BlockSpec kSceneB{5.0, 12.0, 2.0, 3.0, 10.5, 1.4, 3.6, 2.6, 3.2};

// Scene C: box W x 5.2 x 2 m with a wall 0.6 m thick, y in [1.8, 2.4], from x = 1.6 to
// x = W - 1.2. Start (1.8, 1.3) below it and goal (2.5, 2.9) above it, near its left end: one
// class slips round the left end (~3 m), the other runs round the far end. Textured, all facing
// -y so that a camera looking north sees texture all along the long class without having to
// turn round: the wall's underside (from x = 1.7) and a slab along the top of the box (from
// x = 3.9). The middle of the short class, beside the wall's untextured left end, sees none of
// it: the underside faces away from it, and the slab lies outside the 45 degrees from its normal
// within which VoxelMap's line of sight (first occupied voxel on the way to the voxel centre)
// can reach a face voxel. W = 20 m makes the long class ~10x longer.
std::unique_ptr<Scene> buildBeamScene(double width) {
  testing::SyntheticWorld w;
  w.min_W = {0.0, 0.0, 0.0};
  w.max_W = {width, 5.2, 2.0};
  const Eigen::AlignedBox3d wall(Eigen::Vector3d(1.6, 1.8, 0.0), Eigen::Vector3d(width - 1.2, 2.4, 2.0));
  const Eigen::AlignedBox3d top(Eigen::Vector3d(0.0, 4.9, 0.0), Eigen::Vector3d(width, 5.2, 2.0));
  w.solids = {wall, top};
  w.texture(Eigen::AlignedBox3d(Eigen::Vector3d(1.7, 1.8, 0.0), Eigen::Vector3d(width - 1.2, 2.4, 2.0)),
            Eigen::Vector3d(0, -1, 0), 0.1);
  w.texture(Eigen::AlignedBox3d(Eigen::Vector3d(3.9, 4.9, 0.0), Eigen::Vector3d(width, 5.2, 2.0)),
            Eigen::Vector3d(0, -1, 0), 0.1);
  return buildScene(w, {1.8, 1.3}, {2.5, 2.9});
}

const Scene& sceneA() {
  static const std::unique_ptr<Scene> s = buildBlockScene(kSceneA, true);
  return *s;
}
const Scene& sceneB() {
  static const std::unique_ptr<Scene> s = buildBlockScene(kSceneB, true);
  return *s;
}
const Scene& sceneC() {
  static const std::unique_ptr<Scene> s = buildBeamScene(20.0);
  return *s;
}

PerceptionPlannerConfig plannerConfig() {
  PerceptionPlannerConfig c;
  c.topo.max_length_ratio = 20.0;  // keep the long class in the search
  // The paper's perception model: these scenes test eq. 9, and their textured faces are a grid of
  // landmarks 0.1 m apart that covers part of the image only (ImageCoverage tests the limit).
  c.information.min_image_coverage = 0.0;
  c.information.min_detections = 0.0;  // (Detectability tests that gate)
  c.graph.guard_start_turn = false;  // and the paper's free start yaw (StartTurnNeverSweepsABlindView tests the guard)
  return c;
}

// Index of the class through the blind gap: the shorter reference path.
int gapClass(const Plan& r) {
  if (r.topo.classes.size() != 2u) return -1;
  return r.topo.classes[0].length_m <= r.topo.classes[1].length_m ? 0 : 1;
}

const double kBlind = 6.0 * std::log(InformationConfig{}.epsilon);  // c_p of a pose that sees nothing

struct Outcome {
  Plan plan;
  int gap = -1;   // index of the class through the gap
  int over = -1;  // index of the textured class
  const CandidatePath& gapPath() const { return plan.candidates[static_cast<std::size_t>(gap)]; }
  const CandidatePath& texturedPath() const { return plan.candidates[static_cast<std::size_t>(over)]; }
  bool choseTextured() const { return plan.chosen == over; }
  double ratio() const { return texturedPath().length_m / gapPath().length_m; }
  double referenceRatio() const {
    return plan.topo.classes[static_cast<std::size_t>(over)].length_m /
           plan.topo.classes[static_cast<std::size_t>(gap)].length_m;
  }
};

// Solves and checks what every solve must satisfy: two classes, the chosen path is a candidate's,
// it runs from start to goal, and (proposed) each candidate's cost is eq. 9 of its own figures.
Outcome solve(const Scene& scene, const PerceptionPlannerConfig& config, PlannerKind kind, std::uint64_t seed) {
  Outcome o;
  o.plan = makePlanner(kind, *scene.voxels, config, RrtStarConfig{})->solve({scene.start, scene.goal, seed});
  const Plan& plan = o.plan;
  EXPECT_EQ(plan.status, PlanStatus::kSolved);
  EXPECT_EQ(plan.candidates.size(), 2u) << "exactly two homology classes";
  if (plan.status != PlanStatus::kSolved || plan.candidates.size() != 2u) return o;
  o.gap = gapClass(o.plan);
  o.over = 1 - o.gap;
  EXPECT_GE(plan.chosen, 0);
  const CandidatePath& chosen = plan.candidates[static_cast<std::size_t>(plan.chosen)];
  EXPECT_EQ(plan.path.size(), chosen.path.size());
  EXPECT_FALSE(plan.path.empty());
  if (plan.path.empty()) return o;
  EXPECT_LT((plan.path.front().p_WB - scene.start.p_WB).norm(), 1e-9);
  EXPECT_LT((plan.path.back().p_WB - scene.goal.p_WB).norm(), 1e-9);
  if (kind == PlannerKind::kProposed) {
    const double shortest = std::min(plan.candidates[0].length_m, plan.candidates[1].length_m);
    for (const CandidatePath& c : plan.candidates) {
      EXPECT_TRUE(c.feasible);
      EXPECT_NEAR(c.cost, selectionCost(c.length_m, shortest, c.c_p_min, config.selection), 1e-12);
    }
    EXPECT_LE(chosen.cost, plan.candidates[static_cast<std::size_t>(1 - plan.chosen)].cost);
  }
  return o;
}

void printClasses(const std::string& name, const Outcome& o) {
  if (o.gap < 0) return;
  const CandidatePath& g = o.gapPath();
  const CandidatePath& t = o.texturedPath();
  std::cout << "[ figure   ] " << name << ": gap class " << g.length_m << " m, c_p_min " << g.c_p_min << ", q "
            << g.cost << "; textured class " << t.length_m << " m (d/d_min " << o.ratio() << ", reference paths "
            << o.referenceRatio() << "), c_p_min " << t.c_p_min << ", q " << t.cost << "; chosen "
            << (o.choseTextured() ? "textured" : "gap") << "\n";
}

// The scene is what the test needs: the gap class has a blind segment, the textured class has
// none below c_p,thr (so the choice turns on length alone).
void expectScenePremise(const Outcome& o, const SelectionConfig& selection) {
  ASSERT_GE(o.gap, 0);
  EXPECT_NEAR(o.gapPath().c_p_min, kBlind, 1e-9);
  EXPECT_GT(o.texturedPath().c_p_min, selection.c_p_threshold);
  EXPECT_GT(o.texturedPath().length_m, o.gapPath().length_m);
}

// Eq. 9's breakeven d/d_min for these two classes: the textured one wins below it.
double breakeven(const Outcome& o, const SelectionConfig& sel) {
  auto f = [&](double c) { return 1.0 / (1.0 + std::exp(c - sel.c_p_threshold)); };
  return 1.0 + sel.perception_weight * (f(o.gapPath().c_p_min) - f(o.texturedPath().c_p_min)) / sel.distance_weight;
}

TEST(PerceptionPlanner, SceneATexturedClassTwentyPercentLongerIsChosen) {
  const Scene& scene = sceneA();
  const PerceptionPlannerConfig config = plannerConfig();
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const Outcome o = solve(scene, config, PlannerKind::kProposed, seed);
    expectScenePremise(o, config.selection);
    if (o.gap < 0) continue;
    EXPECT_TRUE(o.choseTextured()) << "seed " << seed;
    EXPECT_GT(o.referenceRatio(), 1.1);
    EXPECT_LT(o.referenceRatio(), 1.3);
    printClasses("scene A seed " + std::to_string(seed), o);
  }
  // The perception-agnostic planner takes the short, blind class (yaw along the direction of travel).
  const Outcome ap = solve(scene, config, PlannerKind::kAgnostic, 1);
  ASSERT_GE(ap.gap, 0);
  EXPECT_EQ(ap.plan.chosen, ap.gap);
  EXPECT_EQ(ap.plan.chosen, ap.plan.topo.chosen);
  const auto& path = ap.plan.path;
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    const Eigen::Vector3d d = path[i + 1].p_WB - path[i].p_WB;
    if (d.head<2>().norm() > 1e-6) {
      EXPECT_NEAR(path[i].yaw_rad, std::atan2(d.y(), d.x()), 1e-9);
    }
  }
  // A heavier distance weight (breakeven 1 + 1.5 / 0.6 = 3.5) still picks the textured class here.
  PerceptionPlannerConfig heavy = config;
  heavy.selection.distance_weight = 0.6;
  const Outcome h = solve(scene, heavy, PlannerKind::kProposed, 1);
  EXPECT_TRUE(h.choseTextured());
  printClasses("scene A, eta_d 0.6", h);
}

TEST(PerceptionPlanner, SceneBFourTimesLongerStillWinsUnderTableIButNotWithHeavierDistance) {
  const Scene& scene = sceneB();
  const PerceptionPlannerConfig config = plannerConfig();
  for (std::uint64_t seed = 1; seed <= 2; ++seed) {
    const Outcome o = solve(scene, config, PlannerKind::kProposed, seed);
    expectScenePremise(o, config.selection);
    if (o.gap < 0) continue;
    // d/d_min ~ 4 is well inside Table I's breakeven (~8.5): the textured class is still chosen.
    EXPECT_GT(o.ratio(), 3.7);
    EXPECT_LT(o.ratio(), breakeven(o, config.selection));
    EXPECT_TRUE(o.choseTextured()) << "seed " << seed;
    printClasses("scene B (Table I) seed " + std::to_string(seed), o);
    std::cout << "[ figure   ] scene B: breakeven d/d_min under Table I " << breakeven(o, config.selection) << "\n";
  }
  // Length still matters: eta_d = 0.6 moves the breakeven to ~3.5, below scene B's ratio.
  PerceptionPlannerConfig heavy = config;
  heavy.selection.distance_weight = 0.6;
  const Outcome h = solve(scene, heavy, PlannerKind::kProposed, 1);
  expectScenePremise(h, heavy.selection);
  if (h.gap >= 0) {
    EXPECT_GT(h.ratio(), breakeven(h, heavy.selection));
    EXPECT_FALSE(h.choseTextured());
    printClasses("scene B, eta_d 0.6", h);
    std::cout << "[ figure   ] scene B: breakeven d/d_min with eta_d 0.6 " << breakeven(h, heavy.selection) << "\n";
  }
}

TEST(PerceptionPlanner, SceneCTenTimesLongerLosesToTheBlindShortCut) {
  const Scene& scene = sceneC();
  const PerceptionPlannerConfig config = plannerConfig();
  const Outcome o = solve(scene, config, PlannerKind::kProposed, 1);
  expectScenePremise(o, config.selection);
  if (o.gap < 0) return;
  EXPECT_GT(o.ratio(), breakeven(o, config.selection));
  EXPECT_GT(o.ratio(), 9.0);
  EXPECT_FALSE(o.choseTextured());
  printClasses("scene C (Table I)", o);
}

void expectSamePlan(const Plan& a, const Plan& b) {
  ASSERT_EQ(a.status, b.status);
  ASSERT_EQ(a.chosen, b.chosen);
  ASSERT_EQ(a.candidates.size(), b.candidates.size());
  for (std::size_t i = 0; i < a.candidates.size(); ++i) {
    EXPECT_EQ(a.candidates[i].cost, b.candidates[i].cost);
    EXPECT_EQ(a.candidates[i].c_p_min, b.candidates[i].c_p_min);
    EXPECT_EQ(a.candidates[i].length_m, b.candidates[i].length_m);
  }
  ASSERT_EQ(a.path.size(), b.path.size());
  for (std::size_t j = 0; j < a.path.size(); ++j) {
    EXPECT_EQ(a.path[j].p_WB, b.path[j].p_WB) << "pose " << j;
    EXPECT_EQ(a.path[j].yaw_rad, b.path[j].yaw_rad) << "pose " << j;
  }
}

TEST(PerceptionPlanner, SameSeedSamePlanWhateverTheThreadCount) {
  const Scene& scene = sceneA();
  // With random positions (the paper's sampling; the default lattice does not use the seed).
  PerceptionPlannerConfig one = plannerConfig();
  one.graph.random_positions = true;
  one.threads = 1;
  PerceptionPlannerConfig two = one;
  two.threads = 2;
  const Plan a = ProposedPlanner(*scene.voxels, one).solve({scene.start, scene.goal, 42});
  const Plan b = ProposedPlanner(*scene.voxels, two).solve({scene.start, scene.goal, 42});
  expectSamePlan(a, b);
  // A different seed samples other positions (so the comparison above could fail).
  const Plan c = ProposedPlanner(*scene.voxels, two).solve({scene.start, scene.goal, 43});
  ASSERT_EQ(c.path.size(), a.path.size());
  bool differs = false;
  for (std::size_t j = 0; j < a.path.size(); ++j) differs = differs || a.path[j].p_WB != c.path[j].p_WB;
  EXPECT_TRUE(differs);
}

TEST(PerceptionPlanner, WithoutLandmarksEveryClassIsBlindAndTheShortestWins) {
  const std::unique_ptr<Scene> scene = buildBlockScene(kSceneA, /*textured=*/false);
  ASSERT_EQ(scene->landmarks, 0);
  const PerceptionPlannerConfig config = plannerConfig();
  const Outcome o = solve(*scene, config, PlannerKind::kProposed, 1);
  ASSERT_EQ(o.plan.status, PlanStatus::kSolved);
  ASSERT_EQ(o.plan.candidates.size(), 2u);
  int shortest = 0;
  for (int i = 0; i < 2; ++i) {
    const CandidatePath& c = o.plan.candidates[static_cast<std::size_t>(i)];
    EXPECT_NEAR(c.c_p_min, kBlind, 1e-9);
    EXPECT_NEAR(c.c_p, kBlind, 1e-9);
    for (const ScoredSegment& seg : c.segments) {
      EXPECT_EQ(seg.covisible, 0);
      EXPECT_NEAR(seg.c_p, kBlind, 1e-9);
    }
    if (c.length_m < o.plan.candidates[static_cast<std::size_t>(shortest)].length_m) shortest = i;
  }
  EXPECT_EQ(o.plan.chosen, shortest);
  EXPECT_EQ(o.plan.chosen, o.gap);
  // Blind segments split down to l_min: none is longer.
  for (const ClassDetail& d : o.plan.details) {
    for (const PathSegment& seg : d.segments)
      EXPECT_LE(seg.s_end_m - seg.s_begin_m, config.segments.min_length_m + 1e-12);
  }
}

void expectRejected(const PerceptionPlannerConfig& config, const VoxelMap& voxels, const std::string& field) {
  for (PlannerKind kind : {PlannerKind::kProposed, PlannerKind::kAgnostic}) {
    try {
      const std::unique_ptr<Planner> planner = makePlanner(kind, voxels, config, RrtStarConfig{});
      ADD_FAILURE() << toString(kind) << " accepted, expected a complaint about " << field;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  }
}

TEST(PerceptionPlanner, ConstructorRejectsBadConfigsNamingTheField) {
  testing::SyntheticWorld w;
  w.max_W = {3.0, 3.0, 2.0};
  const FeatureMap map = w.build();
  const VoxelMap voxels(map, w.min_W, w.max_W);
  EXPECT_NO_THROW(ProposedPlanner(voxels, PerceptionPlannerConfig{}));
  EXPECT_NO_THROW(AgnosticPlanner(voxels, PerceptionPlannerConfig{}));
  PerceptionPlannerConfig c;
  c.segments.covisibility_ratio = 1.5;
  expectRejected(c, voxels, "covisibility_ratio");
  c = PerceptionPlannerConfig{};
  c.graph.perception_weight = -1.0;
  expectRejected(c, voxels, "perception_weight");
  c = PerceptionPlannerConfig{};
  c.selection.perception_weight = -1.0;
  expectRejected(c, voxels, "selection.perception_weight");
  c = PerceptionPlannerConfig{};
  c.selection.distance_weight = -0.2;
  expectRejected(c, voxels, "selection.distance_weight");
  c = PerceptionPlannerConfig{};
  c.threads = -1;
  expectRejected(c, voxels, "threads");
}

}  // namespace
}  // namespace tgnav::planner
