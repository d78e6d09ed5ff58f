// Look, then fly (harness/run/explore.h): the search over (cell, yaw) in observed space with
// trackable views, on small synthetic maps.
#include "harness/run/explore.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>

#include "harness/run/look_columns.h"
#include "planner/feature_map.h"
#include "tests/harness/test_util.h"

namespace tgnav::harness {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kHeight = 1.0;

// The map (test::texturedWall(): the wall at x = 3.5, free space observed for x in [0, observed_to),
// everything else unknown) as the planners' voxel map (unknown space free, as online), and a rater
// on it.
struct Room {
  explicit Room(double observed_to, bool landmarks = true) : map(test::texturedWall(observed_to, landmarks)) {}
  planner::FeatureMap map;
  planner::VoxelMap voxels{map, Eigen::Vector3d(-0.5, -2.5, 0), Eigen::Vector3d(4.5, 4.5, 2), 0.3, 1.7, true};
  planner::VisibilityConfig visibility;
  planner::InformationConfig information;
  ViewRater rater{voxels, visibility, information};
};

LookConfig config() {
  LookConfig c;
  c.flight_height_m = kHeight;
  c.half_hfov_rad = 0.5 * planner::VisibilityConfig{}.hfov_rad;
  return c;
}

const planner::Pose4 kStart{Eigen::Vector3d(0.6, 0.0, kHeight), 0.0};  // facing the wall

// A goal north, beyond the observed room (y >= 1 is unknown), and the way on that runs there.
const Eigen::Vector3d kNorthGoal(2.5, 3.5, kHeight);
std::vector<Eigen::Vector3d> northWayOn() {
  std::vector<Eigen::Vector3d> way_on;
  for (double y = 1.2; y <= 3.5; y += 0.2) way_on.emplace_back(2.5, y, kHeight);
  return way_on;
}

bool observedFree(const planner::VoxelMap& voxels, const Eigen::Vector3d& p) {
  return voxels.observed(p) && voxels.state(p) == planner::VoxelState::kFree;
}

TEST(LookThenFly, FliesToAGoalInObservedSpaceWithEveryViewTrackable) {
  Room room(3.4);
  const Eigen::Vector3d goal(2.5, 0.5, kHeight);
  const LookPlan plan =
      planLook(room.voxels, room.rater, kStart, goal, {}, {}, LookMemory{{kStart.p_WB}, {}, {}, {}}, config());
  ASSERT_TRUE(plan.goal);
  ASSERT_GE(plan.path.size(), 2U);
  EXPECT_EQ(plan.path.front().p_WB, kStart.p_WB);
  EXPECT_EQ(plan.path.back().p_WB, goal);
  for (const planner::Pose4& p : plan.path) {
    EXPECT_TRUE(observedFree(room.voxels, p.p_WB)) << p.p_WB.transpose();
    room.rater.moveTo(p.p_WB);
    EXPECT_EQ(room.rater.shortfall(p.yaw_rad), 0.0) << p.p_WB.transpose() << " yaw " << p.yaw_rad;
  }
  std::cout << "[ figure   ] to the goal: " << plan.path.size() << " poses, cost " << plan.cost_m << " m, "
            << plan.states << " states\n";
}

TEST(LookThenFly, TheGoalCountsAsFreeThoughSpaceBeyondItWasNeverObserved) {
  Room room(3.4);
  // Just inside the observed room (y >= 1 is unknown): its cell lies within the robot radius of
  // space never observed, so only the goal's own disc, free as the mission gives it, lets the
  // search enter it.
  const Eigen::Vector3d goal(2.5, 0.85, kHeight);
  const LookMemory memory{{kStart.p_WB}, {}, {}, {}};
  const LookColumns without(room.voxels, config(), memory);
  ASSERT_FALSE(without.clear(goal.head<2>(), config().robot_radius_m, config().known_m));
  const LookPlan plan = planLook(room.voxels, room.rater, kStart, goal, {}, {}, memory, config());
  ASSERT_TRUE(plan.goal);
  ASSERT_GE(plan.path.size(), 2U);
  EXPECT_EQ(plan.path.back().p_WB, goal);
  for (const planner::Pose4& p : plan.path) {
    EXPECT_TRUE(observedFree(room.voxels, p.p_WB)) << p.p_WB.transpose();
    room.rater.moveTo(p.p_WB);
    EXPECT_EQ(room.rater.shortfall(p.yaw_rad), 0.0) << p.p_WB.transpose() << " yaw " << p.yaw_rad;
  }
  // Farther into the unknown than the goal's disc reaches, it does not.
  const LookPlan beyond =
      planLook(room.voxels, room.rater, kStart, Eigen::Vector3d(2.5, 1.9, kHeight), {}, {}, memory, config());
  EXPECT_FALSE(beyond.goal);
}

TEST(LookThenFly, LooksAtTheUnknownWayOnFromAViewThatKeepsTheWallInSight) {
  Room room(3.4);
  // The goal lies north, beyond the observed room (y >= 1 is unknown): the way on runs there.
  const Eigen::Vector3d goal = kNorthGoal;
  const std::vector<Eigen::Vector3d> way_on = northWayOn();
  const LookPlan plan =
      planLook(room.voxels, room.rater, kStart, goal, {}, way_on, LookMemory{{kStart.p_WB}, {}, {}, {}}, config());
  ASSERT_FALSE(plan.goal);
  ASSERT_GE(plan.path.size(), 2U);
  EXPECT_TRUE(plan.way);
  EXPECT_GT(plan.seen, 0);
  for (const planner::Pose4& p : plan.path) {
    EXPECT_TRUE(observedFree(room.voxels, p.p_WB)) << p.p_WB.transpose();
    EXPECT_LE(p.p_WB.y(), 1.0 - config().known_m) << "within the robot radius of unknown space";
    room.rater.moveTo(p.p_WB);
    EXPECT_EQ(room.rater.shortfall(p.yaw_rad), 0.0) << p.p_WB.transpose() << " yaw " << p.yaw_rad;
  }
  // The look pose turns toward the way on (north of the wall's normal), not at it.
  const planner::Pose4& look = plan.path.back();
  const double yaw = std::remainder(look.yaw_rad, 2.0 * M_PI);
  EXPECT_GT(yaw, 5.0 * kDeg);
  EXPECT_LT(yaw, 90.0 * kDeg);
  std::cout << "[ figure   ] look pose (" << look.p_WB.x() << ", " << look.p_WB.y() << ") yaw " << yaw / kDeg
            << " deg sees " << plan.seen << " unknown cells of the way on, cost " << plan.cost_m << " m\n";
  // Flown there, it is not chosen again.
  const LookPlan again =
      planLook(room.voxels, room.rater, kStart, goal, {}, way_on, LookMemory{{kStart.p_WB}, {look}, {}, {}}, config());
  ASSERT_GE(again.path.size(), 2U);
  const planner::Pose4& other = again.path.back();
  EXPECT_TRUE((other.p_WB - look.p_WB).head<2>().norm() > 0.3 ||
              std::abs(std::remainder(other.yaw_rad - look.yaw_rad, 2.0 * M_PI)) > 16.0 * kDeg);
}

TEST(LookThenFly, AdvancesAlongTheRouteWhereNoReachedViewObservesTheWayOn) {
  Room room(3.4);
  // The way on runs behind the wall (x > 3.55, level with it): every line of sight to it crosses
  // the wall. The route's observed part runs east from the start.
  const Eigen::Vector3d goal(4.2, -1.0, kHeight);
  const std::vector<Eigen::Vector3d> route{kStart.p_WB, Eigen::Vector3d(2.6, 0.0, kHeight)};
  std::vector<Eigen::Vector3d> way_on;
  for (double y = 0.0; y >= -1.0; y -= 0.2) way_on.emplace_back(4.2, y, kHeight);
  // Without the option it looks at other unknown space.
  const LookPlan look =
      planLook(room.voxels, room.rater, kStart, goal, route, way_on, LookMemory{{kStart.p_WB}, {}, {}, {}}, config());
  ASSERT_GE(look.path.size(), 2U);
  EXPECT_FALSE(look.way);
  EXPECT_FALSE(look.advance);
  EXPECT_GT(look.seen, 0);
  LookConfig c = config();
  c.advance = true;
  const LookPlan plan =
      planLook(room.voxels, room.rater, kStart, goal, route, way_on, LookMemory{{kStart.p_WB}, {}, {}, {}}, c);
  ASSERT_GE(plan.path.size(), 2U);
  EXPECT_TRUE(plan.advance);
  EXPECT_FALSE(plan.goal);
  EXPECT_FALSE(plan.way);
  EXPECT_LT((plan.path.back().p_WB - route.back()).head<2>().norm(), c.cell_m) << plan.path.back().p_WB.transpose();
  for (const planner::Pose4& p : plan.path) {
    EXPECT_TRUE(observedFree(room.voxels, p.p_WB)) << p.p_WB.transpose();
    room.rater.moveTo(p.p_WB);
    EXPECT_EQ(room.rater.shortfall(p.yaw_rad), 0.0) << p.p_WB.transpose() << " yaw " << p.yaw_rad;
  }
  std::cout << "[ figure   ] advanced to (" << plan.path.back().p_WB.x() << ", " << plan.path.back().p_WB.y()
            << "), cost " << plan.cost_m << " m; without the option the look pose was (" << look.path.back().p_WB.x()
            << ", " << look.path.back().p_WB.y() << ")\n";
  // Flown there, it is not chosen again: the next cell back along the route is.
  const LookPlan again = planLook(room.voxels, room.rater, kStart, goal, route, way_on,
                                  LookMemory{{kStart.p_WB}, {plan.path.back()}, {}, {}}, c);
  ASSERT_TRUE(again.advance);
  EXPECT_NE(again.path.back().p_WB, plan.path.back().p_WB);
  // A route observed for less than advance_min_m: no advance, but a view of the unknown space near
  // the way on (south of the wall's end), not of any.
  const std::vector<Eigen::Vector3d> short_route{kStart.p_WB, kStart.p_WB + Eigen::Vector3d(0.3, 0.0, 0.0)};
  const LookPlan other =
      planLook(room.voxels, room.rater, kStart, goal, short_route, way_on, LookMemory{{kStart.p_WB}, {}, {}, {}}, c);
  EXPECT_FALSE(other.advance);
  ASSERT_TRUE(other.near);
  ASSERT_FALSE(other.watched.empty());
  for (const Eigen::Vector2d& w : other.watched) {
    EXPECT_TRUE(std::any_of(way_on.begin(), way_on.end(), [&](const Eigen::Vector3d& p) {
      return (p.head<2>() - w).norm() <= c.near_m + 1e-9;
    })) << w.transpose();
  }
  EXPECT_GE(other.seen, static_cast<int>(std::ceil(M_PI * c.robot_radius_m * c.robot_radius_m /
                                                   std::pow(room.voxels.resolution(), 2))));
}

TEST(LookThenFly, ProbesTheViewOfTheWayOnRatedLeastShortWhereItCannotAdvance) {
  Room room(3.4);
  // The way on runs north of the observed room (y >= 1 is unknown), at its west side: only views
  // facing away from the wall observe it, and the model rates every such view short. (It is long
  // enough that what it leaves unknown beyond the goal's disc, free as the mission gives it, is more
  // than a footprint.)
  const Eigen::Vector3d goal(0.2, 2.7, kHeight);
  std::vector<Eigen::Vector3d> way_on;
  for (int i = 0; i < 9; ++i) way_on.emplace_back(0.2, 1.1 + 0.2 * i, kHeight);  // 1.6 m
  const std::vector<Eigen::Vector3d> route{kStart.p_WB, kStart.p_WB + Eigen::Vector3d(0.3, 0.0, 0.0)};
  LookConfig c = config();
  c.advance = true;
  const LookMemory memory{{kStart.p_WB}, {}, {}, {}};
  const LookPlan near = planLook(room.voxels, room.rater, kStart, goal, route, way_on, memory, c);
  EXPECT_FALSE(near.way);
  EXPECT_FALSE(near.probe);
  c.probe = true;
  const LookPlan plan = planLook(room.voxels, room.rater, kStart, goal, route, way_on, memory, c);
  ASSERT_TRUE(plan.probe);
  EXPECT_TRUE(plan.way);
  EXPECT_FALSE(plan.advance);
  EXPECT_FALSE(plan.near);
  ASSERT_GE(plan.path.size(), 2U);
  const int footprint =
      static_cast<int>(std::ceil(M_PI * c.robot_radius_m * c.robot_radius_m / std::pow(room.voxels.resolution(), 2)));
  EXPECT_GE(plan.seen, footprint);
  ASSERT_FALSE(plan.watched.empty());
  for (const Eigen::Vector2d& w : plan.watched) {
    EXPECT_TRUE(std::any_of(way_on.begin(), way_on.end(), [&](const Eigen::Vector3d& p) {
      return (p.head<2>() - w).norm() <= c.way_clear_m + 1e-9;
    })) << w.transpose();
  }
  // Every pose up to the last is flown with a trackable view in observed space; the last turns, where
  // the one before it is, to the probed view, which the model rates short.
  for (std::size_t i = 0; i < plan.path.size(); ++i) {
    const planner::Pose4& p = plan.path[i];
    EXPECT_TRUE(observedFree(room.voxels, p.p_WB)) << p.p_WB.transpose();
    room.rater.moveTo(p.p_WB);
    if (i + 1 < plan.path.size()) {
      EXPECT_EQ(room.rater.shortfall(p.yaw_rad), 0.0) << i;
    }
  }
  const planner::Pose4& probe = plan.path.back();
  EXPECT_EQ(probe.p_WB, plan.path[plan.path.size() - 2].p_WB);
  room.rater.moveTo(probe.p_WB);
  const double short_by = room.rater.shortfall(probe.yaw_rad);
  EXPECT_GT(short_by, 0.0);
  std::cout << "[ figure   ] probe from (" << probe.p_WB.x() << ", " << probe.p_WB.y() << ") yaw "
            << std::remainder(probe.yaw_rad, 2.0 * M_PI) / kDeg << " deg, short by " << short_by << ", sees "
            << plan.seen << " columns of the way on; without the option: near " << near.near << ", seen " << near.seen
            << "\n";
  // A way on longer than near_m is not the last stretch: it looks near it instead.
  LookConfig far = c;
  far.near_m = 1.5;  // the way on is 1.6 m long
  EXPECT_FALSE(planLook(room.voxels, room.rater, kStart, goal, route, way_on, memory, far).probe);
  // Where the guard tripped on it, that view is ruled out: the next probe is another.
  GuardEvent trip;
  trip.wedge.apex = probe.p_WB;
  trip.good_yaw_rad = plan.path[plan.path.size() - 2].yaw_rad;
  trip.yaw_rad = probe.yaw_rad;
  const LookPlan next =
      planLook(room.voxels, room.rater, kStart, goal, route, way_on, LookMemory{{kStart.p_WB}, {}, {}, {trip}}, c);
  ASSERT_TRUE(next.probe);
  const planner::Pose4& other = next.path.back();
  EXPECT_FALSE(trippedView(trip, other.p_WB.head<2>(), other.yaw_rad, c.tripped_m, c.half_hfov_rad));
}

TEST(LookThenFly, ColumnsGivenUpNoLongerDrawALook) {
  Room room(3.4);
  const Eigen::Vector3d goal = kNorthGoal;
  const std::vector<Eigen::Vector3d> way_on = northWayOn();
  const LookPlan first =
      planLook(room.voxels, room.rater, kStart, goal, {}, way_on, LookMemory{{kStart.p_WB}, {}, {}, {}}, config());
  ASSERT_TRUE(first.way);
  ASSERT_GE(first.watched.size(), static_cast<std::size_t>(first.seen));
  for (const Eigen::Vector2d& c : first.watched) {
    EXPECT_FALSE(room.voxels.observed(Eigen::Vector3d(c.x(), c.y(), kHeight))) << c.transpose();
  }
  // Given up on, the columns it watched count for no view: the next look watches others.
  const LookPlan next = planLook(room.voxels, room.rater, kStart, goal, {}, way_on,
                                 LookMemory{{kStart.p_WB}, {}, first.watched, {}}, config());
  for (const Eigen::Vector2d& c : next.watched) {
    EXPECT_TRUE(std::none_of(first.watched.begin(), first.watched.end(), [&](const Eigen::Vector2d& w) {
      return (w - c).norm() < 1e-9;
    })) << c.transpose();
  }
  std::cout << "[ figure   ] the first look watches " << first.watched.size() << " columns (" << first.seen
            << " of the way on by its rays); with those given up the next watches " << next.watched.size() << "\n";
}

TEST(LookThenFly, TheColumnsWatchedAreGivenUpAfterTheLooksSet) {
  Room room(3.4);
  const LookPlan first = planLook(room.voxels, room.rater, kStart, kNorthGoal, {}, northWayOn(),
                                  LookMemory{{kStart.p_WB}, {}, {}, {}}, config());
  ASSERT_TRUE(first.way);
  const double res = room.voxels.resolution();
  LookWatch watch;
  watch.note(first.watched, res);
  EXPECT_TRUE(watch.givenUp(2).empty());
  EXPECT_TRUE(watch.givenUp(0).empty());  // 0: never given up
  watch.note(first.watched, res);
  // Given up after two looks: each watched column, in its own column of the search's grid (not one
  // off, at a column's boundary: the defect fixed in 63e55c9).
  const std::vector<Eigen::Vector2d> given_up = watch.givenUp(2);
  ASSERT_EQ(given_up.size(), first.watched.size());
  const LookColumns columns(room.voxels, config(), LookMemory{{kStart.p_WB}, {}, {}, {}});
  const auto cells = [&](const std::vector<Eigen::Vector2d>& points) {
    std::vector<std::pair<int, int>> out;
    for (const Eigen::Vector2d& p : points) out.push_back(columns.cellOf(p));
    std::sort(out.begin(), out.end());
    return out;
  };
  EXPECT_EQ(cells(given_up), cells(first.watched));
  const LookColumns after(room.voxels, config(), LookMemory{{kStart.p_WB}, {}, given_up, {}});
  for (const Eigen::Vector2d& c : first.watched) {
    const auto [i, j] = after.cellOf(c);
    EXPECT_FALSE(after.toObserve(after.index(i, j))) << c.transpose();
  }
}

TEST(LookThenFly, TheFloorCalibratedOnTheTrackedViewLetsItMove) {
  Room room(3.4);
  room.rater.moveTo(kStart.p_WB);
  const double expected = room.rater.detections(kStart.yaw_rad);
  ASSERT_GT(expected, 0.0);
  // A floor no view reaches: held at the start.
  room.rater.setDetectionFloor(10.0 * expected);
  const Eigen::Vector3d goal(2.5, 0.5, kHeight);
  const LookMemory memory{{kStart.p_WB}, {}, {}, {}};
  const LookPlan held = planLook(room.voxels, room.rater, kStart, goal, {}, {}, memory, config());
  EXPECT_FALSE(held.goal);
  EXPECT_EQ(held.states, 1);
  EXPECT_EQ(held.floor, 10.0 * expected);
  // The VO tracks the start's view with 4 times the guard's inliers: the floor drops to a quarter
  // of what the model expects there, and the goal is reached.
  room.rater.setDetectionFloor(10.0 * expected);
  LookConfig c = config();
  c.floor_inliers = 150;
  c.tracked_inliers = 600;
  const LookPlan plan = planLook(room.voxels, room.rater, kStart, goal, {}, {}, memory, c);
  EXPECT_NEAR(plan.floor, 0.25 * expected, 1e-9);
  EXPECT_TRUE(plan.goal);
  // Never raised: a low floor stays.
  room.rater.setDetectionFloor(1.0);
  EXPECT_EQ(planLook(room.voxels, room.rater, kStart, goal, {}, {}, memory, c).floor, 1.0);
  std::cout << "[ figure   ] the model expects " << expected << " detections of the start's view; floor "
            << 10.0 * expected << " holds it (" << held.states << " state), calibrated " << plan.floor
            << " reaches the goal\n";
}

// LookConfig::hold_margin: the view a look stops at expects the floor times (1 + margin); the
// views on the way there, the floor.
TEST(LookThenFly, TheViewALookStopsAtExpectsTheHoldMarginOverTheFloor) {
  Room room(3.4);
  room.rater.moveTo(kStart.p_WB);
  const double floor = 0.3 * room.rater.detections(kStart.yaw_rad);
  room.rater.setDetectionFloor(floor);
  const LookMemory memory{{kStart.p_WB}, {}, {}, {}};
  const auto endView = [&](const LookPlan& plan) {
    room.rater.moveTo(plan.path.back().p_WB);
    return room.rater.detections(plan.path.back().yaw_rad);
  };
  const LookPlan plain = planLook(room.voxels, room.rater, kStart, kNorthGoal, {}, northWayOn(), memory, config());
  ASSERT_GE(plain.path.size(), 2U);
  const double plain_end = endView(plain);
  // A margin the plain look's end view falls short of by one detection: another view is held.
  LookConfig c = config();
  c.hold_margin = (plain_end + 1.0) / floor - 1.0;
  const LookPlan held = planLook(room.voxels, room.rater, kStart, kNorthGoal, {}, northWayOn(), memory, c);
  ASSERT_GE(held.path.size(), 2U);
  EXPECT_TRUE(held.way);
  EXPECT_GE(endView(held), plain_end + 1.0);
  for (const planner::Pose4& p : held.path) {
    room.rater.moveTo(p.p_WB);
    EXPECT_EQ(room.rater.shortfall(p.yaw_rad), 0.0) << p.p_WB.transpose() << " yaw " << p.yaw_rad;
  }
  // A margin no view reaches: no look, where the search still moves (the floor alone).
  c.hold_margin = 10.0;
  const LookPlan none = planLook(room.voxels, room.rater, kStart, kNorthGoal, {}, northWayOn(), memory, c);
  EXPECT_TRUE(none.path.empty());
  EXPECT_GT(none.states, 1);
  std::cout << "[ figure   ] floor " << floor << ": the plain look ends at a view expecting " << plain_end
            << " detections, with the margin " << endView(held) << " (cost " << plain.cost_m << " -> " << held.cost_m
            << " m)\n";
}

// LookConfig::along: of the looks that qualify, the one farthest along the route, not the nearest.
TEST(LookThenFly, TheLookAlongTheRouteIsTheFarthestThatQualifies) {
  Room room(3.4);
  const LookMemory memory{{kStart.p_WB}, {}, {}, {}};
  // The route east through the observed room, then north into the unknown way on.
  const std::vector<Eigen::Vector3d> route{kStart.p_WB, Eigen::Vector3d(2.5, 0.0, kHeight),
                                           Eigen::Vector3d(2.5, 1.0, kHeight)};
  const RouteStations stations(route, 0.1);
  const auto alongEnd = [&](const LookPlan& plan) { return stations.along(plan.path.back().p_WB.head<2>()); };
  const LookPlan nearest = planLook(room.voxels, room.rater, kStart, kNorthGoal, route, northWayOn(), memory, config());
  LookConfig c = config();
  c.along = true;
  const LookPlan along = planLook(room.voxels, room.rater, kStart, kNorthGoal, route, northWayOn(), memory, c);
  ASSERT_GE(nearest.path.size(), 2U);
  ASSERT_GE(along.path.size(), 2U);
  EXPECT_TRUE(nearest.way);
  EXPECT_TRUE(along.way);
  // Farther along the route, at a greater cost, still seeing at least half as much.
  EXPECT_GT(alongEnd(along), alongEnd(nearest) + c.cell_m);
  EXPECT_GT(along.cost_m, nearest.cost_m);
  EXPECT_GE(2 * along.seen, nearest.seen);
  for (const planner::Pose4& p : along.path) {
    EXPECT_TRUE(observedFree(room.voxels, p.p_WB)) << p.p_WB.transpose();
    room.rater.moveTo(p.p_WB);
    EXPECT_EQ(room.rater.shortfall(p.yaw_rad), 0.0) << p.p_WB.transpose() << " yaw " << p.yaw_rad;
  }
  // Without a route, every look is as far along (0): the nearest, as without the option.
  const LookPlan no_route = planLook(room.voxels, room.rater, kStart, kNorthGoal, {}, northWayOn(), memory, c);
  ASSERT_FALSE(no_route.path.empty());
  EXPECT_EQ(no_route.path.back().p_WB, nearest.path.back().p_WB);
  EXPECT_EQ(no_route.path.back().yaw_rad, nearest.path.back().yaw_rad);
  std::cout << "[ figure   ] the nearest look ends " << alongEnd(nearest) << " m along the route (cost "
            << nearest.cost_m << " m, " << nearest.seen << " columns), the look along it " << alongEnd(along)
            << " m (cost " << along.cost_m << " m, " << along.seen << " columns)\n";
}

TEST(LookThenFly, RouteStationsMeasureTheDistanceAlongTheRouteOfItsNearestPoint) {
  const RouteStations stations({Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 0, 1), Eigen::Vector3d(1, 2, 1)}, 0.25);
  ASSERT_EQ(stations.stations().size(), 13U);  // 1 + 4 + 8
  EXPECT_DOUBLE_EQ(stations.stations().back().first, 3.0);
  EXPECT_DOUBLE_EQ(stations.along(Eigen::Vector2d(0.5, -0.3)), 0.5);
  EXPECT_DOUBLE_EQ(stations.along(Eigen::Vector2d(1.4, 1.0)), 2.0);
  EXPECT_DOUBLE_EQ(stations.along(Eigen::Vector2d(5.0, 5.0)), 3.0);
  EXPECT_DOUBLE_EQ(RouteStations({}, 0.25).along(Eigen::Vector2d(1.0, 1.0)), 0.0);
}

