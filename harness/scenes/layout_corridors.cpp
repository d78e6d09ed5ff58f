// The `corridors` kind (partitions along x with doorways, and short spurs, make corridors and
// loops) and the `warehouse` kind (parallel shelf rows with aisles and aligned cross-aisles).
// Both leave an open hall at each end: the start in the west hall, the goal in the east one.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "harness/scenes/scene_layout.h"

namespace tgnav::harness::scenes {

namespace {

constexpr int kMaxCorridorLayouts = 2000;
constexpr double kMinSegmentM = 1.2;
constexpr double kEndOffsetM = 1.1;  // start and goal from the west and east walls

Layout emptyRoom(SceneKind kind, std::uint64_t seed, SceneRng& rng, double w_lo, double w_hi, double h_lo,
                 double h_hi) {
  Layout layout;
  layout.kind = kind;
  layout.seed = seed;
  drawRoomBounds(layout, rng, w_lo, w_hi, h_lo, h_hi);
  layout.light = drawLighting(rng);
  addOuterWalls(layout, rng);
  return layout;
}

// Splits [from, to] into `count` solid segments with `count - 1` openings of [open_lo, open_hi]
// between them, each segment at least kMinSegmentM: {start, end} pairs. Fewer when it is short.
std::vector<std::pair<double, double>> segments(double from, double to, int count, double open_lo, double open_hi,
                                                SceneRng& rng) {
  std::vector<double> openings;
  for (int k = 1; k < count; ++k) openings.push_back(rng.uniform(open_lo, open_hi));
  double open_total = 0.0;
  for (double o : openings) open_total += o;
  while (!openings.empty() && to - from - open_total < kMinSegmentM * (openings.size() + 1)) {
    open_total -= openings.back();
    openings.pop_back();
  }
  std::vector<double> weights;
  double weight_total = 0.0;
  for (std::size_t k = 0; k <= openings.size(); ++k) weight_total += weights.emplace_back(rng.uniform(1.0, 2.0));
  const double spare = to - from - open_total - kMinSegmentM * weights.size();
  std::vector<std::pair<double, double>> out;
  double x = from;
  for (std::size_t k = 0; k < weights.size(); ++k) {
    const double length = kMinSegmentM + spare * weights[k] / weight_total;
    out.emplace_back(round2(x), round2(x + length));
    x += length + (k < openings.size() ? openings[k] : 0.0);
  }
  return out;
}

// A spur along y from a partition at y = `wall_y` (half thickness t) into a corridor of width
// `room` on the side `side`, at a drawn place of the segment [x0, x1].
void addSpur(Layout& layout, int obstacle, double x0, double x1, double wall_y, double t, double room, double side,
             SceneRng& rng) {
  const double longest = std::min(1.4, room - kObstacleGapM - 0.05);
  if (longest < 0.5 || x1 - x0 < 2.0 * t + 0.6) return;
  const double length = rng.uniform(0.5, longest);
  const double x = rng.uniform(x0 + t + 0.3, x1 - t - 0.3);
  addBoxPart(layout, obstacle, x, wall_y + side * (t + 0.5 * length), t, 0.5 * length, kRoomHeightM, rng);
}

Layout drawCorridors(Layout layout, SceneRng& rng) {
  const double h = layout.ymax - layout.ymin;
  const double x0 = layout.xmin + rng.uniform(2.2, 2.8), x1 = layout.xmax - rng.uniform(2.2, 2.8);
  const int most = std::max(1, std::min(3, static_cast<int>((h - 1.8) / 2.05)));
  const int k = rng.uniformInt(std::max(1, most - 1), most);
  const double t = round2(0.5 * rng.uniform(0.15, 0.25));
  const double corridor = (h - 2.0 * t * k) / (k + 1);
  for (int p = 0; p < k; ++p) {
    const double wall_y = layout.ymin + (p + 1) * corridor + (2 * p + 1) * t + rng.uniform(-0.2, 0.2);
    for (const auto& [from, to] : segments(x0, x1, rng.uniformInt(2, 3), 1.3, 2.0, rng)) {
      const int obstacle = addObstacle(layout, "partition");
      addBoxPart(layout, obstacle, 0.5 * (from + to), wall_y, 0.5 * (to - from), t, kRoomHeightM, rng);
      if (rng.chance(0.4)) {
        addSpur(layout, obstacle, from, to, wall_y, t, corridor - 0.2, rng.chance(0.5) ? 1.0 : -1.0, rng);
      }
    }
  }
  return layout;
}

Layout drawWarehouse(Layout layout, SceneRng& rng) {
  const double h = layout.ymax - layout.ymin;
  const double x0 = layout.xmin + rng.uniform(2.4, 3.0), x1 = layout.xmax - rng.uniform(2.4, 3.0);
  const double depth = rng.uniform(0.6, 1.0), aisle_min = rng.uniform(1.6, 2.4);
  const int rows = std::max(1, static_cast<int>((h - aisle_min) / (depth + aisle_min)));
  const double aisle = (h - rows * depth) / (rows + 1);
  const auto cross = segments(x0, x1, rng.uniformInt(2, 3), 1.5, 2.1, rng);
  for (int r = 0; r < rows; ++r) {
    const double y = layout.ymin + (r + 1) * aisle + (r + 0.5) * depth;
    const double height = rng.uniform(2.0, 2.6);
    double from = cross.front().first;
    for (std::size_t s = 0; s < cross.size(); ++s) {
      // A row closes a cross-aisle now and then (never its last one).
      if (s + 1 < cross.size() && cross.size() > 2 && rng.chance(0.2)) continue;
      const double to = cross[s].second;
      const int obstacle = addObstacle(layout, "shelf_row");
      addBoxPart(layout, obstacle, 0.5 * (from + to), y, 0.5 * (to - from), 0.5 * depth, height, rng);
      if (s + 1 < cross.size()) from = cross[s + 1].first;
    }
  }
  return layout;
}

// The centre line of one of the free bands along x, between the y's of `walls` (sorted).
double aisleCentre(const Layout& layout, SceneRng& rng) {
  std::vector<double> edges{layout.ymin};
  for (const Block& b : layout.blocks) {
    if (b.obstacle >= 0 && b.hx > b.hy && b.cx - b.hx < 0.5 * (layout.xmin + layout.xmax)) {
      edges.push_back(b.cy);
    }
  }
  edges.push_back(layout.ymax);
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  const int band = rng.uniformInt(0, static_cast<int>(edges.size()) - 2);
  return round2(0.5 * (edges[band] + edges[band + 1]));
}

template <typename Draw>
Layout drawValid(Layout room, SceneRng& rng, Draw draw, const char* what) {
  for (int attempt = 1; attempt <= kMaxCorridorLayouts; ++attempt) {
    Layout layout = draw(room, rng);
    layout.start = {round2(layout.xmin + kEndOffsetM), aisleCentre(layout, rng), 0.0};
    layout.goal = {round2(layout.xmax - kEndOffsetM), aisleCentre(layout, rng), 0.0};
    if (validateLayout(layout).empty()) {
      layout.attempts = attempt;
      forceVisibleLevels(layout);
      return layout;
    }
  }
  throw std::logic_error(std::string(what) + " layout: no valid layout for seed " + std::to_string(room.seed));
}

}  // namespace

Layout corridorsLayout(std::uint64_t seed) {
  SceneRng rng(mixSeed(seed, 2));
  const Layout room = emptyRoom(SceneKind::kCorridors, seed, rng, 12.0, 18.0, 8.0, 12.0);
  return drawValid(room, rng, drawCorridors, "corridors");
}

Layout warehouseLayout(std::uint64_t seed) {
  SceneRng rng(mixSeed(seed, 3));
  const Layout room = emptyRoom(SceneKind::kWarehouse, seed, rng, 14.0, 20.0, 10.0, 14.0);
  return drawValid(room, rng, drawWarehouse, "warehouse");
}

}  // namespace tgnav::harness::scenes
