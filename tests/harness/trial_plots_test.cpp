// Pictures of a trial: paths and markers land on their pixels in their colours, the caption
// keeps to its band; the error plot's geometry follows the data on {1, 2, 5} x 10^k axes that
// cover it; the frame strip lays out and captions its frames; bad input throws.
#include "harness/trial_plots.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "harness/topdown.h"

namespace tgnav::harness {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

bool isGreen(const cv::Vec3b& c) { return c[1] > 120 && c[1] > c[0] + 60 && c[1] > c[2] + 60; }
bool isBlue(const cv::Vec3b& c) { return c[0] > 150 && c[0] > c[1] + 80 && c[0] > c[2] + 80; }
bool isMagenta(const cv::Vec3b& c) { return c[0] > 150 && c[2] > 150 && c[1] < 80; }
bool isRed(const cv::Vec3b& c) { return c[2] > 150 && c[0] < 80 && c[1] < 80; }
bool isDark(const cv::Vec3b& c) { return c[0] < 50 && c[1] < 50 && c[2] < 50; }
// Text, anti-aliased: darker grey pixels.
bool isText(const cv::Vec3b& c) { return c[0] < 150 && c[0] == c[1] && c[1] == c[2]; }
bool isMidGrey(const cv::Vec3b& c) { return c[0] == c[1] && c[1] == c[2] && c[0] > 40 && c[0] < 130; }
// Curve pixels of the error plot: everything else there (text, grid, frame) is grey.
bool isSaturated(const cv::Vec3b& c) { return std::max({c[0], c[1], c[2]}) - std::min({c[0], c[1], c[2]}) > 80; }

template <typename Pred>
std::vector<cv::Point> pixelsWhere(const cv::Mat& img, Pred pred) {
  std::vector<cv::Point> out;
  for (int y = 0; y < img.rows; ++y) {
    for (int x = 0; x < img.cols; ++x) {
      if (pred(img.at<cv::Vec3b>(y, x))) out.emplace_back(x, y);
    }
  }
  return out;
}

cv::Point2d centroid(const std::vector<cv::Point>& pts) {
  cv::Point2d sum(0, 0);
  for (const cv::Point& p : pts) sum += cv::Point2d(p.x, p.y);
  return sum / static_cast<double>(pts.size());
}

// ---------------------------------------------------------------------------------------------
// Top-down picture

SceneConfig sceneOf(double half_x, double half_y) {
  SceneConfig scene;
  scene.bounds_min_m = Eigen::Vector3d(-half_x, -half_y, 0.0);
  scene.bounds_max_m = Eigen::Vector3d(half_x, half_y, 3.0);
  scene.flight_height_m = 1.0;
  scene.start.p_WB = Eigen::Vector3d(-half_x + 0.8, 0.5, 1.0);
  scene.goal.p_WB = Eigen::Vector3d(half_x - 0.8, 0.5, 1.0);
  return scene;
}

// Observed free space around the flight height over the scene, with an occupied 1 m box at the
// origin reaching through the band.
planner::FeatureMap boxMap(const SceneConfig& scene) {
  constexpr double kRes = 0.2;
  planner::FeatureMap map(kRes);
  for (double x = scene.bounds_min_m.x() + kRes / 2; x < scene.bounds_max_m.x(); x += kRes) {
    for (double y = scene.bounds_min_m.y() + kRes / 2; y < scene.bounds_max_m.y(); y += kRes) {
      for (double z = 0.5 + kRes / 2; z < 1.5; z += kRes) {
        map.occupancy().updateNode(octomap::point3d(x, y, z), std::abs(x) < 0.5 && std::abs(y) < 0.5);
      }
    }
  }
  return map;
}

class TrialTopdownTest : public ::testing::Test {
 protected:
  static constexpr double kMetresPerPx = 0.02;
  // Pixel of p_W in the picture: the map's pixel below the caption band.
  cv::Point at(const cv::Mat& img, const Eigen::Vector2d& p_W) const {
    const Topdown top(scene_, kMetresPerPx);
    return top.toPixel(p_W) + cv::Point(0, img.rows - top.image().rows);
  }
  cv::Vec3b colourAt(const cv::Mat& img, const Eigen::Vector2d& p_W) const { return img.at<cv::Vec3b>(at(img, p_W)); }
  cv::Mat draw(const TrialPaths& paths) const { return drawTrialTopdown(scene_, map_, paths, kMetresPerPx); }

