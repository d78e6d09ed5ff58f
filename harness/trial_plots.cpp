#include "harness/trial_plots.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <utility>

#include "harness/topdown.h"

namespace tgnav::harness {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
// The occupancy band drawn around the flight height, as `tgnav map` draws topdown.png.
constexpr double kMapBandM = 0.3;

const cv::Scalar kWhite(255, 255, 255);
const cv::Scalar kBlack(0, 0, 0);
const cv::Scalar kText(30, 30, 30);
// Topdown path colours (BGR). Planned as plan.png draws the chosen path.
const cv::Scalar kPlanned(200, 60, 0);
const cv::Scalar kTrajectory(70, 70, 70);
const cv::Scalar kFlown(40, 175, 0);
const cv::Scalar kEstimated(210, 0, 210);
const cv::Scalar kCollision(0, 0, 230);
const cv::Scalar kStart(0, 170, 0);  // as Topdown::drawStartGoal
const cv::Scalar kGoal(0, 0, 220);

int px(double v) { return static_cast<int>(std::lround(v)); }

// Smallest {1, 2, 5} x 10^k that is at least `raw` (> 0).
double niceStep(double raw) {
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0}) {
    if (m * magnitude >= raw * (1.0 - 1e-9)) return m * magnitude;
  }
  return 10.0 * magnitude;
}

cv::Size textSize(const std::string& text, double scale, int thickness = 1) {
  int baseline = 0;
  const cv::Size s = cv::getTextSize(text, kFont, scale, thickness, &baseline);
  return {s.width, s.height + baseline};
}

// Height of a line of text from the top of capitals to the bottom of descenders.
int lineHeight(double scale) { return textSize("Ag", scale).height; }

// Draws `text` with its top-left corner (capitals, descenders below) at `top_left`.
void putTextTopLeft(cv::Mat& img, const std::string& text, cv::Point top_left, double scale, const cv::Scalar& colour,
                    int thickness = 1) {
  int baseline = 0;
  const cv::Size s = cv::getTextSize("Ag", kFont, scale, thickness, &baseline);
  cv::putText(img, text, top_left + cv::Point(0, s.height), kFont, scale, colour, thickness, cv::LINE_AA);
}

// `text` shrunk (down to `min_scale`) and then cut with "..." until it is at most `max_width`
// pixels wide; `scale` is updated.
std::string fitText(const std::string& text, int max_width, double& scale, double min_scale) {
  while (textSize(text, scale).width > max_width && scale > min_scale) scale = std::max(min_scale, scale - 0.02);
  if (textSize(text, scale).width <= max_width) return text;
  std::string cut = text;
  while (!cut.empty() && textSize(cut + "...", scale).width > max_width) cut.pop_back();
  return cut.empty() ? std::string() : cut + "...";
}

// Text rotated to read bottom-to-top, centred at `centre`.
void putTextVertical(cv::Mat& img, const std::string& text, cv::Point centre, double scale, const cv::Scalar& colour) {
  const cv::Size s = textSize(text, scale);
  cv::Mat horizontal(s.height + 2, s.width + 2, CV_8UC3, kWhite);
  putTextTopLeft(horizontal, text, {1, 1}, scale, colour);
  cv::Mat vertical;
  cv::rotate(horizontal, vertical, cv::ROTATE_90_COUNTERCLOCKWISE);
  const cv::Rect target(centre.x - vertical.cols / 2, centre.y - vertical.rows / 2, vertical.cols, vertical.rows);
  const cv::Rect clipped = target & cv::Rect(0, 0, img.cols, img.rows);
  if (clipped.empty()) return;
  vertical(cv::Rect(clipped.tl() - target.tl(), clipped.size())).copyTo(img(clipped));
}

// Lines with sub-pixel end points.
constexpr int kShift = 4;
cv::Point fixed(const cv::Point2d& p) { return {px(p.x * (1 << kShift)), px(p.y * (1 << kShift))}; }

