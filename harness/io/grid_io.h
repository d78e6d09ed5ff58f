#pragma once
// Loaders (and a map_server writer) for 2D occupancy grids from the two common formats: ROS map_server maps (YAML +
// PGM) and MovingAI benchmark .map files. Both put image row 0 at the top of the map (largest y), while OccupancyGrid2D
// stores rows from the lowest y, so every loader flips rows. Bad input throws InputError naming the file, the key or
// line, and the offending value.
#include <filesystem>

#include "planner/occupancy_grid.h"

namespace tgnav::harness {

// A map_server YAML (keys image, resolution, origin [x, y, yaw], occupied_thresh, free_thresh,
// negate; optional mode, only "trinary") and the P5/P2 PGM it names (relative to the YAML's
// directory unless absolute). occ = (maxval - pixel) / maxval, or pixel / maxval with negate: 1;
// a cell is free only when occ < free_thresh, and both occupied and unknown are stored occupied.
// origin yaw must be 0: the grid type has no rotation.
planner::OccupancyGrid2D loadRosMap(const std::filesystem::path& yaml);

// A MovingAI .map ("type octile", "height H", "width W", "map", then H rows of W characters).
// '.', 'G' and 'S' are passable; '@', 'O', 'T' and 'W' are obstacles; any other character is an
// error naming its line and column. Origin (0, 0); `resolution_m` must be > 0.
planner::OccupancyGrid2D loadMovingAiMap(const std::filesystem::path& file, double resolution_m);

// Writes `grid` as a map_server map: `yaml` (image: the PGM's file name, resolution, origin
// [x, y, 0], negate 0, occupied_thresh 0.65, free_thresh 0.196) and the binary PGM `pgm` beside
// it (0 = occupied, 254 = free, first row the highest y). loadRosMap reads it back exactly.
// InputError naming the file when it cannot be written.
void writeRosMap(const planner::OccupancyGrid2D& grid, const std::filesystem::path& yaml,
                 const std::filesystem::path& pgm);

// By extension: .yaml/.yml -> loadRosMap, .map -> loadMovingAiMap (with movingai_resolution_m).
planner::OccupancyGrid2D loadGridMap(const std::filesystem::path& file, double movingai_resolution_m);

}  // namespace tgnav::harness