  SceneConfig scene_ = sceneOf(6.0, 5.0);  // storage-sized: 12 m x 10 m
  planner::FeatureMap map_ = boxMap(scene_);
};

TEST_F(TrialTopdownTest, IsTheMapAtScaleWithACaptionBandOnTop) {
  const cv::Mat img = draw({});
  ASSERT_EQ(img.type(), CV_8UC3);
  EXPECT_EQ(img.cols, 600);
  const int band = img.rows - 500;
  EXPECT_GT(band, 10);
  EXPECT_LT(band, 60);
  // The map itself is there: the box is drawn dark at the origin, free space light around it.
  EXPECT_TRUE(isMidGrey(colourAt(img, {0.0, 0.0})));
  const cv::Vec3b free = colourAt(img, {2.0, -2.0});
  EXPECT_GT(free[0], 200);
  EXPECT_LT(free[0], 250);

  const SceneConfig gallery = sceneOf(11.0, 10.0);
  const cv::Mat big = drawTrialTopdown(gallery, boxMap(gallery), {}, 0.04);
  EXPECT_EQ(big.cols, 550);
  EXPECT_GT(big.rows, 500);
}

TEST_F(TrialTopdownTest, PathsAppearInTheirColoursAlongTheirPolylines) {
  TrialPaths paths;
  paths.planned = {{-5.0, 1.5}, {5.0, 1.5}};
  paths.flown = {{-5.0, -1.5}, {0.0, -0.8}, {5.0, -1.5}};
  paths.estimated = {{-5.0, -2.8}, {5.0, -2.8}};
  paths.trajectory = {{-5.0, 0.9}, {5.0, 0.9}};
  const cv::Mat img = draw(paths);
  for (const double x : {-2.5, -1.0, 1.0, 2.5}) {
    SCOPED_TRACE(x);
    EXPECT_TRUE(isBlue(colourAt(img, {x, 1.5})));
    EXPECT_TRUE(isMagenta(colourAt(img, {x, -2.8})));
  }
  // The flown path's segments at their midpoints.
  EXPECT_TRUE(isGreen(colourAt(img, {-2.5, -1.15})));
  EXPECT_TRUE(isGreen(colourAt(img, {2.5, -1.15})));
  EXPECT_TRUE(isGreen(colourAt(img, {0.0, -0.8})));
  EXPECT_FALSE(isGreen(colourAt(img, {0.0, -2.0})));
  // The trajectory is dashed: along its row some pixels are its grey, some the map's.
  const int row = at(img, {0.0, 0.9}).y;
  int on = 0, total = 0;
  for (int x = at(img, {-2.5, 0.9}).x; x <= at(img, {-0.6, 0.9}).x; ++x, ++total) {
    on += isMidGrey(img.at<cv::Vec3b>(row, x)) ? 1 : 0;
  }
  EXPECT_GT(on, total / 4);
  EXPECT_LT(on, total * 9 / 10);
}

TEST_F(TrialTopdownTest, MarkersSitWhereGivenAndOnlyThen) {
  const Eigen::Vector2d lost(2.0, 3.0), crash(-2.0, -3.0);
  TrialPaths paths;
  const cv::Mat without = draw(paths);
  paths.vo_lost_at = lost;
  paths.collision_at = crash;
  const cv::Mat with = draw(paths);
  EXPECT_TRUE(isDark(colourAt(with, lost)));
  EXPECT_TRUE(isRed(colourAt(with, crash)));
  EXPECT_FALSE(isDark(colourAt(without, lost)));
  EXPECT_FALSE(isRed(colourAt(without, crash)));
  // The lost marker's ring: dark pixels on a circle around the point, white between.
  const cv::Point c = at(with, lost);
  int dark_far = 0;
  for (int dx = -20; dx <= 20; ++dx) {
    for (int dy = -20; dy <= 20; ++dy) {
      if (std::hypot(dx, dy) > 8.0 && isDark(with.at<cv::Vec3b>(c + cv::Point(dx, dy)))) ++dark_far;
    }
  }
  EXPECT_GT(dark_far, 20);
}

TEST_F(TrialTopdownTest, LegendListsOnlyWhatHasData) {
  TrialPaths paths;
  paths.flown = {{-5.0, -1.5}, {5.0, -1.5}};
  const cv::Mat img = draw(paths);
  // No estimated or planned path, no collision: none of their colours anywhere (the goal is red
  // but not the collision's red X: no red pixels away from the goal).
  EXPECT_TRUE(pixelsWhere(img, isMagenta).empty());
  EXPECT_TRUE(pixelsWhere(img, isBlue).empty());
  // With an estimate, its colour appears in the legend as well as along the path.
  paths.estimated = {{-5.0, -2.8}, {5.0, -2.8}};
  const cv::Mat with = draw(paths);
  const int row = at(with, {0.0, -2.8}).y;
  bool off_path = false;
  for (const cv::Point& p : pixelsWhere(with, isMagenta)) off_path = off_path || std::abs(p.y - row) > 10;
  EXPECT_TRUE(off_path);
}

TEST_F(TrialTopdownTest, CaptionStaysInItsBandAboveTheMap) {
  TrialPaths paths;
  paths.flown = {{-5.0, -1.5}, {5.0, -1.5}};
  const cv::Mat plain = draw(paths);
  const int band = plain.rows - 500;
  for (const std::string& caption : {std::string("storage proposed seed 1: success"), std::string(400, 'W')}) {
    paths.caption = caption;
    const cv::Mat captioned = draw(paths);
    ASSERT_EQ(captioned.size(), plain.size());
    cv::Mat diff;
    cv::absdiff(captioned, plain, diff);
    cv::cvtColor(diff, diff, cv::COLOR_BGR2GRAY);
    EXPECT_GT(cv::countNonZero(diff.rowRange(0, band)), 50);
    EXPECT_EQ(cv::countNonZero(diff.rowRange(band, diff.rows)), 0);
  }
}

TEST_F(TrialTopdownTest, LinesScaleWithThePicture) {
  // The same flown path, its width in pixels across the line in a small and a large picture.
  auto widthAt = [](const cv::Mat& img, const cv::Point& p) {
    int n = 0;
    for (int y = p.y - 30; y <= p.y + 30; ++y) n += isGreen(img.at<cv::Vec3b>(y, p.x)) ? 1 : 0;
    return n;
  };
  TrialPaths paths;
  paths.flown = {{-2.0, -1.0}, {2.0, -1.0}};
  const SceneConfig smoke = sceneOf(4.0, 3.0);
  const Topdown small_top(smoke, 0.02);
  const cv::Mat small = drawTrialTopdown(smoke, boxMap(smoke), paths, 0.02);
  const cv::Mat large = drawTrialTopdown(smoke, boxMap(smoke), paths, 0.005);
  const Topdown large_top(smoke, 0.005);
  const int w_small =
      widthAt(small, small_top.toPixel({0.0, -1.0}) + cv::Point(0, small.rows - small_top.image().rows));
  const int w_large =
      widthAt(large, large_top.toPixel({0.0, -1.0}) + cv::Point(0, large.rows - large_top.image().rows));
  EXPECT_GE(w_small, 2);
  EXPECT_GT(w_large, w_small + 2);
  EXPECT_GT(large.rows - large_top.image().rows, small.rows - small_top.image().rows);  // larger caption text
}

TEST_F(TrialTopdownTest, SkipsNonFinitePointsAndRejectsABadScale) {
  TrialPaths paths;
  paths.flown = {{-5.0, -1.5}, {-3.0, -1.5}, {kNaN, 0.0}, {kInf, 1.0}, {1e300, 0.0}, {3.0, -1.5}, {5.0, -1.5}};
  paths.estimated = {{kNaN, kNaN}};
  paths.vo_lost_at = Eigen::Vector2d(kInf, 0.0);
  const cv::Mat img = draw(paths);
  EXPECT_TRUE(isGreen(colourAt(img, {-4.0, -1.5})));
  EXPECT_TRUE(isGreen(colourAt(img, {4.0, -1.5})));
  EXPECT_FALSE(isGreen(colourAt(img, {0.0, -1.5})));  // the run breaks at the bad points
  EXPECT_THROW(drawTrialTopdown(scene_, map_, paths, 0.0), std::invalid_argument);
  EXPECT_THROW(drawTrialTopdown(scene_, map_, paths, kNaN), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Error against distance

ErrorCurve curve(std::vector<double> d, std::vector<double> e, std::string label = "") {
  ErrorCurve c;
  c.distance_m = std::move(d);
  c.error_m = std::move(e);
  c.label = std::move(label);
  return c;
}

// The plot's frame and gridlines: rows (or columns) that are mostly grey lines.
std::vector<int> gridLines(const cv::Mat& img, bool rows) {
  std::vector<int> lines;
  const int n = rows ? img.rows : img.cols;
  const int len = rows ? img.cols : img.rows;
  for (int i = 0; i < n; ++i) {
    int grey = 0;
    for (int j = 0; j < len; ++j) {
      const cv::Vec3b c = rows ? img.at<cv::Vec3b>(i, j) : img.at<cv::Vec3b>(j, i);
      grey += (c[0] == c[1] && c[1] == c[2] && c[0] > 60 && c[0] < 245) ? 1 : 0;
    }
    if (grey > len / 2) lines.push_back(i);
  }
  return lines;
}

// Mantissa of a positive number in [1, 10).
double mantissa(double v) { return v / std::pow(10.0, std::floor(std::log10(v))); }

TEST(ErrorPlot, HasTheRequestedSize) {
  const std::vector<ErrorCurve> curves = {curve({0, 1, 2}, {0, 0.1, 0.2}, "ours")};
  for (const auto& [w, h] : {std::pair{800, 500}, std::pair{640, 360}, std::pair{1600, 1000}}) {
    const cv::Mat img = drawErrorVsDistance(curves, "storage", w, h);
    EXPECT_EQ(img.cols, w);
    EXPECT_EQ(img.rows, h);
    EXPECT_EQ(img.type(), CV_8UC3);
  }
}

TEST(ErrorPlot, HigherErrorIsHigherInTheImage) {
  // Rising then falling: a tent peaking at 5 m.
  const cv::Mat img = drawErrorVsDistance(
      {curve({0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10}, {0.0, 0.05, 0.1, 0.15, 0.2, 0.37, 0.2, 0.15, 0.1, 0.05, 0.02})},
      "tent");
  const std::vector<cv::Point> pts = pixelsWhere(img, isSaturated);
  ASSERT_GT(pts.size(), 200u);
  cv::Rect box = cv::boundingRect(pts);
  cv::Point top = pts.front(), left = pts.front(), right = pts.front();
  for (const cv::Point& p : pts) {
    if (p.y < top.y) top = p;
    if (p.x < left.x) left = p;
    if (p.x > right.x) right = p;
  }
  EXPECT_NEAR(top.x, box.x + 0.5 * box.width, 3);  // the peak is at the middle distance
  EXPECT_LT(top.y + 50, left.y);                   // and well above both ends
  EXPECT_LT(top.y + 50, right.y);
  EXPECT_LT(right.y, left.y);  // 0.02 m is above 0
}

TEST(ErrorPlot, AxesEndOnRoundTicksThatCoverTheData) {
  // Data up to 7.3 m and 0.37 m; the peak sits at the last distance.
  const cv::Mat img = drawErrorVsDistance({curve({0, 2, 4, 7.3}, {0.0, 0.1, 0.2, 0.37})}, "ticks");
  const std::vector<int> rows = gridLines(img, true), cols = gridLines(img, false);
  ASSERT_GE(rows.size(), 4u);  // frame top and bottom and at least two ticks between
  ASSERT_GE(cols.size(), 4u);
  ASSERT_LE(rows.size(), 12u);
  ASSERT_LE(cols.size(), 12u);
  // Evenly spaced, frame to frame.
  for (const auto* lines : {&rows, &cols}) {
    const double gap = static_cast<double>(lines->back() - lines->front()) / (lines->size() - 1);
    for (std::size_t i = 0; i < lines->size(); ++i) EXPECT_NEAR((*lines)[i], lines->front() + i * gap, 1.0);
  }
  const std::vector<cv::Point> pts = pixelsWhere(img, isSaturated);
  ASSERT_FALSE(pts.empty());
  const cv::Rect box = cv::boundingRect(pts);
  // The data lie inside the axes, which start at zero (the curve starts at the bottom-left corner)...
  EXPECT_GE(box.y, rows.front() - 2);
  EXPECT_GE(box.x, cols.front() - 2);
  EXPECT_LE(box.br().y, rows.back() + 3);
  EXPECT_LE(box.br().x, cols.back() + 3);
  EXPECT_NEAR(box.br().y, rows.back(), 3);
  EXPECT_NEAR(box.x, cols.front(), 3);
  // ...and end at round values: from where 7.3 and 0.37 land, the axis ends and the tick step
  // are {1, 2, 5} x 10^k.
  const double x_end = 7.3 * (cols.back() - cols.front()) / (box.br().x - 1 - cols.front());
  const double y_end = 0.37 * (rows.back() - rows.front()) / (rows.back() - box.y - 1);
  EXPECT_GE(x_end, 7.3);
  EXPECT_GE(y_end, 0.37);
  for (const double step : {x_end / (cols.size() - 1), y_end / (rows.size() - 1)}) {
    const double m = mantissa(step);
    const double nearest = m < 1.5 ? 1.0 : m < 3.5 ? 2.0 : m < 7.5 ? 5.0 : 10.0;
    EXPECT_NEAR(m / nearest, 1.0, 0.04) << "step " << step;
  }
}

TEST(ErrorPlot, LostMarkerSitsOnTheCurveAtItsDistance) {
  ErrorCurve tent = curve({0, 2, 4, 6, 8, 10}, {0.0, 0.1, 0.2, 0.35, 0.2, 0.1});
  const cv::Mat without = drawErrorVsDistance({tent}, "lost");
  tent.lost_at_distance_m = 6.0;
  const cv::Mat with = drawErrorVsDistance({tent}, "lost");
  cv::Point peak(0, with.rows);
  for (const cv::Point& p : pixelsWhere(without, isSaturated)) {
    if (p.y < peak.y) peak = p;
  }
  // Changed pixels near the peak (the legend's "lost" entry is elsewhere) centre on it.
  cv::Mat diff;
  cv::absdiff(with, without, diff);
  cv::cvtColor(diff, diff, cv::COLOR_BGR2GRAY);
  std::vector<cv::Point> changed;
  for (int y = peak.y - 25; y <= peak.y + 25; ++y) {
    for (int x = peak.x - 25; x <= peak.x + 25; ++x) {
      if (diff.at<uchar>(y, x) > 40) changed.emplace_back(x, y);
    }
  }
  ASSERT_GT(changed.size(), 30u);
  const cv::Point2d c = centroid(changed);
  EXPECT_NEAR(c.x, peak.x, 3.0);
  EXPECT_NEAR(c.y, peak.y, 4.0);
  EXPECT_TRUE(isDark(with.at<cv::Vec3b>(peak + cv::Point(0, 1))));
  // A legend entry "lost" appears with the marker.
  cv::Mat far = diff.clone();
  far(cv::Rect(peak.x - 25, peak.y - 25, 51, 51)).setTo(0);
  EXPECT_GT(cv::countNonZero(far), 30);
}

TEST(ErrorPlot, CurvesGetDistinctColours) {
  const cv::Mat img =
      drawErrorVsDistance({curve({0, 5, 10}, {0.05, 0.05, 0.05}), curve({0, 5, 10}, {0.4, 0.4, 0.4})}, "two");
  const std::vector<cv::Point> pts = pixelsWhere(img, isSaturated);
  ASSERT_FALSE(pts.empty());
  const int middle = (cv::boundingRect(pts).y + cv::boundingRect(pts).br().y) / 2;
  cv::Vec3d low(0, 0, 0), high(0, 0, 0);
  int n_low = 0, n_high = 0;
  for (const cv::Point& p : pts) {
    const cv::Vec3b& c = img.at<cv::Vec3b>(p);
    if (p.y > middle) {
      low += cv::Vec3d(c[0], c[1], c[2]);
      ++n_low;
    } else {
      high += cv::Vec3d(c[0], c[1], c[2]);
      ++n_high;
    }
  }
  ASSERT_GT(n_low, 100);
  ASSERT_GT(n_high, 100);
  EXPECT_GT(cv::norm(low / n_low - high / n_high), 80.0);
}

TEST(ErrorPlot, DegenerateInputStillDraws) {
  // Nothing at all, an empty curve, a single point, all-zero errors.
  EXPECT_FALSE(drawErrorVsDistance({}, "nothing").empty());
  EXPECT_FALSE(drawErrorVsDistance({curve({}, {}, "no data")}, "empty").empty());
  EXPECT_FALSE(pixelsWhere(drawErrorVsDistance({curve({3.0}, {0.2})}, "single"), isSaturated).empty());
  const cv::Mat zeros = drawErrorVsDistance({curve({0, 1, 2, 3}, {0, 0, 0, 0})}, "zeros");
  // The y axis did not collapse: gridlines above the curve, which lies on the bottom of the
  // frame (the zero line). The curve covers that line, so it is taken from a plot of the same
  // size with a rising curve.
  const std::vector<int> rows = gridLines(zeros, true);
  ASSERT_GE(rows.size(), 3u);
  const int frame_bottom = gridLines(drawErrorVsDistance({curve({0, 3}, {0, 1})}, "rising"), true).back();
  const cv::Rect box = cv::boundingRect(pixelsWhere(zeros, isSaturated));
  EXPECT_NEAR(box.y + 0.5 * box.height, frame_bottom, 2);
  EXPECT_GT(frame_bottom - rows.front(), 200);
}

TEST(ErrorPlot, NonFiniteValuesBreakTheCurve) {
  // Finite at 0..4 and 6..10 m; the values at 5 m are not.
  ErrorCurve c = curve({0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10}, {0.2, 0.2, 0.2, 0.2, 0.2, kNaN, 0.2, 0.2, 0.2, 0.2, 0.2});
  c.distance_m[5] = 5.0;
  ErrorCurve inf = c;
  inf.error_m[5] = kInf;
  for (const ErrorCurve& curve_with_gap : {c, inf}) {
    const cv::Mat img = drawErrorVsDistance({curve_with_gap}, "gap");
    const std::vector<cv::Point> pts = pixelsWhere(img, isSaturated);
    ASSERT_FALSE(pts.empty());
    const cv::Rect box = cv::boundingRect(pts);
    // Columns around the middle (4..6 m spans a fifth of the width) hold no curve.
    const int mid = box.x + box.width / 2;
    for (const cv::Point& p : pts) EXPECT_GT(std::abs(p.x - mid), box.width / 20) << p;
    EXPECT_LT(box.height, 8);  // both halves at the same error
  }
}

TEST(ErrorPlot, RejectsMismatchedSizesAndTinyImages) {
  EXPECT_THROW(drawErrorVsDistance({curve({0, 1, 2}, {0, 1})}, "bad"), std::invalid_argument);
  EXPECT_THROW(drawErrorVsDistance({curve({0, 1}, {0, 1})}, "small", 100, 80), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Frame strip

cv::Mat solid(int w, int h, const cv::Scalar& colour) { return cv::Mat(h, w, CV_8UC3, colour); }

std::vector<cv::Point> pixelsOf(const cv::Mat& img, const cv::Scalar& colour) {
  const cv::Vec3b want(static_cast<uchar>(colour[0]), static_cast<uchar>(colour[1]), static_cast<uchar>(colour[2]));
  return pixelsWhere(img, [&](const cv::Vec3b& c) { return c == want; });
}

const std::vector<cv::Scalar> kColours = {cv::Scalar(200, 50, 50), cv::Scalar(50, 200, 50), cv::Scalar(50, 50, 200),
                                          cv::Scalar(200, 200, 50), cv::Scalar(50, 200, 200)};

TEST(FrameStrip, LaysOutThumbnailsInRows) {
  std::vector<cv::Mat> frames;
  frames.reserve(kColours.size());
  for (const auto& c : kColours) frames.push_back(solid(320, 240, c));
  const cv::Mat img = drawFrameStrip(frames, {"a", "b", "c", "d", "e"}, 240, 4);
  EXPECT_GE(img.cols, 4 * 240);
  EXPECT_LE(img.cols, 4 * 240 + 100);
  EXPECT_GE(img.rows, 2 * 180);
  EXPECT_LE(img.rows, 2 * 180 + 150);
  std::vector<cv::Rect> boxes;
  for (const auto& c : kColours) {
    const std::vector<cv::Point> pts = pixelsOf(img, c);
    ASSERT_EQ(pts.size(), 240u * 180u);  // whole, undistorted, uncovered
    boxes.push_back(cv::boundingRect(pts));
    EXPECT_EQ(boxes.back().size(), cv::Size(240, 180));
  }
  for (int i = 1; i < 4; ++i) {
    EXPECT_GT(boxes[i].x, boxes[i - 1].br().x - 1);
    EXPECT_EQ(boxes[i].y, boxes[0].y);
  }
  EXPECT_EQ(boxes[4].x, boxes[0].x);
  EXPECT_GT(boxes[4].y, boxes[0].br().y + 10);  // a caption line between the rows
}

TEST(FrameStrip, FramesOfAnySizeScaleToTheThumbWidth) {
  const cv::Mat img =
      drawFrameStrip({solid(640, 480, kColours[0]), solid(100, 300, kColours[1])}, {"wide", "tall"}, 240, 4);
  EXPECT_EQ(cv::boundingRect(pixelsOf(img, kColours[0])).size(), cv::Size(240, 180));
  EXPECT_EQ(cv::boundingRect(pixelsOf(img, kColours[1])).size(), cv::Size(240, 720));
  EXPECT_GE(img.rows, 720);
}

TEST(FrameStrip, CaptionsSitUnderTheirThumbnails) {
  const cv::Mat img = drawFrameStrip({solid(320, 240, kColours[0]), solid(320, 240, kColours[1])},
                                     {"t = 12.0 s, 85 inliers", ""}, 240, 4);
  for (int i = 0; i < 2; ++i) {
    const cv::Rect thumb = cv::boundingRect(pixelsOf(img, kColours[i]));
    int below = 0, above = 0;
    for (const cv::Point& p : pixelsWhere(img, isText)) {
      if (p.x < thumb.x || p.x >= thumb.br().x) continue;
      (p.y >= thumb.br().y ? below : above) += 1;
    }
    EXPECT_EQ(above, 0);
    if (i == 0) {
      EXPECT_GT(below, 20);
    } else {
      EXPECT_EQ(below, 0);
    }
  }
}

TEST(FrameStrip, EmptyInputAndBadInput) {
  EXPECT_TRUE(drawFrameStrip({}, {}).empty());
  EXPECT_THROW(drawFrameStrip({solid(32, 24, kColours[0])}, {}), std::invalid_argument);
  EXPECT_THROW(drawFrameStrip({solid(32, 24, kColours[0])}, {"a", "b"}), std::invalid_argument);
  EXPECT_THROW(drawFrameStrip({cv::Mat(24, 32, CV_8UC1, cv::Scalar(0))}, {"grey"}), std::invalid_argument);
  EXPECT_THROW(drawFrameStrip({solid(32, 24, kColours[0])}, {"a"}, 0), std::invalid_argument);
}

}  // namespace
}  // namespace tgnav::harness