void line(cv::Mat& img, const cv::Point2d& a, const cv::Point2d& b, const cv::Scalar& colour, int thickness) {
  cv::line(img, fixed(a), fixed(b), colour, thickness, cv::LINE_AA, kShift);
}

void polyline(cv::Mat& img, const std::vector<cv::Point2d>& run, const cv::Scalar& colour, int thickness) {
  if (run.size() == 1) {
    cv::circle(img, fixed(run[0]), std::max(1, thickness) << kShift, colour, cv::FILLED, cv::LINE_AA, kShift);
  }
  for (std::size_t i = 1; i < run.size(); ++i) line(img, run[i - 1], run[i], colour, thickness);
}

// Dashes of `dash` pixels separated by `gap`, continued across the vertices of `run`. Only the
// part of each segment near the image (`img`) is walked, so far-off points cost nothing.
void dashedPolyline(cv::Mat& img, const std::vector<cv::Point2d>& run, const cv::Scalar& colour, int thickness,
                    double dash, double gap) {
  const double period = dash + gap;
  const double margin = 2.0 * period;
  double phase = 0.0;  // position within the current period
  for (std::size_t i = 1; i < run.size(); ++i) {
    const cv::Point2d a = run[i - 1];
    const cv::Point2d d = run[i] - a;
    const double length = std::hypot(d.x, d.y);
    if (length <= 0.0) continue;
    // Liang-Barsky: the parameter range [t0, t1] of a + s d (s in [0, 1]) inside the image.
    double t0 = 0.0, t1 = 1.0;
    const std::array<double, 4> p = {-d.x, d.x, -d.y, d.y};
    const std::array<double, 4> q = {a.x + margin, img.cols + margin - a.x, a.y + margin, img.rows + margin - a.y};
    for (int k = 0; k < 4 && t0 <= t1; ++k) {
      if (p[k] == 0.0) {
        if (q[k] < 0.0) t1 = -1.0;
      } else if (p[k] < 0.0) {
        t0 = std::max(t0, q[k] / p[k]);
      } else {
        t1 = std::min(t1, q[k] / p[k]);
      }
    }
    if (t0 > t1) {
      phase = std::fmod(phase + length, period);
      continue;
    }
    double t = t0 * length;
    const double t_end = t1 * length;
    phase = std::fmod(phase + t, period);
    while (t < t_end) {
      const bool on = phase < dash;
      const double step = std::min((on ? dash : period) - phase, t_end - t);
      if (on) line(img, a + d * (t / length), a + d * ((t + step) / length), colour, thickness);
      t += step;
      phase = std::fmod(phase + step, period);
    }
    phase = std::fmod(phase + (length - t_end), period);
  }
}

void drawCross(cv::Mat& img, const cv::Point2d& c, double r, const cv::Scalar& colour, int thickness) {
  line(img, c + cv::Point2d(-r, -r), c + cv::Point2d(r, r), colour, thickness);
  line(img, c + cv::Point2d(-r, r), c + cv::Point2d(r, -r), colour, thickness);
}

// A drawing and a mask of where it has drawn (so that a legend can avoid it).
struct Canvas {
  cv::Mat img;  // BGR
  cv::Mat ink;  // CV_8UC1, nonzero where something was drawn
};

enum class Symbol { kLine, kDashed, kDisc, kCross, kRingedCross };

struct LegendEntry {
  std::string label;
  cv::Scalar colour;
  Symbol symbol;
  int thickness;
};