TEST(LookThenFly, FindsNothingWhereNoViewIsTrackable) {
  Room bare(3.4, false);
  const Eigen::Vector3d goal(2.5, 3.5, kHeight);
  const std::vector<Eigen::Vector3d> way_on{Eigen::Vector3d(2.5, 2.0, kHeight)};
  const LookPlan plan =
      planLook(bare.voxels, bare.rater, kStart, goal, {}, way_on, LookMemory{{kStart.p_WB}, {}, {}, {}}, config());
  EXPECT_TRUE(plan.path.empty());
  EXPECT_FALSE(plan.goal);
  EXPECT_EQ(plan.states, 1);  // the start alone: no other view is trackable
}

TEST(LookThenFly, CountsNoLandmarkAcrossUnknownSpace) {
  // Free space observed only to x = 2: between it and the wall lies unknown space, where something
  // not mapped yet may hide the wall. The voxel map's line of sight passes through it, so a plain
  // rater rates the view of the wall trackable; the search does not.
  Room room(2.0);
  room.rater.moveTo(Eigen::Vector3d(1.0, 0.0, kHeight));
  ASSERT_EQ(room.rater.shortfall(0.0), 0.0);
  const Eigen::Vector3d goal(1.5, 0.0, kHeight);
  const LookPlan plan =
      planLook(room.voxels, room.rater, kStart, goal, {}, {}, LookMemory{{kStart.p_WB}, {}, {}, {}}, config());
  EXPECT_FALSE(plan.goal);
  EXPECT_TRUE(plan.path.empty());
}

