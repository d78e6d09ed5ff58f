// Trajectory files beside TUM: KITTI poses and EuRoC CSV read from hand-written text (real files'
// first lines), every format round-trips, malformed lines and files of another format are named by
// line; timestamps are read in the file's order (repeated or going back included).
#include "vo/trajectory_formats.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>

#include "vo/metrics.h"

namespace tgnav::vo {
namespace {

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no std::invalid_argument)";
}

std::string parseError(const std::string& text, TrajectoryFormat format) {
  return errorOf([&] { parseTrajectory(text, format); });
}

// Random poses at 20 Hz from time t0 (both quaternion signs, translations over many magnitudes).
std::vector<StampedPose> randomPoses(int n, double t0, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<StampedPose> poses;
  for (int i = 0; i < n; ++i) {
    StampedPose p;
    p.t_s = t0 + 0.05 * i;
    p.X_WC.linear() =
        Eigen::Quaterniond(Eigen::Vector4d(g(rng), g(rng), g(rng), g(rng))).normalized().toRotationMatrix();
    p.X_WC.translation() = Eigen::Vector3d(g(rng) * 100.0, g(rng), g(rng) * 1e-4);
    poses.push_back(p);
  }
  return poses;
}

TEST(TrajectoryFormats, NamesRoundTripAndUnknownIsRejected) {
  for (const char* name : {"tum", "kitti", "euroc"}) EXPECT_STREQ(toString(parseTrajectoryFormat(name)), name);
  EXPECT_EQ(errorOf([] { parseTrajectoryFormat("csv"); }),
            "'csv' is not a trajectory format; expected tum, kitti or euroc");
}

TEST(TrajectoryFormats, EveryFormatRoundTrips) {
  for (const TrajectoryFormat format : {TrajectoryFormat::kTum, TrajectoryFormat::kKitti, TrajectoryFormat::kEuroc}) {
    // KITTI has no timestamps: its poses are numbered 0, 1, 2, ...; EuRoC's are whole nanoseconds.
    auto poses = randomPoses(200, format == TrajectoryFormat::kEuroc ? 17.5 : 1305031098.6659, 3);
    if (format == TrajectoryFormat::kKitti) {
      for (std::size_t i = 0; i < poses.size(); ++i) poses[i].t_s = double(i);
    }
    const std::string text = toTrajectory(poses, format);
    const auto parsed = parseTrajectory(text, format);
    ASSERT_EQ(parsed.size(), poses.size()) << toString(format);
    for (std::size_t i = 0; i < poses.size(); ++i) {
      if (format == TrajectoryFormat::kEuroc) {
        EXPECT_NEAR(parsed[i].t_s, poses[i].t_s, 1e-9) << toString(format);
      } else {
        EXPECT_EQ(parsed[i].t_s, poses[i].t_s) << toString(format);
      }
      EXPECT_TRUE(parsed[i].X_WC.translation() == poses[i].X_WC.translation()) << toString(format);
      EXPECT_LT((parsed[i].X_WC.linear() - poses[i].X_WC.linear()).cwiseAbs().maxCoeff(), 1e-14) << toString(format);
    }
    // Written again, the text is the same but for the last bits of the rotations.
    const auto again = parseTrajectory(toTrajectory(parsed, format), format);
    for (std::size_t i = 0; i < poses.size(); ++i) {
      EXPECT_EQ(again[i].t_s, parsed[i].t_s);
      EXPECT_LT((again[i].X_WC.linear() - parsed[i].X_WC.linear()).cwiseAbs().maxCoeff(), 1e-14);
    }
  }
}

TEST(TrajectoryFormats, EurocUnixTimesKeepMicroseconds) {
  const auto poses = randomPoses(50, 1403636579.758555392, 4);
  const auto parsed = parseEuroc(toEuroc(poses));
  ASSERT_EQ(parsed.size(), poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) EXPECT_NEAR(parsed[i].t_s, poses[i].t_s, 1e-6);
  EXPECT_NE(errorOf([] {
              toEuroc({StampedPose{NAN, Eigen::Isometry3d::Identity()}});
            }).find("nanoseconds"),
            std::string::npos);
}