// Marker symbols with a white outline so that they read on dark map cells too.
void drawMarker(cv::Mat& img, Symbol symbol, const cv::Point2d& c, double r, const cv::Scalar& colour, int thickness,
                bool outline) {
  switch (symbol) {
    case Symbol::kDisc:
      if (outline) cv::circle(img, fixed(c), px((r + 1.5) * (1 << kShift)), kWhite, cv::FILLED, cv::LINE_AA, kShift);
      cv::circle(img, fixed(c), px(r * (1 << kShift)), colour, cv::FILLED, cv::LINE_AA, kShift);
      return;
    case Symbol::kCross:
    case Symbol::kRingedCross: {
      const double ring = 1.3 * r;
      if (outline) {
        drawCross(img, c, r, kWhite, thickness + 3);
        if (symbol == Symbol::kRingedCross) {
          cv::circle(img, fixed(c), px(ring * (1 << kShift)), kWhite, thickness + 3, cv::LINE_AA, kShift);
        }
      }
      drawCross(img, c, r, colour, thickness);
      if (symbol == Symbol::kRingedCross) {
        cv::circle(img, fixed(c), px(ring * (1 << kShift)), colour, thickness, cv::LINE_AA, kShift);
      }
      return;
    }
    case Symbol::kLine:
    case Symbol::kDashed:
      return;
  }
}

struct LegendLayout {
  double scale;
  int pad;
  int row;     // height of one entry
  int sample;  // width of the symbol column
};

LegendLayout legendLayout(double scale) {
  const int h = lineHeight(scale);
  return {scale, std::max(4, h / 2), px(1.5 * h), px(2.4 * h)};
}

cv::Size legendSize(const std::vector<LegendEntry>& entries, const LegendLayout& l) {
  int text_width = 0;
  for (const auto& e : entries) text_width = std::max(text_width, textSize(e.label, l.scale).width);
  return {2 * l.pad + l.sample + l.pad + text_width, 2 * l.pad + static_cast<int>(entries.size()) * l.row};
}

// The place in `area` for a box of `size` that covers the least ink: a corner (top-right first,
// then top-left, bottom-right, bottom-left), else the middle of an edge.
cv::Rect quietestPlace(const cv::Mat& ink, const cv::Rect& area, cv::Size size, int margin) {
  size.width = std::min(size.width, std::max(1, area.width - 2 * margin));
  size.height = std::min(size.height, std::max(1, area.height - 2 * margin));
  const int left = area.x + margin;
  const int right = area.x + area.width - margin - size.width;
  const int centre = (left + right) / 2;
  const int top = area.y + margin;
  const int bottom = area.y + area.height - margin - size.height;
  const int middle = (top + bottom) / 2;
  const std::array<cv::Point, 8> places = {cv::Point(right, top),    cv::Point(left, top),   cv::Point(right, bottom),
                                           cv::Point(left, bottom),  cv::Point(centre, top), cv::Point(centre, bottom),
                                           cv::Point(right, middle), cv::Point(left, middle)};
  cv::Rect best;
  int best_ink = -1;
  for (const cv::Point& place : places) {
    const cv::Rect box = cv::Rect(place, size) & cv::Rect(0, 0, ink.cols, ink.rows);
    if (box.empty()) continue;
    const int covered = cv::countNonZero(ink(box));
    if (best_ink < 0 || covered < best_ink) {
      best = box;
      best_ink = covered;
    }
  }
  return best;
}

// A framed, mostly opaque legend box in the quietest place in `area`.
void drawLegend(Canvas& canvas, const cv::Rect& area, const std::vector<LegendEntry>& entries, double scale) {
  if (entries.empty()) return;
  const LegendLayout l = legendLayout(scale);
  const cv::Rect box = quietestPlace(canvas.ink, area, legendSize(entries, l), l.pad);
  if (box.empty()) return;
  cv::Mat roi = canvas.img(box);
  cv::addWeighted(roi, 0.12, cv::Mat(roi.size(), roi.type(), kWhite), 0.88, 0.0, roi);
  cv::rectangle(canvas.img, box, cv::Scalar(150, 150, 150), 1, cv::LINE_AA);
  const double r = 0.3 * l.row;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const LegendEntry& e = entries[i];
    const int top = box.y + l.pad + static_cast<int>(i) * l.row;
    const cv::Point2d mid(box.x + l.pad + 0.5 * l.sample, top + 0.5 * l.row);
    const cv::Point2d a(box.x + l.pad, mid.y), b(box.x + l.pad + l.sample, mid.y);
    if (e.symbol == Symbol::kLine) line(canvas.img, a, b, e.colour, e.thickness);
    if (e.symbol == Symbol::kDashed)
      dashedPolyline(canvas.img, {a, b}, e.colour, e.thickness, 0.3 * l.sample, 0.15 * l.sample);
    drawMarker(canvas.img, e.symbol, mid, r, e.colour, e.thickness, false);
    const int text_top = top + (l.row - lineHeight(scale)) / 2;
    putTextTopLeft(canvas.img, e.label, {box.x + 2 * l.pad + l.sample, text_top}, scale, kText);
  }
}