TEST(LookThenFly, ViewsTheGuardTrippedOnAreRuledOutNearWhereItTripped) {
  GuardEvent e;
  e.good_yaw_rad = 0.0;
  e.yaw_rad = 0.5;  // a turn counter-clockwise
  e.wedge.apex = Eigen::Vector3d(1.0, 1.0, kHeight);
  const Eigen::Vector2d here(1.2, 1.0);
  EXPECT_FALSE(trippedView(e, here, 0.1, 0.5, 0.6));  // less than halfway
  EXPECT_TRUE(trippedView(e, here, 0.3, 0.5, 0.6));
  EXPECT_TRUE(trippedView(e, here, 1.05, 0.5, 0.6));  // up to 0.6 rad beyond
  EXPECT_FALSE(trippedView(e, here, 1.2, 0.5, 0.6));
  EXPECT_FALSE(trippedView(e, Eigen::Vector2d(1.6, 1.0), 0.3, 0.5, 0.6));  // farther than 0.5 m
  e.yaw_rad = -0.5;                                                        // clockwise
  EXPECT_TRUE(trippedView(e, here, -0.3, 0.5, 0.6));
  EXPECT_FALSE(trippedView(e, here, 0.3, 0.5, 0.6));
  // With the search: turned back from a trip at the start, the wall stays trackable, but the
  // views past it are not flown to.
  Room room(3.4);
  GuardEvent at_start;
  at_start.good_yaw_rad = 0.0;
  at_start.yaw_rad = 0.4;
  at_start.wedge.apex = kStart.p_WB;
  const Eigen::Vector3d goal = kNorthGoal;
  const std::vector<Eigen::Vector3d> way_on = northWayOn();
  const auto tripped = [&](const LookPlan& plan) {
    return std::any_of(plan.path.begin(), plan.path.end(), [&](const planner::Pose4& p) {
      return trippedView(at_start, p.p_WB.head<2>(), p.yaw_rad, config().tripped_m, config().half_hfov_rad);
    });
  };
  // Without the trip the look pose is one of those views.
  ASSERT_TRUE(tripped(
      planLook(room.voxels, room.rater, kStart, goal, {}, way_on, LookMemory{{kStart.p_WB}, {}, {}, {}}, config())));
  const LookPlan plan = planLook(room.voxels, room.rater, kStart, goal, {}, way_on,
                                 LookMemory{{kStart.p_WB}, {}, {}, {at_start}}, config());
  ASSERT_GE(plan.path.size(), 2U);
  EXPECT_FALSE(tripped(plan));
  for (const planner::Pose4& p : plan.path) {
    EXPECT_FALSE(trippedView(at_start, p.p_WB.head<2>(), p.yaw_rad, config().tripped_m, config().half_hfov_rad))
        << p.p_WB.transpose();
  }
}

