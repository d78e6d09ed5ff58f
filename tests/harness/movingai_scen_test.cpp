// MovingAI .scen parsing: exact values (CRLF, tabs, blank lines), and one-line InputErrors naming
// the file, the line and the offending value for every malformed line and every row that does
// not fit its map.
#include "harness/io/movingai_scen.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "harness/base/errors.h"
#include "planner/occupancy_grid.h"
#include "test_util.h"

namespace tgnav::harness {
namespace {

using test::inputError;
using test::tempDir;

class Scen : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = tempDir(); }
  std::filesystem::path write(const std::string& text) {
    const auto file = dir_ / "arena.map.scen";
    std::ofstream(file, std::ios::binary) << text;
    return file;
  }
  std::string error(const std::string& text) {
    const auto file = write(text);
    return inputError([&] { loadMovingAiScen(file); });
  }
  std::string name() const { return (dir_ / "arena.map.scen").string(); }
  // Expects `message` to be one line naming this test's file, `line` and `value`.
  void expectNames(const std::string& message, int line, const std::string& value) const {
    EXPECT_EQ(message.find('\n'), std::string::npos) << "message spans several lines: " << message;
    EXPECT_EQ(message.rfind(name() + ":" + std::to_string(line) + ": ", 0), 0u)
        << "message does not start with FILE:" << line << ": -- " << message;
    EXPECT_NE(message.find(value), std::string::npos) << "message does not name " << value << ": " << message;
  }
  std::filesystem::path dir_;
};

const std::string kRow1 = "0\tarena.map\t49\t49\t1\t11\t1\t12\t1";
const std::string kRow2 = "3 maps/dao/arena.map 49 49  1 13\t4 12 3.41421356";
const std::string kRow3 = "\t12\tarena.map\t49\t49\t48\t0\t0\t48\t67.88225099 ";

TEST_F(Scen, ValidFileWithCrlfTabsAndBlankLinesParsesToExactValues) {
  const auto file = write("version 1\r\n" + kRow1 + "\r\n\r\n" + kRow2 + "\r\n" + kRow3 + "\r\n \t\r\n\r\n");
  const std::vector<ScenRow> rows = loadMovingAiScen(file);
  ASSERT_EQ(rows.size(), 3u) << "three scenario lines, blank lines skipped";

  EXPECT_EQ(rows[0].line, 2);
  EXPECT_EQ(rows[0].bucket, 0);
  EXPECT_EQ(rows[0].map, "arena.map");
  EXPECT_EQ(rows[0].map_width, 49);
  EXPECT_EQ(rows[0].map_height, 49);
  EXPECT_EQ(rows[0].start_x, 1);
  EXPECT_EQ(rows[0].start_y, 11);
  EXPECT_EQ(rows[0].goal_x, 1);
  EXPECT_EQ(rows[0].goal_y, 12);
  EXPECT_EQ(rows[0].optimal_length, 1.0);

  EXPECT_EQ(rows[1].line, 4) << "line numbers count the blank line";
  EXPECT_EQ(rows[1].bucket, 3);
  EXPECT_EQ(rows[1].map, "maps/dao/arena.map");
  EXPECT_EQ(rows[1].start_x, 1);
  EXPECT_EQ(rows[1].start_y, 13);
  EXPECT_EQ(rows[1].goal_x, 4);
  EXPECT_EQ(rows[1].goal_y, 12);
  EXPECT_EQ(rows[1].optimal_length, 3.41421356);

  EXPECT_EQ(rows[2].line, 5);
  EXPECT_EQ(rows[2].bucket, 12);
  EXPECT_EQ(rows[2].map, "arena.map") << "no trailing CR or tab in the last field's neighbours";
  EXPECT_EQ(rows[2].start_x, 48);
  EXPECT_EQ(rows[2].start_y, 0);
  EXPECT_EQ(rows[2].goal_x, 0);
  EXPECT_EQ(rows[2].goal_y, 48);
  EXPECT_EQ(rows[2].optimal_length, 67.88225099);
}

TEST_F(Scen, AcceptsVersionOnePointZeroAndNoFinalNewline) {
  const std::vector<ScenRow> rows = loadMovingAiScen(write("version 1.0\n" + kRow1));
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].goal_y, 12);
  EXPECT_EQ(rows[0].optimal_length, 1.0);
}

