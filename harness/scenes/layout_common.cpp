// Building blocks shared by the layouts: outer walls, obstacle parts, levels, lights.
#include <algorithm>
#include <cmath>

#include "harness/scenes/scene_layout.h"

namespace tgnav::harness::scenes {

namespace {

// Half the camera's horizontal field of view (fovy 60 deg at 4:3 is 75 deg wide) plus a margin.
constexpr double kStartViewHalfFovRad = 42.0 * kPi / 180.0;
constexpr double kStartViewRangeM = 5.0;  // what the VO needs to start: near texture in view
constexpr double kGoalViewRangeM = 3.0;   // ... and to arrive

// Panels of at most kMaxPanelM covering [from, to]: their edges, on centimetres.
std::vector<double> panelEdges(double from, double to) {
  const int n = std::max(1, static_cast<int>(std::ceil((to - from) / kMaxPanelM - 1e-9)));
  std::vector<double> edges;
  for (int k = 0; k <= n; ++k) edges.push_back(round2(from + (to - from) * k / n));
  return edges;
}

void addWall(Layout& layout, const std::string& side, bool along_x, double from, double to, double at, SceneRng& rng) {
  const std::vector<double> edges = panelEdges(from, to);
  for (std::size_t k = 0; k + 1 < edges.size(); ++k) {
    Block b;
    b.name = "wall_" + side + "_" + std::to_string(k);
    const double centre = round2(0.5 * (edges[k] + edges[k + 1])), half = round2(0.5 * (edges[k + 1] - edges[k]));
    b.cx = along_x ? centre : at;
    b.cy = along_x ? at : centre;
    b.hx = along_x ? half : 0.5 * kWallThicknessM;
    b.hy = along_x ? 0.5 * kWallThicknessM : half;
    b.level = drawLevel(rng);
    layout.blocks.push_back(b);
  }
}

void upgrade(Layout& layout, int block) {
  if (block < 0) return;
  TextureLevel& level = layout.blocks[block].level;
  if (level == TextureLevel::kFaint || level == TextureLevel::kPlain) level = TextureLevel::kRich;
}

}  // namespace

const char* toString(SceneKind kind) {
  switch (kind) {
    case SceneKind::kRoom:
      return "room";
    case SceneKind::kCorridors:
      return "corridors";
    case SceneKind::kWarehouse:
      return "warehouse";
    case SceneKind::kDetour:
      return "detour";
  }
  return "?";
}

const char* toString(TextureLevel level) {
  switch (level) {
    case TextureLevel::kRich:
      return "rich";
    case TextureLevel::kMedium:
      return "medium";
    case TextureLevel::kFaint:
      return "faint";
    case TextureLevel::kPlain:
      return "plain";
  }
  return "?";
}

TextureLevel drawLevel(SceneRng& rng) {
  const double u = rng.uniform01();
  if (u < 0.3) return TextureLevel::kRich;
  if (u < 0.6) return TextureLevel::kMedium;
  if (u < 0.8) return TextureLevel::kFaint;
  return TextureLevel::kPlain;
}

void drawRoomBounds(Layout& layout, SceneRng& rng, double w_lo, double w_hi, double h_lo, double h_hi) {
  const double w = std::round(rng.uniform(w_lo, w_hi) * 10.0) / 10.0;
  const double h = std::round(rng.uniform(h_lo, h_hi) * 10.0) / 10.0;
  layout.xmin = round2(-0.5 * w);
  layout.xmax = round2(0.5 * w);
  layout.ymin = round2(-0.5 * h);
  layout.ymax = round2(0.5 * h);
}

void addOuterWalls(Layout& layout, SceneRng& rng) {
  const double t = kWallThicknessM;
  addWall(layout, "s", true, layout.xmin - t, layout.xmax + t, round2(layout.ymin - 0.5 * t), rng);
  addWall(layout, "n", true, layout.xmin - t, layout.xmax + t, round2(layout.ymax + 0.5 * t), rng);
  addWall(layout, "w", false, layout.ymin, layout.ymax, round2(layout.xmin - 0.5 * t), rng);
  addWall(layout, "e", false, layout.ymin, layout.ymax, round2(layout.xmax + 0.5 * t), rng);
}

int addObstacle(Layout& layout, const std::string& shape) {
  const int index = static_cast<int>(layout.obstacles.size());
  layout.obstacles.push_back({"obs" + std::to_string(index), shape});
  return index;
}

void addBoxPart(Layout& layout, int obstacle, double cx, double cy, double hx, double hy, double height_m,
                SceneRng& rng) {
  const bool along_x = hx >= hy;
  const double centre = along_x ? cx : cy, half = along_x ? hx : hy;
  const std::vector<double> edges = panelEdges(centre - half, centre + half);
  int part = 0;
  for (const Block& b : layout.blocks) part += b.obstacle == obstacle;
  for (std::size_t k = 0; k + 1 < edges.size(); ++k) {
    Block b;
    b.name = layout.obstacles[obstacle].name + "_" + std::to_string(part++);
    const double c = round2(0.5 * (edges[k] + edges[k + 1])), h = round2(0.5 * (edges[k + 1] - edges[k]));
    b.cx = along_x ? c : round2(cx);
    b.cy = along_x ? round2(cy) : c;
    b.hx = along_x ? h : round2(hx);
    b.hy = along_x ? round2(hy) : h;
    b.height_m = round2(height_m);
    b.obstacle = obstacle;
    b.level = drawLevel(rng);
    layout.blocks.push_back(b);
  }
}

Lighting drawLighting(SceneRng& rng) {
  Lighting light;
  light.head_ambient = round2(rng.uniform(0.28, 0.40));
  light.head_diffuse = round2(rng.uniform(0.28, 0.40));
  light.top = round2(rng.uniform(0.28, 0.42));
  light.fill = round2(rng.uniform(0.18, 0.30));
  const double angle = rng.uniform(0.0, 2.0 * kPi);
  light.fill_dir_x = round2(std::cos(angle));
  light.fill_dir_y = round2(std::sin(angle));
  return light;
}

void forceVisibleLevels(Layout& layout) {
  const int steps = 168;  // 0.5 deg
  for (int k = 0; k <= steps; ++k) {
    const double angle = layout.start.yaw - kStartViewHalfFovRad + 2.0 * kStartViewHalfFovRad * k / steps;
    upgrade(layout, firstHit(layout, layout.start.x, layout.start.y, angle, kStartViewRangeM));
  }
  for (int k = 0; k < 720; ++k) {
    const double angle = 2.0 * kPi * k / 720;
    upgrade(layout, firstHit(layout, layout.goal.x, layout.goal.y, angle, kGoalViewRangeM));
  }
}

}  // namespace tgnav::harness::scenes
