// The external planner protocol (harness/io/planner_protocol.h, docs/PLANNER_PROTOCOL.md): the
// request a planner reads, and every way a response can break the protocol, each refused with one
// line naming what is wrong.
#include "harness/io/planner_protocol.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace tgnav::harness {
namespace {

const std::string kHead = R"({"protocol":"tgnav-planner","version":1,"id":1,)";

std::string refusal(const std::string& line, int id = 1) {
  try {
    parsePlanResponse(line, id);
  } catch (const ProtocolError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(PlannerProtocol, RequestCarriesEveryDocumentedField) {
  PlanRequestMessage m;
  m.id = 3;
  m.seed = 7;
  m.start.p_WB = Eigen::Vector3d(-3, 0, 1);
  m.goal.p_WB = Eigen::Vector3d(3, 0, 1);
  m.goal.yaw_rad = 0.5;
  m.octomap = "/m/map.bt";
  const std::string line = planRequestLine(m);
  ASSERT_EQ(line.back(), '\n');
  EXPECT_EQ(line.find('\n'), line.size() - 1);  // one line
  const nlohmann::json j = nlohmann::json::parse(line);
  EXPECT_EQ(j["protocol"], "tgnav-planner");
  EXPECT_EQ(j["version"], 1);
  EXPECT_EQ(j["type"], "plan");
  EXPECT_EQ(j["id"], 3);
  EXPECT_EQ(j["seed"], 7);
  EXPECT_EQ(j["goal"], nlohmann::json({3.0, 0.0, 1.0, 0.5}));
  for (const char* key :
       {"time_budget_s", "bounds", "flight_height_m", "robot_radius_m", "check_band_m", "vehicle", "camera", "map"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["map"]["octomap"], "/m/map.bt");
  EXPECT_TRUE(j["map"]["classes"].is_null());
  EXPECT_EQ(nlohmann::json::parse(shutdownLine())["type"], "shutdown");
}

TEST(PlannerProtocol, PathResponseWithItsOptionalFields) {
  const PlanResponse r =
      parsePlanResponse(kHead + R"("status":"ok","path":[[0,0,1,0],[1,2,1,0.5]],"scores":[0.5,1],"homology_class":2,)"
                                R"("solve_time_s":0.25,"reason":"two\nlines"})",
                        1);
  ASSERT_TRUE(r.ok);
  ASSERT_TRUE(r.path);
  EXPECT_FALSE(r.trajectory);
  ASSERT_EQ(r.path->size(), 2u);
  EXPECT_EQ((*r.path)[1].p_WB, Eigen::Vector3d(1, 2, 1));
  EXPECT_EQ((*r.path)[1].yaw_rad, 0.5);
  EXPECT_EQ(r.scores, (std::vector<double>{0.5, 1.0}));
  EXPECT_EQ(r.homology_class, 2);
  EXPECT_EQ(r.solve_time_s, 0.25);
  EXPECT_EQ(r.reason, "two lines");
}

TEST(PlannerProtocol, TrajectoryRowsTakeTheFeedForwardGroups) {
  const PlanResponse r5 =
      parsePlanResponse(kHead + R"("status":"ok","trajectory":[[0,0,0,1,0],[0.5,0.1,0,1,0.1]]})", 1);
  ASSERT_TRUE(r5.trajectory);
  EXPECT_EQ(r5.trajectory->times(), (std::vector<double>{0.0, 0.5}));
  EXPECT_EQ(r5.trajectory->setpoints()[1].v_WB, Eigen::Vector3d::Zero());
  const PlanResponse r12 = parsePlanResponse(
      kHead + R"("status":"ok","trajectory":[[0,0,0,1,0,1,2,3,4,5,6,7],[1,1,0,1,0,1,2,3,4,5,6,7]]})", 1);
  const control::TrajectorySetpoint& s = r12.trajectory->setpoints()[0];
  EXPECT_EQ(s.v_WB, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(s.a_WB, Eigen::Vector3d(4, 5, 6));
  EXPECT_EQ(s.yaw_rate_rad_s, 7.0);
}

TEST(PlannerProtocol, NoPathKeepsItsReason) {
  const PlanResponse r = parsePlanResponse(kHead + R"("status":"no_path","reason":"walled in"})", 1);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.reason, "walled in");
  EXPECT_FALSE(r.path);
}

TEST(PlannerProtocol, BrokenResponsesAreRefusedWithWhatIsWrong) {
  const std::string ok_path = R"("status":"ok","path":[[0,0,1,0],[1,0,1,0]])";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "empty response"},
      {"   ", "empty response"},
      {"Planning... done", "invalid response: not JSON: Planning... done"},
      {kHead + R"("status":"ok","path":[[0,NaN,1,0],[1,0,1,0]]})", "NaN and Infinity are not JSON numbers"},
      {"[1,2,3]", "invalid response: not a JSON object"},
      {R"({"protocol":"other","version":1,"id":1})", "'protocol' is not \"tgnav-planner\""},
      {R"({"protocol":"tgnav-planner","version":2,"id":1})", "protocol version 2, expected 1"},
      {R"({"protocol":"tgnav-planner","version":"1","id":1})", "'version' is not an integer"},
      {R"({"protocol":"tgnav-planner","version":1,"id":2,)" + ok_path + "}", "'id' is 2, expected 1"},
      {R"({"protocol":"tgnav-planner","version":1,)" + ok_path + "}", "'id' is missing, expected 1"},
      {kHead + ok_path + R"(,"pth":1})", "unknown key 'pth'"},
      {kHead + R"("status":"done"})", "'status' is \"done\", expected \"ok\" or \"no_path\""},
      {kHead + R"("status":"ok"})", "give one of 'path' and 'trajectory'"},
      {kHead + R"("status":"ok","path":[[0,0,1,0]]})", "'path' has 1 points, at least 2 needed"},
      {kHead + R"("status":"ok","path":[[0,0,1,0],[1,0,1]]})", "path[1] has 3 numbers, path[0] has 4"},
      {kHead + R"("status":"ok","path":[[0,0,1],[1,0,1]]})", "path[0] has 3 numbers"},
      {kHead + R"("status":"ok","path":[[0,0,1,0],[1,null,1,0]]})", "path[1][1] is not a number"},
      {kHead + R"("status":"ok","path":[[0,0,1,0],[1,1e999,1,0]]})", "invalid response: not JSON"},  // overflows
      {kHead + R"("status":"ok","path":{"x":1}})", "'path' is not an array"},
      {kHead + R"("status":"ok","trajectory":[[0,0,0,1,0],[0,1,0,1,0]]})", "invalid response: trajectory:"},
      {kHead + R"("status":"ok","trajectory":[[0,0,0,1,0,1],[1,1,0,1,0,1]]})", "trajectory[0] has 6 numbers"},
      {kHead + ok_path + R"(,"scores":[1]})", "'scores' is not an array of 2 numbers"},
      {kHead + ok_path + R"(,"homology_class":-1})", "'homology_class' is not an integer >= 0"},
      {kHead + ok_path + R"(,"solve_time_s":-1})", "solve_time_s is negative"},
      {kHead + R"("status":"no_path","path":[[0,0,1,0],[1,0,1,0]]})", "status no_path with a route"},
  };
  for (const auto& [line, expected] : cases) {
    const std::string what = refusal(line);
    EXPECT_NE(what.find(expected), std::string::npos) << line << "\n -> " << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(PlannerProtocol, TooManyPointsAreRefusedByCount) {
  std::string line = kHead + R"("status":"ok","path":[)";
  for (std::size_t i = 0; i <= kMaxPathPoints; ++i) line += std::string(i ? "," : "") + "[0,0,1,0]";
  line += "]}";
  EXPECT_NE(refusal(line).find("'path' has 100001 points, at most 100000 allowed"), std::string::npos);
}

}  // namespace
}  // namespace tgnav::harness
