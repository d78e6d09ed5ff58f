// A trial's status is decided from its events, most severe first; each outcome's detail says
// what decided it.
#include "harness/run/trial_status.h"

#include <gtest/gtest.h>

namespace tgnav::harness {
namespace {

TrialEvents clean() {
  TrialEvents e;
  e.final_distance_to_goal_m = 0.1;
  e.goal_radius_m = 0.5;
  e.sim_time_s = 30.0;
  e.planned_end_s = 31.0;
  e.frames = 600;
  return e;
}

TrialEvent event(double t_s, const std::string& what) { return TrialEvent{t_s, Eigen::Vector3d(1, 2, 1), what}; }

TEST(DecideStatus, ACleanFlightToTheGoalIsASuccess) {
  const TrialVerdict v = decideStatus(clean());
  EXPECT_EQ(v.status, TrialStatus::kSuccess);
  EXPECT_EQ(v.detail, "reached the goal (0.10 m from it) with VO tracking all 600 frames");
}

TEST(DecideStatus, AnOnlineFlightWithoutARouteIsNoPathUnlessItCrashedOrLostTheVo) {
  TrialEvents e = clean();
  e.final_distance_to_goal_m = 4.0;
  e.no_path = event(12.5, "3 plans in a row found no route (last: no path: no_path)");
  TrialVerdict v = decideStatus(e);
  EXPECT_EQ(v.status, TrialStatus::kNoPath);
  EXPECT_STREQ(toString(v.status), "no_path");
  EXPECT_EQ(v.detail,
            "no path at t = 12.50 s at (1.00, 2.00, 1.00): 3 plans in a row found no route (last: no path: "
            "no_path)");
  e.vo_lost = event(10.0, "too few inliers");
  EXPECT_EQ(decideStatus(e).status, TrialStatus::kVoLost);
  e.collision = event(11.0, "wall");
  EXPECT_EQ(decideStatus(e).status, TrialStatus::kCollision);
}

TEST(DecideStatus, EndingOutsideTheGoalRadiusIsATimeout) {
  TrialEvents e = clean();
  e.final_distance_to_goal_m = 0.51;
  const TrialVerdict v = decideStatus(e);
  EXPECT_EQ(v.status, TrialStatus::kTimeout);
  EXPECT_EQ(v.detail, "the flight ended 0.51 m from the goal (goal radius 0.50 m)");
  e.final_distance_to_goal_m = 0.5;  // on the radius counts as reached
  EXPECT_EQ(decideStatus(e).status, TrialStatus::kSuccess);
}

// A VO that tracked to the end but ended further off than max_drift_ratio of the distance
// flown: drifted, not success. On the bound counts as success; a timeout beats drifted, and no
// goal error (the last frame untracked) cannot drift.
TEST(DecideStatus, GoalErrorBeyondTheDriftBoundIsDrifted) {
  TrialEvents e = clean();
  e.path_length_m = 40.0;
  e.max_drift_ratio = 0.01;
  e.goal_error_m = 0.41;
  TrialVerdict v = decideStatus(e);
  EXPECT_EQ(v.status, TrialStatus::kDrifted);
  EXPECT_STREQ(toString(v.status), "drifted");
  EXPECT_EQ(v.detail,
            "reached the goal (0.10 m from it), but the VO ended 0.41 m off, 1.02 % of the 40.00 m flown (bound "
            "1.00 %)");
  e.goal_error_m = 0.4;
  EXPECT_EQ(decideStatus(e).status, TrialStatus::kSuccess);
  e.goal_error_m = 3.0;
  e.final_distance_to_goal_m = 0.6;
  EXPECT_EQ(decideStatus(e).status, TrialStatus::kTimeout);
  e = clean();
  e.path_length_m = 40.0;
  EXPECT_EQ(decideStatus(e).status, TrialStatus::kSuccess);
}

TEST(DecideStatus, VoLossBeatsTimeoutAndSuccess) {
  TrialEvents e = clean();
  e.vo_lost = event(4.0, "17 matches < 30");
  e.final_distance_to_goal_m = 3.0;
  const TrialVerdict v = decideStatus(e);
  EXPECT_EQ(v.status, TrialStatus::kVoLost);
  EXPECT_EQ(v.detail, "VO lost at t = 4.00 s at (1.00, 2.00, 1.00): 17 matches < 30");
}

TEST(DecideStatus, DivergenceAndLeavingTheSceneBeatVoLoss) {
  TrialEvents e = clean();
  e.vo_lost = event(4.0, "lost");
  e.flight_completed = false;
  e.flight_reason = "tilt 95 deg";
  TrialVerdict v = decideStatus(e);
  EXPECT_EQ(v.status, TrialStatus::kDiverged);
  EXPECT_EQ(v.detail, "tilt 95 deg at t = 30.00 s, after VO was lost at t = 4.00 s");
  e.flight_completed = true;
  e.left_bounds = true;
  e.flight_reason = "left the scene at (9.00, 0.00, 1.00)";
  v = decideStatus(e);
  EXPECT_EQ(v.status, TrialStatus::kDiverged);
  EXPECT_EQ(v.detail.rfind("left the scene", 0), 0u) << v.detail;
}

TEST(DecideStatus, CollisionBeatsDivergence) {
  TrialEvents e = clean();
  e.flight_completed = false;
  e.flight_reason = "collision";
  e.collision = event(12.5, "crate_n1");
  const TrialVerdict v = decideStatus(e);
  EXPECT_EQ(v.status, TrialStatus::kCollision);
  EXPECT_EQ(v.detail, "collision with crate_n1 at t = 12.50 s at (1.00, 2.00, 1.00)");
}

TEST(DecideStatus, AnInterruptionBeatsEverything) {
  TrialEvents e = clean();
  e.collision = event(1.0, "wall");
  e.vo_lost = event(0.5, "lost");
  e.flight_completed = false;
  e.interrupted = true;
  e.sim_time_s = 2.0;
  const TrialVerdict v = decideStatus(e);
  EXPECT_EQ(v.status, TrialStatus::kInterrupted);
  EXPECT_EQ(v.detail, "interrupted at t = 2.00 s of 31.00 s");
  EXPECT_STREQ(toString(v.status), "incomplete");
}

}  // namespace
}  // namespace tgnav::harness
