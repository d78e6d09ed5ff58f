// `tgnav eval` end to end on tiny TUM, KITTI and EuRoC files written here: exit 0 with one summary
// line and eval.json, eval_pairs.csv and eval.png holding the hand-computed numbers; without --out
// nothing is written; every kind of bad input is one line, exit 2, and no output folder.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "test_util.h"

namespace tgnav {
namespace {

namespace fs = std::filesystem;
using test::CmdResult;

CmdResult tgnav(const std::string& args) { return test::runShell(std::string(TGNAV_BIN) + " " + args); }

int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

nlohmann::json readJson(const fs::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

std::string number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  return buf;
}

// The reference path: a 2 m-radius arc at 1 m height, heading along it, over 4 s.
Eigen::Vector3d pathAt(double t) { return {2.0 * std::cos(0.5 * t), 2.0 * std::sin(0.5 * t), 1.0 + 0.1 * t}; }
double yawAt(double t) { return 0.5 * t + M_PI / 2; }

// TUM rows every dt_s over 0..4 s (from t0), shifted by `offset`.
std::string tumFile(double dt_s, const Eigen::Vector3d& offset, double t0 = 0.0) {
  std::string text = "# timestamp tx ty tz qx qy qz qw\n";
  for (int k = 0; k * dt_s <= 4.0 + 1e-9; ++k) {
    const double t = k * dt_s;
    const Eigen::Vector3d p = pathAt(t) + offset;
    text += number(t0 + t) + " " + number(p.x()) + " " + number(p.y()) + " " + number(p.z()) + " 0 0 " +
            number(std::sin(yawAt(t) / 2)) + " " + number(std::cos(yawAt(t) / 2)) + "\n";
  }
  return text;
}

// KITTI rows, one per 0.2 s of the path, the positions scaled by `scale` about the origin.
std::string kittiFile(int poses, double scale) {
  std::string text;
  for (int k = 0; k < poses; ++k) {
    const double t = 0.2 * k, c = std::cos(yawAt(t)), s = std::sin(yawAt(t));
    const Eigen::Vector3d p = scale * pathAt(t);
    text += number(c) + " " + number(-s) + " 0 " + number(p.x()) + " " + number(s) + " " + number(c) + " 0 " +
            number(p.y()) + " 0 0 1 " + number(p.z()) + "\n";
  }
  return text;
}

// EuRoC rows every dt_s from a Unix time, in nanoseconds, with the velocity columns EuRoC has.
std::string eurocFile(double dt_s, const Eigen::Vector3d& offset) {
  const long long t0_ns = 1403636579758555392LL;
  std::string text = "#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],q_RS_z []\n";
  for (int k = 0; k * dt_s <= 4.0 + 1e-9; ++k) {
    const double t = k * dt_s;
    const Eigen::Vector3d p = pathAt(t) + offset;
    text += std::to_string(t0_ns + std::llround(t * 1e9)) + "," + number(p.x()) + "," + number(p.y()) + "," +
            number(p.z()) + "," + number(std::cos(yawAt(t) / 2)) + ",0,0," + number(std::sin(yawAt(t) / 2)) +
            ",0.1,0.2,0.3\n";
  }
  return text;
}

TEST(CliEval, TumPairAtDifferentRatesWritesResults) {
  const fs::path dir = test::tempDir();
  const Eigen::Vector3d offset(0.3, -0.4, 0.0);  // 0.5 m
  const fs::path ref = test::writeFile(dir / "gt.tum", tumFile(0.01, Eigen::Vector3d::Zero()));
  const fs::path est = test::writeFile(dir / "est.tum", tumFile(0.05, offset));
  const CmdResult run =
      tgnav("eval --ref " + ref.string() + " --est " + est.string() + " --align none --out " + (dir / "out").string());
  ASSERT_EQ(run.rc, 0) << run.output;
  EXPECT_EQ(lines(run.output), 1) << run.output;
  EXPECT_EQ(run.output.rfind("tgnav eval: 81 pairs of 81 estimates (tum, none): ATE rmse 0.5 m", 0), 0u) << run.output;
  const nlohmann::json j = readJson(dir / "out" / "eval.json");
  EXPECT_EQ(j["format"], "tum");
  EXPECT_EQ(j["align"], "none");
  EXPECT_EQ(j["ref_poses"], 401);
  EXPECT_EQ(j["est_poses"], 81);
  EXPECT_EQ(j["pairs"], 81);
  for (const char* key : {"rmse_m", "mean_m", "median_m", "min_m", "max_m"}) {
    EXPECT_NEAR(j["ate"][key].get<double>(), 0.5, 1e-9) << key;
  }
  EXPECT_NEAR(j["ate"]["std_m"].get<double>(), 0.0, 1e-9);
  EXPECT_NEAR(j["ate"]["sse_m2"].get<double>(), 81 * 0.25, 1e-7);
  EXPECT_EQ(j["alignment"]["scale"], 1.0);
  EXPECT_EQ(j["rpe"]["unit"], "m");
  EXPECT_NEAR(j["rpe"]["trans_rmse_m"].get<double>(), 0.0, 1e-9);  // a constant offset moves nothing
  // The arc: radius 2 m over 2 rad, climbing 0.4 m.
  EXPECT_NEAR(j["ref_path_length_m"].get<double>(), std::hypot(4.0, 0.4), 1e-4);
  std::ifstream csv(dir / "out" / "eval_pairs.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header, "t,ref_x,ref_y,ref_z,est_x,est_y,est_z,error_m,distance_m");
  int rows = 0;
  for (std::string row; std::getline(csv, row);) ++rows;
  EXPECT_EQ(rows, 81);
  EXPECT_TRUE(fs::is_regular_file(dir / "out" / "eval.png"));
  EXPECT_EQ(test::stagingLeftIn(dir), 0);

  // se3 and origin remove the offset.
  for (const std::string align : {"se3", "origin"}) {
    const fs::path out = dir / ("out_" + align);
    const CmdResult again =
        tgnav("eval --ref " + ref.string() + " --est " + est.string() + " --align " + align + " --out " + out.string());
    ASSERT_EQ(again.rc, 0) << again.output;
    EXPECT_LT(readJson(out / "eval.json")["ate"]["max_m"].get<double>(), 1e-9) << align;
  }
}

TEST(CliEval, WithoutOutOnlyPrints) {
  const fs::path dir = test::tempDir();
  const fs::path ref = test::writeFile(dir / "gt.tum", tumFile(0.01, Eigen::Vector3d::Zero()));
  const fs::path est = test::writeFile(dir / "est.tum", tumFile(0.05, Eigen::Vector3d(0.1, 0, 0)));
  const CmdResult run =
      tgnav("eval --ref " + ref.string() + " --est " + est.string() + " --rpe-delta 4 --rpe-unit frames");
  ASSERT_EQ(run.rc, 0) << run.output;
  EXPECT_EQ(lines(run.output), 1) << run.output;
  EXPECT_NE(run.output.find("RPE (4 frames) rmse"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("over 77 pairs"), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("->"), std::string::npos) << run.output;
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 2);
}

TEST(CliEval, KittiFilesPairedByLineAndSim3RecoversScale) {
  const fs::path dir = test::tempDir();
  const fs::path ref = test::writeFile(dir / "00.txt", kittiFile(21, 1.0));
  const fs::path est = test::writeFile(dir / "est.txt", kittiFile(21, 0.5));
  const CmdResult run = tgnav("eval --format kitti --align sim3 --ref " + ref.string() + " --est " + est.string() +
                              " --out " + (dir / "out").string());
  ASSERT_EQ(run.rc, 0) << run.output;
  const nlohmann::json j = readJson(dir / "out" / "eval.json");
  EXPECT_EQ(j["pairs"], 21);
  EXPECT_TRUE(j["max_dt_s"].is_null());
  EXPECT_NEAR(j["alignment"]["scale"].get<double>(), 2.0, 1e-9);
  EXPECT_LT(j["ate"]["max_m"].get<double>(), 1e-9);
  EXPECT_NE(run.output.find(", scale 2;"), std::string::npos) << run.output;
  // se3 cannot scale.
  const CmdResult se3 = tgnav("eval --format kitti --ref " + ref.string() + " --est " + est.string());
  ASSERT_EQ(se3.rc, 0) << se3.output;
  EXPECT_EQ(se3.output.find("ATE rmse 0 m"), std::string::npos) << se3.output;
}

TEST(CliEval, EurocNanosecondFiles) {
  const fs::path dir = test::tempDir();
  const fs::path ref = test::writeFile(dir / "data.csv", eurocFile(0.005, Eigen::Vector3d::Zero()));
  const fs::path est = test::writeFile(dir / "est.csv", eurocFile(0.05, Eigen::Vector3d(0, 0, 0.2)));
  const CmdResult run = tgnav("eval --format euroc --align none --ref " + ref.string() + " --est " + est.string() +
                              " --out " + (dir / "out").string());
  ASSERT_EQ(run.rc, 0) << run.output;
  const nlohmann::json j = readJson(dir / "out" / "eval.json");
  EXPECT_EQ(j["pairs"], 81);
  EXPECT_NEAR(j["ate"]["rmse_m"].get<double>(), 0.2, 1e-9);
}

// TUM's own ground truth repeats timestamps (fr2/desk); estimates may be written out of order. evo
// pairs each pose of the shorter file with the nearest in time of the other, ties to the first in
// the file. Here the reference repeats 0.1 with two positions, 1.0 then 1.5; the estimate has 1.2
// there and the reference's positions elsewhere: paired with the first, the errors are
// 0, 0.2, 0, 0 m (rmse 0.1, mean 0.05); with the second they would be 0, 0.3, 0, 0.
TEST(CliEval, RepeatedAndUnorderedTimestampsArePairedByEvosRule) {
  const fs::path dir = test::tempDir();
  const fs::path ref = test::writeFile(
      dir / "gt.tum",
      "0 0 0 0 0 0 0 1\n0.1 1 0 0 0 0 0 1\n0.1 1.5 0 0 0 0 0 1\n0.2 2 0 0 0 0 0 1\n0.3 3 0 0 0 0 0 1\n");
  const fs::path est =
      test::writeFile(dir / "est.tum", "0 0 0 0 0 0 0 1\n0.2 2 0 0 0 0 0 1\n0.1 1.2 0 0 0 0 0 1\n0.3 3 0 0 0 0 0 1\n");
  const fs::path out = dir / "out";
  const CmdResult run =
      tgnav("eval --ref " + ref.string() + " --est " + est.string() + " --align none --out " + out.string());
  ASSERT_EQ(run.rc, 0) << run.output;
  EXPECT_NE(run.output.find("tgnav eval: warning: " + ref.string() + ": 1 of its timestamps repeat or go back"),
            std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("tgnav eval: warning: " + est.string() + ": 1 of its timestamps"), std::string::npos)
      << run.output;
  const nlohmann::json j = readJson(out / "eval.json");
  EXPECT_EQ(j["pairs"], 4);
  EXPECT_EQ(j["ref_non_increasing"], 1);
  EXPECT_EQ(j["est_non_increasing"], 1);
  EXPECT_NEAR(j["ate"]["rmse_m"].get<double>(), 0.1, 1e-12);
  EXPECT_NEAR(j["ate"]["mean_m"].get<double>(), 0.05, 1e-12);
  EXPECT_NEAR(j["ate"]["max_m"].get<double>(), 0.2, 1e-12);
}

TEST(CliEval, BadInputIsOneLineExit2AndWritesNothing) {
  const fs::path dir = test::tempDir();
  const std::string ref = test::writeFile(dir / "gt.tum", tumFile(0.01, Eigen::Vector3d::Zero())).string();
  const std::string est = test::writeFile(dir / "est.tum", tumFile(0.05, Eigen::Vector3d::Zero())).string();
  const std::string kitti = test::writeFile(dir / "00.txt", kittiFile(10, 1.0)).string();
  const std::string kitti9 = test::writeFile(dir / "09.txt", kittiFile(9, 1.0)).string();
  const std::string empty = test::writeFile(dir / "empty.tum", "# no poses\n").string();
  const std::string nan = test::writeFile(dir / "nan.tum", "0 0 0 0 0 0 0 1\n0.1 0 nan 0 0 0 0 1\n").string();
  const std::string late = test::writeFile(dir / "late.tum", tumFile(0.05, Eigen::Vector3d::Zero(), 100.0)).string();
  const std::string tilted = test::writeFile(dir / "tilted.txt", "1 0 0 0 0 1 0 0 0 0.1 1 0\n").string();
  const fs::path taken = dir / "taken";
  fs::create_directories(taken);
  const std::string pair = " --ref " + ref + " --est " + est;
  const struct {
    std::string args;
    std::string message;
  } cases[] = {
      {" --ref " + (dir / "missing.tum").string() + " --est " + est, (dir / "missing.tum").string() + ": cannot read"},
      {" --ref " + ref + " --est " + empty, empty + ": no poses (an empty trajectory)"},
      {" --ref " + ref + " --est " + dir.string(), dir.string() + ": cannot read: it is a directory"},
      {" --ref " + ref + " --est " + late, late + ": no pose within --max-dt 0.02 s of a pose of " + ref +
                                               " (estimate t 100 .. 104 s, reference t 0 .. 4 s)"},
      {" --ref " + ref + " --est " + kitti,
       kitti + ":1: expected 8 numbers (timestamp tx ty tz qx qy qz qw), got 12 (read as --format tum)"},
      {" --format kitti" + pair, ref + ":2: expected 12 numbers (the 3x4 pose matrix [R | t] row by row), got 8"},
      {" --format euroc" + pair, ref + ":2: expected at least 8 comma-separated numbers"},
      {" --ref " + ref + " --est " + nan, nan + ":2: field 3 is nan; a pose must be finite"},
      {" --format kitti --ref " + kitti + " --est " + tilted, tilted + ":1: rotation is not orthonormal"},
      {" --format kitti --ref " + kitti + " --est " + kitti9,
       kitti9 + ": 9 poses but " + kitti + " has 10; KITTI poses are paired by line"},
      {" --format g2o" + pair, "--format: 'g2o' is not a trajectory format; expected tum, kitti or euroc"},
      {" --align sim2" + pair, "--align: 'sim2' is not an alignment; expected se3, sim3, posyaw, origin or none"},
      {" --rpe-unit frames --rpe-delta 2.5" + pair, "--rpe-delta: 2.5 is not a whole number of frames >= 1"},
      {" --rpe-unit km" + pair, "--rpe-unit: 'km' is not a unit; expected m or frames"},
      {" --rpe-delta 0" + pair, "--rpe-delta: 0 is not a distance > 0 in metres"},
      {" --max-dt -0.1" + pair, "--max-dt: -0.1 is not a time >= 0 in seconds"},
  };
  for (const auto& c : cases) {
    const fs::path out = dir / "out";
    const CmdResult run = tgnav("eval" + c.args + " --out " + out.string());
    EXPECT_EQ(run.rc, 2) << c.args << "\n" << run.output;
    EXPECT_EQ(lines(run.output), 1) << run.output;
    EXPECT_NE(run.output.find("tgnav: error: " + c.message), std::string::npos) << run.output;
    EXPECT_FALSE(fs::exists(out)) << c.args;
    EXPECT_EQ(test::stagingLeftIn(dir), 0) << c.args;
  }
  // An existing --out is refused and left as it was.
  const CmdResult run = tgnav("eval" + pair + " --out " + taken.string());
  EXPECT_EQ(run.rc, 2) << run.output;
  EXPECT_NE(run.output.find("--out: " + taken.string() + " already exists"), std::string::npos) << run.output;
  EXPECT_TRUE(fs::is_empty(taken));
}

}  // namespace
}  // namespace tgnav
