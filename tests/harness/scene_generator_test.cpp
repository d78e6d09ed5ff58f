// tgnav scene generate (harness/scenes/): the same kind and seed give the same bytes; every kind
// loads as a scene and a scenario and compiles in MuJoCo; the MJCF's own geometry keeps the
// guarantees (start and goal clear and connected at the flight height, a free-standing obstacle);
// texture levels order the features; bad input is refused before anything is written.
#include "harness/scenes/scene_generator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <fstream>
#include <iterator>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "harness/config/scenario.h"
#include "harness/scenes/scene_textures.h"
#include "harness/sim/mujoco_sim.h"
#include "harness/sim/vehicle_model.h"
#include "test_util.h"

namespace tgnav::harness::scenes {
namespace {

namespace fs = std::filesystem;

const SceneKind kKinds[] = {SceneKind::kRoom, SceneKind::kCorridors, SceneKind::kWarehouse, SceneKind::kDetour};

std::string bytesOf(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Footprints at the flight height read back from the compiled model: every static box and
// cylinder that spans z = 1 m (the floor plane and the ceiling do not).
struct Footprint {
  bool cylinder;
  double x, y, hx, hy;
  double distance(double px, double py) const {
    if (cylinder) return std::max(0.0, std::hypot(px - x, py - y) - hx);
    return std::hypot(std::max(0.0, std::abs(px - x) - hx), std::max(0.0, std::abs(py - y) - hy));
  }
};

std::vector<Footprint> footprints(const mjModel* m) {
  std::vector<Footprint> out;
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_bodyid[g] != 0) continue;  // the vehicle
    const int type = m->geom_type[g];
    const mjtNum* p = m->geom_pos + 3 * g;
    const mjtNum* s = m->geom_size + 3 * g;
    if (type == mjGEOM_BOX && p[2] - s[2] <= 1.0 && p[2] + s[2] >= 1.0) {
      EXPECT_NEAR(std::abs(m->geom_quat[4 * g]), 1.0, 1e-9) << "boxes are axis-aligned";
      out.push_back({false, p[0], p[1], s[0], s[1]});
    } else if (type == mjGEOM_CYLINDER && p[2] - s[1] <= 1.0 && p[2] + s[1] >= 1.0) {
      out.push_back({true, p[0], p[1], s[0], s[0]});
    }
  }
  return out;
}

double clearance(const std::vector<Footprint>& fps, double x, double y) {
  double best = 1e9;
  for (const Footprint& f : fps) best = std::min(best, f.distance(x, y));
  return best;
}

// BFS over 5 cm cells of the bounds whose centres keep 0.45 m from every footprint.
bool connectedAt(const std::vector<Footprint>& fps, const SceneConfig& scene) {
  const double cell = 0.05;
  const double x0 = scene.bounds_min_m.x(), y0 = scene.bounds_min_m.y();
  const int nx = static_cast<int>((scene.bounds_max_m.x() - x0) / cell);
  const int ny = static_cast<int>((scene.bounds_max_m.y() - y0) / cell);
  auto index = [&](double x, double y) {
    return static_cast<int>((y - y0) / cell) * nx + static_cast<int>((x - x0) / cell);
  };
  std::vector<char> free(nx * ny), seen(nx * ny, 0);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i)
      free[j * nx + i] = clearance(fps, x0 + (i + 0.5) * cell, y0 + (j + 0.5) * cell) >= 0.45;
  }
  const int from = index(scene.start.p_WB.x(), scene.start.p_WB.y());
  const int to = index(scene.goal.p_WB.x(), scene.goal.p_WB.y());
  std::deque<int> queue{from};
  seen[from] = 1;
  while (!queue.empty()) {
    const int c = queue.front();
    queue.pop_front();
    if (c == to) return true;
    const int i = c % nx, j = c / nx;
    for (const auto& [a, b] : {std::pair{i + 1, j}, std::pair{i - 1, j}, std::pair{i, j + 1}, std::pair{i, j - 1}}) {
      if (a < 0 || a >= nx || b < 0 || b >= ny || !free[b * nx + a] || seen[b * nx + a]) continue;
      seen[b * nx + a] = 1;
      queue.push_back(b * nx + a);
    }
  }
  return false;
}

TEST(SceneGenerator, SameSeedGivesTheSameBytesInAnyFolder) {
  const GeneratedScene a = generateScene(SceneKind::kRoom, 7);
  const GeneratedScene b = generateScene(SceneKind::kRoom, 7);
  EXPECT_EQ(a.files, b.files);
  const fs::path dir = test::tempDir();
  writeGeneratedScene(a, dir / "one");
  writeGeneratedScene(b, dir / "deeper" / "two");
  for (const auto& [name, bytes] : a.files) {
    EXPECT_EQ(bytesOf(dir / "one" / name), bytes) << name;
    EXPECT_EQ(bytesOf(dir / "deeper" / "two" / name), bytes) << name;
  }
  EXPECT_EQ(bytesOf(dir / "one" / "quadrotor.xml"), bytesOf(test::sourceDir() / "models/quadrotor.xml"));
  EXPECT_EQ(bytesOf(dir / "one" / "quadrotor.yaml"), bytesOf(test::sourceDir() / "models/quadrotor.yaml"));
  EXPECT_EQ(test::stagingLeftIn(dir), 0);
}