// A look guard's trip (GuardEvent::predicted) rules out the view it foresaw ahead, near its apex,
// not the cell the vehicle held in: from there the search turns and moves on. Ruling out the held
// cell too, every move (its neighbours lie within tripped_m of the apex) and every turn (within
// half the field of the trip's yaw) from the start was ruled out, and nothing was reached.
TEST(LookThenFly, ALookGuardsTripLeavesTheHeldCellFreeToTurnAndMoveFrom) {
  Room room(3.4);
  GuardEvent ahead;
  ahead.yaw_rad = ahead.good_yaw_rad = kStart.yaw_rad;
  ahead.turning = false;
  ahead.predicted_detections = 100.0;
  ahead.wedge.apex = kStart.p_WB + Eigen::Vector3d(0.2, 0.0, 0.0);  // 0.2 m ahead, toward the wall
  const LookMemory memory{{kStart.p_WB}, {}, {}, {ahead}};
  const LookPlan plan = planLook(room.voxels, room.rater, kStart, kNorthGoal, {}, northWayOn(), memory, config());
  ASSERT_GE(plan.path.size(), 2U);
  EXPECT_GT(plan.states, 1);
  for (std::size_t i = 1; i < plan.path.size(); ++i) {
    const planner::Pose4& p = plan.path[i];
    const bool held_cell = (p.p_WB - kStart.p_WB).head<2>().norm() < 1e-9;
    EXPECT_TRUE(held_cell ||
                !trippedView(ahead, p.p_WB.head<2>(), p.yaw_rad, config().tripped_m, config().half_hfov_rad))
        << p.p_WB.transpose() << " yaw " << p.yaw_rad;
  }
  // The same trip by the tracking guard (not foreseen) still rules out the held cell's views: the
  // inliers said the view there was not trackable.
  GuardEvent still = ahead;
  still.predicted_detections = -1.0;
  const LookPlan boxed = planLook(room.voxels, room.rater, kStart, kNorthGoal, {}, northWayOn(),
                                  LookMemory{{kStart.p_WB}, {}, {}, {still}}, config());
  std::cout << "[ figure   ] after a look guard's trip 0.2 m ahead: " << plan.states << " states, look at ("
            << plan.path.back().p_WB.x() << ", " << plan.path.back().p_WB.y()
            << "); after the same trip not foreseen: " << boxed.states << " states\n";
  EXPECT_EQ(boxed.states, 1);
}

TEST(LookThenFly, TheLooksStallWhereNoRouteHasBeenHalfAMetreShorterForAWhile) {
  RouteProgress progress(0.5);
  EXPECT_EQ(progress.note(4.0, 12.0), 0.0);    // the first plan: progress from here
  EXPECT_EQ(progress.note(6.0, 11.6), 2.0);    // 0.4 m shorter: not yet
  EXPECT_EQ(progress.note(8.0, 11.5), 4.0);    // 0.5 m: not more than the margin
  EXPECT_EQ(progress.note(10.0, 11.4), 0.0);   // 0.6 m shorter than 12, step by step: progress
  EXPECT_EQ(progress.note(12.0, 14.0), 2.0);   // a longer route (a wedge blocked the way) is none
  EXPECT_EQ(progress.note(70.0, 11.0), 60.0);  // 0.4 m shorter than 11.4: stalled for 60 s
  EXPECT_EQ(progress.note(72.0, 10.8), 0.0);
}

}  // namespace
}  // namespace tgnav::harness
