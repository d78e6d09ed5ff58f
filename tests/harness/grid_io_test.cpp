// Grid map loaders: exact cells (image row 0 is the top of the map), map_server thresholds with
// unknown stored as occupied, and one-line InputErrors naming the file and the offending value.
#include "harness/io/grid_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "harness/base/errors.h"
#include "test_util.h"

namespace tgnav::harness {
namespace {

using test::inputError;

using planner::OccupancyGrid2D;

// The grid drawn top row first ('#' occupied, '.' free), so it reads like the image.
std::vector<std::string> drawn(const OccupancyGrid2D& grid) {
  std::vector<std::string> rows;
  for (int iy = grid.height - 1; iy >= 0; --iy) {
    std::string row;
    for (int ix = 0; ix < grid.width; ++ix) row += grid.isOccupied(ix, iy) ? '#' : '.';
    rows.push_back(row);
  }
  return rows;
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

// 3x2, top row black / near-white / map_server's unknown grey (occ 0.196..0.65 is unknown),
// bottom row white / mid grey (occ 0.61: unknown) / light grey (occ 0.02: free).
const std::string kP5 =
    std::string("P5\n# a comment\n3 2\n255\n") + '\x00' + '\xfe' + '\xcd' + '\xff' + '\x64' + '\xfa';
const std::string kYaml =
    "image: map.pgm\nresolution: 0.05\norigin: [-1.5, 2.0, 0.0]\noccupied_thresh: 0.65\n"
    "free_thresh: 0.196\nnegate: 0\n";

class RosMap : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::tempDir(); }
  std::filesystem::path write(const std::string& yaml, const std::string& pgm = kP5) {
    test::writeFile(dir_ / "map.pgm", pgm);
    return test::writeFile(dir_ / "map.yaml", yaml);
  }
  std::string error(const std::string& yaml, const std::string& pgm = kP5) {
    const auto file = write(yaml, pgm);
    return inputError([&] { loadRosMap(file); });
  }
  std::string pgmError(const std::string& pgm) { return error(kYaml, pgm); }
  std::string pgmName() const { return (dir_ / "map.pgm").string(); }
  std::string yamlName() const { return (dir_ / "map.yaml").string(); }
  std::filesystem::path dir_;
};

TEST_F(RosMap, BinaryPgmGivesExactCellsWithTopRowAtLargestY) {
  const OccupancyGrid2D grid = loadRosMap(write(kYaml));
  ASSERT_EQ(grid.width, 3);
  ASSERT_EQ(grid.height, 2);
  EXPECT_EQ(drawn(grid), (std::vector<std::string>{"#.#", ".#."}));
  EXPECT_TRUE(grid.isOccupied(0, 1));  // the black pixel at image row 0
  EXPECT_FALSE(grid.isOccupied(0, 0));
  EXPECT_DOUBLE_EQ(grid.resolution_m, 0.05);
  EXPECT_DOUBLE_EQ(grid.origin_m.x(), -1.5);
  EXPECT_DOUBLE_EQ(grid.origin_m.y(), 2.0);
}

TEST_F(RosMap, WrittenMapReadsBackExactly) {
  OccupancyGrid2D grid(5, 3, 0.1, Eigen::Vector2d(-1.25, 0.3));
  grid.set(0, 0, true);
  grid.set(4, 2, true);
  grid.set(2, 1, true);
  const auto dir = test::tempDir();
  writeRosMap(grid, dir / "slice.yaml", dir / "slice.pgm");
  const OccupancyGrid2D back = loadRosMap(dir / "slice.yaml");
  EXPECT_EQ(drawn(back), (std::vector<std::string>{"....#", "..#..", "#...."}));
  EXPECT_EQ(back.resolution_m, 0.1);
  EXPECT_EQ(back.origin_m, Eigen::Vector2d(-1.25, 0.3));
}

TEST_F(RosMap, AsciiPgmScalesThresholdsWithMaxval) {
  // maxval 15: 15 free, 0 occupied, 8 (occ 0.47) unknown, 14 (occ 0.07) free.
  const auto file = write(kYaml + "mode: trinary\n", "P2\n# comment\n2 # inline comment\n2\n15\n15 0\n8 14\n");
  EXPECT_EQ(drawn(loadRosMap(file)), (std::vector<std::string>{".#", "#."}));
}

TEST_F(RosMap, NegateTreatsDarkAsFree) {
  const auto file = write(replaced(kYaml, "negate: 0", "negate: 1"));
  EXPECT_EQ(drawn(loadRosMap(file)), (std::vector<std::string>{".##", "###"}));
}

TEST_F(RosMap, AllOccupiedMapIsNotAnError) {
  const std::string black = std::string("P5 2 1 255 ") + '\x00' + '\x00';
  EXPECT_EQ(loadRosMap(write(kYaml, black)).freeCells(), 0);
}

TEST_F(RosMap, MissingYamlNamesFile) {
  const std::string msg = inputError([&] { loadRosMap(dir_ / "absent.yaml"); });
  EXPECT_NE(msg.find("absent.yaml"), std::string::npos) << msg;
}

TEST_F(RosMap, MissingImageNamesKeyAndValue) {
  const std::string msg = error(replaced(kYaml, "map.pgm", "nowhere.pgm"));
  EXPECT_NE(msg.find(yamlName() + ":1:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'image' has value 'nowhere.pgm'"), std::string::npos) << msg;
}

TEST_F(RosMap, UnknownKeyIsNamed) {
  const std::string msg = error(kYaml + "resolutoin: 0.1\n");
  EXPECT_NE(msg.find(yamlName() + ":7:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("unknown key 'resolutoin'"), std::string::npos) << msg;
}

TEST_F(RosMap, MissingKeyIsNamed) {
  const std::string msg = error(replaced(kYaml, "negate: 0\n", ""));
  EXPECT_NE(msg.find("missing required key 'negate'"), std::string::npos) << msg;
}

TEST_F(RosMap, NonNumericResolutionIsRejected) {
  const std::string msg = error(replaced(kYaml, "0.05", "fine"));
  EXPECT_NE(msg.find(yamlName() + ":2:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'resolution' has value 'fine'"), std::string::npos) << msg;
}

TEST_F(RosMap, NegativeResolutionIsRejected) {
  const std::string msg = error(replaced(kYaml, "0.05", "-0.05"));
  EXPECT_NE(msg.find(yamlName() + ":2:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'resolution' has value '-0.05'"), std::string::npos) << msg;
}

TEST_F(RosMap, ThresholdOutsideUnitIntervalIsRejected) {
  const std::string msg = error(replaced(kYaml, "0.65", "1.5"));
  EXPECT_NE(msg.find(yamlName()), std::string::npos) << msg;
  EXPECT_NE(msg.find("'occupied_thresh' has value '1.5'"), std::string::npos) << msg;
  const std::string neg = error(replaced(kYaml, "0.196", "-0.1"));
  EXPECT_NE(neg.find("'free_thresh' has value '-0.1'"), std::string::npos) << neg;
}

TEST_F(RosMap, FreeThresholdNotBelowOccupiedIsRejected) {
  const std::string msg = error(replaced(kYaml, "0.196", "0.65"));
  EXPECT_NE(msg.find(yamlName() + ":5:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'free_thresh' has value '0.65'"), std::string::npos) << msg;
}

TEST_F(RosMap, RotatedOriginIsRejected) {
  const std::string msg = error(replaced(kYaml, "2.0, 0.0]", "2.0, 0.5]"));
  EXPECT_NE(msg.find(yamlName() + ":3:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'origin' has yaw '0.5'"), std::string::npos) << msg;
}

TEST_F(RosMap, ShortOriginIsRejected) {
  const std::string msg = error(replaced(kYaml, "[-1.5, 2.0, 0.0]", "[-1.5, 2.0]"));
  EXPECT_NE(msg.find("'origin' has value"), std::string::npos) << msg;
  EXPECT_NE(msg.find("3 finite numbers"), std::string::npos) << msg;
}

TEST_F(RosMap, NegateOtherThanZeroOrOneIsRejected) {
  const std::string msg = error(replaced(kYaml, "negate: 0", "negate: 2"));
  EXPECT_NE(msg.find("'negate' has value '2'"), std::string::npos) << msg;
}

TEST_F(RosMap, ModeOtherThanTrinaryIsRejected) {
  const std::string msg = error(kYaml + "mode: scale\n");
  EXPECT_NE(msg.find(yamlName() + ":7:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'mode' has value 'scale'"), std::string::npos) << msg;
}

TEST_F(RosMap, BadMagicIsRejected) {
  const std::string msg = pgmError("P6\n3 2\n255\n" + std::string(18, '\0'));
  EXPECT_NE(msg.find(pgmName()), std::string::npos) << msg;
  EXPECT_NE(msg.find("bad PGM magic 'P6'"), std::string::npos) << msg;
  const std::string png = pgmError("\x89PNG\r\n\x1a\n");
  EXPECT_NE(png.find("bad PGM magic"), std::string::npos) << png;
}

TEST_F(RosMap, TruncatedBinaryDataIsRejected) {
  const std::string msg = pgmError("P5\n3 2\n255\n" + std::string(4, '\xff'));
  EXPECT_NE(msg.find(pgmName()), std::string::npos) << msg;
  EXPECT_NE(msg.find("truncated pixel data: 4 of 6 bytes"), std::string::npos) << msg;
}

TEST_F(RosMap, TruncatedAsciiDataIsRejected) {
  const std::string msg = pgmError("P2\n3 2\n255\n0 0 0\n0\n");
  EXPECT_NE(msg.find(pgmName()), std::string::npos) << msg;
  EXPECT_NE(msg.find("truncated pixel data: 4 of 6 values"), std::string::npos) << msg;
}

TEST_F(RosMap, TruncatedHeaderIsRejected) {
  const std::string msg = pgmError("P5\n3");
  EXPECT_NE(msg.find("'height' has value ''"), std::string::npos) << msg;
}

TEST_F(RosMap, NonPositiveSideIsRejected) {
  const std::string msg = pgmError("P5\n0 2\n255\n");
  EXPECT_NE(msg.find(pgmName()), std::string::npos) << msg;
  EXPECT_NE(msg.find("'width' has value '0'"), std::string::npos) << msg;
  const std::string neg = pgmError("P2\n3 -2\n255\n");
  EXPECT_NE(neg.find("'height' has value '-2'"), std::string::npos) << neg;
  const std::string word = pgmError("P2\nwide 2\n255\n");
  EXPECT_NE(word.find("'width' has value 'wide'"), std::string::npos) << word;
}

TEST_F(RosMap, AbsurdSideIsRejectedBeforeAllocating) {
  const std::string msg = pgmError("P5\n20001 20001\n255\n");
  EXPECT_NE(msg.find(pgmName()), std::string::npos) << msg;
  EXPECT_NE(msg.find("'width' has value '20001'"), std::string::npos) << msg;
  // Allowed sides, but far more pixels than the file holds.
  const std::string big = pgmError("P2\n20000 20000\n255\n0 0\n");
  EXPECT_NE(big.find("truncated pixel data: 2 of 400000000 values"), std::string::npos) << big;
}

TEST_F(RosMap, MaxvalAbove255IsRejected) {
  const std::string msg = pgmError("P5\n1 1\n65535\n\xff\xff");
  EXPECT_NE(msg.find(pgmName()), std::string::npos) << msg;
  EXPECT_NE(msg.find("'maxval' has value '65535'"), std::string::npos) << msg;
}

TEST_F(RosMap, PixelAboveMaxvalIsRejected) {
  const std::string msg = pgmError("P2\n2 1\n15\n3 16\n");
  EXPECT_NE(msg.find(pgmName()), std::string::npos) << msg;
  EXPECT_NE(msg.find("pixel 1 (row 0, column 1) has value '16' > maxval 15"), std::string::npos) << msg;
  const std::string word = pgmError("P2\n2 1\n15\n3 x\n");
  EXPECT_NE(word.find("pixel 1 has value 'x'"), std::string::npos) << word;
}

// 4x3 with a wall ('@'), trees ('T'), a swamp ('S'), a ground alias ('G') and water ('W').
const std::string kMovingAi = "type octile\nheight 3\nwidth 4\nmap\n@...\n.TSW\nG..@\n";

class MovingAiMap : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::tempDir(); }
  std::string error(const std::string& text, double resolution_m = 0.5) {
    const auto file = test::writeFile(dir_ / "m.map", text);
    return inputError([&] { loadMovingAiMap(file, resolution_m); });
  }
  std::string name() const { return (dir_ / "m.map").string(); }
  std::filesystem::path dir_;
};

TEST_F(MovingAiMap, SampleGivesExactCellsWithTopRowAtLargestY) {
  const OccupancyGrid2D grid = loadMovingAiMap(test::writeFile(dir_ / "m.map", kMovingAi), 0.5);
  ASSERT_EQ(grid.width, 4);
  ASSERT_EQ(grid.height, 3);
  EXPECT_EQ(drawn(grid), (std::vector<std::string>{"#...", ".#.#", "...#"}));
  EXPECT_TRUE(grid.isOccupied(0, 2));   // '@' at the start of the first row
  EXPECT_FALSE(grid.isOccupied(0, 0));  // 'G' at the start of the last row
  EXPECT_DOUBLE_EQ(grid.resolution_m, 0.5);
  EXPECT_EQ(grid.origin_m, Eigen::Vector2d::Zero());
}

TEST_F(MovingAiMap, CrlfLineEndsAndTrailingBlankLinesAreAccepted) {
  const auto file = test::writeFile(dir_ / "m.map", "type octile\r\nheight 1\r\nwidth 2\r\nmap\r\n.@\r\n\r\n");
  EXPECT_EQ(drawn(loadMovingAiMap(file, 1.0)), (std::vector<std::string>{".#"}));
}

TEST_F(MovingAiMap, AllObstacleMapIsNotAnError) {
  const auto file = test::writeFile(dir_ / "m.map", "type octile\nheight 1\nwidth 2\nmap\n@T\n");
  EXPECT_EQ(loadMovingAiMap(file, 1.0).freeCells(), 0);
}

TEST_F(MovingAiMap, MissingFileIsNamed) {
  const std::string msg = inputError([&] { loadMovingAiMap(dir_ / "absent.map", 1.0); });
  EXPECT_NE(msg.find("absent.map"), std::string::npos) << msg;
}

TEST_F(MovingAiMap, NonPositiveResolutionIsRejected) {
  const std::string msg = error(kMovingAi, 0.0);
  EXPECT_NE(msg.find(name()), std::string::npos) << msg;
  EXPECT_NE(msg.find("resolution has value '0'"), std::string::npos) << msg;
  EXPECT_NE(error(kMovingAi, -0.5).find("value '-0.5'"), std::string::npos);
  EXPECT_NE(error(kMovingAi, std::nan("")).find("resolution has value"), std::string::npos);
}

TEST_F(MovingAiMap, WrongTypeIsRejected) {
  const std::string msg = error(replaced(kMovingAi, "octile", "grid"));
  EXPECT_NE(msg.find(name() + ":1:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'type' has value 'grid'"), std::string::npos) << msg;
}

TEST_F(MovingAiMap, MissingHeaderLineIsRejected) {
  const std::string msg = error(replaced(kMovingAi, "height 3\n", ""));
  EXPECT_NE(msg.find(name() + ":2:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("expected 'height <value>', got 'width 4'"), std::string::npos) << msg;
  const std::string no_map = error(replaced(kMovingAi, "map\n", ""));
  EXPECT_NE(no_map.find(name() + ":4:"), std::string::npos) << no_map;
  EXPECT_NE(no_map.find("expected 'map', got '@...'"), std::string::npos) << no_map;
  EXPECT_NE(error("").find(name() + ":1: expected 'type <value>', got ''"), std::string::npos);
}

TEST_F(MovingAiMap, BadSideIsRejected) {
  const std::string msg = error(replaced(kMovingAi, "height 3", "height three"));
  EXPECT_NE(msg.find(name() + ":2:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'height' has value 'three'"), std::string::npos) << msg;
  const std::string zero = error(replaced(kMovingAi, "width 4", "width 0"));
  EXPECT_NE(zero.find("'width' has value '0'"), std::string::npos) << zero;
  const std::string big = error(replaced(kMovingAi, "width 4", "width 30000"));
  EXPECT_NE(big.find("'width' has value '30000'"), std::string::npos) << big;
}

TEST_F(MovingAiMap, EveryTerrainLetterHasMovingAisPassability) {
  const auto file = test::writeFile(dir_ / "m.map", "type octile\nheight 1\nwidth 7\nmap\n.GS@OTW\n");
  EXPECT_EQ(drawn(loadMovingAiMap(file, 1.0)), (std::vector<std::string>{"...####"}));
}

TEST_F(MovingAiMap, UnknownTerrainLetterIsAnErrorNotAnObstacle) {
  const std::string msg = error(replaced(kMovingAi, ".TSW", ".T?W"));
  EXPECT_NE(msg.find(name() + ":6: column 2: terrain '?' is not one of"), std::string::npos) << msg;
  const std::string tab = error(replaced(kMovingAi, "G..@", "G.\t@"));
  EXPECT_NE(tab.find(name() + ":7: column 2: terrain '?'"), std::string::npos) << tab;
}

TEST_F(MovingAiMap, RowOfWrongLengthIsRejected) {
  const std::string msg = error(replaced(kMovingAi, ".TSW", ".TS"));
  EXPECT_NE(msg.find(name() + ":6:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("row 1 '.TS' has 3 characters, expected 4"), std::string::npos) << msg;
}

TEST_F(MovingAiMap, TooFewRowsIsRejected) {
  const std::string msg = error(replaced(kMovingAi, "G..@\n", ""));
  EXPECT_NE(msg.find(name() + ":7:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("too few rows: found 2 of 3"), std::string::npos) << msg;
  // Allowed sides, but far more rows than the file holds.
  const std::string big = error("type octile\nheight 20000\nwidth 20000\nmap\n");
  EXPECT_NE(big.find("too few rows: found 0 of 20000"), std::string::npos) << big;
}

TEST_F(MovingAiMap, ExtraRowIsRejected) {
  const std::string msg = error(kMovingAi + "....\n");
  EXPECT_NE(msg.find(name() + ":8:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("unexpected '....' after the 3 map rows"), std::string::npos) << msg;
}

TEST(GridMapFile, ChoosesLoaderByExtension) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "map.pgm", kP5);
  EXPECT_EQ(loadGridMap(test::writeFile(dir / "a.yaml", kYaml), 1.0).width, 3);
  EXPECT_EQ(loadGridMap(test::writeFile(dir / "a.yml", kYaml), 1.0).width, 3);
  const OccupancyGrid2D moving = loadGridMap(test::writeFile(dir / "a.map", kMovingAi), 0.25);
  EXPECT_EQ(moving.width, 4);
  EXPECT_DOUBLE_EQ(moving.resolution_m, 0.25);
}

TEST(GridMapFile, UnknownExtensionIsRejected) {
  const auto file = test::writeFile(test::tempDir() / "map.png", "x");
  const std::string msg = inputError([&] { loadGridMap(file, 1.0); });
  EXPECT_NE(msg.find(file.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("unknown grid map type '.png'"), std::string::npos) << msg;
}

}  // namespace
}  // namespace tgnav::harness
