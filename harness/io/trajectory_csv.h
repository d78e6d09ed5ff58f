#pragma once
// Setpoint trajectory files, as `tgnav fly --trajectory` reads them and `tgnav plan` writes them:
// CSV with a header row naming its columns. Required: t,x,y,z,yaw (s, m, rad). Optional
// feed-forward groups: vx,vy,vz (m/s), ax,ay,az (m/s^2) - all three or none - and yaw_rate
// (rad/s). '#' starts a comment line.
#include <filesystem>
#include <vector>

#include "control/trajectory.h"
#include "planner/pose4.h"

namespace tgnav::harness {

// InputError naming file:line, column and value for anything malformed: unknown, missing or
// duplicated columns, short rows, non-numbers, non-finite values, non-increasing time.
control::SetpointTrajectory readTrajectoryCsv(const std::filesystem::path& file);
// A 4-DoF path (`tgnav trial --path`): CSV with the header x,y,z,yaw (any order; m, rad), one
// waypoint per row, at least 2. InputError naming file:line, column and value as above.
std::vector<planner::Pose4> readPathCsv(const std::filesystem::path& file);
// All columns, full precision.
std::string trajectoryCsv(const control::SetpointTrajectory& trajectory);

}  // namespace tgnav::harness