TEST(SceneGenerator, DifferentSeedsAndKindsDiffer) {
  const GeneratedScene a = generateScene(SceneKind::kRoom, 1);
  const GeneratedScene b = generateScene(SceneKind::kRoom, 2);
  const GeneratedScene c = generateScene(SceneKind::kCorridors, 1);
  EXPECT_NE(a.files.at("room-1.xml"), b.files.at("room-2.xml"));
  EXPECT_NE(a.files.at("room-1.xml"), c.files.at("corridors-1.xml"));
  EXPECT_EQ(sceneFile(SceneKind::kRoom, 2), "scenes/room-2.yaml");
  EXPECT_EQ(scenarioFile(SceneKind::kWarehouse, 7), "scenarios/warehouse-7.yaml");
  const auto png = [](const GeneratedScene& s) {
    return std::find_if(s.files.begin(), s.files.end(),
                        [](const auto& f) { return f.first.rfind("textures/", 0) == 0; });
  };
  ASSERT_NE(png(a), a.files.end());
  EXPECT_NE(png(a)->second, png(b)->second);
}

TEST(SceneGenerator, EveryKindLoadsCompilesAndKeepsItsGuarantees) {
  const fs::path dir = test::tempDir();
  for (SceneKind kind : kKinds) {
    for (std::uint64_t seed : {1u, 2u, 3u}) {
      SCOPED_TRACE(std::string(toString(kind)) + " seed " + std::to_string(seed));
      const fs::path out = dir / (std::string(toString(kind)) + "-" + std::to_string(seed));
      writeGeneratedScene(generateScene(kind, seed), out);
      const SceneConfig scene = loadSceneConfig(out / sceneFile(kind, seed));
      const Scenario scenario = loadScenario(out / scenarioFile(kind, seed));
      EXPECT_EQ(scene.source.stem(), sceneName(kind, seed));
      EXPECT_EQ(scenario.source.stem(), sceneName(kind, seed));
      EXPECT_EQ(scenario.scene.mjcf, scene.mjcf);
      EXPECT_DOUBLE_EQ(scenario.camera.rgb_noise_sigma, 2.0);
      const ModelPtr model = loadVehicleModel(scene.mjcf, scene.vehicle).model;
      const std::vector<Footprint> fps = footprints(model.get());
      EXPECT_GE(clearance(fps, scene.start.p_WB.x(), scene.start.p_WB.y()), 1.0);
      EXPECT_GE(clearance(fps, scene.goal.p_WB.x(), scene.goal.p_WB.y()), 1.0);
      EXPECT_TRUE(connectedAt(fps, scene));
      // A free-standing obstacle: 1.2 m from the bounds on every side (a second homology class).
      const bool free_standing = std::any_of(fps.begin(), fps.end(), [&](const Footprint& f) {
        return f.x - f.hx >= scene.bounds_min_m.x() + 1.2 - 1e-9 && f.x + f.hx <= scene.bounds_max_m.x() - 1.2 + 1e-9 &&
               f.y - f.hy >= scene.bounds_min_m.y() + 1.2 - 1e-9 && f.y + f.hy <= scene.bounds_max_m.y() - 1.2 + 1e-9;
      });
      EXPECT_TRUE(free_standing);
    }
  }
}

// The detour kind keeps the paper's premise from its layout alone: the straight route from start
// to goal is clear, and from its middle 30 % no ray at the flight height reaches a rich or medium
// surface within the VO's 10 m; the start's and the goal's yaws face texture within 7 m in at
// least half their view; and the levels were drawn, not all set.
TEST(SceneGenerator, DetourKeepsTheShortestRouteBlindAndTheStartTextured) {
  constexpr double kPi = 3.14159265358979323846;
  auto textured = [](const Layout& l, int b) {
    return b >= 0 && (l.blocks[b].level == TextureLevel::kRich || l.blocks[b].level == TextureLevel::kMedium);
  };
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    SCOPED_TRACE("detour seed " + std::to_string(seed));
    const Layout l = detourLayout(seed);
    const double dx = l.goal.x - l.start.x, dy = l.goal.y - l.start.y;
    for (double f = 0.0; f <= 1.0; f += 0.01) {
      ASSERT_GE(clearanceAt(l, l.start.x + f * dx, l.start.y + f * dy), kInflationM) << f;
    }
    int blind_rays = 0;
    for (double f = 0.35; f <= 0.65; f += 0.05) {
      for (int k = 0; k < 360; ++k) {
        const int hit = firstHit(l, l.start.x + f * dx, l.start.y + f * dy, 2.0 * kPi * k / 360, 10.0);
        EXPECT_FALSE(textured(l, hit)) << "f " << f << " ray " << k << " hits " << l.blocks[hit].name;
        ++blind_rays;
      }
    }
    EXPECT_GT(blind_rays, 2000);
    for (const Pose2& end : {l.start, l.goal}) {
      int view = 0;
      for (int r = -20; r <= 20; ++r)
        view += textured(l, firstHit(l, end.x, end.y, end.yaw + 37.5 * kPi / 180.0 * r / 20, 7.0));
      EXPECT_GE(view, 20) << "rays of the view at (" << end.x << ", " << end.y << ") on texture, of 41";
    }
    int textured_blocks = 0;
    for (int b = 0; b < static_cast<int>(l.blocks.size()); ++b) textured_blocks += textured(l, b);
    EXPECT_GT(textured_blocks, 0);
    EXPECT_LT(textured_blocks, static_cast<int>(l.blocks.size()));
  }
}

