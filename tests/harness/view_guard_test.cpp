// The tracking guard of an online trial (harness/run/view_guard.h): when it trips, which wedge of
// bearings it blames, and how that wedge's unknown space is planned.
#include "harness/run/view_guard.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include "control/trajectory.h"
#include "harness/run/look_ahead.h"

namespace tgnav::harness {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kHalfFov = 37.5 * kDeg;

ViewGuard guard() { return ViewGuard(150, 5.0 * kDeg, kHalfFov, 3.0); }

TEST(ViewGuard, TripsOnlyWhenATurningCameraLosesTheInliers) {
  ViewGuard g = guard();
  const Eigen::Vector3d p(1.0, 2.0, 1.0);
  // Nothing tracked well yet: nothing to turn back to.
  EXPECT_FALSE(g.observe(0.0, p, 0.0, 40).has_value());
  EXPECT_FALSE(g.observe(0.05, p, 0.0, 400).has_value());
  // Few inliers while still (3 deg over the last 0.5 s): not the turn's doing.
  EXPECT_FALSE(g.observe(0.10, p, 1.0 * kDeg, 100).has_value());
  EXPECT_FALSE(g.observe(0.40, p, 3.0 * kDeg, 100).has_value());
  // A turn of 5 deg or more over the last 0.5 s, losing them: trips.
  const auto w = g.observe(0.45, p, 6.0 * kDeg, 100);
  ASSERT_TRUE(w.has_value());
  EXPECT_DOUBLE_EQ(g.goodYaw(), 0.0);
  // The new part of the view: from the good view's left edge over the 6 deg turned and 45 deg on.
  EXPECT_NEAR(w->from_rad, kHalfFov, 1e-12);
  EXPECT_NEAR(w->width_rad, 6.0 * kDeg + ViewGuard::kBeyondRad, 1e-12);
  EXPECT_EQ(w->apex, p);
  EXPECT_DOUBLE_EQ(w->range_m, 3.0);
  // Disarmed until a new plan is flown and a frame tracks enough again.
  EXPECT_FALSE(g.observe(0.50, p, 20.0 * kDeg, 50).has_value());
  g.rearm();
  EXPECT_FALSE(g.observe(0.55, p, 30.0 * kDeg, 50).has_value());
  EXPECT_FALSE(g.observe(0.60, p, 90.0 * kDeg, 200).has_value());  // tracks enough: armed, new good yaw
  EXPECT_TRUE(g.observe(0.65, p, 70.0 * kDeg, 149).has_value());   // turning right
}

TEST(ViewGuard, ATurnToTheRightBlamesTheBearingsRightOfTheGoodView) {
  ViewGuard g = guard();
  const Eigen::Vector3d p = Eigen::Vector3d::Zero();
  g.observe(0.0, p, M_PI - 0.1, 500);                 // across the +-pi seam
  const auto w = g.observe(0.1, p, -M_PI + 0.2, 10);  // 0.3 rad to the left, through the seam
  ASSERT_TRUE(w.has_value());
  // Left of a view looking at ~pi: bearings beyond pi - 0.1 + half fov.
  const double left = M_PI - 0.1 + kHalfFov + 0.1;
  EXPECT_TRUE(inWedge(*w, Eigen::Vector3d(std::cos(left), std::sin(left), 0.0)));
  ViewGuard h = guard();
  h.observe(0.0, p, 0.0, 500);
  const auto r = h.observe(0.1, p, -0.5, 10);
  ASSERT_TRUE(r.has_value());
  const double right_edge = -kHalfFov;
  auto at = [](double bearing, double range) {
    return Eigen::Vector3d(range * std::cos(bearing), range * std::sin(bearing), 1.0);
  };
  EXPECT_TRUE(inWedge(*r, at(right_edge - 0.05, 2.0)));
  EXPECT_TRUE(inWedge(*r, at(right_edge - 0.5 - ViewGuard::kBeyondRad + 0.05, 2.0)));
  EXPECT_FALSE(inWedge(*r, at(right_edge - 0.5 - ViewGuard::kBeyondRad - 0.05, 2.0)));  // past it
  EXPECT_FALSE(inWedge(*r, at(right_edge + 0.05, 2.0)));                                // inside the good view
  EXPECT_FALSE(inWedge(*r, at(0.0, 1.0)));               // straight ahead of the good view
  EXPECT_FALSE(inWedge(*r, at(right_edge - 0.1, 3.5)));  // beyond its range
}

TEST(ViewGuard, StillItTripsWithoutATurnAndBlamesTheViewItLost) {
  ViewGuard g(150, 5.0 * kDeg, kHalfFov, 3.0, GuardLead{}, /*still=*/true);
  const Eigen::Vector3d p(1.0, 2.0, 1.0);
  const double yaw = 0.5;
  EXPECT_FALSE(g.observe(0.0, p, yaw, 40).has_value());  // nothing tracked well yet
  EXPECT_FALSE(g.observe(0.05, p, yaw, 400).has_value());
  // The texture leaves the image while the camera keeps its yaw (1 deg over 0.5 s).
  const auto w = g.observe(0.40, p, yaw + 1.0 * kDeg, 149);
  ASSERT_TRUE(w.has_value());
  EXPECT_FALSE(g.lastTripTurned());
  auto at = [&](double bearing, double range) {
    return Eigen::Vector3d(p.x() + range * std::cos(bearing), p.y() + range * std::sin(bearing), 1.0);
  };
  // The bad view's field of view, out to the range: ahead and near both edges, not beyond them.
  EXPECT_TRUE(inWedge(*w, at(yaw, 2.0)));
  EXPECT_TRUE(inWedge(*w, at(yaw + kHalfFov - 0.02, 2.0)));
  EXPECT_TRUE(inWedge(*w, at(yaw - kHalfFov + 0.05, 2.0)));
  EXPECT_FALSE(inWedge(*w, at(yaw + kHalfFov + 0.05, 2.0)));
  EXPECT_FALSE(inWedge(*w, at(yaw - kHalfFov - 0.05, 2.0)));
  EXPECT_FALSE(inWedge(*w, at(yaw, 3.5)));
  // A turn still trips it as before, and says so.
  g.rearm();
  EXPECT_FALSE(g.observe(0.45, p, yaw, 400).has_value());
  ASSERT_TRUE(g.observe(0.50, p, yaw + 10.0 * kDeg, 100).has_value());
  EXPECT_TRUE(g.lastTripTurned());
  // The view it lost is ruled out for the look search near where it tripped, either side of its yaw.
  GuardEvent still{0.4, yaw, yaw, 149, /*turning=*/false, *w};
  const Eigen::Vector2d here = p.head<2>();
  EXPECT_TRUE(trippedView(still, here, yaw + 0.4 * kHalfFov, 1.0, kHalfFov));
  EXPECT_TRUE(trippedView(still, here, yaw - 0.4 * kHalfFov, 1.0, kHalfFov));
  EXPECT_FALSE(trippedView(still, here, yaw + 0.6 * kHalfFov, 1.0, kHalfFov));
  EXPECT_FALSE(trippedView(still, here + Eigen::Vector2d(1.5, 0.0), yaw, 1.0, kHalfFov));
}

using Columns = std::array<int, vo::FrameResult::kColumnBins>;

// 640 px wide, 90 deg across: fx = 320.
vo::CameraIntrinsics camera() { return vo::CameraIntrinsics{640, 480, 320.0, 320.0, 320.0, 240.0}; }

TEST(InliersAfterTurn, CountsTheInliersWhoseBearingStaysInsideTheImage) {
  Columns c{};
  c[0] = 7;    // centre 10 px: inside the detector's edge of 19 px already
  c[2] = 100;  // centre 50 px: bearing atan(-270 / 320) = -40.2 deg
  c[31] = 5;   // centre 630 px: bearing +40.2 deg
  const vo::CameraIntrinsics k = camera();
  EXPECT_EQ(inliersAfterTurn(c, k, 0.0, 0.0), 112);
  EXPECT_EQ(inliersAfterTurn(c, k, 0.0, 19.0), 100);
  // The image's left edge (19 px in) lies at atan(-301 / 320) = -43.25 deg: a turn to the right
  // (clockwise, negative) by 2.5 deg keeps bin 2, by 3.5 deg takes it out, and brings bin 31 in
  // from the right edge (43.15 deg); a turn to the left moves every point right.
  EXPECT_EQ(inliersAfterTurn(c, k, -2.5 * kDeg, 19.0), 105);
  EXPECT_EQ(inliersAfterTurn(c, k, -3.5 * kDeg, 19.0), 5);
  EXPECT_EQ(inliersAfterTurn(c, k, 10.0 * kDeg, 19.0), 107);  // bin 0 comes inside, bin 31 leaves
}

TEST(ViewGuard, WithALeadItTripsBeforeTheTextureAtTheTrailingEdgeLeavesTheImage) {
  // A turn to the right at 0.6 rad/s; 600 inliers, all 20-100 px from the image's left edge: the
  // 0.36 rad the turn goes on for over a lead of 0.6 s takes every one of them out.
  Columns crowded{};
  for (std::size_t b = 1; b <= 4; ++b) crowded[b] = 150;
  Columns even{};
  for (int& n : even) n = 600 / vo::FrameResult::kColumnBins;
  const Eigen::Vector3d p = Eigen::Vector3d::Zero();
  auto fly = [&](const Columns& columns, double lead_s) {
    ViewGuard g(150, 5.0 * kDeg, kHalfFov, 3.0, GuardLead{lead_s, camera(), 19.0});
    for (int i = 0; i <= 20; ++i) {
      const double t = 0.05 * i;
      if (auto w = g.observe(t, p, -0.6 * t, 600, &columns)) return std::make_pair(t, *w);
    }
    return std::make_pair(-1.0, BlindWedge{});
  };
  const auto [t_trip, w] = fly(crowded, 0.6);
  // It trips once the turn is 5 deg over the last 0.5 s (0.15 s in), with all 600 still tracked.
  EXPECT_NEAR(t_trip, 0.15, 1e-9);
  // The wedge reaches past the view by the 0.36 rad the lead foresaw too.
  EXPECT_NEAR(w.width_rad, 0.6 * 0.15 + 0.36 + ViewGuard::kBeyondRad, 1e-9);
  EXPECT_LT(fly(even, 0.6).first, 0.0);     // texture all across: a turn keeps most of it
  EXPECT_LT(fly(crowded, 0.0).first, 0.0);  // no lead: the inliers alone, still 600
}

TEST(ViewGuard, WithThePlannedTurnItTripsBeforeTheTurnStarts) {
  // At rest, 600 inliers 20-100 px from the image's left edge; the trajectory commands a turn to the
  // right of 0.36 rad over the 0.6 s lead, which would take every one of them out. Measured, the
  // camera has not turned at all.
  Columns crowded{};
  for (std::size_t b = 1; b <= 4; ++b) crowded[b] = 150;
  const Eigen::Vector3d p = Eigen::Vector3d::Zero();
  const double yaw = 0.2;
  auto first = [&](double planned_rad) {
    ViewGuard g(150, 5.0 * kDeg, kHalfFov, 3.0, GuardLead{0.6, camera(), 19.0});
    EXPECT_FALSE(g.observe(0.0, p, yaw, 600, &crowded).has_value());  // nothing commanded yet
    auto w = g.observe(0.05, p, yaw, 600, &crowded, planned_rad);
    return std::make_pair(w, g.lastTripPlannedRad());
  };
  const auto [w, planned] = first(-0.36);
  ASSERT_TRUE(w.has_value());
  EXPECT_DOUBLE_EQ(planned, -0.36);
  // The wedge lies on the right of the good view, over the commanded turn and beyond.
  EXPECT_NEAR(w->width_rad, 0.36 + ViewGuard::kBeyondRad, 1e-9);
  EXPECT_NEAR(w->from_rad, yaw - kHalfFov - w->width_rad, 1e-9);
  EXPECT_FALSE(first(0.0).first.has_value());   // nothing commanded: the rate alone, zero
  EXPECT_FALSE(first(0.36).first.has_value());  // a turn to the left keeps the points in view
  // The look search rules out the views the commanded turn was heading to, not the good one.
  const GuardEvent trip{0.05, yaw, yaw, 600, true, *w, planned};
  EXPECT_TRUE(trippedView(trip, p.head<2>(), yaw - 0.3, 1.0, kHalfFov));
  EXPECT_FALSE(trippedView(trip, p.head<2>(), yaw, 1.0, kHalfFov));
  EXPECT_FALSE(trippedView(trip, p.head<2>(), yaw + 0.3, 1.0, kHalfFov));
}

TEST(BlockWedges, MarksOnlyUnknownSpaceInsideTheWedgeAwayFromKeptPlaces) {
  octomap::OcTree tree(0.1);
  // Observed free: a 1 m square right of the apex, ahead of the vehicle (x in [1, 2]).
  for (double x = 1.05; x < 2.0; x += 0.1) {
    for (double y = -0.95; y < 0.0; y += 0.1) {
      for (double z = 0.75; z < 1.3; z += 0.1) tree.updateNode(octomap::point3d(x, y, z), false);
    }
  }
  BlindWedge w;
  w.apex = Eigen::Vector3d(0.0, 0.0, 1.0);
  w.from_rad = -M_PI / 2.0;  // bearings -90 .. 0 deg: the quadrant x > 0, y < 0
  w.width_rad = M_PI / 2.0;
  w.range_m = 2.5;
  const ClearanceBand band{0.7, 1.3};
  const Eigen::Vector3d kept(0.5, -1.5, 1.0);
  const int marked = blockWedges(&tree, {w}, band, {kept}, 0.4);
  EXPECT_GT(marked, 0);
  auto occupied = [&](double x, double y) {
    const octomap::OcTreeNode* n = tree.search(x, y, 1.05);
    return n != nullptr && tree.isNodeOccupied(n);
  };
  auto unknown = [&](double x, double y) { return tree.search(x, y, 1.05) == nullptr; };
  EXPECT_TRUE(occupied(0.85, -1.15));  // unknown, inside: blocked
  EXPECT_TRUE(occupied(2.05, -0.35));
  EXPECT_FALSE(occupied(1.45, -0.45));  // observed free: as it is
  EXPECT_TRUE(unknown(-0.55, -1.05));   // outside the wedge's bearings
  EXPECT_TRUE(unknown(1.05, 0.55));
  EXPECT_TRUE(unknown(2.35, -1.35));                   // beyond its range (2.73 m)
  EXPECT_TRUE(unknown(0.15, -0.15));                   // within keep_m of the apex
  EXPECT_TRUE(unknown(0.55, -1.45));                   // within keep_m of a kept place
  EXPECT_EQ(tree.search(0.85, -1.15, 1.55), nullptr);  // above the band
}

// The guard's stop (and a vehicle's hold without a route): a hold spliced into a moving, turning
// trajectory is at rest, at its place and yaw, from the end of the blend on.
TEST(HoldTrajectory, SplicedIntoAMovingTrajectoryItIsAtRestOnceTheBlendEnds) {
  std::vector<double> t;
  std::vector<control::TrajectorySetpoint> sp;
  for (int i = 0; i <= 1000; ++i) {
    control::TrajectorySetpoint s;
    s.p_WB = Eigen::Vector3d(0.4 * i * 0.01, 0.0, 1.0);
    s.v_WB = Eigen::Vector3d(0.4, 0.0, 0.0);
    s.yaw_rad = -0.6 * i * 0.01;
    s.yaw_rate_rad_s = -0.6;
    t.push_back(i * 0.01);
    sp.push_back(s);
  }
  const control::SetpointTrajectory moving(t, sp);
  const planner::Pose4 hold{Eigen::Vector3d(0.8, 0.0, 1.0), -1.0};
  const control::SetpointTrajectory h = holdTrajectory(hold, 4.5, 100.0);
  EXPECT_EQ(h.times().size(), 451U);
  const control::SetpointTrajectory spliced = control::spliceTrajectory(moving, h, 2.0, 0.3);
  EXPECT_NEAR(spliced.sample(1.99).v_WB.x(), 0.4, 1e-9);  // before the switch: as it was
  for (double tt = 2.3; tt <= 6.5; tt += 0.05) {
    const control::TrajectorySetpoint s = spliced.sample(tt);
    EXPECT_NEAR((s.p_WB - hold.p_WB).norm(), 0.0, 1e-9) << tt;
    EXPECT_NEAR(s.v_WB.norm(), 0.0, 1e-9) << tt;
    EXPECT_NEAR(s.yaw_rad, -1.0, 1e-9) << tt;
    EXPECT_NEAR(s.yaw_rate_rad_s, 0.0, 1e-9) << tt;
  }
}

}  // namespace
}  // namespace tgnav::harness
