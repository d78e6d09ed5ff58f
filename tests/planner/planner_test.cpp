// The Planner interface (planner.h): the three planners of the paper's Table II, made by
// makePlanner and used alike through it, each return a collision-free path from the start to the
// goal and the homology class of the flight-height slice that path is in; the planner names of
// the command line and the configs round-trip.
#include "planner/planner.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "planner/perception_planner.h"
#include "planner/rrt_star.h"
#include "tests/planner/synthetic_world.h"

namespace tgnav::planner {
namespace {

constexpr double kFlightZ = 1.0;
constexpr PlannerKind kKinds[] = {PlannerKind::kProposed, PlannerKind::kAgnostic, PlannerKind::kRrtStar};

TEST(PlannerKind, NamesRoundTripAndAnythingElseIsRefused) {
  EXPECT_STREQ(toString(PlannerKind::kProposed), "proposed");
  EXPECT_STREQ(toString(PlannerKind::kAgnostic), "agnostic");
  EXPECT_STREQ(toString(PlannerKind::kRrtStar), "rrtstar");
  for (PlannerKind kind : kKinds) {
    PlannerKind parsed = kind == PlannerKind::kProposed ? PlannerKind::kAgnostic : PlannerKind::kProposed;
    EXPECT_TRUE(parsePlannerKind(toString(kind), &parsed)) << toString(kind);
    EXPECT_EQ(parsed, kind) << toString(kind);
  }
  for (const char* text : {"", "Proposed", "AGNOSTIC", "ap", "rrt_star", "rrt*", "RRTstar", " proposed", "agnostic ",
                           "rrtstar\n", "perception"}) {
    PlannerKind kind = PlannerKind::kAgnostic;
    EXPECT_FALSE(parsePlannerKind(text, &kind)) << "'" << text << "'";
    EXPECT_EQ(kind, PlannerKind::kAgnostic) << "'" << text << "' changed the kind";
  }
}

// 10 x 6 x 2 m room with two pillars, the second higher up than the first: four homology classes
// (above or below each), all within the topological search's length ratio. Their north and south
// faces are textured every 0.2 m, so the perception-aware planners have something to weigh.
struct TwoPillars {
  Eigen::AlignedBox3d west{Eigen::Vector3d(3.0, 2.0, 0.0), Eigen::Vector3d(4.0, 3.5, 2.0)};
  Eigen::AlignedBox3d east{Eigen::Vector3d(6.0, 2.5, 0.0), Eigen::Vector3d(7.0, 4.0, 2.0)};
  FeatureMap map;
  VoxelMap voxels;
  Pose4 start{{1.0, 3.0, kFlightZ}, 0.3};
  Pose4 goal{{9.0, 3.0, kFlightZ}, -0.2};

  TwoPillars() : map(build()), voxels(map, Eigen::Vector3d::Zero(), Eigen::Vector3d(10.0, 6.0, 2.0)) {}

