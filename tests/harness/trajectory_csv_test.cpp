// Trajectory CSV files: what plan writes, fly reads back; malformed files name line, column
// and value.
#include "harness/io/trajectory_csv.h"

#include <gtest/gtest.h>

#include "harness/base/errors.h"
#include "test_util.h"

namespace tgnav::harness {
namespace {

std::string errorOf(const std::string& text) {
  const auto file = test::writeFile(test::tempDir() / "traj.csv", text);
  try {
    readTrajectoryCsv(file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(TrajectoryCsv, MinimalColumnsAnyOrderWithComments) {
  const auto file =
      test::writeFile(test::tempDir() / "t.csv", "# comment\nyaw, t, z, y, x\n0.5, 0, 1, 2, 3\n0.6, 1.5, 1, 2, 4\n");
  const control::SetpointTrajectory t = readTrajectoryCsv(file);
  ASSERT_EQ(t.times().size(), 2u);
  EXPECT_DOUBLE_EQ(t.setpoints()[1].p_WB.x(), 4.0);
  EXPECT_DOUBLE_EQ(t.setpoints()[0].yaw_rad, 0.5);
  EXPECT_EQ(t.setpoints()[0].v_WB.norm(), 0.0);
  EXPECT_DOUBLE_EQ(t.endTime(), 1.5);
}

TEST(TrajectoryCsv, RoundTripsAllColumns) {
  control::TrajectorySetpoint a;
  a.p_WB = Eigen::Vector3d(1.25, -2.5, 1.0);
  a.v_WB = Eigen::Vector3d(0.1, 0.2, 0.3);
  a.a_WB = Eigen::Vector3d(-0.1, 0.05, 0.0);
  a.yaw_rad = 3.1;
  a.yaw_rate_rad_s = 0.3;
  control::TrajectorySetpoint b = a;
  b.yaw_rad = -3.1;  // unwrapped on construction
  const control::SetpointTrajectory original({0.0, 0.01}, {a, b});
  const auto file = test::writeFile(test::tempDir() / "rt.csv", trajectoryCsv(original));
  const control::SetpointTrajectory back = readTrajectoryCsv(file);
  ASSERT_EQ(back.times().size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR((back.setpoints()[i].p_WB - original.setpoints()[i].p_WB).norm(), 0.0, 1e-9);
    EXPECT_NEAR((back.setpoints()[i].v_WB - original.setpoints()[i].v_WB).norm(), 0.0, 1e-9);
    EXPECT_NEAR((back.setpoints()[i].a_WB - original.setpoints()[i].a_WB).norm(), 0.0, 1e-9);
    EXPECT_NEAR(back.setpoints()[i].yaw_rad, original.setpoints()[i].yaw_rad, 1e-9);
    EXPECT_NEAR(back.setpoints()[i].yaw_rate_rad_s, 0.3, 1e-12);
  }
}

TEST(TrajectoryCsv, ErrorsNameLineColumnAndValue) {
  EXPECT_NE(errorOf("t,x,y,z,yaw\n0,0,0,1,0\n0,1,0,1,0\n").find(":3: column 't' has value '0'"), std::string::npos);
  EXPECT_NE(errorOf("t,x,y,z,yaw\n0,0,0,1,0\n1,abc,0,1,0\n").find(":3: column 'x' has value 'abc'"), std::string::npos);
  EXPECT_NE(errorOf("t,x,y,z,yaw\n0,0,0,nan,0\n").find("column 'z' has value 'nan'"), std::string::npos);
  EXPECT_NE(errorOf("t,x,y,z,yaw\n0,0,0,1\n").find(":2: row has 4 fields"), std::string::npos);
  EXPECT_NE(errorOf("t,x,y,z,heading\n").find(":1: unknown column 'heading'"), std::string::npos);
  EXPECT_NE(errorOf("t,x,y,yaw\n").find("missing required column 'z'"), std::string::npos);
  EXPECT_NE(errorOf("t,x,y,z,yaw,vx\n").find("vx,vy,vz come all together"), std::string::npos);
  EXPECT_NE(errorOf("t,x,x,y,z,yaw\n").find("column 'x' appears twice"), std::string::npos);
  EXPECT_NE(errorOf("").find("empty trajectory file"), std::string::npos);
  EXPECT_NE(errorOf("t,x,y,z,yaw\n").find("no setpoints"), std::string::npos);
}

}  // namespace
}  // namespace tgnav::harness
