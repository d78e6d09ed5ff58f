// `tgnav plan --grid X.map --scen X.scen`: every row planned on a map built once; against the
// 8-connected optima written into the file (robot radius 0, as MovingAI's), the shortest class
// is within 1 %; a start or goal on an obstacle cell is an error naming the .scen line.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "../planner/grid_maps.h"
#include "harness/base/errors.h"
#include "harness/run/plan_job.h"
#include "test_util.h"

namespace tgnav::harness {
namespace {

using planner::testmaps::gridFromMovingAi;

// A .scen for `map_text`: `n` reachable queries with their octile optima (cells), y from the top.
std::string scenFor(const std::string& map_text, int n, std::uint32_t seed) {
  const planner::OccupancyGrid2D g = gridFromMovingAi(map_text, 1.0);
  const std::vector<std::uint8_t> free = planner::testmaps::inflatedFreeMask(g, 0.0);
  std::ostringstream out;
  out << "version 1\n";
  out.precision(10);
  for (const auto& [s, e] : planner::testmaps::randomQueries(g, n, 0.0, seed, /*connected_only=*/true)) {
    const auto path = planner::testmaps::inflated8Path(g, free, s, e);
    out << "0\tm.map\t" << g.width << "\t" << g.height << "\t" << s.x() << "\t" << g.height - 1 - s.y() << "\t" << e.x()
        << "\t" << g.height - 1 - e.y() << "\t" << path.length_m << "\n";
  }
  return out.str();
}

std::vector<std::vector<std::string>> csvRows(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);  // header
  std::vector<std::vector<std::string>> rows;
  while (std::getline(in, line)) {
    std::vector<std::string> fields;
    std::stringstream ss(line);
    std::string f;
    while (std::getline(ss, f, ',')) fields.push_back(f);
    rows.push_back(fields);
  }
  return rows;
}

TEST(GridScen, ShortestClassIsWithinOnePercentOfTheFilesOptimum) {
  const auto dir = test::tempDir();
  for (const auto& [name, text] :
       {std::pair<std::string, std::string>{"maze", planner::testmaps::mazeMap(10, 10, 4, 5)},
        {"rooms", planner::testmaps::roomsMap(40, 30, 6, 4)}}) {
    const auto map = test::writeFile(dir / (name + ".map"), text);
    const auto scen = test::writeFile(dir / (name + ".map.scen"), scenFor(text, 10, 11));
    GridScenJob job;
    job.grid = map;
    job.scen = scen;
    job.robot_radius_m = 0.0;
    job.out = dir / name;
    const PlanJobResult r = runGridScen(job);
    EXPECT_NE(r.summary.find("10 of 10 scenarios found a path"), std::string::npos) << r.summary;
    const auto rows = csvRows(dir / name / "scen.csv");
    ASSERT_EQ(rows.size(), 10u);
    for (const auto& row : rows) {
      ASSERT_EQ(row.size(), 12u);
      EXPECT_EQ(row[6], "solved") << name << " line " << row[0];
      EXPECT_LE(std::stod(row[10]), 1.01) << name << " line " << row[0] << ": " << row[8] << " m vs " << row[9];
    }
    EXPECT_TRUE(std::filesystem::exists(dir / name / "scen.json"));
  }
}

TEST(GridScen, StartOnAnObstacleIsAnErrorNamingTheLineAndNothingIsWritten) {
  const auto dir = test::tempDir();
  const auto map = test::writeFile(dir / "m.map", "type octile\nheight 3\nwidth 4\nmap\n....\n.@..\n....\n");
  const auto scen = test::writeFile(dir / "m.map.scen",
                                    "version 1\n0\tm.map\t4\t3\t0\t0\t3\t2\t3.8\n"
                                    "0\tm.map\t4\t3\t1\t1\t3\t2\t2.4\n");
  GridScenJob job;
  job.grid = map;
  job.scen = scen;
  job.out = dir / "out";
  const std::string msg = test::inputError([&] { runGridScen(job); });
  EXPECT_NE(msg.find(scen.string() + ":3: start (1, 1) is an obstacle cell"), std::string::npos) << msg;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
  job.bucket = 7;
  const std::string bucket = test::inputError([&] { runGridScen(job); });
  EXPECT_NE(bucket.find("--bucket: 7 has no rows"), std::string::npos) << bucket;
}

}  // namespace
}  // namespace tgnav::harness
