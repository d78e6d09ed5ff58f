// The `detour` kind (issue 38: the paper's premise): the shortest route is blind, a longer one is
// flyable only by looking at texture beside or behind it.
//
// One room, start near the west wall, goal near the east wall. A long barrier north of the
// straight line start-goal leaves two routes: the short one straight along the south, and a long
// one through the gap at the barrier's west end, along the north corridor (0-2 pillars in it) and
// back through the east gap. The barrier is two layers, so its south and north faces carry
// different textures. Levels are drawn as in the other kinds, then made to keep the premise from
// the layout alone (2D rays at the flight height; every block is full height, so they are exact):
//   1. the middle 30 % of the straight route is blind: every block a ray from it reaches within
//      the VO's depth range (kBlindRangeM, any direction) becomes plain or faint;
//   2. from every point of the long route (its centre line and a line beside the barrier), some
//      yaw sees rich or medium blocks that the blind stretch cannot see in at least a third of
//      its view within kRouteViewRangeM (blocks upgraded where needed; the layout is drawn again
//      when no yaw sees enough such blocks);
//   3. the start's and the goal's yaws face such texture in at least half their view within
//      kEndViewRangeM (the VO initialises in the start's view; RRT* plans to the goal's yaw).
// Unlike the other kinds, start and goal views are not made rich all round: the texture is where
// the long route passes, beside or behind the direction of travel.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "harness/scenes/scene_layout.h"

