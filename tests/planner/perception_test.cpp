// The perception model's trackability terms (planner/perception.h): where a landmark falls in the
// image, the image coverage of a view, and the blind score below min_landmarks or
// min_image_coverage; how far a pose falls short of its gates (the search's order among gated
// poses); the incidence limit.
#include "planner/perception.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

namespace tgnav::planner {
namespace {

// A wall 2 m in front of a camera at the origin looking along +x (yaw 0), landmarks on a grid
// over y in [y0, y1], z in [-0.9, 0.9] (the camera's height is 0).
std::vector<WeightedPoint> wall(double y0, double y1, double spacing) {
  std::vector<WeightedPoint> points;
  for (double y = y0; y <= y1 + 1e-9; y += spacing) {
    for (double z = -0.9; z <= 0.9 + 1e-9; z += spacing) points.push_back({{2.0, y, z}, 1.0, {-1.0, 0.0, 0.0}});
  }
  return points;
}

// withinHalfAngle() gives std::atan2's answer, at random and on the boundary itself (the
// vertical FoV's edge, where only the arctangent decides).
TEST(WithinHalfAngle, AgreesWithTheArctangentEverywhere) {
  const VisibilityConfig vis;
  const double half = 0.5 * vis.vfov_rad;
  const double tan_half = std::tan(half);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int inside = 0;
  int outside = 0;
  for (int i = 0; i < 200000; ++i) {
    const double adjacent = i % 100 == 0 ? 0.0 : 10.0 * unit(rng);
    // A third of the cases within 3e-9 (relative) of the edge, across the fast tests' margins.
    const double opposite = i % 3 == 0 ? tan_half * adjacent * (1.0 + 3e-9 * (2.0 * unit(rng) - 1.0))
                                       : 2.0 * tan_half * adjacent * unit(rng) + (i % 7 == 0 ? unit(rng) : 0.0);
    const bool expected = std::atan2(opposite, adjacent) <= half;
    ASSERT_EQ(withinHalfAngle(opposite, adjacent, half, tan_half), expected) << opposite << " " << adjacent;
    (expected ? inside : outside) += 1;
  }
  EXPECT_TRUE(withinHalfAngle(0.0, 0.0, half, tan_half));  // atan2(0, 0) = 0
  EXPECT_GT(inside, 50000);
  EXPECT_GT(outside, 50000);
}

// FieldOfView gives inFieldOfView()'s answer for every point: at random, near the horizontal
// FoV's edges (where only the arctangent decides), behind the camera and at every yaw.
TEST(FieldOfView, AgreesWithInFieldOfViewEverywhere) {
  const VisibilityConfig vis;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int inside = 0;
  int outside = 0;
  for (int i = 0; i < 200000; ++i) {
    const double yaw = (i % 50 == 0) ? 0.25 * M_PI * (i % 8) : 2.0 * M_PI * unit(rng) - M_PI;
    const FieldOfView in_view(yaw, vis);
    const Eigen::Vector3d p(10.0 * unit(rng), 10.0 * unit(rng), 2.0 * unit(rng));
    const double range = 8.0 * unit(rng);
    // A third of the points within 3e-9 rad of a side edge of the image, the rest anywhere.
    const double bearing = i % 3 == 0
                               ? (i % 2 == 0 ? 1.0 : -1.0) * (0.5 * vis.hfov_rad + 3e-9 * (2.0 * unit(rng) - 1.0))
                               : 2.0 * M_PI * unit(rng);
    const double elevation = (unit(rng) - 0.5) * vis.vfov_rad * 1.2;
    const Eigen::Vector3d l =
        p + range * Eigen::Vector3d(std::cos(elevation) * std::cos(yaw + bearing),
                                    std::cos(elevation) * std::sin(yaw + bearing), std::sin(elevation));
    const bool expected = inFieldOfView(p, yaw, l, vis);
    ASSERT_EQ(in_view(p, l), expected) << i;
    (expected ? inside : outside) += 1;
  }
  EXPECT_GT(inside, 30000);
  EXPECT_GT(outside, 30000);
}

TEST(ImageCell, CornersCentreAndSidesOfTheImage) {
  const VisibilityConfig vis;
  const Eigen::Vector3d o = Eigen::Vector3d::Zero();
  const double tx = std::tan(0.5 * vis.hfov_rad);
  const double tz = std::tan(0.5 * vis.vfov_rad);
  // Just inside the four corners: left is +y (the image's left column), up is +z (the top row).
  EXPECT_EQ(imageCell(o, 0.0, {1.0, 0.99 * tx, 0.99 * tz}, vis), 0);
  EXPECT_EQ(imageCell(o, 0.0, {1.0, -0.99 * tx, 0.99 * tz}, vis), kImageCols - 1);
  EXPECT_EQ(imageCell(o, 0.0, {1.0, 0.99 * tx, -0.99 * tz}, vis), (kImageRows - 1) * kImageCols);
  EXPECT_EQ(imageCell(o, 0.0, {1.0, -0.99 * tx, -0.99 * tz}, vis), kImageRows * kImageCols - 1);
  // Turning the camera turns the image: just right of and above the centre of yaw pi/2 (right is -x).
  EXPECT_EQ(imageCell(o, M_PI / 2, {0.01, 3.0, 0.01}, vis), (kImageRows / 2 - 1) * kImageCols + kImageCols / 2);
  EXPECT_EQ(imageCell(o, 0.0, {-1.0, 0.0, 0.0}, vis), -1);  // behind the camera
}

TEST(ImageCoverage, ANarrowTexturedStripScoresBlindAFullViewDoesNot) {
  const VisibilityConfig vis;
  InformationConfig info;
  const Eigen::Vector3d o = Eigen::Vector3d::Zero();
  const double half_width = 2.0 * std::tan(0.5 * vis.hfov_rad);  // the wall's visible half width at 2 m
  // Dense landmarks on a strip one eighth of the image wide at its left edge, sparser ones over all of it.
  const std::vector<WeightedPoint> strip = wall(half_width * 0.76, half_width * 0.99, 0.02);
  const std::vector<WeightedPoint> full = wall(-0.99 * half_width, 0.99 * half_width, 0.15);
  ViewSupport a, b;
  poseInformation(o, 0.0, strip, vis, info, &a);
  poseInformation(o, 0.0, full, vis, info, &b);
  EXPECT_GT(a.landmarks, b.landmarks);                 // more map landmarks in the strip ...
  EXPECT_NEAR(a.coverage(), 1.0 / kImageCols, 1e-12);  // ... on one column of cells
  EXPECT_GT(b.coverage(), 0.95);
  const double blind = 6.0 * std::log(info.epsilon);
  EXPECT_GT(poseScore(o, 0.0, strip, vis, info), blind);  // off by default: the paper's model
  info.min_image_coverage = 0.25;
  EXPECT_DOUBLE_EQ(poseScore(o, 0.0, strip, vis, info), blind);
  EXPECT_GT(poseScore(o, 0.0, full, vis, info), blind);
  info.min_landmarks = b.landmarks + 1.0;
  EXPECT_DOUBLE_EQ(poseScore(o, 0.0, full, vis, info), blind);
}

// A faint wall: the same landmarks, each detected by one survey view in eight that had it in
// view. The information is the paper's (every landmark in view counts), so both walls score
// alike; min_detections counts the detections they promise, and only the faint wall falls short.
TEST(Detectability, FewExpectedDetectionsScoreBlindWhateverTheLandmarkCount) {
  const VisibilityConfig vis;
  InformationConfig info;
  info.min_image_coverage = 0.0;
  info.min_detections = 0.0;
  const Eigen::Vector3d o = Eigen::Vector3d::Zero();
  const double half_width = 2.0 * std::tan(0.5 * vis.hfov_rad);
  const std::vector<WeightedPoint> rich = wall(-0.99 * half_width, 0.99 * half_width, 0.3);
  std::vector<WeightedPoint> faint = rich;
  for (WeightedPoint& pt : faint) pt.detections = 0.125;
  ViewSupport a, b;
  poseInformation(o, 0.0, rich, vis, info, &a);
  poseInformation(o, 0.0, faint, vis, info, &b);
  EXPECT_DOUBLE_EQ(a.landmarks, b.landmarks);
  EXPECT_DOUBLE_EQ(a.detections, a.landmarks);
  EXPECT_NEAR(b.detections, 0.125 * a.detections, 1e-9);
  EXPECT_DOUBLE_EQ(poseScore(o, 0.0, rich, vis, info), poseScore(o, 0.0, faint, vis, info));
  info.min_detections = 0.5 * (a.detections + b.detections);
  const double blind = 6.0 * std::log(info.epsilon);
  EXPECT_GT(poseScore(o, 0.0, rich, vis, info), info.epsilon);
  EXPECT_DOUBLE_EQ(poseScore(o, 0.0, faint, vis, info), blind);
}

// Gated poses all score 6 ln eps; rankedScore() keeps them in order of how far they miss their
// gates (the smallest share of a threshold reached), below every pose that passes.
TEST(GateShortfall, RanksGatedPosesByTheGateTheyMissMostAndLeavesPassingOnesAlone) {
  InformationConfig info;
  info.min_image_coverage = 0.0;
  info.min_detections = 0.0;
  const double blind = 6.0 * std::log(info.epsilon);
  ViewSupport none;
  EXPECT_DOUBLE_EQ(gateShortfall(none, info), 0.0);  // no gate set: nothing to fall short of
  EXPECT_DOUBLE_EQ(rankedScore(blind, none, info), blind);
  ViewSupport some;
  some.landmarks = 40.0;
  some.detections = 10.0;
  for (int cell = 0; cell < 12; ++cell) some.cover(cell);  // a quarter of the image
  info.min_detections = 40.0;
  EXPECT_DOUBLE_EQ(gateShortfall(some, info), 0.75);  // 10 of 40 detections
  EXPECT_DOUBLE_EQ(rankedScore(blind, some, info), blind - 0.75 * std::abs(blind));
  info.min_image_coverage = 0.5;  // a quarter of the image of half: detections still the worst
  EXPECT_DOUBLE_EQ(gateShortfall(some, info), 0.75);
  info.min_detections = 5.0;  // now the coverage alone fails, by half
  EXPECT_DOUBLE_EQ(gateShortfall(some, info), 0.5);
  info.min_landmarks = 80.0;  // and the landmarks, by half too
  EXPECT_DOUBLE_EQ(gateShortfall(some, info), 0.5);
  info.min_landmarks = 20.0;
  info.min_image_coverage = 0.25;  // exactly at every threshold: passes
  EXPECT_DOUBLE_EQ(gateShortfall(some, info), 0.0);
  EXPECT_DOUBLE_EQ(rankedScore(3.5, some, info), 3.5);
  // More detections rank higher among gated poses, and every gated one below 6 ln eps.
  info.min_detections = 100.0;
  ViewSupport more = some;
  more.detections = 60.0;
  EXPECT_GT(rankedScore(blind, more, info), rankedScore(blind, some, info));
  EXPECT_LT(rankedScore(blind, more, info), blind);
}

// The support's spans and ranges: which columns and rows hold a cell, the detections near the
// camera and their mean range.
TEST(ViewSupport, SpansAndRangesOfAView) {
  ViewSupport s;
  EXPECT_DOUBLE_EQ(s.columnSpan(), 0.0);
  EXPECT_DOUBLE_EQ(s.rowSpan(), 0.0);
  EXPECT_DOUBLE_EQ(s.meanRangeM(), 0.0);
  s.cover(0);                                // row 0, column 0
  s.cover(kImageCols + 0);                   // row 1, column 0
  s.cover(3 * kImageCols + kImageCols - 1);  // row 3, the last column
  EXPECT_DOUBLE_EQ(s.columnSpan(), 2.0 / kImageCols);
  EXPECT_DOUBLE_EQ(s.rowSpan(), 3.0 / kImageRows);
  WeightedPoint near_point;
  near_point.detections = 3.0;
  WeightedPoint far_point;
  far_point.detections = 1.0;
  s.count(near_point, 2.0, false);
  s.count(far_point, 8.0, true);
  WeightedPoint near_inner_point;
  near_inner_point.detections = 0.5;
  s.count(near_inner_point, 1.0, true);
  EXPECT_DOUBLE_EQ(s.detections, 4.5);
  EXPECT_DOUBLE_EQ(s.near_detections, 3.5);  // within kNearRangeM = 3 m
  EXPECT_DOUBLE_EQ(s.inner_detections, 1.5);
  EXPECT_DOUBLE_EQ(s.inner_near_detections, 0.5);
  EXPECT_DOUBLE_EQ(s.meanRangeM(), (3.0 * 2.0 + 8.0 + 0.5 * 1.0) / 4.5);
}

// The image's inner part: a point counts as inner up to kImageBorderShare of the half-width (and
// half-height) from the edge, whatever the yaw; behind the camera it is not.
TEST(ViewSupport, InnerPartIsTheImageLessItsBorder) {
  VisibilityConfig visibility;
  const Eigen::Vector3d p(1.0, -2.0, 1.0);
  const double tan_h = std::tan(0.5 * visibility.hfov_rad);
  const double tan_v = std::tan(0.5 * visibility.vfov_rad);
  const double inside = 1.0 - kImageBorderShare - 0.01;
  const double outside = 1.0 - kImageBorderShare + 0.01;
  for (double yaw : {0.0, 1.0, -2.5}) {
    const ImageCells cells(yaw, visibility);
    const Eigen::Vector3d forward(std::cos(yaw), std::sin(yaw), 0.0);
    const Eigen::Vector3d left(-std::sin(yaw), std::cos(yaw), 0.0);
    const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
    for (double side : {-1.0, 1.0}) {
      EXPECT_TRUE(cells.inner(p, p + 4.0 * forward + side * inside * 4.0 * tan_h * left)) << yaw;
      EXPECT_FALSE(cells.inner(p, p + 4.0 * forward + side * outside * 4.0 * tan_h * left)) << yaw;
      EXPECT_TRUE(cells.inner(p, p + 2.0 * forward + side * inside * 2.0 * tan_v * up)) << yaw;
      EXPECT_FALSE(cells.inner(p, p + 2.0 * forward + side * outside * 2.0 * tan_v * up)) << yaw;
    }
    EXPECT_TRUE(cells.inner(p, p + 3.0 * forward));
    EXPECT_FALSE(cells.inner(p, p - 3.0 * forward));
  }
}

// A learned model in place of the gates: the probability is the logistic of the standardised
// features; a pose below min_track_probability scores blind however the gates would rate it,
// and ranks by how far it falls short.
TEST(TrackModel, ReplacesTheGatesWithAProbability) {
  TrackModel model;
  model.terms.push_back({TrackFeature::kLogDetections, std::log1p(50.0), 0.5, 2.0});
  model.terms.push_back({TrackFeature::kCoverage, 0.2, 0.1, 1.0});
  model.intercept = 0.0;
  ViewSupport s;
  s.detections = 50.0;
  for (int cell = 0; cell < 10; ++cell) s.cover(cell);  // 10 of 48 cells: coverage 0.208
  const double z = 2.0 * 0.0 + 1.0 * (10.0 / 48.0 - 0.2) / 0.1;
  EXPECT_NEAR(model.probability(s), 1.0 / (1.0 + std::exp(-z)), 1e-12);
  ViewSupport poor = s;
  poor.detections = 5.0;
  EXPECT_LT(model.probability(poor), 0.05);

  InformationConfig info;
  info.min_detections = 1000.0;  // the gates would blind both; with a model they are not used
  info.model = std::make_shared<const TrackModel>(model);
  info.min_track_probability = 0.5;
  Matrix6d fisher = Matrix6d::Identity() * 100.0;
  const double blind = 6.0 * std::log(info.epsilon);
  EXPECT_GT(scoreInformation(fisher, s, info), blind);
  EXPECT_DOUBLE_EQ(gateShortfall(s, info), 0.0);
  EXPECT_DOUBLE_EQ(scoreInformation(fisher, poor, info), blind);
  EXPECT_NEAR(gateShortfall(poor, info), 1.0 - model.probability(poor) / 0.5, 1e-12);
  ViewSupport poorer = poor;
  poorer.detections = 1.0;
  EXPECT_LT(rankedScore(blind, poorer, info), rankedScore(blind, poor, info));
  EXPECT_TRUE(info.usesImageCells());  // its coverage term
  EXPECT_FALSE(info.usesInnerDetections());
  // A model without a term on the image's cells does not need them, whatever the coverage gate
  // (not used with a model) says; one on the inner detections needs those.
  TrackModel inner_only;
  inner_only.terms = {{TrackFeature::kLogInnerDetections, 3.0, 1.0, 2.0}};
  info.model = std::make_shared<const TrackModel>(inner_only);
  info.min_image_coverage = 0.5;
  EXPECT_FALSE(info.usesImageCells());
  EXPECT_TRUE(info.usesInnerDetections());
  info.model = nullptr;
  EXPECT_TRUE(info.usesImageCells());
  EXPECT_FALSE(info.usesInnerDetections());
  info.min_image_coverage = 0.0;
  EXPECT_FALSE(info.usesImageCells());
}

TEST(TrackModel, FeatureNamesRoundTrip) {
  for (const std::string& name : trackFeatureNames()) {
    TrackFeature f{};
    ASSERT_TRUE(parseTrackFeature(name, &f)) << name;
    EXPECT_EQ(trackFeatureNames()[static_cast<std::size_t>(f)], name);
  }
  TrackFeature f{};
  EXPECT_FALSE(parseTrackFeature("detections", &f));
}

TEST(Incidence, GrazingViewsDoNotCountWhereTheNormalIsKnown) {
  InformationConfig info;
  info.max_incidence_rad = M_PI / 3.0;
  const WeightedPoint facing{{2.0, 0.0, 0.0}, 1.0, {-1.0, 0.0, 0.0}};
  EXPECT_TRUE(withinIncidence(Eigen::Vector3d::Zero(), facing, info));
  EXPECT_FALSE(withinIncidence({0.0, 4.0, 0.0}, facing, info));  // 63 deg off the normal
  EXPECT_FALSE(withinIncidence({3.0, 0.0, 0.0}, facing, info));  // behind the surface
  const WeightedPoint unknown{{2.0, 0.0, 0.0}, 1.0, Eigen::Vector3d::Zero()};
  EXPECT_TRUE(withinIncidence({0.0, 4.0, 0.0}, unknown, info));
}

TEST(InformationConfig, ValidationNamesTheKey) {
  InformationConfig info;
  info.min_image_coverage = 1.5;
  try {
    info.validate();
    FAIL() << "expected an error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("min_image_coverage"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tgnav::planner
