// Trajectory generation on the planners' real outputs (issue 7 acceptance): the chosen paths of
// every planner on the rendered storage and gallery maps become smooth trajectories that hold
// the limits at 1 kHz, keep the clearance target in the map, stay in the path's homology class,
// survive the CSV round trip `tgnav fly --trajectory` reads, and are flown through MuJoCo and
// the cascade without touching the scene.
#include <gtest/gtest.h>

#include <iostream>

#include "harness/io/trajectory_csv.h"
#include "harness/run/plan_run.h"
#include "harness/sim/flight_loop.h"
#include "harness/sim/mujoco_sim.h"
#include "harness/sim/scene_geometry.h"
#include "harness/sim/vehicle_model.h"
#include "planner/topological_planner.h"
#include "test_util.h"

namespace tgnav::harness {
namespace {

struct Checked {
  double min_clearance = 1e9;
  double max_speed = 0.0;
  double max_accel = 0.0;
  double max_yaw_rate = 0.0;
};

// Every acceptance property of one run's trajectory.
Checked checkTrajectory(const Scenario& scenario, const PlanRun& run, const std::string& what) {
  Checked c;
  const planner::TrajectoryReport& tr = run.trajectory;
  const planner::TrajectoryConfig& config = scenario.planner.trajectory;
  EXPECT_EQ(tr.status, planner::TrajectoryStatus::kOptimised) << what << ": " << tr.reason;
  if (!tr.trajectory) {
    ADD_FAILURE() << what << ": no trajectory";
    return c;
  }
  const planner::Trajectory& traj = *tr.trajectory;
  const planner::VoxelClearance field(*run.voxels);
  std::vector<Eigen::Vector2d> xy;
  const int n = static_cast<int>(std::ceil(traj.duration() * 1000.0));
  for (int i = 0; i <= n; ++i) {
    const planner::TrajectorySample s = traj.at(traj.duration() * i / n);
    c.min_clearance = std::min(c.min_clearance, field.clearance(s.p_W, nullptr));
    c.max_speed = std::max(c.max_speed, s.v_W.norm());
    c.max_accel = std::max(c.max_accel, s.a_W.norm());
    c.max_yaw_rate = std::max(c.max_yaw_rate, std::abs(s.yaw_rate_rad_s));
    xy.push_back(s.p_W.head<2>());
  }
  EXPECT_LE(c.max_speed, config.max_speed_mps) << what;
  EXPECT_LE(c.max_accel, config.max_accel_mps2) << what;
  EXPECT_LE(c.max_yaw_rate, config.max_yaw_rate_rad_s) << what;
  EXPECT_GE(c.min_clearance, config.margin_m()) << what;
  // Same homology class as the planned path and as the topological class it was chosen from.
  std::vector<Eigen::Vector2d> path_xy;
  for (const auto& p : run.plan.path) path_xy.push_back(p.p_WB.head<2>());
  const auto& obstacles = run.plan.topo.obstacle_points;
  const std::vector<double> h_traj = planner::windingAngles(xy, obstacles);
  EXPECT_TRUE(planner::TopologicalPlanner::sameClass(h_traj, planner::windingAngles(path_xy, obstacles))) << what;
  EXPECT_TRUE(tr.same_homology) << what;
  if (run.plan.chosen_class >= 0) {
    EXPECT_TRUE(planner::TopologicalPlanner::sameClass(
        h_traj, run.plan.topo.classes[static_cast<std::size_t>(run.plan.chosen_class)].h_signature))
        << what;
  }
  // Rest to rest, from the start to the path's end.
  const planner::TrajectorySample a = traj.at(0.0);
  const planner::TrajectorySample b = traj.at(traj.duration());
  EXPECT_LT((a.p_W - scenario.scene.start.p_WB).norm(), 1e-6) << what;
  EXPECT_LT((b.p_W - run.plan.path.back().p_WB).norm(), 1e-6) << what;
  EXPECT_LT(a.v_W.norm() + b.v_W.norm() + a.a_W.norm() + b.a_W.norm(), 1e-9) << what;
  return c;
}

void checkScene(const std::string& name) {
  const Scenario scenario = loadScenario(test::sourceDir() / "configs/scenarios" / (name + ".yaml"));
  const planner::FeatureMap map = test::sceneMap(name);
  struct Case {
    planner::PlannerKind planner;
    std::uint64_t seed;
  };
  for (const Case& k : {Case{planner::PlannerKind::kProposed, 1}, Case{planner::PlannerKind::kProposed, 2},
                        Case{planner::PlannerKind::kProposed, 3}, Case{planner::PlannerKind::kAgnostic, 1},
                        Case{planner::PlannerKind::kRrtStar, 1}}) {
    const PlanRun run = runPlanner(scenario, map, k.planner, k.seed, 0);
    ASSERT_EQ(run.plan.status, planner::PlanStatus::kSolved);
    const std::string what = name + " " + toString(k.planner) + " seed " + std::to_string(k.seed);
    const Checked c = checkTrajectory(scenario, run, what);
    std::cout << "[ figure   ] " << what << ": path " << run.plan.candidates[run.plan.chosen].length_m
              << " m -> trajectory " << run.trajectory.length_m << " m, " << run.trajectory.duration_s
              << " s; 1 kHz: min clearance " << c.min_clearance << " m, max |v| " << c.max_speed << " m/s, max |a| "
              << c.max_accel << " m/s^2, max |yaw rate| " << c.max_yaw_rate << " rad/s; " << run.trajectory.iterations
              << " L-BFGS iterations in " << run.trajectory_s * 1e3 << " ms\n";
  }
}

TEST(SceneTrajectory, StoragePlannersGiveFeasibleClearSameClassTrajectories) { checkScene("storage"); }
TEST(SceneTrajectory, GalleryPlannersGiveFeasibleClearSameClassTrajectories) { checkScene("gallery"); }

// plan -> trajectory.csv -> fly: the CSV holds every column at full precision, and the vehicle
// flies it through the scene close to the setpoints and clear of every geom.
TEST(SceneTrajectory, StorageProposedTrajectoryRoundTripsAndIsFlownClearOfTheScene) {
  const Scenario scenario = loadScenario(test::sourceDir() / "configs/scenarios/storage.yaml");
  const planner::FeatureMap map = test::sceneMap("storage");
  const PlanRun run = runPlanner(scenario, map, planner::PlannerKind::kProposed, 1, 0);
  ASSERT_TRUE(run.trajectory.trajectory) << run.trajectory.reason;
  const control::SetpointTrajectory written = setpoints(run, scenario.planner.trajectory.sample_rate_hz);
  const auto csv = test::writeFile(test::tempDir() / "trajectory.csv", trajectoryCsv(written));
  const control::SetpointTrajectory read = readTrajectoryCsv(csv);
  ASSERT_EQ(read.times().size(), written.times().size());
  for (std::size_t i = 0; i < read.times().size(); ++i) {
    const auto& w = written.setpoints()[i];
    const auto& r = read.setpoints()[i];
    ASSERT_EQ(read.times()[i], written.times()[i]);
    ASSERT_EQ(r.p_WB, w.p_WB) << i;
    ASSERT_EQ(r.v_WB, w.v_WB) << i;
    ASSERT_EQ(r.a_WB, w.a_WB) << i;
    ASSERT_EQ(r.yaw_rate_rad_s, w.yaw_rate_rad_s) << i;
    ASSERT_EQ(r.yaw_rad, w.yaw_rad) << i;
  }

  VehicleModel vehicle = loadVehicleModel(scenario.scene.mjcf, scenario.vehicle);
  ModelPtr model = std::move(vehicle.model);
  DataPtr data = makeData(model.get());
  const VehicleIds& ids = vehicle.ids;
  planner::Pose4 landed = scenario.scene.start;
  landed.p_WB.z() = scenario.scene.bounds_min_m.z() + 0.035;
  setVehiclePose(model.get(), data.get(), ids, landed);
  FlightLoop loop(model.get(), data.get(), ids, control::CascadeConfig{});
  const FlightResult flight = flyTrajectory(loop, read, FlightConfig{});
  ASSERT_EQ(flight.status, FlightStatus::kCompleted) << flight.reason;
  const SceneGeometry geometry(model.get(), data.get());
  double max_error = 0.0;
  double min_distance = 1e9;
  for (const FlightSample& f : flight.log) {
    if (!f.on_trajectory) continue;
    max_error = std::max(max_error, (f.state.p_WB - f.setpoint.p_WB).norm());
    min_distance = std::min(min_distance, geometry.signedDistance(f.state.p_WB));
  }
  std::cout << "[ figure   ] storage proposed flown: max tracking error " << max_error
            << " m, closest approach of the body centre to the scene " << min_distance << " m\n";
  EXPECT_LT(max_error, 0.1);
  EXPECT_GT(min_distance, scenario.planner.perception.robot_radius_m);
}

}  // namespace
}  // namespace tgnav::harness
