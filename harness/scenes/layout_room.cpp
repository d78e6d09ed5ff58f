// The `room` kind: one room with 1-6 free-standing obstacles (boxes, cylinders, L-shapes, thin
// walls) between a start near the west wall and a goal near the east wall.
#include <cmath>
#include <stdexcept>

#include "harness/scenes/scene_layout.h"

namespace tgnav::harness::scenes {

namespace {

constexpr int kPlacementTries = 40;
constexpr int kMaxRoomLayouts = 2000;
constexpr double kObstacleToEndsM = 1.3;  // an obstacle's distance to start and goal

double drawHeight(SceneRng& rng) { return rng.chance(0.5) ? kRoomHeightM : rng.uniform(1.8, 2.6); }

void addCylinder(Layout& layout, int obstacle, double cx, double cy, double r, double height_m, SceneRng& rng) {
  Block b;
  b.name = layout.obstacles[obstacle].name + "_0";
  b.cylinder = true;
  b.cx = round2(cx);
  b.cy = round2(cy);
  b.hx = b.hy = round2(r);
  b.height_m = round2(height_m);
  b.obstacle = obstacle;
  b.level = drawLevel(rng);
  layout.blocks.push_back(b);
}

// An L: an arm along x and, at one of its ends, an arm along y; turned by `variant` (0-3).
void addLShape(Layout& layout, int obstacle, double cx, double cy, SceneRng& rng) {
  const double a = rng.uniform(1.4, 3.0), b = rng.uniform(1.2, 2.4), t = rng.uniform(0.3, 0.6);
  const double height = drawHeight(rng);
  const int variant = rng.uniformInt(0, 3);
  const double sx = (variant & 1) ? 1.0 : -1.0, sy = (variant & 2) ? 1.0 : -1.0;
  const double arm_x = round2(0.5 * a), arm_t = round2(0.5 * t), arm_y = round2(0.5 * b);
  addBoxPart(layout, obstacle, cx, cy, arm_x, arm_t, height, rng);
  addBoxPart(layout, obstacle, cx + sx * (arm_x - arm_t), cy + sy * (arm_t + arm_y), arm_t, arm_y, height, rng);
}

void addShape(Layout& layout, int obstacle, double cx, double cy, SceneRng& rng) {
  const std::string& shape = layout.obstacles[obstacle].shape;
  if (shape == "box") {
    const double hx = rng.uniform(0.25, 1.1), hy = rng.uniform(0.25, 1.1);
    addBoxPart(layout, obstacle, cx, cy, hx, hy, drawHeight(rng), rng);
  } else if (shape == "cylinder") {
    const double r = rng.uniform(0.25, 0.6);
    addCylinder(layout, obstacle, cx, cy, r, drawHeight(rng), rng);
  } else if (shape == "l_shape") {
    addLShape(layout, obstacle, cx, cy, rng);
  } else {
    const double half = 0.5 * rng.uniform(1.5, 4.0), t = 0.5 * rng.uniform(0.1, 0.2);
    const double height = rng.uniform(2.2, kRoomHeightM);
    if (rng.chance(0.5)) {
      addBoxPart(layout, obstacle, cx, cy, half, t, height, rng);
    } else {
      addBoxPart(layout, obstacle, cx, cy, t, half, height, rng);
    }
  }
}

// Whether the blocks of `obstacle` keep their gaps to everything else and to start and goal.
bool fits(const Layout& layout, int obstacle) {
  for (const Block& b : layout.blocks) {
    if (b.obstacle != obstacle) continue;
    if (distanceTo(b, layout.start.x, layout.start.y) < kObstacleToEndsM) return false;
    if (distanceTo(b, layout.goal.x, layout.goal.y) < kObstacleToEndsM) return false;
    for (const Block& other : layout.blocks) {
      if (other.obstacle != obstacle && gapBetween(b, other) < kObstacleGapM) return false;
    }
  }
  return true;
}

// One obstacle of a drawn shape at up to kPlacementTries drawn positions; the first one blocks
// the straight line from start to goal. Nothing is added when no position fits.
void placeObstacle(Layout& layout, SceneRng& rng, bool first) {
  static const char* const kShapes[] = {"box", "cylinder", "l_shape", "thin_wall"};
  const int obstacle = addObstacle(layout, kShapes[rng.uniformInt(0, 3)]);
  const std::size_t before = layout.blocks.size();
  for (int t = 0; t < kPlacementTries; ++t) {
    double cx = rng.uniform(layout.xmin + 1.5, layout.xmax - 1.5);
    double cy = rng.uniform(layout.ymin + 1.5, layout.ymax - 1.5);
    if (first) {
      cx = 0.5 * (layout.start.x + layout.goal.x) + rng.uniform(-1.0, 1.0);
      cy = 0.5 * (layout.start.y + layout.goal.y) + rng.uniform(-0.6, 0.6);
    }
    addShape(layout, obstacle, cx, cy, rng);
    if (fits(layout, obstacle)) return;
    layout.blocks.resize(before);
  }
  layout.obstacles.pop_back();
}

}  // namespace

Layout roomLayout(std::uint64_t seed) {
  SceneRng rng(mixSeed(seed, 1));
  Layout layout;
  layout.kind = SceneKind::kRoom;
  layout.seed = seed;
  drawRoomBounds(layout, rng, 8.0, 16.0, 6.0, 12.0);
  layout.start = {round2(layout.xmin + 1.3), round2(rng.uniform(layout.ymin + 1.5, layout.ymax - 1.5)), 0.0};
  layout.goal = {round2(layout.xmax - 1.3), round2(rng.uniform(layout.ymin + 1.5, layout.ymax - 1.5)), 0.0};
  layout.light = drawLighting(rng);
  addOuterWalls(layout, rng);
  const std::size_t walls = layout.blocks.size();
  for (layout.attempts = 1; layout.attempts <= kMaxRoomLayouts; ++layout.attempts) {
    layout.blocks.resize(walls);
    layout.obstacles.clear();
    const int n = rng.uniformInt(1, 6);
    for (int k = 0; k < n; ++k) placeObstacle(layout, rng, k == 0);
    if (validateLayout(layout).empty()) {
      forceVisibleLevels(layout);
      return layout;
    }
  }
  throw std::logic_error("room layout: no valid layout for seed " + std::to_string(seed));
}

}  // namespace tgnav::harness::scenes