int fastCorners(const cv::Mat& bgr) {
  cv::Mat gray;
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  std::vector<cv::KeyPoint> keypoints;
  cv::FAST(gray, keypoints, 20);
  return static_cast<int>(keypoints.size());
}

TEST(SceneGenerator, TextureLevelsOrderTheFeatures) {
  SceneRng rng(5);
  int corners[3] = {0, 0, 0};
  for (int k = 0; k < 4; ++k) {
    corners[0] += fastCorners(makeFaceImage(TextureLevel::kRich, 2.0, 3.0, 384, rng));
    corners[1] += fastCorners(makeFaceImage(TextureLevel::kMedium, 2.0, 3.0, 384, rng));
    corners[2] += fastCorners(makeFaceImage(TextureLevel::kFaint, 2.0, 3.0, 384, rng));
  }
  EXPECT_GT(corners[0], 2 * corners[1]);
  EXPECT_GT(corners[1], 2 * corners[2]);
  EXPECT_GT(corners[2], 0) << "faint is not flat";
}

TEST(SceneGenerator, BadInputIsRefusedNamingTheOption) {
  for (const char* bad : {"-1", "1.5", "abc", "", "18446744073709551616", "+3"}) {
    const std::string message = test::inputError([&] { parseSceneSeed(bad); });
    EXPECT_NE(message.find(std::string("--seed: '") + bad + "'"), std::string::npos) << message;
  }
  EXPECT_EQ(parseSceneSeed("18446744073709551615"), 18446744073709551615ULL);
  EXPECT_NE(test::inputError([] { parseSceneKind("cave"); }).find("--kind: 'cave'"), std::string::npos);
  const fs::path dir = test::tempDir();
  test::writeFile(dir / "keep.txt", "x");
  EXPECT_NE(test::inputError([&] { writeGeneratedScene(generateScene(SceneKind::kRoom, 1), dir); }).find("--out"),
            std::string::npos);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  EXPECT_EQ(test::stagingLeftIn(dir.parent_path()), 0);
}

test::CmdResult tgnav(const std::string& args) { return test::runShell(std::string(TGNAV_BIN) + " " + args); }

TEST(SceneGeneratorCli, WritesAScene) {
  const fs::path out = test::tempDir() / "scene";
  const test::CmdResult run = tgnav("scene generate --seed 4 --kind corridors --out " + out.string());
  ASSERT_EQ(run.rc, 0) << run.output;
  for (const char* f : {"corridors-4.xml", "scenes/corridors-4.yaml", "scenarios/corridors-4.yaml", "generated.json",
                        "quadrotor.xml", "quadrotor.yaml"}) {
    EXPECT_TRUE(fs::is_regular_file(out / f)) << f;
  }
  EXPECT_FALSE(fs::is_empty(out / "textures"));
}

TEST(SceneGeneratorCli, BadSeedKindOrFolderIsExit2AndWritesNothing) {
  const fs::path dir = test::tempDir();
  const std::pair<std::string, std::string> cases[] = {
      {"--seed=-1", "--seed: '-1'"},
      {"--seed 2.5", "--seed: '2.5'"},
      {"--seed 99999999999999999999", "--seed: '99999999999999999999'"},
      {"--seed 1 --kind cave", "--kind: 'cave'"}};
  for (const auto& [args, expected] : cases) {
    const test::CmdResult run = tgnav("scene generate " + args + " --out " + (dir / "out").string());
    EXPECT_EQ(run.rc, 2) << args;
    EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << run.output;
    EXPECT_NE(run.output.find(expected), std::string::npos) << run.output;
    EXPECT_FALSE(fs::exists(dir / "out")) << args;
  }
  test::writeFile(dir / "full.txt", "x");
  const test::CmdResult run = tgnav("scene generate --seed 1 --out " + dir.string());
  EXPECT_EQ(run.rc, 2);
  EXPECT_NE(run.output.find("--out: " + dir.string()), std::string::npos) << run.output;
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

}  // namespace
}  // namespace tgnav::harness::scenes