  FeatureMap build() const {
    testing::SyntheticWorld world;
    world.max_W = Eigen::Vector3d(10.0, 6.0, 2.0);
    world.solids = {west, east};
    for (const Eigen::AlignedBox3d& pillar : world.solids) {
      world.texture(pillar, Eigen::Vector3d(0.0, -1.0, 0.0), 0.2);
      world.texture(pillar, Eigen::Vector3d(0.0, 1.0, 0.0), 0.2);
    }
    return world.build();
  }
};

const TwoPillars& twoPillars() {
  static const TwoPillars world;
  return world;
}

// Through the interface only: every planner solves, its path is the chosen candidate's, runs from
// the start to the goal and keeps the robot radius, and its chosen_class is the one class of the
// slice (found here by a TopologicalPlanner of our own) whose H-signature the path has.
TEST(Planner, EachPlannerReturnsAClearPathFromStartToGoalAndTheClassItIsIn) {
  const TwoPillars& w = twoPillars();
  const PerceptionPlannerConfig perception;
  RrtStarConfig rrt_star;
  rrt_star.samples = 800;
  TopoPlannerConfig topo_config = perception.topo;
  topo_config.robot_radius_m = perception.robot_radius_m;
  topo_config.path_margin_m = w.voxels.segmentCheckMargin();
  const TopologicalPlanner labeller(
      w.voxels.slice(kFlightZ - perception.slice_half_height_m, kFlightZ + perception.slice_half_height_m),
      topo_config);
  const TopoPlan slice = labeller.solve(w.start.p_WB.head<2>(), w.goal.p_WB.head<2>());
  ASSERT_EQ(slice.status, PlanStatus::kSolved);
  ASSERT_EQ(slice.classes.size(), 4u) << "above or below each pillar";

  for (PlannerKind kind : kKinds) {
    const std::unique_ptr<Planner> planner = makePlanner(kind, w.voxels, perception, rrt_star);
    EXPECT_STREQ(planner->name(), toString(kind));
    for (std::uint64_t seed : {1u, 2u}) {
      const std::string what = std::string(planner->name()) + " seed " + std::to_string(seed);
      const Plan plan = planner->solve({w.start, w.goal, seed});
      ASSERT_EQ(plan.status, PlanStatus::kSolved) << what;
      ASSERT_GE(plan.chosen, 0) << what;
      ASSERT_LT(plan.chosen, static_cast<int>(plan.candidates.size())) << what;
      const CandidatePath& chosen = plan.candidates[static_cast<std::size_t>(plan.chosen)];
      ASSERT_EQ(plan.path.size(), chosen.path.size()) << what;
      ASSERT_GE(plan.path.size(), 2u) << what;
      EXPECT_LT((plan.path.front().p_WB - w.start.p_WB).norm(), 1e-9) << what;
      EXPECT_LT((plan.path.back().p_WB - w.goal.p_WB).norm(), 1e-9) << what;
      EXPECT_EQ(plan.flight_height_m, kFlightZ) << what;
      std::vector<Eigen::Vector2d> xy;
      for (std::size_t i = 0; i < plan.path.size(); ++i) {
        EXPECT_EQ(plan.path[i].p_WB, chosen.path[i].p_WB) << what << " pose " << i;
        if (i > 0) {
          EXPECT_TRUE(w.voxels.segmentClear(plan.path[i - 1].p_WB, plan.path[i].p_WB, perception.robot_radius_m))
              << what << " edge " << i;
        }
        xy.push_back(plan.path[i].p_WB.head<2>());
      }

      // The same classes for every planner, and the path in exactly the one it names.
      ASSERT_EQ(plan.topo.status, PlanStatus::kSolved) << what;
      ASSERT_EQ(plan.topo.classes.size(), slice.classes.size()) << what;
      for (std::size_t k = 0; k < slice.classes.size(); ++k) {
        EXPECT_EQ(plan.topo.classes[k].h_signature, slice.classes[k].h_signature) << what << " class " << k;
      }
      ASSERT_GE(plan.chosen_class, 0) << what;
      ASSERT_LT(plan.chosen_class, static_cast<int>(slice.classes.size())) << what;
      const std::vector<double> h = labeller.hSignature(xy);
      for (std::size_t k = 0; k < slice.classes.size(); ++k) {
        EXPECT_EQ(TopologicalPlanner::sameClass(h, slice.classes[k].h_signature),
                  static_cast<int>(k) == plan.chosen_class)
            << what << " class " << k;
      }
      EXPECT_TRUE(TopologicalPlanner::sameClass(chosen.h_signature, h)) << what;
      const std::size_t details = kind == PlannerKind::kProposed ? slice.classes.size() : 0;
      EXPECT_EQ(plan.details.size(), details) << what;
      std::cout << "[ figure   ] " << what << ": class " << plan.chosen_class << " of " << slice.classes.size() << ", "
                << chosen.length_m << " m, c_p,min " << chosen.c_p_min << "\n";
    }
  }
}

// The oracle: asked for class K, proposed and AP fly class K (its path lies in K, whatever they
// would have chosen), still scoring every class; no class K is no path; RRT* refuses the request.
TEST(Planner, TheOracleFliesTheRequestedClass) {
  const TwoPillars& w = twoPillars();
  const PerceptionPlannerConfig perception;
  const RrtStarConfig rrt_star;
  for (PlannerKind kind : {PlannerKind::kProposed, PlannerKind::kAgnostic}) {
    const std::unique_ptr<Planner> planner = makePlanner(kind, w.voxels, perception, rrt_star);
    const Plan own = planner->solve({w.start, w.goal, 1});
    ASSERT_EQ(own.topo.classes.size(), 4u);
    for (int k = 0; k < 4; ++k) {
      PlanRequest request{w.start, w.goal, 1};
      request.homology_class = k;
      const Plan forced = planner->solve(request);
      const std::string what = std::string(planner->name()) + " class " + std::to_string(k);
      ASSERT_EQ(forced.status, PlanStatus::kSolved) << what;
      EXPECT_EQ(forced.chosen, k) << what;
      EXPECT_EQ(forced.chosen_class, k) << what;
      std::vector<Eigen::Vector2d> xy;
      for (const Pose4& p : forced.path) xy.push_back(p.p_WB.head<2>());
      EXPECT_TRUE(TopologicalPlanner::sameClass(windingAngles(xy, forced.topo.obstacle_points),
                                                forced.topo.classes[static_cast<std::size_t>(k)].h_signature))
          << what;
      ASSERT_EQ(forced.candidates.size(), own.candidates.size()) << what;
      for (std::size_t i = 0; i < own.candidates.size(); ++i) {  // every class scored as without the oracle
        EXPECT_EQ(forced.candidates[i].length_m, own.candidates[i].length_m) << what;
        const double a = forced.candidates[i].cost, b = own.candidates[i].cost;
        EXPECT_TRUE(a == b || (std::isnan(a) && std::isnan(b))) << what << ": " << a << " vs " << b;
      }
      if (k == own.chosen) {
        EXPECT_EQ(forced.path.size(), own.path.size()) << what;
      }
    }
    PlanRequest missing{w.start, w.goal, 1};
    missing.homology_class = 4;
    const Plan none = planner->solve(missing);
    EXPECT_EQ(none.status, PlanStatus::kNoPath) << planner->name();
    EXPECT_EQ(none.chosen, -1) << planner->name();
    EXPECT_TRUE(none.path.empty()) << planner->name();
  }
  PlanRequest rrt_request{w.start, w.goal, 1};
  rrt_request.homology_class = 0;
  EXPECT_THROW(makePlanner(PlannerKind::kRrtStar, w.voxels, perception, rrt_star)->solve(rrt_request),
               std::invalid_argument);
}

}  // namespace
}  // namespace tgnav::planner
