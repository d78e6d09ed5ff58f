#pragma once
// The geometry of a generated scene (harness/scenes/scene_generator.h) before it becomes files:
// a rectangular room of free space [xmin, xmax] x [ymin, ymax], 3 m high, closed by outer wall
// panels, with free-standing obstacles made of axis-aligned boxes and vertical cylinders standing
// on the floor; start and goal; lighting. Every block carries the texture level of its faces.
#include <cstdint>
#include <string>
#include <vector>

#include "harness/scenes/scene_random.h"

namespace tgnav::harness::scenes {

enum class SceneKind { kRoom, kCorridors, kWarehouse, kDetour };
enum class TextureLevel { kRich, kMedium, kFaint, kPlain };

const char* toString(SceneKind kind);
const char* toString(TextureLevel level);

constexpr double kPi = 3.14159265358979323846;

// What a generated scene guarantees (checked by validateLayout).
constexpr double kFlightHeightM = 1.0;
constexpr double kRoomHeightM = 3.0;
constexpr double kInflationM = 0.45;     // robot radius 0.3 m plus margin: free cells of the check
constexpr double kEndClearanceM = 1.0;   // around start and goal
constexpr double kObstacleGapM = 1.2;    // between obstacles, and between an obstacle and a wall
constexpr double kCellM = 0.05;          // raster of the connectivity check
constexpr double kMaxPanelM = 2.5;       // wall panels and shelf units are at most this long
constexpr double kWallThicknessM = 0.1;  // outer walls, outside the free space

// A solid on the floor: an axis-aligned box (half sizes hx, hy) or a vertical cylinder (radius hx).
struct Block {
  std::string name;
  bool cylinder = false;
  double cx = 0.0;
  double cy = 0.0;
  double hx = 0.0;
  double hy = 0.0;
  double height_m = kRoomHeightM;
  int obstacle = -1;  // index into Layout::obstacles; -1: an outer wall panel
  TextureLevel level = TextureLevel::kPlain;
};

struct Obstacle {
  std::string name;
  std::string shape;  // box, cylinder, l_shape, thin_wall, partition, shelf_row
};

struct Pose2 {
  double x = 0.0;
  double y = 0.0;
  double yaw = 0.0;
};

struct Lighting {
  double head_ambient = 0.35;
  double head_diffuse = 0.35;
  double top = 0.35;
  double fill = 0.25;
  double fill_dir_x = 1.0;  // direction of the first fill light in the horizontal plane
  double fill_dir_y = 0.3;
};

struct Layout {
  SceneKind kind = SceneKind::kRoom;
  std::uint64_t seed = 0;
  double xmin = 0.0, xmax = 0.0, ymin = 0.0, ymax = 0.0;
  std::vector<Block> blocks;  // outer wall panels first, then the parts of the obstacles
  std::vector<Obstacle> obstacles;
  Pose2 start, goal;
  Lighting light;
  int attempts = 0;  // obstacle layouts drawn until one was valid
};

// --- Geometry at the flight height (harness/scenes/layout_geometry.cpp) ---
double round2(double v);                                // to centimetres
double distanceTo(const Block& b, double x, double y);  // 0 inside
double gapBetween(const Block& a, const Block& b);
double clearanceAt(const Layout& layout, double x, double y);  // to the nearest block
// Index of the first block a horizontal ray from (x, y) at `angle_rad` hits within `range_m`; -1.
int firstHit(const Layout& layout, double x, double y, double angle_rad, double range_m);
// Whether the goal can be reached from the start through cells with clearance >= inflation_m.
bool connected(const Layout& layout, double inflation_m);
// "" when the layout keeps every guarantee above, else what it breaks.
std::string validateLayout(const Layout& layout);

// --- Building blocks of the layouts (harness/scenes/layout_common.cpp) ---
TextureLevel drawLevel(SceneRng& rng);
// A room of free space w x h centred on the origin, w in [w_lo, w_hi] and h in [h_lo, h_hi]
// drawn in that order, each to decimetres; sets the layout's bounds.
void drawRoomBounds(Layout& layout, SceneRng& rng, double w_lo, double w_hi, double h_lo, double h_hi);
// Outer wall panels (at most kMaxPanelM long) around the free space, each with a drawn level.
void addOuterWalls(Layout& layout, SceneRng& rng);
// A new obstacle; returns its index.
int addObstacle(Layout& layout, const std::string& shape);
// A box part of obstacle `obstacle`, split along its long axis into pieces of at most kMaxPanelM.
void addBoxPart(Layout& layout, int obstacle, double cx, double cy, double hx, double hy, double height_m,
                SceneRng& rng);
// Lights from the seed, within a band that keeps every texture level visible.
Lighting drawLighting(SceneRng& rng);
// Faint and plain blocks that the camera sees at the start (within the field of view around the
// start's yaw) or around the goal become rich, so a trial can start and end.
void forceVisibleLevels(Layout& layout);

// --- The kinds (harness/scenes/layout_room.cpp, layout_corridors.cpp, layout_detour.cpp) ---
Layout roomLayout(std::uint64_t seed);
Layout corridorsLayout(std::uint64_t seed);
Layout warehouseLayout(std::uint64_t seed);
// The paper's premise: the shortest route blind, a longer one flyable by looking beside or behind
// it (harness/scenes/layout_detour.cpp).
Layout detourLayout(std::uint64_t seed);

}  // namespace tgnav::harness::scenes