// Whether p_W can be drawn: finite and within reach of int pixel coordinates (with sub-pixel bits).
bool drawable(const Eigen::Vector2d& p_W, const SceneConfig& scene, double metres_per_px) {
  constexpr double kMaxPx = 5e7;
  return p_W.allFinite() && std::abs(p_W.x() - scene.bounds_min_m.x()) / metres_per_px < kMaxPx &&
         std::abs(scene.bounds_max_m.y() - p_W.y()) / metres_per_px < kMaxPx;
}

// Runs of consecutive drawable points in pixels (a point that is not drawable breaks a run).
std::vector<std::vector<cv::Point2d>> pixelRuns(const std::vector<Eigen::Vector2d>& path, const Topdown& top,
                                                const SceneConfig& scene, double metres_per_px) {
  std::vector<std::vector<cv::Point2d>> runs(1);
  for (const Eigen::Vector2d& p : path) {
    if (!drawable(p, scene, metres_per_px)) {
      if (!runs.back().empty()) runs.emplace_back();
      continue;
    }
    const cv::Point q = top.toPixel(p);
    runs.back().emplace_back(q.x, q.y);
  }
  if (runs.back().empty()) runs.pop_back();
  return runs;
}

// Scale bar of a round length (about a tenth of the map's width) right-aligned in `band`.
// Returns the x where it starts.
int drawScaleBar(cv::Mat& img, const cv::Rect& band, double map_width_m, double metres_per_px, double font, int pad,
                 int thickness) {
  const double length_m = niceStep(map_width_m / 10.0);
  const int length_px = std::max(1, px(length_m / metres_per_px));
  char label[32];
  std::snprintf(label, sizeof label, "%g m", length_m);
  const cv::Size ts = textSize(label, font);
  const int y = band.y + band.height / 2;
  const int x1 = band.x + band.width - pad;
  const int x0 = x1 - length_px;
  const int tick = std::max(3, ts.height / 3);
  cv::line(img, {x0, y}, {x1, y}, kText, thickness, cv::LINE_AA);
  cv::line(img, {x0, y - tick}, {x0, y + tick}, kText, thickness, cv::LINE_AA);
  cv::line(img, {x1, y - tick}, {x1, y + tick}, kText, thickness, cv::LINE_AA);
  const int text_x = x0 - pad - ts.width;
  putTextTopLeft(img, label, {text_x, band.y + (band.height - ts.height) / 2}, font, kText);
  return text_x;
}

}  // namespace

