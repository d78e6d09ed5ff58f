// The tgnav program's contract: exit 0 and complete outputs on success; exit 2 with a one-line
// error naming the file, key or value on bad input, and no output written.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iterator>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "harness/io/tum_sequence.h"
#include "test_util.h"

namespace tgnav {
namespace {

using test::CmdResult;

CmdResult tgnav(const std::string& args, const std::string& env = "") {
  return test::runShell(env + " " + TGNAV_BIN + " " + args);
}

std::string smoke() { return (test::sourceDir() / "configs/scenes/smoke.yaml").string(); }

int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

TEST(CliRender, WritesImagesAndIntrinsics) {
  const auto out = test::tempDir() / "out";
  const CmdResult run =
      tgnav("render --scene " + smoke() + " --pose 1.2,0.2,1,0 --width 320 --height 240 --out " + out.string());
  ASSERT_EQ(run.rc, 0) << run.output;
  const cv::Mat rgb = cv::imread((out / "rgb.png").string(), cv::IMREAD_UNCHANGED);
  const cv::Mat depth = cv::imread((out / "depth.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(rgb.type(), CV_8UC3);
  EXPECT_EQ(rgb.cols, 320);
  EXPECT_EQ(rgb.rows, 240);
  ASSERT_EQ(depth.type(), CV_16UC1);
  // Facing the east crates from 2.2 m: the centre depth is a plausible millimetre value.
  const int centre_mm = depth.at<uint16_t>(120, 160);
  EXPECT_GT(centre_mm, 1500);
  EXPECT_LT(centre_mm, 3000);
  EXPECT_TRUE(std::filesystem::is_regular_file(out / "intrinsics.yaml"));
  for (const auto& entry : std::filesystem::directory_iterator(out)) {
    EXPECT_NE(entry.path().extension(), ".tmp") << "temporary file left behind";
  }
}

TEST(CliRender, BadPoseIsOneLineExit2AndWritesNothing) {
  const auto out = test::tempDir() / "out";
  const CmdResult run = tgnav("render --scene " + smoke() + " --pose 1,2,x,0 --out " + out.string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_EQ(lines(run.output), 1) << run.output;
  EXPECT_NE(run.output.find("--pose: '1,2,x,0'"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CliRender, MissingSceneNamesTheFile) {
  const CmdResult run = tgnav("render --scene /nonexistent/scene.yaml --out " + (test::tempDir() / "o").string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_NE(run.output.find("/nonexistent/scene.yaml"), std::string::npos) << run.output;
}

TEST(CliRender, InvalidMjcfNamesTheFile) {
  const auto dir = test::tempDir();
  const auto bad = test::writeFile(dir / "bad.xml", "<mujoco><worldbody><geom type='nope'/></worldbody></mujoco>");
  const CmdResult run = tgnav("render --scene " + bad.string() + " --pose 0,0,1,0 --out " + (dir / "o").string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_EQ(lines(run.output), 1) << run.output;
  EXPECT_NE(run.output.find(bad.string() + ": invalid MJCF"), std::string::npos) << run.output;
}

TEST(CliRender, MjcfWithoutVehicleIsRejected) {
  const auto dir = test::tempDir();
  const auto xml = test::writeFile(dir / "empty.xml", "<mujoco/>");
  const CmdResult run = tgnav("render --scene " + xml.string() + " --pose 0,0,1,0 --out " + (dir / "o").string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_EQ(lines(run.output), 1) << run.output;
  EXPECT_NE(run.output.find(xml.string() + ": includes no vehicle"), std::string::npos) << run.output;
}

TEST(CliRender, BadResolutionNamesTheValue) {
  const CmdResult run = tgnav("render --scene " + smoke() + " --width -5 --out " + (test::tempDir() / "o").string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_NE(run.output.find("width_px = -5"), std::string::npos) << run.output;
}

TEST(CliRender, MissingEglSaysWhatToInstall) {
  const CmdResult run = tgnav("render --scene " + smoke() + " --out " + (test::tempDir() / "o").string(),
                              "__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json");
  EXPECT_EQ(run.rc, 2);
  EXPECT_EQ(lines(run.output), 1) << run.output;
  EXPECT_NE(run.output.find("install libegl1 libegl-mesa0 libgl1-mesa-dri"), std::string::npos) << run.output;
}

std::string pillarCsv() { return (test::sourceDir() / "configs/trajectories/smoke_around_pillar.csv").string(); }

TEST(CliFly, FliesAroundThePillarAndWritesResults) {
  const auto out = test::tempDir() / "out";
  const CmdResult run = tgnav("fly --scene " + smoke() + " --trajectory " + pillarCsv() + " --out " + out.string());
  ASSERT_EQ(run.rc, 0) << run.output;
  EXPECT_NE(run.output.find("tgnav fly: completed"), std::string::npos) << run.output;
  for (const char* f : {"gt.tum", "flight.csv", "tracking.json"}) {
    EXPECT_TRUE(std::filesystem::is_regular_file(out / f)) << f;
  }
  std::ifstream json(out / "tracking.json");
  const std::string text((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"status\": \"completed\""), std::string::npos) << text;
  // 100 Hz ground truth over take-off, settling, 14.76 s of trajectory and the 2 s hold.
  std::ifstream tum(out / "gt.tum");
  int rows = 0;
  for (std::string line; std::getline(tum, line);) rows += (!line.empty() && line[0] != '#');
  EXPECT_GT(rows, 1700);
}

TEST(CliFly, BadTrajectoryIsOneLineExit2AndWritesNothing) {
  const auto dir = test::tempDir();
  const auto csv = test::writeFile(dir / "bad.csv", "t,x,y,z,yaw\n0,-3,0,1,0\n2,-2,0,1,0\n1,-1,0,1,0\n");
  const CmdResult run =
      tgnav("fly --scene " + smoke() + " --trajectory " + csv.string() + " --out " + (dir / "o").string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_EQ(lines(run.output), 1) << run.output;
  EXPECT_NE(run.output.find(csv.string() + ":4: column 't' has value '1'"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "o"));
}

TEST(CliFly, TrajectoryOutsideTheSceneIsRejected) {
  const auto dir = test::tempDir();
  const auto far = test::writeFile(dir / "far.csv", "t,x,y,z,yaw\n0,2,2,1,0\n");
  CmdResult run = tgnav("fly --scene " + smoke() + " --trajectory " + far.string() + " --out " + (dir / "o").string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_NE(run.output.find("from the scene's start"), std::string::npos) << run.output;
  const auto out_of_bounds = test::writeFile(dir / "oob.csv", "t,x,y,z,yaw\n0,-3,0,1,0\n5,-3,0,7,0\n");
  run = tgnav("fly --scene " + smoke() + " --trajectory " + out_of_bounds.string() + " --out " + (dir / "o").string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_NE(run.output.find("outside the scene bounds"), std::string::npos) << run.output;
}

TEST(CliFly, ControllerConfigErrorsNameTheKey) {
  const auto dir = test::tempDir();
  const auto yaml = test::writeFile(dir / "c.yaml", "rates_hz:\n  position: 300\n");
  const CmdResult run = tgnav("fly --scene " + smoke() + " --trajectory " + pillarCsv() + " --controller " +
                              yaml.string() + " --out " + (dir / "o").string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_NE(run.output.find(yaml.string() + ": rates_hz.position = 300"), std::string::npos) << run.output;
}

// A copy of the smoke scene YAML with one line replaced.
std::filesystem::path smokeWith(const std::filesystem::path& dir, const std::string& from, const std::string& to) {
  std::ifstream in(smoke());
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.replace(text.find(from), from.size(), to);
  const std::string mjcf = (test::sourceDir() / "models/scenes/smoke.xml").string();
  text.replace(text.find("../../models/scenes/smoke.xml"), 29, mjcf);
  return test::writeFile(dir / "scene.yaml", text);
}

TEST(CliMap, StartInsideAnObstacleIsRejected) {
  const auto dir = test::tempDir();
  const auto yaml = smokeWith(dir, "start: [-3.0, 0.0, 1.0, 0.0]", "start: [0.1, 0.0, 1.0, 0.0]");
  const CmdResult run = tgnav("map --scene " + yaml.string() + " --out " + (dir / "m").string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_EQ(lines(run.output), 1) << run.output;
  EXPECT_NE(run.output.find("key 'start' = [0.1, 0, 1] is inside an obstacle"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "m"));
}

TEST(CliMap, SurveyWithoutFreePosesIsRejected) {
  const auto dir = test::tempDir();
  const auto yaml = smokeWith(dir, "clearance_m: 0.45", "clearance_m: 9.0");
  const CmdResult run = tgnav("map --scene " + yaml.string() + " --out " + (dir / "m").string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_NE(run.output.find("survey plan has no free pose"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "m"));
}

TEST(CliMap, RefusesToOverwriteSomethingElse) {
  const auto dir = test::tempDir();
  test::writeFile(dir / "precious.txt", "keep me");
  const CmdResult run = tgnav("map --scene " + smoke() + " --out " + dir.string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_TRUE(std::filesystem::exists(dir / "precious.txt"));
  const CmdResult here = tgnav("map --scene " + smoke() + " --out .");
  EXPECT_EQ(here.rc, 2);
  EXPECT_NE(here.output.find("is the working directory"), std::string::npos) << here.output;
}

TEST(CliMap, UnreadableTextureNamesTheMjcfAndTexture) {
  const auto dir = test::tempDir();
  const auto xml = test::writeFile(
      dir / "scene.xml", "<mujoco><asset><texture name='t' type='cube' file='missing.png'/></asset></mujoco>");
  const CmdResult run = tgnav("render --scene " + xml.string() + " --pose 0,0,1,0 --out " + (dir / "o").string());
  EXPECT_EQ(run.rc, 2);
  // MuJoCo 2.2 names the texture and its line, not the PNG's path.
  EXPECT_NE(run.output.find(xml.string() + ": invalid MJCF"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("PNG file load error"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("Object name = t"), std::string::npos) << run.output;
}

// A MovingAI map: 20 x 12 cells, two pillars in the middle row.
std::filesystem::path twoPillars(const std::filesystem::path& dir) {
  std::string text = "type octile\nheight 12\nwidth 20\nmap\n";
  for (int r = 0; r < 12; ++r) {
    std::string row(20, '.');
    if (r >= 5 && r <= 6) {
      row.replace(5, 2, "@@");
      row.replace(13, 2, "@@");
    }
    text += row + "\n";
  }
  return test::writeFile(dir / "two.map", text);
}

TEST(CliPlan, GridPlanWritesClassesAndPicture) {
  const auto dir = test::tempDir();
  const CmdResult run =
      tgnav("plan --grid " + twoPillars(dir).string() + " --start 1.5,6 --goal 18.5,6 --out " + (dir / "p").string());
  ASSERT_EQ(run.rc, 0) << run.output;
  EXPECT_NE(run.output.find("solved, 4 homology classes"), std::string::npos) << run.output;
  std::ifstream json(dir / "p" / "plan.json");
  const std::string text((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
  for (const char* key :
       {"\"classes\"", "\"h_signature\"", "\"waypoints\"", "\"chosen_class\": 0", "\"class_cap\": 10"}) {
    EXPECT_NE(text.find(key), std::string::npos) << key;
  }
  EXPECT_FALSE(cv::imread((dir / "p" / "plan.png").string()).empty());
}

TEST(CliPlan, BadStartIsOneLineExit2AndNoPathIsAResult) {
  const auto dir = test::tempDir();
  const auto map = twoPillars(dir);
  CmdResult run = tgnav("plan --grid " + map.string() + " --start 5.5,5.5 --goal 18.5,6 --out " + (dir / "p").string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_EQ(lines(run.output), 1) << run.output;
  EXPECT_NE(run.output.find("--start: '5.5,5.5'"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "p"));
  // A wall of '@' across the map: planning succeeds in saying there is no path.
  std::string walled = "type octile\nheight 6\nwidth 10\nmap\n";
  for (int r = 0; r < 6; ++r) walled += "....@.....\n";
  const auto wall = test::writeFile(dir / "wall.map", walled);
  run = tgnav("plan --grid " + wall.string() + " --start 1.5,3 --goal 8.5,3 --out " + (dir / "w").string());
  EXPECT_EQ(run.rc, 0) << run.output;
  EXPECT_NE(run.output.find("no_path"), std::string::npos) << run.output;
  run = tgnav("plan --grid " + map.string() + " --start 1.5,6 --goal 18.5,6 --planner proposed --out " +
              (dir / "x").string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_NE(run.output.find("--planner: 'proposed'"), std::string::npos) << run.output;
}

TEST(CliPlan, ScenRunsEveryRowAndBadRowsAreOneLineExit2) {
  const auto dir = test::tempDir();
  const auto map = twoPillars(dir);
  // Row 1 goes around the pillars; row 2 starts on one ('@' at column 5, row 5 from the top).
  const auto scen = test::writeFile(dir / "two.map.scen", "version 1\n0\ttwo.map\t20\t12\t1\t6\t18\t6\t17.0\n");
  CmdResult run = tgnav("plan --grid " + map.string() + " --scen " + scen.string() + " --robot-radius 0 --out " +
                        (dir / "s").string());
  ASSERT_EQ(run.rc, 0) << run.output;
  EXPECT_NE(run.output.find("1 of 1 scenarios found a path"), std::string::npos) << run.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "s" / "scen.csv"));
  const auto bad = test::writeFile(dir / "bad.scen", "version 1\n0\ttwo.map\t20\t12\t5\t5\t18\t6\t17.0\n");
  run = tgnav("plan --grid " + map.string() + " --scen " + bad.string() + " --out " + (dir / "b").string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_EQ(lines(run.output), 1) << run.output;
  EXPECT_NE(run.output.find(bad.string() + ":2: start (5, 5) is an obstacle cell"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "b"));
  const auto wide = test::writeFile(dir / "wide.scen", "version 1\n0\ttwo.map\t21\t12\t1\t6\t18\t6\t17.0\n");
  run = tgnav("plan --grid " + map.string() + " --scen " + wide.string() + " --out " + (dir / "w").string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_NE(run.output.find(wide.string() + ":2: map_width has value '21'"), std::string::npos) << run.output;
  run =
      tgnav("plan --grid " + map.string() + " --scen " + scen.string() + " --start 1,1 --out " + (dir / "x").string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_NE(run.output.find("--start/--goal: with --scen"), std::string::npos) << run.output;
}

TEST(Cli, UnknownSubcommandExits2AndHelpExits0) {
  const CmdResult bad = tgnav("fly-to-the-moon");
  EXPECT_EQ(bad.rc, 2);
  EXPECT_EQ(lines(bad.output), 1) << bad.output;
  const CmdResult missing = tgnav("render --scene x.yaml");
  EXPECT_EQ(missing.rc, 2);
  EXPECT_NE(missing.output.find("--out is required"), std::string::npos) << missing.output;
  EXPECT_EQ(tgnav("--help").rc, 0);
  EXPECT_EQ(tgnav("render --help").rc, 0);
}

TEST(CliPlanScenario, BadInputIsOneLineExit2AndWritesNothing) {
  const auto dir = test::tempDir();
  const auto out = dir / "out";
  const std::string storage = (test::sourceDir() / "configs/scenarios/storage.yaml").string();
  const auto bad_key =
      test::writeFile(dir / "bad.yaml", "scene: " + (test::sourceDir() / "configs/scenes/storage.yaml").string() +
                                            "\nseed: 1\nplanner: {selection: {c_p_treshold: 6}}\n");
  const auto bad_eta =
      test::writeFile(dir / "eta.yaml", "scene: " + (test::sourceDir() / "configs/scenes/storage.yaml").string() +
                                            "\nseed: 1\nplanner: {segments: {covisibility_ratio: 1.5}}\n");
  const auto bad_traj_key =
      test::writeFile(dir / "traj_key.yaml", "scene: " + (test::sourceDir() / "configs/scenes/storage.yaml").string() +
                                                 "\nseed: 1\nplanner: {trajectory: {max_sped_mps: 2}}\n");
  const auto bad_traj_speed = test::writeFile(dir / "traj_speed.yaml",
                                              "scene: " + (test::sourceDir() / "configs/scenes/storage.yaml").string() +
                                                  "\nseed: 1\nplanner: {trajectory: {nominal_speed_mps: 2.5}}\n");
  const struct {
    std::string args;
    std::string expect;
  } cases[] = {
      {"--scenario " + storage + " --planner dijkstra", "--planner: 'dijkstra'"},
      {"--scenario " + bad_traj_key.string(), "planner.trajectory.max_sped_mps"},
      {"--scenario " + bad_traj_speed.string(),
       "trajectory.nominal_speed_mps = 2.5: must be <= trajectory.max_speed_mps"},
      {"--scenario " + storage + " --seed -3", "--seed: -3"},
      {"--scenario " + storage + " --planner proposed --samples 10", "--samples"},
      {"--scenario " + bad_key.string(), "planner.selection.c_p_treshold"},
      {"--scenario " + bad_eta.string(), "covisibility_ratio = 1.5"},
      {"--scenario " + storage + " --map " + (dir / "nomap").string(), "map.bt"},
      {"--scenario " + storage + " --grid x.map", "excludes"},
  };
  for (const auto& c : cases) {
    const CmdResult run = tgnav("plan " + c.args + " --out " + out.string());
    EXPECT_EQ(run.rc, 2) << c.args << ": " << run.output;
    EXPECT_EQ(lines(run.output), 1) << run.output;
    EXPECT_NE(run.output.find(c.expect), std::string::npos) << run.output;
    EXPECT_FALSE(std::filesystem::exists(out)) << c.args;
  }
}

// --- tgnav fly --record and tgnav vo -------------------------------------------------------

int dataRows(const std::filesystem::path& file) {
  std::ifstream in(file);
  int rows = 0;
  for (std::string line; std::getline(in, line);) rows += (!line.empty() && line[0] != '#');
  return rows;
}

int filesIn(const std::filesystem::path& dir) {
  return static_cast<int>(
      std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()));
}

nlohmann::json readJson(const std::filesystem::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

TEST(CliRecord, RecordsATumSequenceThatVoRuns) {
  const auto dir = test::tempDir();
  const auto seq = dir / "seq";
  const CmdResult run = tgnav("fly --scene " + smoke() + " --trajectory " + pillarCsv() + " --out " +
                              (dir / "flight").string() + " --record " + seq.string() + " --width 160 --height 120");
  ASSERT_EQ(run.rc, 0) << run.output;
  EXPECT_NE(run.output.find("recorded"), std::string::npos) << run.output;
  EXPECT_EQ(test::stagingLeftIn(dir), 0);
  // 20 Hz over the whole flight, from t = 0 on the ground.
  const double sim_time_s = readJson(dir / "flight" / "tracking.json")["sim_time_s"].get<double>();
  const int frames = dataRows(seq / "rgb.txt");
  EXPECT_EQ(frames, static_cast<int>(std::floor(sim_time_s * 20.0 + 1e-6)) + 1) << sim_time_s;
  EXPECT_EQ(dataRows(seq / "depth.txt"), frames);
  EXPECT_EQ(dataRows(seq / "groundtruth.txt"), frames);
  EXPECT_EQ(filesIn(seq / "rgb"), frames);
  EXPECT_EQ(filesIn(seq / "depth"), frames);
  EXPECT_TRUE(std::filesystem::is_regular_file(seq / "intrinsics.yaml"));
  const harness::Sequence loaded = harness::loadSequence(seq);
  ASSERT_EQ(static_cast<int>(loaded.frames.size()), frames);
  ASSERT_TRUE(loaded.intrinsics.has_value());
  EXPECT_EQ(loaded.intrinsics->width_px, 160);
  EXPECT_EQ(loaded.intrinsics->height_px, 120);
  const harness::SequenceImages mid = harness::loadFrame(loaded, frames / 2);
  EXPECT_EQ(mid.bgr.type(), CV_8UC3);
  EXPECT_GT(cv::countNonZero(mid.depth_m), 160 * 120 / 2) << "mid-flight, the camera sees the scene";
  // The camera's pose in mid-flight is the vehicle's, about 1 m up and facing +x (optical z).
  const Eigen::Isometry3d& X_WC = loaded.groundtruth[frames / 2].X_WC;
  EXPECT_NEAR(X_WC.translation().z(), 1.0, 0.1);
  EXPECT_GT((X_WC.linear() * Eigen::Vector3d::UnitZ()).x(), 0.9);

  const auto out = dir / "vo";
  const CmdResult vo = tgnav("vo --sequence " + seq.string() + " --out " + out.string());
  ASSERT_EQ(vo.rc, 0) << vo.output;
  EXPECT_EQ(lines(vo.output), 1) << vo.output;
  for (const char* f : {"est.tum", "status.csv", "summary.json"}) {
    EXPECT_TRUE(std::filesystem::is_regular_file(out / f)) << f;
  }
  EXPECT_EQ(dataRows(out / "status.csv"), frames + 1) << "a header and one row per frame";
  std::ifstream status(out / "status.csv");
  std::string header;
  std::getline(status, header);
  EXPECT_EQ(header, "t,status,features,with_depth,matches,inliers,keyframe,keyframe_rule,reason");
  const nlohmann::json summary = readJson(out / "summary.json");
  EXPECT_EQ(summary["frames"].get<int>(), frames);
  EXPECT_EQ(summary["ok"].get<int>() + summary["weak"].get<int>() + summary["lost"].get<int>(), frames);
  EXPECT_EQ(dataRows(out / "est.tum"), summary["ok"].get<int>() + summary["weak"].get<int>());
  EXPECT_EQ(summary["groundtruth"], true);
  EXPECT_EQ(summary["initial_pose"], "groundtruth");
  for (const char* key : {"failed_at_s", "ate_rmse_aligned_m", "ate_rmse_anchored_m", "rpe_trans_rmse_percent",
                          "distance_travelled_m", "goal_error_m", "ms_per_frame"}) {
    EXPECT_TRUE(summary.contains(key)) << key;
  }
  // Never overwritten.
  const CmdResult again = tgnav("vo --sequence " + seq.string() + " --out " + out.string());
  EXPECT_EQ(again.rc, 2);
  EXPECT_EQ(lines(again.output), 1) << again.output;
  EXPECT_NE(again.output.find("--out: " + out.string() + " already exists"), std::string::npos) << again.output;
}

TEST(CliRecord, BadRecordingOptionsAreOneLineExit2AndWriteNothing) {
  const auto dir = test::tempDir();
  const auto taken = dir / "taken";
  std::filesystem::create_directories(taken);
  test::writeFile(taken / "keep.txt", "keep me");
  const auto out = dir / "flight";
  const std::string fly = "fly --scene " + smoke() + " --trajectory " + pillarCsv() + " --out " + out.string();
  const struct {
    std::string args;
    std::string expect;
  } cases[] = {
      {" --record " + taken.string(), "--record: " + taken.string() + " already exists"},
      {" --record " + (dir / "seq").string() + " --record-rate 30", "--record-rate: 30 Hz does not divide"},
      {" --record " + (dir / "seq").string() + " --record-rate 0", "--record-rate: 0 Hz"},
      {" --record " + (dir / "seq").string() + " --width 8", "width_px = 8"},
      {" --record " + out.string(), "is also --out"},
      {" --width 160", "--width requires --record"},
  };
  for (const auto& c : cases) {
    const CmdResult run = tgnav(fly + c.args);
    EXPECT_EQ(run.rc, 2) << c.args << ": " << run.output;
    EXPECT_EQ(lines(run.output), 1) << run.output;
    EXPECT_NE(run.output.find(c.expect), std::string::npos) << run.output;
    EXPECT_FALSE(std::filesystem::exists(out)) << c.args;
    EXPECT_FALSE(std::filesystem::exists(dir / "seq")) << c.args;
    EXPECT_EQ(test::stagingLeftIn(dir), 0) << c.args;
  }
  EXPECT_EQ(filesIn(taken), 1);
}

// A small synthetic sequence: noise images, flat depth, ground truth along x.
std::filesystem::path smallSequence(const std::filesystem::path& dir, int frames = 4) {
  harness::SequenceWriter writer(dir, vo::CameraIntrinsics{64, 48, 50.0, 50.0, 31.5, 23.5});
  cv::RNG rng(3);
  for (int i = 0; i < frames; ++i) {
    cv::Mat bgr(48, 64, CV_8UC3);
    rng.fill(bgr, cv::RNG::UNIFORM, 0, 256);
    Eigen::Isometry3d X_WC = Eigen::Isometry3d::Identity();
    X_WC.translation().x() = 0.01 * i;
    writer.add(0.05 * i, bgr, cv::Mat(48, 64, CV_32FC1, cv::Scalar(2.0f)), X_WC);
  }
  writer.finish();
  return dir;
}

TEST(CliVo, BadSequencesAreOneLineExit2AndWriteNothing) {
  const auto dir = test::tempDir();
  const auto out = dir / "out";
  const struct {
    std::string name;
    std::function<void(const std::filesystem::path&)> spoil;
    std::string expect;  // after the sequence's path
    std::string extra_args;
  } cases[] = {
      {"missing", [](const std::filesystem::path& s) { std::filesystem::remove_all(s); },
       ": no such sequence directory", ""},
      {"empty_rgb", [](const std::filesystem::path& s) { test::writeFile(s / "rgb.txt", "# no frames\n"); },
       "/rgb.txt: lists no images", ""},
      {"non_monotonic",
       [](const std::filesystem::path& s) {
         test::writeFile(s / "depth.txt", "0.0 depth/0.000000.png\n0.1 depth/0.100000.png\n0.05 depth/0.050000.png\n");
       },
       "/depth.txt:3: timestamp 0.05 does not increase", ""},
      {"missing_depth", [](const std::filesystem::path& s) { std::filesystem::remove(s / "depth/0.100000.png"); },
       "/depth/0.100000.png (depth.txt:6): no such image file", ""},
      {"no_intrinsics", [](const std::filesystem::path& s) { std::filesystem::remove(s / "intrinsics.yaml"); },
       "/intrinsics.yaml: missing; give the camera as --intrinsics fx,fy,cx,cy", ""},
      {"bad_intrinsics_option", [](const std::filesystem::path&) {}, "", " --intrinsics 50,50,31.5"},
  };
  for (const auto& c : cases) {
    const auto seq = smallSequence(dir / c.name);
    c.spoil(seq);
    const CmdResult run = tgnav("vo --sequence " + seq.string() + " --out " + out.string() + c.extra_args);
    EXPECT_EQ(run.rc, 2) << c.name << ": " << run.output;
    EXPECT_EQ(lines(run.output), 1) << run.output;
    EXPECT_NE(run.output.find(c.extra_args.empty() ? seq.string() + c.expect : "--intrinsics: '50,50,31.5'"),
              std::string::npos)
        << c.name << ": " << run.output;
    EXPECT_FALSE(std::filesystem::exists(out)) << c.name;
    EXPECT_EQ(test::stagingLeftIn(out.parent_path()), 0) << c.name;
  }
}

// An image file that no decoder reads. Apart from the other bad sequences: OpenCV's imread then
// loads GDAL's plugins, whose thread-local storage crashes LeakSanitizer's tracer at exit (a
// runtime bug, not a finding), so scripts/sanitize.sh leaves this one test out.
TEST(CliVo, CorruptImageIsOneLineExit2AndWritesNothing) {
  const auto dir = test::tempDir();
  const auto out = dir / "out";
  const auto seq = smallSequence(dir / "corrupt_depth");
  test::writeFile(seq / "depth/0.150000.png", "junk");
  const CmdResult run = tgnav("vo --sequence " + seq.string() + " --out " + out.string());
  EXPECT_EQ(run.rc, 2) << run.output;
  EXPECT_EQ(lines(run.output), 1) << run.output;
  EXPECT_NE(run.output.find(seq.string() + "/depth/0.150000.png (depth.txt:7): cannot read image"), std::string::npos)
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_EQ(test::stagingLeftIn(dir), 0);
}

TEST(CliVo, ConfigErrorsNameTheFileAndKey) {
  const auto dir = test::tempDir();
  const auto seq = smallSequence(dir / "seq");
  const auto yaml = test::writeFile(dir / "vo.yaml", "min_inliers: 20\nfeatures:\n  max_featres: 500\n");
  const CmdResult run =
      tgnav("vo --sequence " + seq.string() + " --out " + (dir / "out").string() + " --config " + yaml.string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_EQ(lines(run.output), 1) << run.output;
  EXPECT_NE(run.output.find(yaml.string() + ":3: unknown key 'features.max_featres'"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(CliVo, SequenceWithoutGroundtruthTakesIntrinsicsFromTheCommandLine) {
  const auto dir = test::tempDir();
  const auto seq = smallSequence(dir / "seq");
  std::filesystem::remove(seq / "groundtruth.txt");
  std::filesystem::remove(seq / "intrinsics.yaml");
  const auto out = dir / "out";
  const CmdResult run = tgnav("vo --sequence " + seq.string() + " --out " + out.string() +
                              " --intrinsics 50,50,31.5,23.5 --reinitialise");
  ASSERT_EQ(run.rc, 0) << run.output;
  EXPECT_NE(run.output.find("no ground truth"), std::string::npos) << run.output;
  const nlohmann::json summary = readJson(out / "summary.json");
  EXPECT_EQ(summary["frames"], 4);
  EXPECT_EQ(summary["groundtruth"], false);
  EXPECT_EQ(summary["initial_pose"], "identity");
  EXPECT_EQ(summary["reinitialise_after_lost"], true);
  EXPECT_EQ(summary["odometry_config"]["reinitialise_after_lost"], true);
  EXPECT_EQ(summary["intrinsics"]["width"], 64);
  EXPECT_EQ(summary["intrinsics"]["source"], "--intrinsics");
  EXPECT_TRUE(summary["ate_rmse_aligned_m"].is_null());
  EXPECT_TRUE(summary["goal_error_m"].is_null());
  EXPECT_EQ(dataRows(out / "status.csv"), 5);
}

}  // namespace
}  // namespace tgnav
