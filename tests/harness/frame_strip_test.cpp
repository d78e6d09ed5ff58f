// The frame strip (a trial's frames.png) lays out and captions its frames; bad input throws.
#include "harness/io/frame_strip.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace tgnav::harness {
namespace {

// Text, anti-aliased: darker grey pixels.
bool isText(const cv::Vec3b& c) { return c[0] < 150 && c[0] == c[1] && c[1] == c[2]; }

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