cv::Mat drawTrialTopdown(const SceneConfig& scene, const planner::FeatureMap& map, const TrialPaths& paths,
                         double metres_per_px) {
  if (!(metres_per_px > 0.0) || !std::isfinite(metres_per_px)) {
    throw std::invalid_argument("drawTrialTopdown: metres_per_px = " + std::to_string(metres_per_px) +
                                ": must be positive");
  }
  const Eigen::Vector3d extent = scene.bounds_max_m - scene.bounds_min_m;
  if (!(extent.x() > 0.0 && extent.y() > 0.0)) {
    throw std::invalid_argument("drawTrialTopdown: scene bounds have no area in x-y");
  }
  Topdown top(scene, metres_per_px);
  top.drawMap(map, kMapBandM);
  const cv::Mat& base = top.image();

  // Sizes follow the picture: 1 for about 600 x 500 px (a 12 m scene at 2 cm per pixel).
  const double u = std::clamp(std::sqrt(static_cast<double>(base.cols) * base.rows) / 550.0, 0.7, 3.0);
  const double font = std::max(0.42, 0.5 * u);
  const int pad = std::max(4, px(6 * u));
  const int band_height = lineHeight(font) + 2 * pad;

  cv::Mat out(base.rows + band_height, base.cols, CV_8UC3, kWhite);
  const cv::Rect map_rect(0, band_height, base.cols, base.rows);
  base.copyTo(out(map_rect));
  // Everything on the map is drawn through this view, so nothing spills into the caption band.
  Canvas canvas{out(map_rect), cv::Mat(base.size(), CV_8UC1, cv::Scalar(0))};

  const int thin = std::max(1, px(1.5 * u));
  const int thick = std::max(2, px(3.5 * u));
  const int medium = std::max(2, px(2 * u));
  const double marker_r = 7.0 * u;
  const int ink_margin = 2 * pad;
  auto drawRuns = [&](const std::vector<Eigen::Vector2d>& path, const cv::Scalar& colour, int thickness, bool dashed,
                      bool outline) {
    for (const auto& run : pixelRuns(path, top, scene, metres_per_px)) {
      if (outline) polyline(canvas.img, run, kWhite, thickness + 2);
      if (dashed && run.size() > 1) {
        dashedPolyline(canvas.img, run, colour, thickness, 8.0 * u, 5.0 * u);
      } else {
        polyline(canvas.img, run, colour, thickness);
      }
      polyline(canvas.ink, run, cv::Scalar(255), thickness + ink_margin);
    }
  };
  // The trajectory goes over the flown path, so the reference shows as dashes where they coincide.
  drawRuns(paths.planned, kPlanned, thin, false, false);
  drawRuns(paths.flown, kFlown, thick, false, true);
  drawRuns(paths.trajectory, kTrajectory, std::max(1, px(1.2 * u)), true, false);
  drawRuns(paths.estimated, kEstimated, medium, false, true);
  const int marker_thickness = std::max(2, px(2.5 * u));
  auto drawable_point = [&](const std::optional<Eigen::Vector2d>& p) {
    return p && drawable(*p, scene, metres_per_px);
  };
  auto drawPoint = [&](const std::optional<Eigen::Vector2d>& p, Symbol symbol, const cv::Scalar& colour) {
    if (!drawable_point(p)) return;
    const cv::Point q = top.toPixel(*p);
    drawMarker(canvas.img, symbol, cv::Point2d(q.x, q.y), marker_r, colour, marker_thickness, true);
    cv::circle(canvas.ink, q, px(1.5 * marker_r) + ink_margin, cv::Scalar(255), cv::FILLED);
  };
  // Start and goal in Topdown::drawStartGoal's colours and size, but on top of the paths.
  const int start_goal_r = std::max(3, static_cast<int>(0.2 / metres_per_px));
  for (const auto& [pose, colour] : {std::pair{&scene.start, kStart}, std::pair{&scene.goal, kGoal}}) {
    const cv::Point q = top.toPixel(pose->p_WB.head<2>());
    drawMarker(canvas.img, Symbol::kDisc, cv::Point2d(q.x, q.y), start_goal_r, colour, 1, true);
    cv::circle(canvas.ink, q, start_goal_r + ink_margin, cv::Scalar(255), cv::FILLED);
  }
  drawPoint(paths.vo_lost_at, Symbol::kRingedCross, kBlack);
  drawPoint(paths.collision_at, Symbol::kCross, kCollision);

  std::vector<LegendEntry> legend = {{"start", kStart, Symbol::kDisc, 1}, {"goal", kGoal, Symbol::kDisc, 1}};
  if (!paths.planned.empty()) legend.push_back({"planned path", kPlanned, Symbol::kLine, thin});
  if (!paths.trajectory.empty())
    legend.push_back({"trajectory", kTrajectory, Symbol::kDashed, std::max(1, px(1.2 * u))});
  if (!paths.flown.empty()) legend.push_back({"flown (true)", kFlown, Symbol::kLine, thick});
  if (!paths.estimated.empty()) legend.push_back({"VO estimate", kEstimated, Symbol::kLine, medium});
  if (drawable_point(paths.vo_lost_at))
    legend.push_back({"VO lost", kBlack, Symbol::kRingedCross, std::max(1, px(2 * u))});
  if (drawable_point(paths.collision_at))
    legend.push_back({"collision", kCollision, Symbol::kCross, std::max(1, px(2 * u))});
  drawLegend(canvas, cv::Rect(0, 0, base.cols, base.rows), legend, std::max(0.4, 0.45 * u));

  const cv::Rect band(0, 0, out.cols, band_height);
  const int caption_right =
      drawScaleBar(out, band, extent.x(), metres_per_px, font, pad, std::max(1, px(1.5 * u))) - 2 * pad;
  double caption_font = font;
  const std::string caption = fitText(paths.caption, caption_right - pad, caption_font, 0.8 * font);
  if (!caption.empty()) {
    putTextTopLeft(out, caption, {pad, (band_height - lineHeight(caption_font)) / 2}, caption_font, kText);
  }
  return out;
}

