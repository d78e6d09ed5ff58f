// The paper's planning claims (Sec. VI-A) on feature maps built by rendering our storage and
// gallery scenes: the proposed planner takes the textured class for every seed, the
// perception-agnostic planner (AP) the shortest, which runs through texture-poor space.
#include <gtest/gtest.h>

#include <iostream>

#include "harness/run/plan_run.h"
#include "test_util.h"

namespace tgnav::harness {
namespace {

constexpr int kSeeds = 10;

// Points every ~5 cm along the path (x, y), with the length each stands for.
std::vector<std::pair<Eigen::Vector2d, double>> sampleAlong(const std::vector<planner::Pose4>& path) {
  std::vector<std::pair<Eigen::Vector2d, double>> out;
  for (std::size_t i = 1; i < path.size(); ++i) {
    const Eigen::Vector2d a = path[i - 1].p_WB.head<2>();
    const Eigen::Vector2d b = path[i].p_WB.head<2>();
    const int steps = std::max(1, static_cast<int>((b - a).norm() / 0.05));
    for (int k = 0; k < steps; ++k) out.emplace_back(a + (b - a) * ((k + 0.5) / steps), (b - a).norm() / steps);
  }
  return out;
}

// Metres of the path inside the axis-aligned box [lo, hi].
double metresInside(const std::vector<planner::Pose4>& path, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  double inside = 0.0;
  for (const auto& [p, ds] : sampleAlong(path)) {
    if ((p.array() >= lo.array()).all() && (p.array() <= hi.array()).all()) inside += ds;
  }
  return inside;
}

// Mean y of the path where it passes the storage partition (|x| < 2.5): the two classes go
// around it above (y ~ +4) or below (y ~ -3.7).
double meanYAtPartition(const std::vector<planner::Pose4>& path) {
  double sum = 0.0, len = 0.0;
  for (const auto& [p, ds] : sampleAlong(path)) {
    if (std::abs(p.x()) < 2.5) {
      sum += p.y() * ds;
      len += ds;
    }
  }
  return len > 0.0 ? sum / len : 0.0;
}

TEST(PaperPlanning, StorageProposedTakesTheTexturedLowerClassAgnosticTheUpper) {
  const Scenario scenario = loadScenario(test::sourceDir() / "configs/scenarios/storage.yaml");
  const planner::FeatureMap map = test::sceneMap("storage");
  int lower = 0;
  double time_sum = 0.0;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    const PlanRun run = runPlanner(scenario, map, planner::PlannerKind::kProposed, static_cast<std::uint64_t>(seed), 0);
    ASSERT_EQ(run.plan.status, planner::PlanStatus::kSolved) << "seed " << seed;
    ASSERT_EQ(run.plan.candidates.size(), 2u);
    lower += meanYAtPartition(run.plan.path) < 0.0;
    time_sum += run.plan_time_s();
    const auto& chosen = run.plan.candidates[static_cast<std::size_t>(run.plan.chosen)];
    EXPECT_GT(chosen.c_p_min, scenario.planner.perception.selection.c_p_threshold) << "seed " << seed;
  }
  const PlanRun ap = runPlanner(scenario, map, planner::PlannerKind::kAgnostic, 1, 0);
  ASSERT_EQ(ap.plan.status, planner::PlanStatus::kSolved);
  const double ap_y = meanYAtPartition(ap.plan.path);
  std::cout << "[ figure   ] storage: proposed took the lower (textured) class for " << lower << "/" << kSeeds
            << " seeds, mean plan time " << time_sum / kSeeds << " s; AP's path passes the partition at mean y " << ap_y
            << " m, " << ap.plan.candidates[static_cast<std::size_t>(ap.plan.chosen)].length_m << " m\n";
  EXPECT_EQ(lower, kSeeds);
  EXPECT_GT(ap_y, 0.0);
}

TEST(PaperPlanning, GalleryProposedAvoidsBothTexturePoorCorridors) {
  const Scenario scenario = loadScenario(test::sourceDir() / "configs/scenarios/gallery.yaml");
  const planner::FeatureMap map = test::sceneMap("gallery");
  // The poor corridors (models/scenes/gallery.xml) without their mouths at the central crossing.
  const Eigen::Vector2d h_lo(1.8, 0.0), h_hi(7.5, 2.4);   // horizontal, right of the centre
  const Eigen::Vector2d v_lo(-1.7, 3.4), v_hi(0.8, 7.0);  // longitudinal, upper middle
  int avoided = 0;
  double time_sum = 0.0;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    const PlanRun run = runPlanner(scenario, map, planner::PlannerKind::kProposed, static_cast<std::uint64_t>(seed), 0);
    ASSERT_EQ(run.plan.status, planner::PlanStatus::kSolved) << "seed " << seed;
    avoided += metresInside(run.plan.path, h_lo, h_hi) == 0.0 && metresInside(run.plan.path, v_lo, v_hi) == 0.0;
    time_sum += run.plan_time_s();
  }
  const PlanRun ap = runPlanner(scenario, map, planner::PlannerKind::kAgnostic, 1, 0);
  ASSERT_EQ(ap.plan.status, planner::PlanStatus::kSolved);
  const double ap_h = metresInside(ap.plan.path, h_lo, h_hi);
  const double ap_v = metresInside(ap.plan.path, v_lo, v_hi);
  std::cout << "[ figure   ] gallery: proposed avoided both texture-poor corridors for " << avoided << "/" << kSeeds
            << " seeds, mean plan time " << time_sum / kSeeds << " s; AP (" << ap.plan.topo.classes.size()
            << " classes) flies " << ap_h << " m and " << ap_v << " m inside them\n";
  EXPECT_EQ(avoided, kSeeds);
  EXPECT_EQ(ap.plan.topo.classes.size(), 10u);
  EXPECT_GT(ap_h + ap_v, 3.0);
}

}  // namespace
}  // namespace tgnav::harness
