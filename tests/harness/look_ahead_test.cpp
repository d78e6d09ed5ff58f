// The camera's yaw in an online trial (harness/run/look_ahead.h): smoothing within a yaw-rate
// limit that keeps the first yaw, the rate limit applied to a spliced trajectory, and the turn
// toward the way ahead that keeps the view trackable; the prior for unseen surfaces the perception
// model rates those views with (harness/run/unseen_prior.h); and the check that the path ahead is
// blocked (occupiedWithin, harness/run/incremental_map.h).
#include "harness/run/look_ahead.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <vector>

#include "harness/run/frame_prediction.h"
#include "harness/run/incremental_map.h"
#include "harness/run/online_planning.h"
#include "harness/run/unseen_prior.h"
#include "planner/feature_map.h"
#include "planner/perception.h"
#include "planner/track_model.h"
#include "planner/voxel_map.h"
#include "tests/harness/test_util.h"

namespace tgnav::harness {
namespace {

// Setpoints every 0.01 s over `duration_s`, flying along the x axis from the origin at speed_mps
// (0: at rest there), yaw(t).
template <typename Yaw>
control::SetpointTrajectory along(double duration_s, double speed_mps, const Yaw& yaw) {
  std::vector<double> t;
  std::vector<control::TrajectorySetpoint> sp;
  for (int i = 0; i * 0.01 <= duration_s + 1e-9; ++i) {
    t.push_back(i * 0.01);
    control::TrajectorySetpoint s;
    s.p_WB.x() = speed_mps * i * 0.01;
    s.v_WB.x() = speed_mps;
    s.yaw_rad = yaw(i * 0.01);
    sp.push_back(s);
  }
  return control::SetpointTrajectory(t, sp);
}

template <typename Yaw>
control::SetpointTrajectory spinning(double duration_s, const Yaw& yaw) {
  return along(duration_s, 0.0, yaw);
}

double maxRate(const control::SetpointTrajectory& traj) {
  double m = 0.0;
  const auto& t = traj.times();
  const auto& sp = traj.setpoints();
  for (std::size_t i = 1; i < sp.size(); ++i) {
    m = std::max(m, std::abs(sp[i].yaw_rad - sp[i - 1].yaw_rad) / (t[i] - t[i - 1]));
    m = std::max(m, std::abs(sp[i].yaw_rate_rad_s));
  }
  return m;
}

TEST(LookAhead, SmoothYawKeepsTheFirstYawAndTheRateLimitAndTurnsEarly) {
  // A step of 2 rad at t = 3 s: smoothed and rate-limited, the turn starts before 3 s (the
  // backward pass) and ends at the new yaw; the first yaw stays as it was.
  const control::SetpointTrajectory step = spinning(8.0, [](double t) { return t < 3.0 ? 0.5 : 2.5; });
  std::vector<control::TrajectorySetpoint> sp = step.setpoints();
  smoothYaw(step.times(), 0.6, &sp);
  const control::SetpointTrajectory out(step.times(), sp);
  EXPECT_DOUBLE_EQ(out.sample(0.0).yaw_rad, 0.5);
  EXPECT_LE(maxRate(out), 0.6 + 1e-9);
  EXPECT_NEAR(out.sample(8.0).yaw_rad, 2.5, 1e-6);
  EXPECT_GT(out.sample(2.5).yaw_rad, 0.6);  // already turning half a second before the step
}

TEST(LimitYawRate, HoldsTheLimitFromTheSwitchOnAndRejoinsTheYaw) {
  // A swing of 3 rad/s for 1 s from t = 2 s, across +-pi: limited to 0.6 rad/s from t = 1.5 s on,
  // the yaw lags, then rejoins the trajectory's (pi - 0.2 + 3 = -pi + 2.8 after wrapping).
  const auto yaw = [](double t) {
    return std::remainder(M_PI - 0.2 + 3.0 * std::clamp(t - 2.0, 0.0, 1.0), 2.0 * M_PI);
  };
  const control::SetpointTrajectory swing = spinning(10.0, yaw);
  const control::SetpointTrajectory out = limitYawRate(swing, 1.5, 0.6);
  EXPECT_LE(maxRate(out), 0.6 + 1e-9);
  EXPECT_NEAR(std::remainder(out.sample(10.0).yaw_rad - yaw(10.0), 2.0 * M_PI), 0.0, 1e-9);
  EXPECT_NEAR(std::remainder(out.sample(3.0).yaw_rad - (M_PI - 0.2 + 0.6), 2.0 * M_PI), 0.0, 1e-9);
  // Before the switch nothing changes, even where it is too fast.
  const control::SetpointTrajectory late = limitYawRate(swing, 2.5, 0.6);
  EXPECT_DOUBLE_EQ(late.sample(2.5).yaw_rad, swing.sample(2.5).yaw_rad);
  // Within the limit, nothing changes at all.
  const control::SetpointTrajectory slow = spinning(5.0, [](double t) { return 0.5 * t; });
  EXPECT_EQ(limitYawRate(slow, 0.0, 0.6).setpoints().back().yaw_rad, slow.setpoints().back().yaw_rad);
}

TEST(RenewedViews, KeepTheVehiclesYawAtTheSwitchAndTurnToThePlansWithinTheLimit) {
  // Flying along x with the camera at yaw 0; a plan along the same line, made for the switch at
  // t = 3 s (1.2 m along), looks at yaw 1.5 all the way.
  const control::SetpointTrajectory current = along(10.0, 0.4, [](double) { return 0.0; });
  const control::SetpointTrajectory plan = [&] {
    control::SetpointTrajectory p = along(7.0, 0.4, [](double) { return 1.5; });
    std::vector<control::TrajectorySetpoint> sp = p.setpoints();
    for (control::TrajectorySetpoint& s : sp) s.p_WB.x() += 1.2;
    return control::SetpointTrajectory(p.times(), sp);
  }();
  const std::optional<control::SetpointTrajectory> out = renewedViews(current, plan, 3.0, 0.6);
  ASSERT_TRUE(out.has_value());
  EXPECT_DOUBLE_EQ(out->startTime(), 3.0);
  EXPECT_DOUBLE_EQ(out->sample(3.0).yaw_rad, 0.0);  // the vehicle's, not the plan's 1.5
  EXPECT_LE(maxRate(*out), 0.6 + 1e-9);
  EXPECT_NEAR(out->sample(8.0).yaw_rad, 1.5, 1e-6);                           // turned to the plan's view
  EXPECT_DOUBLE_EQ(out->sample(6.0).p_WB.x(), current.sample(6.0).p_WB.x());  // the route as it was
  // Too little left of the current trajectory: nothing.
  EXPECT_FALSE(renewedViews(current, plan, 9.995, 0.6).has_value());
}

constexpr double kDeg = M_PI / 180.0;

// test::texturedWall() (nothing known but the wall) as the planners' voxel map (unknown space
// free), and a rater of views on it (the gates: 50 detections, a fifth of the image).
struct WallViews {
  planner::FeatureMap map = test::texturedWall();
  planner::VoxelMap voxels{map, Eigen::Vector3d(-1, -3, 0), Eigen::Vector3d(5, 5, 2), 0.5, 1.5, true};
  planner::VisibilityConfig visibility;
  planner::InformationConfig information;
  ViewRater rater{voxels, visibility, information};
};

TEST(LookAhead, KeepsTheViewTrackableAsFarTowardTheWayAheadAsItMay) {
  WallViews wall;
  ViewRater& rater = wall.rater;
  rater.moveTo(Eigen::Vector3d(1.75, 0.0, 1.0));
  // The planner looks at the wall; the way ahead turns north, where nothing is known.
  const double planned = 0.0;
  const double look = 60.0 * kDeg;
  ASSERT_EQ(rater.shortfall(planned), 0.0);
  ASSERT_GT(rater.shortfall(look), 0.0);
  // The turn stops at the first yaw from the way ahead back that keeps the wall trackable.
  const double share = trackableShare(rater, planned, look, look, M_PI);
  ASSERT_GT(share, 0.0);
  ASSERT_LT(share, 1.0);
  const double kept = planned + share * look;
  EXPECT_EQ(rater.shortfall(kept), 0.0);
  EXPECT_GT(rater.shortfall(kept + 5.0 * kDeg), 0.0);
  std::cout << "[ figure   ] the view keeps the wall at " << kept / kDeg << " deg (way ahead: 60)\n";
  // A view of the way ahead that is trackable is kept as it is.
  EXPECT_EQ(trackableShare(rater, planned, 10.0 * kDeg, 10.0 * kDeg, M_PI), 1.0);
  // The way just ahead stays in the image: where it lies at 90 deg within 35, no yaw that keeps it
  // sees enough of the wall; the least short of them is kept, within the limit.
  const double limited = planned + trackableShare(rater, planned, look, 90.0 * kDeg, 35.0 * kDeg) * look;
  EXPECT_GE(limited, 55.0 * kDeg - 1e-9);
}

TEST(LookAhead, ADetectionFloorRatesAViewTheModelPassesShort) {
  WallViews wall;
  ViewRater& rater = wall.rater;
  rater.moveTo(Eigen::Vector3d(1.75, 0.0, 1.0));
  ASSERT_EQ(rater.shortfall(0.0), 0.0);
  rater.setDetectionFloor(1.0);  // far below what the wall promises: no change
  EXPECT_EQ(rater.shortfall(0.0), 0.0);
  rater.setDetectionFloor(1e6);
  const double short_of = rater.shortfall(0.0);
  EXPECT_GT(short_of, 0.99);
  EXPECT_LT(short_of, 1.0);
}

TEST(LookAhead, TheBestViewKeepsTheWayAheadInViewOnTheSideOfTheTexture) {
  WallViews wall;
  ViewRater& rater = wall.rater;
  rater.moveTo(Eigen::Vector3d(1.75, 0.0, 1.0));
  // The way ahead at 60 deg, the planner looking at 120 deg, away from the wall (east): the least
  // turn that keeps the way within 27.6 deg, 87.6 deg, sees no texture; the far side of the way
  // sees the wall.
  const double heading = 60.0 * kDeg;
  const double half_fov = 27.6 * kDeg;
  ASSERT_GT(rater.shortfall(heading + half_fov), 0.0);
  const double offset = bestViewOffset(rater, 120.0 * kDeg, heading, half_fov);
  std::cout << "[ figure   ] the best view looks at " << (heading + offset) / kDeg << " deg (way ahead: 60)\n";
  EXPECT_LT(offset, 0.0);
  EXPECT_GE(offset, -half_fov - 1e-9);
  EXPECT_EQ(rater.shortfall(heading + offset), 0.0);
  // Of the yaws it rates trackable, the least turn: the one before it (toward the planner's) is not.
  EXPECT_GT(rater.shortfall(heading + offset + 5.0 * kDeg + 1e-6), 0.0);
  // A planner's yaw within the window that is trackable is kept as it is.
  ASSERT_EQ(rater.shortfall(40.0 * kDeg), 0.0);
  EXPECT_NEAR(bestViewOffset(rater, 40.0 * kDeg, heading, half_fov), -20.0 * kDeg, 1e-12);
  // Where no yaw in the window is trackable (way ahead north), the least short, not a blind turn
  // toward nothing.
  const double north = bestViewOffset(rater, 150.0 * kDeg, 90.0 * kDeg, half_fov);
  EXPECT_LE(rater.shortfall(90.0 * kDeg + north), rater.shortfall(90.0 * kDeg + half_fov));
}

TEST(LookAhead, WithARaterTheTrajectoryKeepsItsYawWhereTheWayAheadIsTrackable) {
  // East along y = 0 toward the wall, the planner looking south: the look-ahead turns the camera
  // east, where the wall is in view and trackable, and the rater changes nothing.
  WallViews wall;
  ViewRater& rater = wall.rater;
  std::vector<double> t;
  std::vector<control::TrajectorySetpoint> sp;
  for (int i = 0; i <= 600; ++i) {
    t.push_back(i * 0.01);
    control::TrajectorySetpoint s;
    s.p_WB = Eigen::Vector3d(1.5 + 0.2 * i * 0.01, 0.0, 1.0);
    s.yaw_rad = -80.0 * kDeg;
    sp.push_back(s);
  }
  const control::SetpointTrajectory east(t, sp);
  const control::SetpointTrajectory plain = lookWhereUnknown(east, wall.map, 2.0, 27.6 * kDeg, false, 0.6);
  const control::SetpointTrajectory rated = lookWhereUnknown(east, wall.map, 2.0, 27.6 * kDeg, false, 0.6, &rater);
  for (double at : {1.0, 3.0, 5.0}) {
    EXPECT_GT(plain.sample(at).yaw_rad, -60.0 * kDeg);  // turned toward the way ahead
    EXPECT_DOUBLE_EQ(rated.sample(at).yaw_rad, plain.sample(at).yaw_rad);
  }
}

TEST(LevelCamera, LooksAlongTheYawWithTheImageUpright) {
  const Eigen::Isometry3d X_WC = levelCamera(Eigen::Vector3d(1.0, 2.0, 1.5), 90.0 * kDeg);
  EXPECT_TRUE(X_WC.linear().col(2).isApprox(Eigen::Vector3d::UnitY(), 1e-12));   // optical axis: north
  EXPECT_TRUE(X_WC.linear().col(1).isApprox(-Eigen::Vector3d::UnitZ(), 1e-12));  // image y: down
  EXPECT_TRUE(X_WC.linear().col(0).isApprox(Eigen::Vector3d::UnitX(), 1e-12));   // image x: right (east)
  EXPECT_TRUE(X_WC.translation().isApprox(Eigen::Vector3d(1.0, 2.0, 1.5)));
  EXPECT_NEAR(X_WC.linear().determinant(), 1.0, 1e-12);
}

// A hovering camera 1.75 m in front of the textured wall turns from it (east, yaw 0) to the north
// (nothing known there) over 2 s, then holds. worstView finds the view the vehicle would lose the
// VO in, at the model's rating, within the span asked and not after it.
TEST(WorstView, FindsTheLeastTrackableViewOfTheSpanAtTheModelsRating) {
  WallViews wall;
  planner::TrackModel model;
  model.terms.push_back({planner::TrackFeature::kLogDetections, std::log1p(50.0), 0.5, 2.0});
  wall.information.model = std::make_shared<const planner::TrackModel>(model);
  const control::SetpointTrajectory turn = [] {
    std::vector<double> t;
    std::vector<control::TrajectorySetpoint> sp;
    for (int i = 0; i <= 400; ++i) {
      t.push_back(i * 0.01);
      control::TrajectorySetpoint s;
      s.p_WB = Eigen::Vector3d(1.75, 0.0, 1.0);
      s.yaw_rad = std::min(1.0, i * 0.01 / 2.0) * 90.0 * kDeg;
      sp.push_back(s);
    }
    return control::SetpointTrajectory(t, sp);
  }();
  const auto rate = [&](double from, double span) {
    return worstView(turn, from, span, 0.1, wall.voxels, wall.visibility, wall.information);
  };
  // Facing the wall it tracks; facing north it does not: the worst view is the turn's end.
  const RatedView start = rate(0.0, 0.0);
  ASSERT_GT(start.prediction.track_probability, 0.9);
  const RatedView whole = rate(0.0, 3.0);
  EXPECT_LT(whole.prediction.track_probability, 0.1);
  EXPECT_GE(whole.tau, 1.4);
  EXPECT_LE(whole.tau, 3.0 + 1e-9);
  EXPECT_DOUBLE_EQ(whole.yaw_rad, turn.sample(whole.tau).yaw_rad);
  // No view of the span is worse than the one returned.
  for (double tau = 0.0; tau <= 3.0 + 1e-9; tau += 0.1) {
    const FramePrediction f = predictFrame(wall.voxels, levelCamera(turn.sample(tau).p_WB, turn.sample(tau).yaw_rad),
                                           wall.visibility, wall.information);
    EXPECT_GE(f.track_probability, whole.prediction.track_probability);
  }
  // The first half second of the turn (22.5 deg) keeps the wall in view: the span bounds the search.
  EXPECT_GT(rate(0.0, 0.5).prediction.track_probability, 0.9);
  EXPECT_THROW(rate(0.0, -1.0), std::invalid_argument);
}

TEST(ViewAheadFallsShort, TripsWhileTheViewNowMeetsTheFloorAndTheViewAheadDoesNot) {
  // trial.look_guard: the camera faces the textured wall (x = 3.5, landmarks for y in [-1.45, 1])
  // from 1.75 m and slides north along it at 0.4 m/s, the texture leaving the image, without a turn.
  WallViews wall;
  const control::SetpointTrajectory slide = [] {
    std::vector<double> t;
    std::vector<control::TrajectorySetpoint> sp;
    for (int i = 0; i <= 1000; ++i) {
      t.push_back(i * 0.01);
      control::TrajectorySetpoint s;
      s.p_WB = Eigen::Vector3d(1.75, 0.4 * i * 0.01, 1.0);
      s.v_WB.y() = 0.4;
      sp.push_back(s);
    }
    return control::SetpointTrajectory(t, sp);
  }();
  const auto detections = [&](double tau) {
    const control::TrajectorySetpoint sp = slide.sample(tau);
    const Eigen::Vector3d p_WC = planner::cameraPosition(sp.p_WB, sp.yaw_rad, wall.visibility);
    return predictFrame(wall.voxels, levelCamera(p_WC, sp.yaw_rad), wall.visibility, wall.information)
        .support.detections;
  };
  const double floor = 0.5 * detections(0.0);
  ASSERT_GT(floor, 10.0);
  const double lead = 0.6;
  double first_trip = -1.0;
  double first_below = -1.0;  // the first view below the floor
  for (double tau = 0.0; tau <= 9.0 + 1e-9; tau += 0.05) {
    const bool below = detections(tau) < floor;
    if (below && first_below < 0.0) first_below = tau;
    const std::optional<RatedView> trip =
        viewAheadFallsShort(slide, tau, lead, floor, wall.voxels, wall.visibility, wall.information);
    if (below) {
      EXPECT_FALSE(trip) << tau;  // flown into already
      continue;
    }
    if (!trip) continue;
    if (first_trip < 0.0) first_trip = tau;
    EXPECT_NEAR(trip->tau, tau + lead, 1e-9);
    EXPECT_LT(trip->prediction.support.detections, floor);
    EXPECT_NEAR(trip->prediction.support.detections, detections(tau + lead), 1e-9);
    // Without a lead the view ahead is the view now, which meets the floor.
    EXPECT_FALSE(viewAheadFallsShort(slide, tau, 0.0, floor, wall.voxels, wall.visibility, wall.information));
  }
  std::cout << "[ figure   ] floor " << floor << ": trips from " << first_trip << " s, the view below it from "
            << first_below << " s\n";
  ASSERT_GT(first_trip, 0.0);
  ASSERT_GT(first_below, first_trip);
  EXPECT_LE(first_below - first_trip, lead + 0.05 + 1e-9);  // as soon as the lead reaches the bad view
  // A floor the whole slide meets never trips.
  for (double tau = 0.0; tau <= 9.0 + 1e-9; tau += 0.5) {
    EXPECT_FALSE(viewAheadFallsShort(slide, tau, lead, 0.0, wall.voxels, wall.visibility, wall.information)) << tau;
  }
}

TEST(StopBeforeUnknown, EndsBeforeThePathComesNearUnobservedSpaceAndLooksAtTheWayOn) {
  // A path along voxel centres east along y = 0.05 from x = 0.05 to 5.95, then north to y = 3.05;
  // observed free: a band y in [-0.3, 0.3) from x = 0.3 to 3.0, but for a hole at x in [1.4, 1.7).
  // The vehicle started at the path's start (its own place, which the forward camera never sees).
  planner::FeatureMap map(0.1);
  const auto observe = [&](int from, int to) {  // the voxels x in [0.1 from, 0.1 to) of the band
    for (int k = from; k < to; ++k) {
      for (int j = -3; j < 3; ++j) {
        map.occupancy().updateNode(
            octomap::point3d(static_cast<float>(0.1 * k + 0.05), static_cast<float>(0.1 * j + 0.05), 1.05F), false);
      }
    }
  };
  observe(3, 14);
  observe(17, 30);
  std::vector<planner::Pose4> path;
  path.reserve(90);
  for (int i = 0; i < 60; ++i) path.push_back(planner::Pose4{Eigen::Vector3d(0.1 * i + 0.05, 0.05, 1.05), 0.0});
  for (int k = 1; k <= 30; ++k) path.push_back(planner::Pose4{Eigen::Vector3d(5.95, 0.1 * k + 0.05, 1.05), M_PI / 2});
  const Eigen::Vector3d start = path.front().p_WB;
  const Eigen::Vector3d hole(1.55, 0.05, 1.05);
  // Within 0.25 m of the path (beyond 0.45 m on; the points lie 0.1 m apart): the hole stops it
  // at x = 1.15, whose voxels within 0.25 m reach x = 1.35 ...
  StopRule rule{0.25, 0.45, 0.95, 30.0 * kDeg};
  std::vector<planner::Pose4> part = stopBeforeUnknown(path, map, {start}, rule);
  ASSERT_EQ(part.size(), 12U);
  EXPECT_NEAR(part.back().p_WB.x(), 1.15, 1e-9);
  // ... unless the vehicle has been there; then it goes on to x = 2.75, where the way on lies
  // straight ahead and the planner's yaw stays.
  part = stopBeforeUnknown(path, map, {start, hole}, rule);
  ASSERT_EQ(part.size(), 28U);
  EXPECT_NEAR(part.back().p_WB.x(), 2.75, 1e-9);
  EXPECT_DOUBLE_EQ(part.back().yaw_rad, 0.0);
  // Observed up to the corner's x = 6.0: it stops at x = 5.75, where the way on turns north, and
  // the camera turns as little as keeps it within 30 deg of its axis.
  observe(14, 17);
  observe(30, 60);
  part = stopBeforeUnknown(path, map, {start}, rule);
  ASSERT_EQ(part.size(), 58U);
  EXPECT_NEAR(part.back().p_WB.x(), 5.75, 1e-9);
  const double heading = std::atan2(0.8, 0.2);  // to (5.95, 0.85), 0.95 m on along the path
  EXPECT_NEAR(part.back().yaw_rad, heading - 30.0 * kDeg, 1e-9);
  EXPECT_DOUBLE_EQ(part[56].yaw_rad, 0.0);  // only the last point turns
  // Where nothing is observed, it goes only as far as the vehicle's own place reaches (0.25 m),
  // and without even that, nowhere: the start alone, its yaw turned to see the way on.
  const planner::FeatureMap empty(0.1);
  part = stopBeforeUnknown(path, empty, {start}, rule);
  ASSERT_EQ(part.size(), 3U);
  EXPECT_NEAR(part.back().p_WB.x(), 0.25, 1e-9);
  const std::vector<planner::Pose4> north = {path[0], planner::Pose4{Eigen::Vector3d(0.05, 1.05, 1.05), 0.0}};
  part = stopBeforeUnknown(north, empty, {}, rule);
  ASSERT_EQ(part.size(), 1U);
  EXPECT_NEAR(part.back().yaw_rad, M_PI / 2 - 30.0 * kDeg, 1e-9);
  // A path in observed space is kept whole, and so is one within 0.45 m whose own voxels are
  // observed.
  const std::vector<planner::Pose4> short_path(path.begin(), path.begin() + 21);
  EXPECT_EQ(stopBeforeUnknown(short_path, map, {start}, rule).size(), 21U);
  const std::vector<planner::Pose4> near_end(path.begin(), path.begin() + 5);
  EXPECT_EQ(stopBeforeUnknown(near_end, map, {start}, rule).size(), 5U);
}

// A slab one voxel thick (z in [1.0, 1.1)) of 10 x 10 voxels: observed free for x < 0.5; at
// x in [0.5, 0.6) a wall observed for y < 0.5, each of its 5 voxels holding 2 landmarks
// (detectability 0.25 and 0.75), and not observed for y >= 0.5; nothing observed beyond.
std::unique_ptr<planner::FeatureMap> slabMap(bool landmarks) {
  auto map = std::make_unique<planner::FeatureMap>(0.1);
  const auto at = [](int i, int j) {
    return octomap::point3d(static_cast<float>(0.1 * i + 0.05), static_cast<float>(0.1 * j + 0.05), 1.05F);
  };
  for (int j = 0; j < 10; ++j) {
    for (int i = 0; i < 5; ++i) map->occupancy().updateNode(at(i, j), false);
  }
  std::vector<planner::Landmark> seen;
  for (int j = 0; j < 5; ++j) {
    map->occupancy().updateNode(at(5, j), true);
    for (int observations : {1, 3}) {
      planner::Landmark lm;
      lm.p_W = Eigen::Vector3d(0.52, 0.1 * j + 0.05, 1.05);
      lm.ref_kf_p_W = Eigen::Vector3d(0.05, 0.1 * j + 0.05, 1.05);
      lm.observations = observations;
      lm.opportunities = 4;
      seen.push_back(lm);
    }
  }
  map->setLandmarks(landmarks ? seen : std::vector<planner::Landmark>{});
  EXPECT_EQ(map->embedLandmarks(0.1), 0);
  return map;
}

TEST(UnseenPrior, MeanPutsTheSeenSurfacesDensityOnTheFrontierWhereTheVoxelMapSeesIt) {
  const Eigen::Vector3d lo(0.0, 0.0, 1.0);
  const Eigen::Vector3d hi(0.99, 0.99, 1.09);
  std::unique_ptr<planner::FeatureMap> map = slabMap(true);
  const UnseenPriorStats stats = addUnseenPrior(map.get(), lo, hi);
  EXPECT_EQ(stats.surface_voxels, 5);  // the wall's observed voxels
  EXPECT_EQ(stats.surface_landmarks, 10);
  EXPECT_EQ(stats.frontier_voxels, 5);  // its unobserved ones: the voxels beyond border no free space
  EXPECT_DOUBLE_EQ(stats.density, 2.0);
  EXPECT_DOUBLE_EQ(stats.detectability, 0.5);
  ASSERT_EQ(stats.added, 10);
  ASSERT_EQ(map->landmarks().size(), 20U);
  for (int id = 10; id < 20; ++id) {
    const Eigen::Vector3d v = map->landmarkVoxel(id);
    EXPECT_NEAR(v.x(), 0.55, 1e-6);
    const int voxel = (id - 10) / 2;  // two in each frontier voxel
    EXPECT_NEAR(v.y(), 0.55 + 0.1 * voxel, 1e-6);
    EXPECT_DOUBLE_EQ(map->landmarks()[static_cast<std::size_t>(id)].detectability(), 0.5);
    EXPECT_FALSE(map->isKnown(v));
  }
  // The planners' voxel map (unknown space free, as online) sees them from the free side, beside
  // the wall's own; without the prior only the wall's.
  const planner::VisibilityConfig view;
  const Eigen::Vector3d camera(0.05, 0.5, 1.05);  // every voxel of x = 0.55 in view, none grazed
  const planner::VoxelMap voxels(*map, Eigen::Vector3d(-0.5, -0.5, 0.5), Eigen::Vector3d(1.5, 1.5, 1.5), -1e9, 1e9,
                                 true);
  EXPECT_EQ(voxels.visibleFrom(camera, view).size(), 20U);
  std::unique_ptr<planner::FeatureMap> blind = slabMap(true);
  const planner::VoxelMap without(*blind, Eigen::Vector3d(-0.5, -0.5, 0.5), Eigen::Vector3d(1.5, 1.5, 1.5), -1e9, 1e9,
                                  true);
  EXPECT_EQ(without.visibleFrom(camera, view).size(), 10U);
  // Seen surfaces without landmarks (a bare scene so far), or nothing seen: nothing to average.
  std::unique_ptr<planner::FeatureMap> bare = slabMap(false);
  EXPECT_EQ(addUnseenPrior(bare.get(), lo, hi).added, 0);
  EXPECT_TRUE(bare->landmarks().empty());
  planner::FeatureMap empty(0.1);
  const UnseenPriorStats none = addUnseenPrior(&empty, lo, hi);
  EXPECT_EQ(none.added + none.surface_voxels + none.frontier_voxels, 0);
}

TEST(OccupiedWithin, MeasuresTheDistanceToTheVoxelsCubeAsThePlannersClearanceDoes) {
  // One occupied voxel, the cube [0.5, 0.6] x [0, 0.1] x [1.0, 1.1]; a free one beside it.
  octomap::OcTree tree(0.1);
  tree.updateNode(octomap::point3d(0.55F, 0.05F, 1.05F), true);
  tree.updateNode(octomap::point3d(0.15F, 0.05F, 1.05F), false);
  const auto near = [&](const Eigen::Vector3d& p) { return occupiedWithin(tree, {p}, 0.3); };
  EXPECT_TRUE(near(Eigen::Vector3d(0.25, 0.05, 1.05)));   // 0.25 m from its face
  EXPECT_FALSE(near(Eigen::Vector3d(0.15, 0.05, 1.05)));  // 0.35 m
  EXPECT_TRUE(near(Eigen::Vector3d(0.3, -0.2, 1.05)));    // 0.28 m from its edge
  // 0.33 m from its edge: a probe 0.3 m along each axis from the point (the check before) lands in
  // the voxel, 0.42 m away, and called the path blocked.
  EXPECT_FALSE(near(Eigen::Vector3d(0.27, -0.23, 1.05)));
  EXPECT_TRUE(near(Eigen::Vector3d(0.55, 0.05, 1.32)));  // above it, 0.22 m
  EXPECT_TRUE(occupiedWithin(tree, {Eigen::Vector3d(-3.0, 0.0, 1.0), Eigen::Vector3d(0.55, 0.05, 0.8)}, 0.3));
  EXPECT_FALSE(occupiedWithin(tree, {}, 0.3));
}

// A plan leaves the current route at once only where its choice is blind for shorter than the
// current route's class on the same map by more than the tolerance, and both are known.
TEST(LeavesBlindRoute, OnlyWhenTheChoiceIsBlindForShorterByMoreThanTheTolerance) {
  OnlinePlan p;
  p.chosen_blind_m = 4.9;
  p.route_blind_m = 8.0;  // storage seed 1 at 4 s: the route ahead turns past the bare shelf end
  EXPECT_TRUE(leavesBlindRoute(p, 0.5));
  EXPECT_FALSE(leavesBlindRoute(p, 3.1));  // within the tolerance: equal
  p.route_blind_m = 4.9;                   // the choice is the current route
  EXPECT_FALSE(leavesBlindRoute(p, 0.0));
  p.route_blind_m = -1.0;  // no candidate follows the current route
  EXPECT_FALSE(leavesBlindRoute(p, 0.5));
  p.route_blind_m = 8.0;
  p.chosen_blind_m = -1.0;  // not rated (before take-off)
  EXPECT_FALSE(leavesBlindRoute(p, 0.5));
}

TEST(WorthLeavingRoute, OnlyForARouteGoneBlinderOrLongerByTheMargin) {
  OnlinePlan p;
  p.chosen_blind_m = 0.0;
  p.route_blind_m = 0.2;  // gallery on the survey map: two classes, both seen textured
  p.chosen_length_m = 20.0;
  p.route_length_m = 21.0;
  EXPECT_FALSE(worthLeavingRoute(p, 0.5, 0.2));  // a near tie: keep the route
  EXPECT_TRUE(worthLeavingRoute(p, 0.1, 0.2));   // blind for longer beyond the tolerance
  p.route_length_m = 24.5;
  EXPECT_TRUE(worthLeavingRoute(p, 0.5, 0.2));  // longer by more than 20 %
  EXPECT_FALSE(worthLeavingRoute(p, 0.5, 0.25));
  p.route_blind_m = -1.0;  // no candidate follows the current route
  EXPECT_TRUE(worthLeavingRoute(p, 0.5, 10.0));
  p.route_blind_m = 0.2;
  p.chosen_blind_m = -1.0;  // not rated (before take-off)
  EXPECT_TRUE(worthLeavingRoute(p, 0.5, 10.0));
}

// trial.look_keep_class: the class in force is the one the route last adopted follows from the
// vehicle's place on, by H-signature around the plan's obstacles (one here, at the origin).
TEST(ClassInForce, TheClassTheRouteLastAdoptedFollowsFromHere) {
  planner::Plan plan;
  plan.topo.obstacle_points = {Eigen::Vector2d(0.0, 0.0)};
  const std::vector<std::vector<Eigen::Vector2d>> classes = {{{-3.0, 0.0}, {0.0, 2.0}, {3.0, 0.0}},    // north of it
                                                             {{-3.0, 0.0}, {0.0, -2.0}, {3.0, 0.0}}};  // south of it
  for (const std::vector<Eigen::Vector2d>& path : classes) {
    planner::HomologyClass c;
    c.path = path;
    c.h_signature = planner::windingAngles(path, plan.topo.obstacle_points);
    plan.topo.classes.push_back(c);
    plan.candidates.emplace_back();
  }
  const Eigen::Vector2d here(-3.0, 0.0);
  // Adopted from farther back, south of the obstacle, and bent where it was then unknown.
  const std::vector<Eigen::Vector2d> south = {{-6.0, 0.0}, {-4.0, -1.0}, {-1.0, -3.0}, {1.0, -1.0}, {3.0, 0.0}};
  EXPECT_EQ(classInForce(plan, south, here), 1);
  // The vehicle off the route (a look pose): it joins the route at its nearest point.
  EXPECT_EQ(classInForce(plan, south, Eigen::Vector2d(-3.5, 0.5)), 1);
  const std::vector<Eigen::Vector2d> north = {{-6.0, 0.0}, {-2.0, 1.5}, {3.0, 0.0}};
  EXPECT_EQ(classInForce(plan, north, here), 0);
  plan.candidates[0].feasible = false;  // its class has no 4-DoF path here
  EXPECT_EQ(classInForce(plan, north, here), -1);
  EXPECT_EQ(classInForce(plan, {}, here), -1);  // nothing adopted yet
  // A route around the obstacle once more than either class: none.
  const std::vector<Eigen::Vector2d> around = {{-3.0, 0.0}, {0.0, 2.0}, {2.0, 0.0}, {0.0, -2.0},
                                               {-2.0, 0.0}, {0.0, 2.5}, {3.0, 0.0}};
  EXPECT_EQ(classInForce(plan, around, here), -1);
}

}  // namespace
}  // namespace tgnav::harness