namespace {

// Axis over [lo, hi] (which must hold the data) with {1, 2, 5} x 10^k ticks; the ends are ticks.
struct Axis {
  double lo;
  double hi;
  double step;
  std::vector<double> ticks;
  int decimals;  // for the tick labels

  std::string label(double v) const {
    if (std::abs(v) < 1e-9 * step) v = 0.0;
    char s[40];
    std::snprintf(s, sizeof s, "%.*f", decimals, v);
    return s;
  }
};

Axis niceAxis(double lo, double hi, int max_ticks) {
  // A range with no extent (all errors zero, a single point at distance zero) gets a unit span.
  constexpr double kMinSpan = 1e-6;
  if (hi - lo < kMinSpan) hi = lo + 1.0;
  Axis a;
  a.step = niceStep((hi - lo) / (max_ticks - 1));
  a.lo = std::floor(lo / a.step + 1e-9) * a.step;
  a.hi = std::ceil(hi / a.step - 1e-9) * a.step;
  const int n = static_cast<int>(std::lround((a.hi - a.lo) / a.step));
  for (int i = 0; i <= n; ++i) a.ticks.push_back(a.lo + i * a.step);
  a.decimals = std::max(0, -static_cast<int>(std::floor(std::log10(a.step) + 1e-9)));
  return a;
}

// Colours of the curves (BGR), the "tab10" palette.
const std::array<cv::Scalar, 10> kPalette = {
    cv::Scalar(180, 119, 31),  cv::Scalar(14, 127, 255), cv::Scalar(44, 160, 44),   cv::Scalar(40, 39, 214),
    cv::Scalar(189, 103, 148), cv::Scalar(75, 86, 140),  cv::Scalar(194, 119, 227), cv::Scalar(127, 127, 127),
    cv::Scalar(34, 189, 188),  cv::Scalar(207, 190, 23)};

bool finitePoint(const ErrorCurve& c, std::size_t i) {
  return std::isfinite(c.distance_m[i]) && std::isfinite(c.error_m[i]);
}

// The point of `c` at distance `d` (clamped to the curve's extent), interpolated between its
// finite points; none when it has none.
std::optional<std::pair<double, double>> pointAt(const ErrorCurve& c, double d) {
  std::optional<std::size_t> prev;
  for (std::size_t i = 0; i < c.distance_m.size(); ++i) {
    if (!finitePoint(c, i)) continue;
    if (c.distance_m[i] >= d) {
      if (!prev) return std::make_pair(c.distance_m[i], c.error_m[i]);
      const double span = c.distance_m[i] - c.distance_m[*prev];
      const double t = span > 0.0 ? (d - c.distance_m[*prev]) / span : 1.0;
      return std::make_pair(d, c.error_m[*prev] + t * (c.error_m[i] - c.error_m[*prev]));
    }
    prev = i;
  }
  if (prev) return std::make_pair(c.distance_m[*prev], c.error_m[*prev]);
  return std::nullopt;
}

}  // namespace

