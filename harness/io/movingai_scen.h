#pragma once
// MovingAI benchmark scenario (.scen, version 1) files (movingai.com/benchmarks/formats):
// "version 1" (or "version 1.0") on the first line, then one problem per line, nine fields
// separated by spaces or tabs:
//   bucket map map_width map_height start_x start_y goal_x goal_y optimal_length
// x is the column and y the row from the TOP of the map, in cells; optimal_length is the 8-connected
// octile path length (diagonal sqrt(2), no corner cutting). Blank lines are allowed anywhere after
// the version line; CRLF line ends are accepted. Bad input throws InputError "FILE:LINE: what",
// one line, naming the offending value.
#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "planner/occupancy_grid.h"

namespace tgnav::harness {

// One scenario line, as written in the file (cells, y from the top).
struct ScenRow {
  int line = 0;  // 1-based line number in the .scen file, for messages
  int bucket = 0;
  std::string map;  // the map file name as written (no spaces; may contain a directory)
  int map_width = 0, map_height = 0;
  int start_x = 0, start_y = 0, goal_x = 0, goal_y = 0;
  double optimal_length = 0.0;  // cells
};

// Parses a .scen file. Throws InputError "FILE:LINE: what" on: a missing or unknown version line
// (including an empty file), a line without exactly 9 fields, a bucket that is not an integer in
// 0..999999999, a map width/height not in 1..20000, a coordinate that is not an integer inside the
// line's own map width/height, a map name with control bytes, or an optimal length that is not a
// finite decimal number >= 0 (so "nan", "inf" and "-1" are refused). A file with a version line but
// no scenario is an error too ("FILE: no scenarios ...").
std::vector<ScenRow> loadMovingAiScen(const std::filesystem::path& file);

// Checks every row against the map it is run on: its width/height fields must equal the map's
// (scaled scenarios, which the format allows, are not supported) and its start and goal must lie
// inside the map. Throws InputError "FILE:LINE: ..." (FILE = scen_file, LINE = row.line) naming the
// field and its value. Does not check the map name or that the cells are free.
void checkScenAgainstMap(const std::filesystem::path& scen_file, const std::vector<ScenRow>& rows, int map_width,
                         int map_height);
inline void checkScenAgainstMap(const std::filesystem::path& scen_file, const std::vector<ScenRow>& rows,
                                const planner::OccupancyGrid2D& map) {
  checkScenAgainstMap(scen_file, rows, map.width, map.height);
}

// The centre of scenario cell (x, y) (y from the top) in metres in the map frame of a grid loaded
// by loadMovingAiMap (origin (0, 0), y up): ((x + 0.5) * res, (map_height - 1 - y + 0.5) * res).
// The same point as OccupancyGrid2D::centreOf(x, map_height - 1 - y) for that grid.
Eigen::Vector2d scenCellCentre(int x, int y, int map_height, double resolution_m);

}  // namespace tgnav::harness
