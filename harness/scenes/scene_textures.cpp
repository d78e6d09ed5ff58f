#include "harness/scenes/scene_textures.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

namespace tgnav::harness::scenes {

namespace {

constexpr int kShift = 4;  // sub-pixel bits of the polygon vertices

// What a level draws: three scales of shapes (count per square metre, size range in metres),
// their contrast against the background, sparse stronger marks, and fine pixel noise.
struct LevelSpec {
  double density[3];
  bool full_contrast;
  double delta_lo, delta_hi;  // grey levels from the background (when not full_contrast)
  double strong_density;      // marks of [strong_lo, strong_hi] per square metre
  double strong_lo, strong_hi;
  int noise;  // +- grey levels per pixel
};

constexpr double kSizeLo[3] = {0.25, 0.06, 0.02};
constexpr double kSizeHi[3] = {0.8, 0.25, 0.07};

LevelSpec specOf(TextureLevel level) {
  switch (level) {
    case TextureLevel::kRich:
      return {{1.5, 14.0, 45.0}, true, 0.0, 0.0, 0.0, 0.0, 0.0, 5};
    case TextureLevel::kMedium:
      return {{0.8, 5.0, 10.0}, false, 25.0, 55.0, 0.0, 0.0, 0.0, 3};
    case TextureLevel::kFaint:
      return {{1.5, 6.0, 6.0}, false, 3.0, 8.0, 1.0, 22.0, 30.0, 2};
    case TextureLevel::kPlain:
      break;
  }
  throw std::logic_error("makeFaceImage: a plain face has no image");
}

// The face in metres (x right, y down from the top edge) on the square image.
struct Canvas {
  cv::Mat image;
  double px_per_m_x;
  double px_per_m_y;

