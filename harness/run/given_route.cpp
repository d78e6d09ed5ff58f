#include "harness/run/given_route.h"

#include <functional>
#include <sstream>

#include "harness/base/errors.h"
#include "harness/run/plan_run.h"
#include "harness/run/trial_status.h"

namespace tgnav::harness {

namespace {

// The checks of TrialOptions::given_trajectory and given_path on their points; `at(i)` names the
// i-th in messages.
void checkGivenPoints(const Scenario& scenario, const planner::VoxelMap& voxels,
                      const std::vector<Eigen::Vector3d>& points, const std::function<std::string(std::size_t)>& at) {
  const SceneConfig& scene = scenario.scene;
  const Eigen::Vector2d off = points.front().head<2>() - scene.start.p_WB.head<2>();
  if (off.norm() > kGivenStartTolerance_m) {
    std::ostringstream s;
    s << at(0) << " is " << off.norm() << " m from the scenario's start " << formatPoint(scene.start.p_WB)
      << "; a trial takes off there (tolerance " << kGivenStartTolerance_m << " m)";
    throw InputError(s.str());
  }
  const double radius = scenario.planner.perception.robot_radius_m;
  const ClearanceBand band = clearanceBand(scenario);
  auto inBand = [&](const Eigen::Vector3d& p) { return p.z() >= band.lo_m && p.z() <= band.hi_m; };
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    if ((p.array() < scene.bounds_min_m.array()).any() || (p.array() > scene.bounds_max_m.array()).any()) {
      throw InputError(at(i) + " is outside the scene's bounds " + formatPoint(scene.bounds_min_m) + " .. " +
                       formatPoint(scene.bounds_max_m));
    }
    if (voxels.state(p) == planner::VoxelState::kOccupied) throw InputError(at(i) + " is inside an obstacle");
    if (!inBand(p)) continue;
    const double clearance = voxels.clearance(p);
    if (clearance < radius) {
      std::ostringstream s;
      s << at(i) << " is " << clearance << " m from an obstacle, closer than the robot radius " << radius
        << " m (planner.perception.robot_radius_m)";
      throw InputError(s.str());
    }
    if (i > 0 && inBand(points[i - 1]) && !voxels.segmentClear(points[i - 1], p, radius)) {
      std::ostringstream s;
      s << at(i) << ": the straight line from the one before passes closer than the robot radius " << radius
        << " m to an obstacle";
      throw InputError(s.str());
    }
  }
}

}  // namespace

void checkGivenTrajectory(const Scenario& scenario, const planner::VoxelMap& voxels,
                          const control::SetpointTrajectory& trajectory, const std::string& file) {
  std::vector<Eigen::Vector3d> points;
  points.reserve(trajectory.setpoints().size());
  for (const control::TrajectorySetpoint& sp : trajectory.setpoints()) points.push_back(sp.p_WB);
  checkGivenPoints(scenario, voxels, points, [&](std::size_t i) {
    std::ostringstream s;
    s << file << ": setpoint " << i + 1 << " (t = " << trajectory.times()[i] << " s) at " << formatPoint(points[i]);
    return s.str();
  });
}

void checkGivenPath(const Scenario& scenario, const planner::VoxelMap& voxels, const std::vector<planner::Pose4>& path,
                    const std::string& file) {
  std::vector<Eigen::Vector3d> points;
  points.reserve(path.size());
  for (const planner::Pose4& p : path) points.push_back(p.p_WB);
  checkGivenPoints(scenario, voxels, points, [&](std::size_t i) {
    return file + ": waypoint " + std::to_string(i + 1) + " at " + formatPoint(points[i]);
  });
}

}  // namespace tgnav::harness