TEST_F(Scen, AcceptsPlainDecimalLengthForms) {
  const std::vector<ScenRow> rows =
      loadMovingAiScen(write("version 1\n0 m 4 4 0 0 0 0 0\n0 m 4 4 0 0 1 1 .5\n0 m 4 4 0 0 3 3 4.2e0\n"));
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].optimal_length, 0.0);
  EXPECT_EQ(rows[1].optimal_length, 0.5);
  EXPECT_EQ(rows[2].optimal_length, 4.2);
}

TEST_F(Scen, MissingFileIsAnInputError) {
  const std::string message = inputError([&] { loadMovingAiScen(dir_ / "absent.scen"); });
  EXPECT_NE(message.find("absent.scen: cannot open file"), std::string::npos) << message;
}

TEST_F(Scen, EmptyFileNamesLineOne) { expectNames(error(""), 1, "'version 1'"); }

TEST_F(Scen, MissingVersionLineNamesLineOneAndWhatWasThere) {
  expectNames(error(kRow1 + "\n"), 1, "'0?arena.map?49?49?1?11?1?12?1'");
}

TEST_F(Scen, UnknownVersionNamesIt) { expectNames(error("version 2\n" + kRow1 + "\n"), 1, "'version 2'"); }

TEST_F(Scen, BlankFirstLineIsNotAVersion) { expectNames(error("\nversion 1\n" + kRow1 + "\n"), 1, "got ''"); }

TEST_F(Scen, VersionWithoutScenariosIsAnError) {
  const std::string message = error("version 1\n\n");
  EXPECT_EQ(message, name() + ": no scenarios after the version line");
}

TEST_F(Scen, EightFieldsNamesTheLineAndTheCount) {
  const std::string message = error("version 1\n" + kRow1 + "\n0 arena.map 49 49 1 11 1 12\n");
  expectNames(message, 3, "got 8 in '0 arena.map 49 49 1 11 1 12'");
}

TEST_F(Scen, TenFieldsIsAnError) { expectNames(error("version 1\n0 arena.map 49 49 1 11 1 12 1 x\n"), 2, "got 10"); }

TEST_F(Scen, CommentLineIsAnError) { expectNames(error("version 1\n" + kRow1 + "\n# note\n"), 3, "got 2"); }

TEST_F(Scen, LetterInStartXNamesFieldAndValue) {
  const std::string message = error("version 1\n\n" + kRow1 + "\n0 arena.map 49 49 1a 11 1 12 1\n");
  expectNames(message, 4, "field 5 (start_x) has value '1a'");
}

TEST_F(Scen, NegativeGoalNamesFieldAndValue) {
  expectNames(error("version 1\n0 arena.map 49 49 1 11 1 -4 1\n"), 2, "field 8 (goal_y) has value '-4'");
}

TEST_F(Scen, SignedOrFractionalIntegersAreRefused) {
  expectNames(error("version 1\n+1 arena.map 49 49 1 11 1 4 1\n"), 2, "(bucket) has value '+1'");
  expectNames(error("version 1\n0 arena.map 49 49 1.0 11 1 4 1\n"), 2, "(start_x) has value '1.0'");
  expectNames(error("version 1\n0 arena.map 49 49 1 11 99999999999 4 1\n"), 2, "(goal_x) has value '99999999999'");
}

TEST_F(Scen, MapSideOutOfBoundsNamesIt) {
  expectNames(error("version 1\n0 arena.map 0 49 0 0 0 0 0\n"), 2, "(map_width) has value '0'");
  expectNames(error("version 1\n0 arena.map 49 20001 0 0 0 0 0\n"), 2, "(map_height) has value '20001'");
}

TEST_F(Scen, CoordinateOutsideTheLinesOwnMapSizeNamesIt) {
  const std::string message = error("version 1\n0 arena.map 49 30 49 0 0 0 0\n");
  expectNames(message, 2, "(start_x) has value '49', expected an integer in 0..48 (inside map_width 49)");
  expectNames(error("version 1\n0 arena.map 49 30 0 0 0 30 0\n"), 2, "(goal_y) has value '30'");
}

TEST_F(Scen, BadOptimalLengthsNameTheValue) {
  for (const std::string length : {"nan", "NaN", "inf", "-inf", "-1.5", "1e999", "0x1p3", "1.2.3", "1e", ".", "+2"}) {
    SCOPED_TRACE("optimal_length " + length);
    expectNames(error("version 1\n" + kRow1 + "\n0 arena.map 49 49 1 11 1 12 " + length + "\n"), 3,
                "field 9 (optimal_length) has value '" + length + "', expected a finite decimal number >= 0");
  }
}

