// TUM trajectory text: numbers written as the shortest round-tripping decimal and read back
// bit-exact, the quaternion sign convention, malformed lines named, non-unit quaternions rejected.
#include "vo/tum.h"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

namespace tgnav::vo {
namespace {

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> out;
  std::istringstream in(line);
  for (std::string f; in >> f;) out.push_back(f);
  return out;
}

double number(const std::string& field) {
  char* end = nullptr;
  const double v = std::strtod(field.c_str(), &end);
  EXPECT_EQ(*end, '\0') << field;
  return v;
}

std::string shortest(double v) {
  char buf[32];
  return std::string(buf, std::to_chars(buf, buf + sizeof(buf), v).ptr);
}

StampedPose stampedPose(double t, const Eigen::Quaterniond& q, const Eigen::Vector3d& p) {
  StampedPose s;
  s.t_s = t;
  s.X_WC.linear() = q.toRotationMatrix();
  s.X_WC.translation() = p;
  return s;
}

// Poses from random unit quaternions (both signs of w), with timestamps and translations over
// many magnitudes, including negative zero.
std::vector<StampedPose> randomPoses(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_int_distribution<int> exponent(-12, 6);
  std::vector<StampedPose> poses;
  double t = 1305031098.6659;
  for (int i = 0; i < n; ++i) {
    t += 0.001 + std::abs(g(rng)) / 30.0;
    const Eigen::Quaterniond q = Eigen::Quaterniond(Eigen::Vector4d(g(rng), g(rng), g(rng), g(rng))).normalized();
    Eigen::Vector3d p(g(rng) * std::pow(10.0, exponent(rng)), g(rng) * 10.0, g(rng) / 3.0);
    if (i % 17 == 0) p.z() = -0.0;
    poses.push_back(stampedPose(t, q, p));
  }
  return poses;
}

std::string errorOf(const std::string& text) {
  try {
    parseTum(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no std::invalid_argument)";
}

TEST(Tum, WritesShortestTextThatReadsBackBitExact) {
  const auto poses = randomPoses(500, 1);
  const std::string text = toTum(poses);
  const auto rows = lines(text);
  ASSERT_EQ(rows.size(), poses.size() + 1);
  EXPECT_EQ(rows[0], "# timestamp tx ty tz qx qy qz qw");
  const auto parsed = parseTum(text);
  ASSERT_EQ(parsed.size(), poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const auto f = fields(rows[i + 1]);
    ASSERT_EQ(f.size(), 8u) << rows[i + 1];
    double v[8];
    for (int k = 0; k < 8; ++k) {
      v[k] = number(f[k]);
      EXPECT_EQ(f[k], shortest(v[k])) << "not the shortest text: " << rows[i + 1];
    }
    // The text holds exactly the timestamp, the translation and Eigen's quaternion (w >= 0).
    const Eigen::Vector3d& p = poses[i].X_WC.translation();
    EXPECT_TRUE(sameBits(v[0], poses[i].t_s)) << rows[i + 1];
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(sameBits(v[1 + k], p[k])) << rows[i + 1];
    Eigen::Quaterniond q(poses[i].X_WC.linear());
    if (q.w() < 0) q.coeffs() = -q.coeffs();
    for (int k = 0; k < 4; ++k) EXPECT_EQ(v[4 + k], q.coeffs()[k]) << rows[i + 1];
    // parseTum reads them back bit for bit: the same timestamp and translation, and the rotation
    // built from exactly the written quaternion coefficients.
    EXPECT_TRUE(sameBits(parsed[i].t_s, poses[i].t_s));
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(sameBits(parsed[i].X_WC.translation()[k], p[k]));
    const Eigen::Matrix3d R = Eigen::Quaterniond(v[7], v[4], v[5], v[6]).normalized().toRotationMatrix();
    EXPECT_TRUE(parsed[i].X_WC.linear() == R) << rows[i + 1];
    EXPECT_LT((parsed[i].X_WC.linear() - poses[i].X_WC.linear()).cwiseAbs().maxCoeff(), 4e-15);
    EXPECT_EQ(parsed[i].X_WC.matrix().row(3), Eigen::RowVector4d(0, 0, 0, 1));
  }
}

TEST(Tum, RewritingParsedPosesKeepsAllButTheQuaternionsLastBits) {
  // A 3x3 rotation matrix and a quaternion are not exact inverses in floating point, so only the
  // quaternion may move, by rounding; everything else is byte-identical.
  const std::string first = toTum(randomPoses(300, 2));
  const std::string second = toTum(parseTum(first));
  const auto a = lines(first), b = lines(second);
  ASSERT_EQ(a.size(), b.size());
  int identical = 0;
  for (std::size_t i = 1; i < a.size(); ++i) {
    const auto fa = fields(a[i]), fb = fields(b[i]);
    ASSERT_EQ(fb.size(), 8u);
    for (int k = 0; k < 4; ++k) EXPECT_EQ(fa[k], fb[k]) << a[i] << "\n" << b[i];
    for (int k = 4; k < 8; ++k) EXPECT_NEAR(number(fa[k]), number(fb[k]), 4e-15) << a[i] << "\n" << b[i];
    identical += a[i] == b[i];
  }
  EXPECT_GT(identical, 0);
}

TEST(Tum, ExactRotationsRoundTripByteIdentical) {
  // Rotations whose quaternion and matrix are exact in binary: identity, quarter and half turns.
  const double h = 0.5;
  std::vector<StampedPose> poses;
  int i = 0;
  for (const Eigen::Quaterniond& q :
       {Eigen::Quaterniond(1, 0, 0, 0), Eigen::Quaterniond(0, 1, 0, 0), Eigen::Quaterniond(0, 0, 1, 0),
        Eigen::Quaterniond(0, 0, 0, 1), Eigen::Quaterniond(h, h, h, h), Eigen::Quaterniond(h, -h, h, -h),
        Eigen::Quaterniond(-h, h, h, h), Eigen::Quaterniond(0, -1, 0, 0), Eigen::Quaterniond(0, 0, 0, -1)}) {
    poses.push_back(stampedPose(0.1 * ++i, q, Eigen::Vector3d(0.1, -2.5e-7, 1e6 / 3)));
  }
  const std::string text = toTum(poses);
  EXPECT_EQ(toTum(parseTum(text)), text);
  const auto rows = lines(text);
  EXPECT_EQ(rows[1], "0.1 0.1 -2.5e-07 333333.3333333333 0 0 0 1");
  // One sign per rotation: w >= 0, and a half turn has its first non-zero of x, y, z positive.
  EXPECT_EQ(rows[2], "0.2 0.1 -2.5e-07 333333.3333333333 1 0 0 0");
  EXPECT_EQ(rows[7], "0.7000000000000001 0.1 -2.5e-07 333333.3333333333 -0.5 -0.5 -0.5 0.5");
  EXPECT_EQ(rows[8], "0.8 0.1 -2.5e-07 333333.3333333333 1 0 0 0");
  EXPECT_EQ(rows[9], "0.9 0.1 -2.5e-07 333333.3333333333 0 0 1 0");
  EXPECT_EQ(text.find("-0 "), std::string::npos) << text;
}

TEST(Tum, HalfTurnHasOneSign) {
  // A half turn about (-0.6, 0.8, 0): Eigen gives x < 0 < y, as does the flipped axis; written
  // with x, the first non-zero, positive.
  for (const double sign : {1.0, -1.0}) {
    const auto f = fields(
        lines(toTum({stampedPose(0, Eigen::Quaterniond(0, -0.6 * sign, 0.8 * sign, 0), Eigen::Vector3d::Zero())}))[1]);
    ASSERT_EQ(f.size(), 8u);
    EXPECT_NEAR(number(f[4]), 0.6, 1e-15);
    EXPECT_NEAR(number(f[5]), -0.8, 1e-15);
    EXPECT_EQ(f[6], "0");
    EXPECT_EQ(f[7], "0");
  }
}

TEST(Tum, ReadsOtherWritersAndSkipsCommentsAndBlankLines) {
  const auto poses = parseTum(
      "# ground truth\n"
      "\n"
      "  \t\r\n"
      "1305031098.6659 1.3563 0.6305 1.6380 0.0 0.0 0.0 1.0\r\n"
      "\t1305031098.6759\t1.3543 0.6306  1.6360 0.000000000 0.707106781 0.000000000 0.707106781\n"
      "  # indented comment\n");
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_EQ(poses[0].t_s, 1305031098.6659);
  EXPECT_EQ(poses[1].X_WC.translation(), Eigen::Vector3d(1.3543, 0.6306, 1.6360));
  EXPECT_TRUE(poses[0].X_WC.linear().isIdentity(0.0));
  EXPECT_TRUE(
      poses[1].X_WC.linear().isApprox(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix(), 1e-9));
  EXPECT_TRUE(parseTum("").empty());
  EXPECT_TRUE(parseTum(toTum({})).empty());
}

TEST(Tum, MalformedLinesAreNamed) {
  const std::string ok = "0 0 0 0 0 0 0 1\n";
  const std::string head = "# c\n" + ok + "\n";  // the bad line is line 4
  for (const char* bad : {"1 2 3 4 5 6 7", "1 2 3 4 5 6 7 8 9", "1 2 3 x 0 0 0 1", "nan 0 0 0 0 0 0 1",
                          "0 inf 0 0 0 0 0 1", "0 0 0 0 0 0 0 1e999", "0,0,0,0,0,0,0,1", "0 0 0 0 0 0 0 1x"}) {
    const std::string msg = errorOf(head + bad + "\n" + ok);
    EXPECT_EQ(msg.rfind("line 4: ", 0), 0u) << bad << " -> " << msg;
  }
  EXPECT_EQ(errorOf(head + "1 2 3 4 5 6 7\n"), "line 4: expected 8 numbers (timestamp tx ty tz qx qy qz qw), got 7");
  EXPECT_EQ(errorOf(head + "1 2 3 4 5 6 7 8 9\n"),
            "line 4: expected 8 numbers (timestamp tx ty tz qx qy qz qw), got 9");
  EXPECT_EQ(errorOf(head + "1 2 3 x 0 0 0 1\n"), "line 4: field 4 'x' is not a number");
  EXPECT_EQ(errorOf(head + "0 0 nan 0 0 0 0 1\n"), "line 4: field 3 is nan; a pose must be finite");
}

TEST(Tum, NonUnitQuaternionIsRejected) {
  const std::string head = "# c\n0 0 0 0 0 0 0 1\n";
  for (const char* bad : {"0 0 0 0 0 0 0 0", "0 0 0 0 0 0 0 2", "0 0 0 0 0 0 0 1.002", "0 0 0 0 0 0 0 0.998"}) {
    const std::string msg = errorOf(head + bad + "\n");
    EXPECT_EQ(msg.rfind("line 3: quaternion is not unit length", 0), 0u) << bad << " -> " << msg;
  }
  // Within 1e-3 of unit: accepted and normalised, e.g. TUM's own ground truth, which rounds
  // quaternions to 4 decimals (|q| - 1 = -1.1e-5 here).
  const auto poses = parseTum(
      "0 0 0 0 0.6 0 0 0.8000005\n1 0 0 0 0 0 0 0.9999991\n"
      "1305031098.6659 1.3563 0.6305 1.6380 0.6132 0.5962 -0.3311 -0.3986\n");
  ASSERT_EQ(poses.size(), 3u);
  for (const StampedPose& p : poses) {
    EXPECT_LT((p.X_WC.linear() * p.X_WC.linear().transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-15);
  }
  EXPECT_TRUE(poses[1].X_WC.linear().isIdentity(0.0));
}

}  // namespace
}  // namespace tgnav::vo