cv::Mat drawErrorVsDistance(const std::vector<ErrorCurve>& curves, const std::string& title, int width, int height) {
  if (width < 200 || height < 150) {
    throw std::invalid_argument("drawErrorVsDistance: " + std::to_string(width) + " x " + std::to_string(height) +
                                " px: must be at least 200 x 150");
  }
  for (const ErrorCurve& c : curves) {
    if (c.distance_m.size() != c.error_m.size()) {
      throw std::invalid_argument("drawErrorVsDistance: curve '" + c.label + "' has " +
                                  std::to_string(c.distance_m.size()) + " distances and " +
                                  std::to_string(c.error_m.size()) + " errors");
    }
  }
  // Data range, always from zero (distance travelled and error both start there).
  double x_lo = 0.0, x_hi = 0.0, y_lo = 0.0, y_hi = 0.0;
  bool any_data = false;
  for (const ErrorCurve& c : curves) {
    for (std::size_t i = 0; i < c.distance_m.size(); ++i) {
      if (!finitePoint(c, i)) continue;
      any_data = true;
      x_lo = std::min(x_lo, c.distance_m[i]);
      x_hi = std::max(x_hi, c.distance_m[i]);
      y_lo = std::min(y_lo, c.error_m[i]);
      y_hi = std::max(y_hi, c.error_m[i]);
    }
  }
  const Axis ax = niceAxis(x_lo, x_hi, 9);
  const Axis ay = niceAxis(y_lo, y_hi, 7);

  const double u = std::min(width / 800.0, height / 500.0);
  const double tick_font = std::max(0.38, 0.48 * u);
  const double label_font = std::max(0.4, 0.55 * u);
  const double title_font = std::max(0.45, 0.65 * u);
  const int pad = std::max(4, px(8 * u));
  const int tick_len = std::max(3, px(5 * u));
  const std::string x_label = "distance travelled [m]";
  const std::string y_label = "position error [m]";

  int y_tick_width = 0;
  for (const double t : ay.ticks) y_tick_width = std::max(y_tick_width, textSize(ay.label(t), tick_font).width);
  const int left = pad + lineHeight(label_font) + pad + y_tick_width + pad / 2 + tick_len;
  const int top = 2 * pad + lineHeight(title_font);
  const int bottom = tick_len + pad / 2 + lineHeight(tick_font) + pad + lineHeight(label_font) + pad;
  const int right = std::max(2 * pad, textSize(ax.label(ax.hi), tick_font).width / 2 + pad);
  const cv::Rect plot(left, top, width - left - right, height - top - bottom);

  Canvas canvas{cv::Mat(height, width, CV_8UC3, kWhite), cv::Mat(height, width, CV_8UC1, cv::Scalar(0))};
  cv::Mat& img = canvas.img;
  auto toPixel = [&](double x, double y) {
    return cv::Point2d(plot.x + (x - ax.lo) / (ax.hi - ax.lo) * (plot.width - 1),
                       plot.y + plot.height - 1 - (y - ay.lo) / (ay.hi - ay.lo) * (plot.height - 1));
  };

  // Gridlines, ticks and their labels, then the frame.
  const cv::Scalar grid(228, 228, 228), frame(90, 90, 90);
  for (const double t : ax.ticks) {
    const int x = px(toPixel(t, 0).x);
    cv::line(img, {x, plot.y}, {x, plot.y + plot.height - 1}, grid, 1);
    cv::line(img, {x, plot.y + plot.height}, {x, plot.y + plot.height + tick_len}, frame, 1);
    const std::string s = ax.label(t);
    putTextTopLeft(img, s, {x - textSize(s, tick_font).width / 2, plot.y + plot.height + tick_len + pad / 2}, tick_font,
                   kText);
  }
  for (const double t : ay.ticks) {
    const int y = px(toPixel(0, t).y);
    cv::line(img, {plot.x, y}, {plot.x + plot.width - 1, y}, grid, 1);
    cv::line(img, {plot.x - tick_len - 1, y}, {plot.x - 1, y}, frame, 1);
    const std::string s = ay.label(t);
    const cv::Size ts = textSize(s, tick_font);
    putTextTopLeft(img, s, {plot.x - tick_len - pad / 2 - ts.width, y - ts.height / 2}, tick_font, kText);
  }
  cv::rectangle(img, plot, frame, 1);

  // Axis labels and title.
  putTextTopLeft(
      img, x_label,
      {plot.x + (plot.width - textSize(x_label, label_font).width) / 2, height - pad - lineHeight(label_font)},
      label_font, kText);
  putTextVertical(img, y_label, {pad + lineHeight(label_font) / 2, plot.y + plot.height / 2}, label_font, kText);
  double fitted_title_font = title_font;
  const std::string fitted_title = fitText(title, width - 2 * pad, fitted_title_font, 0.75 * title_font);
  putTextTopLeft(img, fitted_title, {(width - textSize(fitted_title, fitted_title_font).width) / 2, pad},
                 fitted_title_font, kText);

  // Curves: breaks at non-finite points, single points as dots.
  const int curve_thickness = std::max(2, px(2 * u));
  const double marker_r = std::max(5.0, 7.0 * u);
  std::vector<LegendEntry> legend;
  bool any_lost = false;
  for (std::size_t k = 0; k < curves.size(); ++k) {
    const ErrorCurve& c = curves[k];
    const cv::Scalar& colour = kPalette[k % kPalette.size()];
    std::vector<std::vector<cv::Point2d>> runs(1);
    for (std::size_t i = 0; i < c.distance_m.size(); ++i) {
      if (finitePoint(c, i)) {
        runs.back().push_back(toPixel(c.distance_m[i], c.error_m[i]));
      } else if (!runs.back().empty()) {
        runs.emplace_back();
      }
    }
    bool has_data = false;
    for (const auto& run : runs) {
      if (run.empty()) continue;
      has_data = true;
      polyline(img, run, colour, run.size() == 1 ? curve_thickness + 1 : curve_thickness);
      polyline(canvas.ink, run, cv::Scalar(255), curve_thickness + 2 * pad);
    }
    if (!c.label.empty()) {
      legend.push_back({has_data ? c.label : c.label + " (no data)", colour, Symbol::kLine, curve_thickness});
    }
  }
  // Lost markers last, so that no curve hides one.
  for (const ErrorCurve& c : curves) {
    if (!c.lost_at_distance_m || !std::isfinite(*c.lost_at_distance_m)) continue;
    const auto p = pointAt(c, *c.lost_at_distance_m);
    if (!p) continue;
    const cv::Point2d q = toPixel(p->first, p->second);
    drawMarker(img, Symbol::kCross, q, marker_r, kBlack, curve_thickness, true);
    cv::circle(canvas.ink, fixed(q), px((marker_r + 2 * pad) * (1 << kShift)), cv::Scalar(255), cv::FILLED, cv::LINE_8,
               kShift);
    any_lost = true;
  }
  if (any_lost) legend.push_back({"lost", kBlack, Symbol::kCross, curve_thickness});
  if (!any_data) {
    const std::string s = "no data";
    const cv::Size ts = textSize(s, label_font);
    putTextTopLeft(img, s, {plot.x + (plot.width - ts.width) / 2, plot.y + (plot.height - ts.height) / 2}, label_font,
                   cv::Scalar(140, 140, 140));
  }
  drawLegend(canvas, plot, legend, tick_font);
  return img;
}

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