TEST(TrajectoryFormats, ExactRotationsWriteExactText) {
  StampedPose a, b;
  a.t_s = 0.5;
  a.X_WC.translation() = Eigen::Vector3d(1, 2, 3);
  b.t_s = 1.25;
  b.X_WC.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  b.X_WC.linear() = b.X_WC.linear().array().round().matrix();  // exactly [0 -1 0; 1 0 0; 0 0 1]
  b.X_WC.translation() = Eigen::Vector3d(-0.5, 0.25, 1e-3);
  EXPECT_EQ(toKitti({a, b}), "1 0 0 1 0 1 0 2 0 0 1 3\n0 -1 0 -0.5 1 0 0 0.25 0 0 1 0.001\n");
  const std::string euroc = toEuroc({a, b});
  EXPECT_EQ(euroc.substr(euroc.find('\n') + 1),
            "500000000,1,2,3,1,0,0,0\n1250000000,-0.5,0.25,0.001,0.7071067811865476,0,0,0.7071067811865475\n");
  EXPECT_EQ(euroc.rfind("#timestamp [ns],p_RS_R_x [m]", 0), 0u);
  EXPECT_EQ(toKitti(parseKitti(toKitti({a, b}))), toKitti({a, b}));
}

TEST(TrajectoryFormats, ReadsKittiPoses) {
  // A line as KITTI odometry's ground truth writes them (6 significant digits, R R^T off I by
  // ~1e-7), then a quarter turn about z, tab-separated.
  const auto poses = parseKitti(
      "1.000000e+00 9.043680e-12 2.326809e-11 5.551115e-17 9.043683e-12 1.000000e+00 2.392370e-10 "
      "3.330669e-16 2.326810e-11 2.392370e-10 9.999999e-01 -4.440892e-16\n"
      "\n"
      "0\t-1\t0\t4\t1\t0\t0\t5\t0\t0\t1\t6\r\n");
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_EQ(poses[0].t_s, 0.0);
  EXPECT_EQ(poses[1].t_s, 1.0);
  EXPECT_TRUE(poses[0].X_WC.linear().isIdentity(1e-6));
  const Eigen::Matrix3d R0 = poses[0].X_WC.linear();
  EXPECT_LT((R0 * R0.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-14);  // the nearest rotation
  EXPECT_EQ(poses[1].X_WC.translation(), Eigen::Vector3d(4, 5, 6));
  EXPECT_TRUE(
      poses[1].X_WC.linear().isApprox(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix(), 1e-14));
}

TEST(TrajectoryFormats, ReadsEurocGroundTruth) {
  // EuRoC's ground-truth header and a row of its 17 columns (velocity and biases after the pose),
  // then a row of 8 with spaces after the commas.
  const auto poses = parseEuroc(
      "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], v_RS_R_x "
      "[m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z "
      "[rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n"
      "1403636580838555648,4.688319,-1.786938,0.783338,0.534108,-0.153029,-0.827383,-0.082152,-0.027876,0.033207,"
      "0.800006,-0.003172,0.021267,0.078502,-0.025266,0.136696,0.075593\n"
      "1403636580843555648, 4.688, -1.787, 0.783, 1, 0, 0, 0\n");
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_NEAR(poses[0].t_s, 1403636580.838555648, 1e-6);
  EXPECT_NEAR(poses[1].t_s - poses[0].t_s, 0.005, 1e-6);
  EXPECT_EQ(poses[0].X_WC.translation(), Eigen::Vector3d(4.688319, -1.786938, 0.783338));
  const Eigen::Quaterniond q(0.534108, -0.153029, -0.827383, -0.082152);  // w first
  EXPECT_TRUE(poses[0].X_WC.linear().isApprox(q.normalized().toRotationMatrix(), 1e-12));
  EXPECT_TRUE(poses[1].X_WC.linear().isIdentity(0.0));
}

TEST(TrajectoryFormats, MalformedLinesAreNamed) {
  const TrajectoryFormat kitti = TrajectoryFormat::kKitti, euroc = TrajectoryFormat::kEuroc;
  const std::string k_ok = "1 0 0 0 0 1 0 0 0 0 1 0\n";
  EXPECT_EQ(parseError(k_ok + "1 0 0 0 0 1 0 0 0 0 1\n", kitti),
            "line 2: expected 12 numbers (the 3x4 pose matrix [R | t] row by row), got 11");
  EXPECT_EQ(parseError(k_ok + "1 0 0 0 0 1 0 0 0 0 nan 0\n", kitti), "line 2: field 11 is nan; a pose must be finite");
  EXPECT_EQ(parseError(k_ok + "2 0 0 0 0 2 0 0 0 0 2 0\n", kitti),
            "line 2: rotation is not orthonormal (max |R R^T - I| = 3, tolerance 0.001)");
  EXPECT_EQ(parseError(k_ok + "1 0 0 0 0 1 0 0 0 0 -1 0\n", kitti), "line 2: rotation is a reflection (det R < 0)");
  const std::string e_ok = "#t,x,y,z,qw,qx,qy,qz\n0,0,0,0,1,0,0,0\n";
  EXPECT_EQ(parseError(e_ok + "1,0,0,0,1,0,0\n", euroc),
            "line 3: expected at least 8 comma-separated numbers (timestamp [ns], p x y z, q w x y z), got 7");
  EXPECT_EQ(parseError(e_ok + "1,0,0,0,1,0,0,0.1\n", euroc),
            "line 3: quaternion is not unit length (|q| = 1.004987562112089, tolerance 0.001)");
  EXPECT_EQ(parseError(e_ok + "1,0,,0,1,0,0,0\n", euroc), "line 3: field 3 '' is not a number");
  EXPECT_EQ(parseError(e_ok + "1,0,0,inf,1,0,0,0\n", euroc), "line 3: field 4 is inf; a pose must be finite");
}

TEST(TrajectoryFormats, FileOfAnotherFormatIsNamedByLine) {
  const std::vector<StampedPose> poses = randomPoses(3, 1.0, 5);
  const std::string tum = toTum(poses), kitti = toKitti(poses), euroc = toEuroc(poses);
  EXPECT_EQ(parseError(kitti, TrajectoryFormat::kTum),
            "line 1: expected 8 numbers (timestamp tx ty tz qx qy qz qw), got 12");
  EXPECT_EQ(parseError(tum, TrajectoryFormat::kKitti),
            "line 2: expected 12 numbers (the 3x4 pose matrix [R | t] row by row), got 8");
  EXPECT_EQ(parseError(tum, TrajectoryFormat::kEuroc),
            "line 2: expected at least 8 comma-separated numbers (timestamp [ns], p x y z, q w x y z), got 1");
  const std::string as_tum = parseError(euroc, TrajectoryFormat::kTum);
  EXPECT_EQ(as_tum.rfind("line 2: field 1 '1000000000,", 0), 0u) << as_tum;
  EXPECT_NE(as_tum.find("...' is not a number"), std::string::npos) << as_tum;
}

TEST(TrajectoryFormats, TimestampsAreTakenInTheFilesOrder) {
  // Repeated (TUM's fr2/desk ground truth) and going back: read as they stand, and counted.
  const std::string head = "# t x y z qx qy qz qw\n0.1 0 0 0 0 0 0 1\n";
  const auto repeated = parseTrajectory(head + "\n0.1 1 0 0 0 0 0 1\n", TrajectoryFormat::kTum);
  ASSERT_EQ(repeated.size(), 2u);
  EXPECT_EQ(repeated[1].X_WC.translation().x(), 1.0);
  EXPECT_EQ(nonIncreasingTimes(repeated), 1);
  const auto back = parseTrajectory(head + "0.05 1 0 0 0 0 0 1\n0.2 2 0 0 0 0 0 1\n", TrajectoryFormat::kTum);
  ASSERT_EQ(back.size(), 3u);
  EXPECT_EQ(back[1].t_s, 0.05);
  EXPECT_EQ(nonIncreasingTimes(back), 1);
  const auto euroc = parseTrajectory("#\n2,0,0,0,1,0,0,0\n1,0,0,0,1,0,0,0\n", TrajectoryFormat::kEuroc);
  ASSERT_EQ(euroc.size(), 2u);
  EXPECT_EQ(nonIncreasingTimes(euroc), 1);
  EXPECT_EQ(nonIncreasingTimes(parseTum(head + "0.2 1 0 0 0 0 0 1\n")), 0);
  EXPECT_TRUE(parseTrajectory("# nothing\n", TrajectoryFormat::kKitti).empty());
  // What is really broken is still refused, naming the line.
  EXPECT_EQ(parseError(head + "0.2 nan 0 0 0 0 0 1\n", TrajectoryFormat::kTum),
            "line 3: field 2 is nan; a pose must be finite");
}

}  // namespace
}  // namespace tgnav::vo