namespace tgnav::harness::scenes {

namespace {

constexpr int kMaxDetourLayouts = 500;
constexpr double kBlindRangeM = 10.0;     // the VO's depth range (configs/vo.yaml max_depth_m)
constexpr double kRouteViewRangeM = 7.0;  // texture the long route keeps in view (as the start)
constexpr double kEndViewRangeM = 7.0;    // texture at start and goal (the VO's depth range: 10 m)
// The camera's horizontal half FoV (75 deg wide).
constexpr double kViewHalfFovRad = 37.5 * kPi / 180.0;
constexpr int kRays = 720;     // all round
constexpr int kViewRays = 41;  // across one view
constexpr int kYaws = 72;      // the yaws a view is looked for at
constexpr double kStepM = 0.1;

bool texturedLevel(TextureLevel level) { return level == TextureLevel::kRich || level == TextureLevel::kMedium; }

// Points every kStepM along the polyline.
std::vector<Pose2> sample(const std::vector<Pose2>& polyline) {
  std::vector<Pose2> points;
  for (std::size_t i = 0; i + 1 < polyline.size(); ++i) {
    const double dx = polyline[i + 1].x - polyline[i].x, dy = polyline[i + 1].y - polyline[i].y;
    const int n = std::max(1, static_cast<int>(std::ceil(std::hypot(dx, dy) / kStepM)));
    for (int k = 0; k < n; ++k) points.push_back({polyline[i].x + dx * k / n, polyline[i].y + dy * k / n, 0.0});
  }
  points.push_back(polyline.back());
  return points;
}

// Indices of the blocks a ray from (x, y) reaches within range_m, any direction.
std::vector<int> blocksSeen(const Layout& layout, double x, double y, double range_m) {
  std::vector<int> seen;
  for (int k = 0; k < kRays; ++k) {
    const int hit = firstHit(layout, x, y, 2.0 * kPi * k / kRays, range_m);
    if (hit >= 0 && std::find(seen.begin(), seen.end(), hit) == seen.end()) seen.push_back(hit);
  }
  return seen;
}

// Calls visit(block) for the first block of each of kViewRays rays across the horizontal FoV
// of a camera at p looking along yaw, within range_m (-1 where a ray hits nothing).
template <typename Visit>
void forView(const Layout& layout, const Pose2& p, double yaw, double range_m, Visit&& visit) {
  for (int r = 0; r < kViewRays; ++r) {
    const double angle = yaw + kViewHalfFovRad * (2.0 * r / (kViewRays - 1) - 1.0);
    visit(firstHit(layout, p.x, p.y, angle, range_m));
  }
}

// How many of those rays end on a block `counts` accepts.
template <typename Counts>
int viewCount(const Layout& layout, const Pose2& p, double yaw, double range_m, Counts&& counts) {
  int n = 0;
  forView(layout, p, yaw, range_m, [&](int b) { n += b >= 0 && counts(b); });
  return n;
}

double round2cm(double v) { return std::round(v * 50.0) / 50.0; }

// A layer of the barrier along x from x0 to x1 (on the 2 cm grid) at y = cy, panels of at most
// kMaxPanelM whose edges lie on the grid, so that neighbours touch exactly.
void addLayer(Layout& layout, int obstacle, double x0, double x1, double cy, double hy, SceneRng& rng) {
  const int n = std::max(1, static_cast<int>(std::ceil((x1 - x0) / kMaxPanelM - 1e-9)));
  int part = 0;
  for (const Block& b : layout.blocks) part += b.obstacle == obstacle;
  for (int k = 0; k < n; ++k) {
    const double a = round2cm(x0 + (x1 - x0) * k / n), b = round2cm(x0 + (x1 - x0) * (k + 1) / n);
    Block block;
    block.name = layout.obstacles[obstacle].name + "_" + std::to_string(part++);
    block.cx = round2(0.5 * (a + b));
    block.cy = round2(cy);
    block.hx = round2(0.5 * (b - a));
    block.hy = hy;
    block.height_m = kRoomHeightM;
    block.obstacle = obstacle;
    block.level = drawLevel(rng);
    layout.blocks.push_back(block);
  }
}

double length(const std::vector<Pose2>& polyline) {
  double sum = 0.0;
  for (std::size_t i = 0; i + 1 < polyline.size(); ++i) {
    sum += std::hypot(polyline[i + 1].x - polyline[i].x, polyline[i + 1].y - polyline[i].y);
  }
  return sum;
}

bool clear(const Layout& layout, const std::vector<Pose2>& polyline) {
  for (const Pose2& p : sample(polyline)) {
    if (clearanceAt(layout, p.x, p.y) < kInflationM) return false;
  }
  return true;
}

// Rule 2: texture in view all along the long route, on two lines (its centre and one beside
// the barrier, where a shortest path of its class runs): at each point some yaw sees usable
// textured blocks in at least a third of its view; else the blocks of the yaw that sees the most
// usable ones are upgraded (false when even that yaw sees too few).
template <typename Usable, typename Textured, typename Upgrade>
bool keepRoutesInView(const Layout& layout, const std::vector<std::vector<Pose2>>& long_routes, Usable&& usable,
                      Textured&& textured, Upgrade&& upgrade) {
  for (const std::vector<Pose2>& line : long_routes) {
    for (const Pose2& p : sample(line)) {
      if (clearanceAt(layout, p.x, p.y) < kInflationM) continue;  // at a pillar: the route goes round it
      double best_yaw = 0.0;
      int best_usable = -1;
      bool has = false;
      for (int k = 0; k < kYaws && !has; ++k) {
        const double yaw = 2.0 * kPi * k / kYaws;
        has = viewCount(layout, p, yaw, kRouteViewRangeM, [&](int b) { return usable(b) && textured(b); }) >=
              kViewRays / 3;
        const int n = viewCount(layout, p, yaw, kRouteViewRangeM, usable);
        if (n > best_usable) {
          best_usable = n;
          best_yaw = yaw;
        }
      }
      if (has) continue;
      if (best_usable < kViewRays / 3) return false;
      forView(layout, p, best_yaw, kRouteViewRangeM, [&](int b) {
        if (usable(b)) upgrade(b);
      });
    }
  }
  return true;
}

// Rule 3: the yaw of `pose` (start or goal) whose view holds the most usable blocks within
// kEndViewRangeM, those blocks made textured; false when under half the view is usable.
template <typename Usable, typename Upgrade>
bool faceTexture(const Layout& layout, Pose2* pose, Usable&& usable, Upgrade&& upgrade) {
  int best_rays = 0;
  for (int k = 0; k < kRays; ++k) {
    const double yaw = round2(2.0 * kPi * k / kRays - kPi);
    const int rays = viewCount(layout, *pose, yaw, kEndViewRangeM, usable);
    if (rays > best_rays) {
      best_rays = rays;
      pose->yaw = yaw;
    }
  }
  if (best_rays < kViewRays / 2) return false;
  forView(layout, *pose, pose->yaw, kEndViewRangeM, [&](int b) {
    if (usable(b)) upgrade(b);
  });
  return true;
}

// The premise's rules 1-3 on a layout whose blocks are placed; false when they cannot hold.
bool keepPremise(Layout& layout, const std::vector<Pose2>& short_route,
                 const std::vector<std::vector<Pose2>>& long_routes, SceneRng& rng) {
  // 1. The blind stretch and what it sees.
  const std::vector<Pose2> straight = sample(short_route);
  const auto n = straight.size();
  std::vector<char> seen_by_stretch(layout.blocks.size(), 0);
  for (std::size_t i = n * 35 / 100; i <= n * 65 / 100; ++i) {
    for (int b : blocksSeen(layout, straight[i].x, straight[i].y, kBlindRangeM)) seen_by_stretch[b] = 1;
  }
  for (std::size_t b = 0; b < layout.blocks.size(); ++b) {
    if (seen_by_stretch[b] && texturedLevel(layout.blocks[b].level)) {
      layout.blocks[b].level = rng.chance(0.5) ? TextureLevel::kPlain : TextureLevel::kFaint;
    }
  }
  auto usable = [&](int b) { return b >= 0 && !seen_by_stretch[b]; };
  auto textured = [&](int b) { return texturedLevel(layout.blocks[b].level); };
  auto upgrade = [&](int b) {
    if (!texturedLevel(layout.blocks[b].level)) {
      layout.blocks[b].level = rng.chance(0.5) ? TextureLevel::kRich : TextureLevel::kMedium;
    }
  };
  // 2. Texture in view all along the long route.
  if (!keepRoutesInView(layout, long_routes, usable, textured, upgrade)) return false;
  // 3. Start and goal face such texture.
  if (!faceTexture(layout, &layout.start, usable, upgrade)) return false;
  if (!faceTexture(layout, &layout.goal, usable, upgrade)) return false;
  // Rule 1 again: nothing above may have textured what the stretch sees.
  for (std::size_t b = 0; b < layout.blocks.size(); ++b) {
    if (seen_by_stretch[b] && texturedLevel(layout.blocks[b].level)) return false;
  }
  return true;
}

}  // namespace

Layout detourLayout(std::uint64_t seed) {
  SceneRng rng(mixSeed(seed, 4));
  Layout layout;
  layout.kind = SceneKind::kDetour;
  layout.seed = seed;
  drawRoomBounds(layout, rng, 13.0, 17.0, 9.0, 12.0);
  const double w = layout.xmax - layout.xmin;
  layout.light = drawLighting(rng);
  for (layout.attempts = 1; layout.attempts <= kMaxDetourLayouts; ++layout.attempts) {
    layout.blocks.clear();
    layout.obstacles.clear();
    addOuterWalls(layout, rng);
    // Start and goal below the middle; the barrier 1.3-1.8 m north of the higher of the two.
    const double line_y = rng.uniform(layout.ymin + 1.6, -0.6);
    layout.start = {round2(layout.xmin + 1.4), round2(line_y + rng.uniform(-0.3, 0.3)), 0.0};
    layout.goal = {round2(layout.xmax - 1.4), round2(line_y + rng.uniform(-0.3, 0.3)), 0.0};
    // On a 2 cm grid, so that the panels and the two layers touch exactly (no slit between them).
    const double barrier_y = round2cm(std::max(layout.start.y, layout.goal.y) + rng.uniform(1.3, 1.8));
    const double half = round2cm(rng.uniform(0.30, 0.36) * w);
    const double centre_x = round2cm(rng.uniform(-0.6, 0.6));
    const double layer = round2(0.5 * rng.uniform(0.12, 0.2));  // half thickness of each layer
    const int barrier = addObstacle(layout, "barrier");
    addLayer(layout, barrier, centre_x - half, centre_x + half, barrier_y - layer, layer, rng);
    addLayer(layout, barrier, centre_x - half, centre_x + half, barrier_y + layer, layer, rng);
    const double north = barrier_y + 2.0 * layer;  // the barrier's north face
    const double corridor_y = 0.5 * (north + layout.ymax);
    const int pillars = rng.uniformInt(0, 2);
    for (int k = 0; k < pillars; ++k) {
      const int obstacle = addObstacle(layout, "pillar");
      Block b;
      b.name = layout.obstacles[obstacle].name + "_0";
      b.cylinder = true;
      b.cx = round2(rng.uniform(centre_x - half + 1.0, centre_x + half - 1.0));
      b.cy = round2(corridor_y + rng.uniform(-0.3, 0.3));
      b.hx = b.hy = round2(rng.uniform(0.2, 0.35));
      b.height_m = kRoomHeightM;
      b.obstacle = obstacle;
      b.level = drawLevel(rng);
      layout.blocks.push_back(b);
    }
    if (!validateLayout(layout).empty()) continue;
    // The two routes (centre lines; the planner's own are smoother).
    const double west_x = 0.5 * (layout.xmin + centre_x - half);
    const double east_x = 0.5 * (centre_x + half + layout.xmax);
    const std::vector<Pose2> short_route{layout.start, layout.goal};
    auto longRoute = [&](double y) {
      return std::vector<Pose2>{layout.start,     {west_x, barrier_y, 0.0}, {west_x, y, 0.0},
                                {east_x, y, 0.0}, {east_x, barrier_y, 0.0}, layout.goal};
    };
    const std::vector<std::vector<Pose2>> long_routes{longRoute(corridor_y), longRoute(north + 0.6)};
    if (!clear(layout, short_route) || length(long_routes[0]) < 1.2 * length(short_route)) continue;
    if (keepPremise(layout, short_route, long_routes, rng)) return layout;
  }
  throw std::logic_error("detour layout: no valid layout for seed " + std::to_string(seed));
}

}  // namespace tgnav::harness::scenes
