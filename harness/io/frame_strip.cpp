#include "harness/io/frame_strip.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace tgnav::harness {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
const cv::Scalar kWhite(255, 255, 255);
const cv::Scalar kText(30, 30, 30);

int px(double v) { return static_cast<int>(std::lround(v)); }

cv::Size textSize(const std::string& text, double scale, int thickness = 1) {
  int baseline = 0;
  const cv::Size s = cv::getTextSize(text, kFont, scale, thickness, &baseline);
  return {s.width, s.height + baseline};
}

int lineHeight(double scale) { return textSize("Ag", scale).height; }

void putTextTopLeft(cv::Mat& img, const std::string& text, cv::Point top_left, double scale, const cv::Scalar& colour,
                    int thickness = 1) {
  int baseline = 0;
  const cv::Size s = cv::getTextSize("Ag", kFont, scale, thickness, &baseline);
  cv::putText(img, text, top_left + cv::Point(0, s.height), kFont, scale, colour, thickness, cv::LINE_AA);
}

std::string fitText(const std::string& text, int max_width, double& scale, double min_scale) {
  while (textSize(text, scale).width > max_width && scale > min_scale) scale = std::max(min_scale, scale - 0.02);
  if (textSize(text, scale).width <= max_width) return text;
  std::string cut = text;
  while (!cut.empty() && textSize(cut + "...", scale).width > max_width) cut.pop_back();
  return cut.empty() ? std::string() : cut + "...";
}

}  // namespace

cv::Mat drawFrameStrip(const std::vector<cv::Mat>& frames, const std::vector<std::string>& captions, int thumb_width,
                       int per_row) {
  if (frames.size() != captions.size()) {
    throw std::invalid_argument("drawFrameStrip: " + std::to_string(frames.size()) + " frames but " +
                                std::to_string(captions.size()) + " captions");
  }
  if (frames.empty()) return {};
  if (thumb_width < 16 || per_row < 1) {
    throw std::invalid_argument("drawFrameStrip: thumb_width = " + std::to_string(thumb_width) +
                                " (at least 16), per_row = " + std::to_string(per_row) + " (at least 1)");
  }
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (frames[i].empty() || frames[i].type() != CV_8UC3) {
      throw std::invalid_argument("drawFrameStrip: frame " + std::to_string(i) + " is empty or not CV_8UC3");
    }
  }

  std::vector<cv::Mat> thumbs;
  for (const cv::Mat& f : frames) {
    const int h = std::max(1, px(static_cast<double>(f.rows) * thumb_width / f.cols));
    cv::Mat t;
    cv::resize(f, t, cv::Size(thumb_width, h), 0, 0, f.cols > thumb_width ? cv::INTER_AREA : cv::INTER_LINEAR);
    thumbs.push_back(t);
  }
  const double u = thumb_width / 240.0;
  const double font = std::max(0.35, std::min(0.5, 0.45 * u));
  const int gap = std::max(4, px(8 * u));
  const int caption_height = lineHeight(font) + gap;
  const int n = static_cast<int>(frames.size());
  const int columns = std::min(n, per_row);
  const int rows = (n + per_row - 1) / per_row;

  std::vector<int> row_height(rows, 0);  // tallest thumbnail of each row
  for (int i = 0; i < n; ++i) row_height[i / per_row] = std::max(row_height[i / per_row], thumbs[i].rows);
  int total_height = gap;
  for (const int h : row_height) total_height += h + caption_height + gap;
  cv::Mat out(total_height, gap + columns * (thumb_width + gap), CV_8UC3, kWhite);

  int y = gap;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < columns && r * per_row + c < n; ++c) {
      const int i = r * per_row + c;
      const int x = gap + c * (thumb_width + gap);
      thumbs[i].copyTo(out(cv::Rect(x, y, thumb_width, thumbs[i].rows)));
      double caption_font = font;
      const std::string caption = fitText(captions[i], thumb_width, caption_font, 0.8 * font);
      const int text_x = x + (thumb_width - textSize(caption, caption_font).width) / 2;
      putTextTopLeft(out, caption, {text_x, y + thumbs[i].rows + gap / 2}, caption_font, kText);
    }
    y += row_height[r] + caption_height + gap;
  }
  return out;
}

}  // namespace tgnav::harness