TEST_F(Scen, ControlBytesAreMaskedInMessages) {
  const std::string message = error(std::string("version 1\n0 are\x01na.map 49 49 1 11 1 12 1\n"));
  expectNames(message, 2, "(map) has value 'are?na.map'");
  expectNames(error(std::string("version 1\n0 arena.map 49 49 1 1\x1b[2J 1 12 1\n")), 2, "has value '1?[2J'");
}

TEST_F(Scen, StrayCarriageReturnIsNotALineEnd) {
  expectNames(error("version 1\r\n" + kRow1 + "\r\r\n"), 2, "(optimal_length) has value '1?'");
}

class ScenAgainstMap : public Scen {
 protected:
  std::vector<ScenRow> rows(const std::string& text) { return loadMovingAiScen(write(text)); }
};

TEST_F(ScenAgainstMap, MatchingMapPasses) {
  const auto parsed = rows("version 1\n" + kRow1 + "\n" + kRow3 + "\n");
  EXPECT_NO_THROW(checkScenAgainstMap(name(), parsed, 49, 49));
  const planner::OccupancyGrid2D grid(49, 49, 0.1, Eigen::Vector2d::Zero());
  EXPECT_NO_THROW(checkScenAgainstMap(name(), parsed, grid));
}

TEST_F(ScenAgainstMap, WidthMismatchNamesTheRowsLineAndValue) {
  const auto parsed = rows("version 1\n" + kRow1 + "\n\n0 arena.map 48 49 1 11 1 12 1\n");
  const std::string message = inputError([&] { checkScenAgainstMap(name(), parsed, 49, 49); });
  expectNames(message, 4, "map_width has value '48', expected the map's width 49");
}

TEST_F(ScenAgainstMap, HeightMismatchNamesTheValue) {
  const auto parsed = rows("version 1\n" + kRow1 + "\n");
  const planner::OccupancyGrid2D grid(49, 50, 0.1, Eigen::Vector2d::Zero());
  const std::string message = inputError([&] { checkScenAgainstMap(name(), parsed, grid); });
  expectNames(message, 2, "map_height has value '49', expected the map's height 50");
}

TEST_F(ScenAgainstMap, CoordinateOutsideTheMapNamesIt) {
  // A row built in code (the parser already refuses coordinates outside the line's own size).
  ScenRow row;
  row.line = 7;
  row.map = "arena.map";
  row.map_width = 10;
  row.map_height = 8;
  row.goal_x = 9;
  row.goal_y = 8;
  const std::string message = inputError([&] { checkScenAgainstMap(name(), {row}, 10, 8); });
  expectNames(message, 7, "goal_y has value '8', outside the map (expected 0..7 for map height 8)");
  row.goal_y = 0;
  row.start_x = -1;
  expectNames(inputError([&] { checkScenAgainstMap(name(), {row}, 10, 8); }), 7, "start_x has value '-1'");
}

TEST(ScenCellCentre, RowZeroIsTheTopOfTheMap) {
  const double res = 0.25;
  const Eigen::Vector2d top_left = scenCellCentre(0, 0, 8, res);
  EXPECT_DOUBLE_EQ(top_left.x(), 0.125);
  EXPECT_DOUBLE_EQ(top_left.y(), 7.5 * res);
  const Eigen::Vector2d bottom_right = scenCellCentre(9, 7, 8, res);
  EXPECT_DOUBLE_EQ(bottom_right.x(), 9.5 * res);
  EXPECT_DOUBLE_EQ(bottom_right.y(), 0.125);
  // The same point as the grid's cell for that scenario cell (as loadMovingAiMap flips rows).
  const planner::OccupancyGrid2D grid(10, 8, res, Eigen::Vector2d::Zero());
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 10; ++x) {
      const Eigen::Vector2d c = scenCellCentre(x, y, 8, res);
      EXPECT_TRUE(c.isApprox(grid.centreOf(x, 8 - 1 - y))) << "cell " << x << "," << y;
      EXPECT_EQ(grid.cellOf(c), Eigen::Vector2i(x, 8 - 1 - y)) << "cell " << x << "," << y;
    }
  }
}

}  // namespace
}  // namespace tgnav::harness