  cv::Point at(double x_m, double y_m) const {
    return {static_cast<int>(std::lround(x_m * px_per_m_x * (1 << kShift))),
            static_cast<int>(std::lround(y_m * px_per_m_y * (1 << kShift)))};
  }
  // A polygon of `n` vertices: (x, y) + R(angle) (rx cos a_k, ry sin a_k) at the angles `a`.
  void polygon(double x, double y, double rx, double ry, double angle, const std::vector<double>& a,
               const cv::Scalar& colour) {
    std::vector<cv::Point> points;
    const double c = std::cos(angle), s = std::sin(angle);
    for (double ak : a) {
      const double u = rx * std::cos(ak), v = ry * std::sin(ak);
      points.push_back(at(x + c * u - s * v, y + s * u + c * v));
    }
    const std::vector<std::vector<cv::Point>> polys{points};
    cv::fillPoly(image, polys, colour, cv::LINE_AA, kShift);
  }
};

cv::Scalar clampColour(double b, double g, double r) {
  return {std::clamp(b, 0.0, 255.0), std::clamp(g, 0.0, 255.0), std::clamp(r, 0.0, 255.0)};
}

// Full contrast: a dark or a light colour with a tint.
cv::Scalar strongColour(SceneRng& rng) {
  const double base = rng.chance(0.5) ? rng.uniform(0.0, 90.0) : rng.uniform(165.0, 255.0);
  return clampColour(base + rng.uniform(-45.0, 45.0), base + rng.uniform(-45.0, 45.0), base + rng.uniform(-45.0, 45.0));
}

// The background moved by [lo, hi] grey levels up or down, with a slight tint.
cv::Scalar offsetColour(const cv::Scalar& bg, double lo, double hi, SceneRng& rng) {
  const double delta = (rng.chance(0.5) ? 1.0 : -1.0) * rng.uniform(lo, hi);
  const double tint = 0.15 * delta;
  return clampColour(bg[0] + delta + rng.uniform(-tint, tint), bg[1] + delta + rng.uniform(-tint, tint),
                     bg[2] + delta + rng.uniform(-tint, tint));
}

// One shape of size `size_m` at a drawn place: an ellipse, a rectangle, a triangle or a stroke.
void drawShape(Canvas& canvas, double width_m, double height_m, double size_m, const cv::Scalar& colour,
               SceneRng& rng) {
  const double x = rng.uniform(-0.1 * size_m, width_m + 0.1 * size_m);
  const double y = rng.uniform(-0.1 * size_m, height_m + 0.1 * size_m);
  const double angle = rng.uniform(0.0, kPi);
  const int type = rng.uniformInt(0, 3);
  if (type == 0) {
    std::vector<double> a;
    a.reserve(28);
    for (int k = 0; k < 28; ++k) a.push_back(2.0 * kPi * k / 28);
    canvas.polygon(x, y, 0.5 * size_m, 0.5 * size_m * rng.uniform(0.4, 1.0), angle, a, colour);
  } else if (type == 1) {
    const std::vector<double> a{0.25 * kPi, 0.75 * kPi, 1.25 * kPi, 1.75 * kPi};
    const double aspect = rng.uniform(0.3, 1.0);
    canvas.polygon(x, y, 0.7 * size_m, 0.7 * size_m * aspect, rng.chance(0.5) ? 0.0 : angle, a, colour);
  } else if (type == 2) {
    const double a0 = rng.uniform(0.0, 2.0 * kPi);
    const std::vector<double> a{a0, a0 + rng.uniform(1.6, 2.6), a0 + rng.uniform(3.6, 4.6)};
    canvas.polygon(x, y, 0.6 * size_m, 0.6 * size_m, 0.0, a, colour);
  } else {
    // A stroke: a thin rectangle (the 4 angles of a 1 x w box).
    const double w = rng.uniform(0.06, 0.2), t = std::atan(w);
    const std::vector<double> a{t, kPi - t, kPi + t, 2.0 * kPi - t};
    canvas.polygon(x, y, 1.2 * size_m, 1.2 * size_m, angle, a, colour);
  }
}

// Fine noise on 2 x 2 pixel cells (a grain that survives the texture's magnification and keeps
// the PNG small), the same on the three channels.
void addNoise(cv::Mat& image, int amplitude, SceneRng& rng) {
  for (int r = 0; r < image.rows; r += 2) {
    for (int c = 0; c < image.cols; c += 2) {
      const int n = rng.uniformInt(-amplitude, amplitude);
      for (int dr = 0; dr < 2 && r + dr < image.rows; ++dr) {
        for (int dc = 0; dc < 2 && c + dc < image.cols; ++dc) {
          cv::Vec3b& px = image.at<cv::Vec3b>(r + dr, c + dc);
          for (int k = 0; k < 3; ++k) px[k] = cv::saturate_cast<uchar>(px[k] + n);
        }
      }
    }
  }
}

}  // namespace

int faceImageSize(double extent_m) { return extent_m > 2.0 ? 384 : 256; }

cv::Mat makeFaceImage(TextureLevel level, double width_m, double height_m, int size_px, SceneRng& rng) {
  const LevelSpec spec = specOf(level);
  const double grey = level == TextureLevel::kRich ? rng.uniform(60.0, 200.0) : rng.uniform(110.0, 190.0);
  const double tint = level == TextureLevel::kRich ? 40.0 : 15.0;
  const cv::Scalar bg =
      clampColour(grey + rng.uniform(-tint, tint), grey + rng.uniform(-tint, tint), grey + rng.uniform(-tint, tint));
  Canvas canvas{cv::Mat(size_px, size_px, CV_8UC3, bg), size_px / width_m, size_px / height_m};
  const double area = width_m * height_m;
  for (int scale = 0; scale < 3; ++scale) {
    const long count = std::lround(spec.density[scale] * area);
    for (long k = 0; k < count; ++k) {
      const cv::Scalar colour =
          spec.full_contrast ? strongColour(rng) : offsetColour(bg, spec.delta_lo, spec.delta_hi, rng);
      drawShape(canvas, width_m, height_m, rng.uniform(kSizeLo[scale], kSizeHi[scale]), colour, rng);
    }
  }
  const long strong = std::lround(spec.strong_density * area);
  for (long k = 0; k < strong; ++k) {
    const cv::Scalar colour = offsetColour(bg, spec.strong_lo, spec.strong_hi, rng);
    drawShape(canvas, width_m, height_m, rng.uniform(kSizeLo[1], kSizeHi[1]), colour, rng);
  }
  addNoise(canvas.image, spec.noise, rng);
  return canvas.image;
}

}  // namespace tgnav::harness::scenes
