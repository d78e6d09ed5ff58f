// The feature map built from rendered RGB-D agrees with the scene's true geometry: exposed
// surfaces are occupied, free space is free, landmarks lie on surfaces, textured surfaces
// carry landmarks and plain ones do not.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <iostream>

#include "harness/config/scenario.h"
#include "harness/run/map_builder.h"
#include "harness/run/online_metrics.h"
#include "harness/sim/mujoco_sim.h"
#include "harness/sim/scene_geometry.h"
#include "planner/occupancy_grid.h"
#include "test_util.h"

namespace tgnav::harness {
namespace {

class SmokeMapTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new SceneConfig(loadSceneConfig(test::sourceDir() / "configs/scenes/smoke.yaml"));
    map_ = new planner::FeatureMap(buildFeatureMap(*scene_, MapBuildConfig{}, &stats_));
    model_ = loadModel(scene_->mjcf).release();
    data_ = makeData(model_).release();
    mj_forward(model_, data_);
    geometry_ = new SceneGeometry(model_, data_);
  }
  static void TearDownTestSuite() {
    delete geometry_;
    mj_deleteData(data_);
    mj_deleteModel(model_);
    delete map_;
    delete scene_;
  }
  static bool insideBounds(const Eigen::Vector3d& p) {
    return (p.array() > scene_->bounds_min_m.array()).all() && (p.array() < scene_->bounds_max_m.array()).all();
  }
  // Voxel centres of the horizontal layer containing the flight height.
  static std::vector<Eigen::Vector3d> flightLayer() {
    const octomap::OcTree& tree = map_->occupancy();
    const double z = tree.keyToCoord(tree.coordToKey(0.0, 0.0, scene_->flight_height_m)).z();
    std::vector<Eigen::Vector3d> cells;
    const double res = map_->resolution();
    for (double x = scene_->bounds_min_m.x() + res / 2; x < scene_->bounds_max_m.x(); x += res) {
      for (double y = scene_->bounds_min_m.y() + res / 2; y < scene_->bounds_max_m.y(); y += res) {
        const octomap::point3d c = tree.keyToCoord(tree.coordToKey(x, y, z));
        cells.emplace_back(c.x(), c.y(), c.z());
      }
    }
    return cells;
  }

  static SceneConfig* scene_;
  static planner::FeatureMap* map_;
  static MapBuildStats stats_;
  static mjModel* model_;
  static mjData* data_;
  static SceneGeometry* geometry_;
};
SceneConfig* SmokeMapTest::scene_ = nullptr;
planner::FeatureMap* SmokeMapTest::map_ = nullptr;
MapBuildStats SmokeMapTest::stats_;
mjModel* SmokeMapTest::model_ = nullptr;
mjData* SmokeMapTest::data_ = nullptr;
SceneGeometry* SmokeMapTest::geometry_ = nullptr;

TEST_F(SmokeMapTest, SurveyCoversTheFreeSpace) {
  EXPECT_GT(stats_.survey_positions, 40);
  EXPECT_EQ(stats_.frames, stats_.survey_positions * scene_->survey.yaw_count);
  for (const auto& pose : surveyPoses(*scene_, *geometry_)) {
    ASSERT_GE(geometry_->signedDistance(pose.p_WB), scene_->survey.clearance_m);
  }
}

TEST_F(SmokeMapTest, OccupancyAgreesWithTheGeometryAtFlightHeight) {
  const double res = map_->resolution();
  int surface = 0, surface_occupied = 0, free_known = 0, free_occupied = 0, free_total = 0;
  for (const Eigen::Vector3d& c : flightLayer()) {
    const double sd = geometry_->signedDistance(c);
    if (sd > 0.0) {
      // Each horizontal step from this free voxel into geometry crosses a surface, which lies
      // in one of the two voxels (on their boundary when aligned with the grid): one of them
      // must be occupied. Only exposed surfaces count: the voxel behind `c` is free too (a
      // 5 cm slot between a crate and a wall is never seen). Interiors stay unknown.
      for (int axis = 0; axis < 2; ++axis) {
        for (double sign : {-1.0, 1.0}) {
          Eigen::Vector3d n = c;
          n[axis] += sign * res;
          Eigen::Vector3d behind = c;
          behind[axis] -= sign * res;
          if (geometry_->signedDistance(n) > 0.0 || !insideBounds(behind) || geometry_->signedDistance(behind) <= 0.0) {
            continue;
          }
          ++surface;
          surface_occupied += map_->isOccupied(c) || map_->isOccupied(n);
        }
      }
    }
    if (sd > res) {
      ++free_total;
      if (!map_->isKnown(c)) continue;
      ++free_known;
      free_occupied += map_->isOccupied(c);
    }
  }
  const double occupied_ratio = static_cast<double>(surface_occupied) / surface;
  const double false_ratio = static_cast<double>(free_occupied) / free_known;
  std::cout << "[ figure   ] smoke map at flight height: " << surface_occupied << "/" << surface
            << " exposed surface crossings occupied (" << 100 * occupied_ratio << " %), " << free_occupied << "/"
            << free_known << " known free voxels occupied (" << 100 * false_ratio << " %), " << free_known << "/"
            << free_total << " free voxels observed\n";
  EXPECT_GT(surface, 300);  // walls, pillar and crates: about 360 crossings
  EXPECT_GE(occupied_ratio, 0.95);
  EXPECT_LE(false_ratio, 0.02);
  EXPECT_GE(static_cast<double>(free_known) / free_total, 0.9);
}

// The online map's holes (online_metrics.h, mapHoles) on the survey's map: few, and every
// surface voxel punched free at the flight height counted.
TEST_F(SmokeMapTest, HolesAreTheTrueSurfacesTheMapSaysAreFree) {
  const Scenario scenario = loadScenario(test::sourceDir() / "configs/scenarios/smoke.yaml");
  const MapHoles survey = mapHoles(map_->occupancy(), scenario, *geometry_);
  std::cout << "[ figure   ] smoke survey map: " << survey.holes << " holes of " << survey.crossings
            << " observed surface crossings in the flight band (" << 100 * survey.share() << " %)\n";
  EXPECT_GT(survey.crossings, 1000);
  EXPECT_LT(survey.share(), 0.02);
  // Punch the flight layer's occupied voxels inside the geometry whose outer neighbour (-x) is
  // free: each is then a hole.
  octomap::OcTree tree(map_->occupancy());
  const double res = tree.getResolution();
  int punched = 0;
  for (const Eigen::Vector3d& c : flightLayer()) {
    const Eigen::Vector3d out = c - Eigen::Vector3d(res, 0.0, 0.0);
    if (geometry_->signedDistance(c) > 0.0 || geometry_->signedDistance(out) <= 0.0) continue;
    const octomap::OcTreeNode* in_node = tree.search(c.x(), c.y(), c.z());
    const octomap::OcTreeNode* out_node = tree.search(out.x(), out.y(), out.z());
    if (in_node == nullptr || !tree.isNodeOccupied(in_node) || out_node == nullptr || tree.isNodeOccupied(out_node)) {
      continue;
    }
    while (tree.isNodeOccupied(tree.search(c.x(), c.y(), c.z()))) tree.updateNode(c.x(), c.y(), c.z(), false);
    ++punched;
  }
  const MapHoles after = mapHoles(tree, scenario, *geometry_);
  ASSERT_GT(punched, 10);
  EXPECT_EQ(after.crossings, survey.crossings);
  EXPECT_GE(after.holes, survey.holes + punched);
}

TEST_F(SmokeMapTest, LandmarksLieOnSurfaces) {
  std::vector<double> d;
  for (const auto& lm : map_->landmarks()) d.push_back(geometry_->distanceToSurface(lm.p_W));
  ASSERT_GT(d.size(), 1000u);
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  const double median = d[d.size() / 2];
  std::cout << "[ figure   ] " << d.size() << " landmarks, median distance to a surface " << median << " m\n";
  EXPECT_LT(median, map_->resolution());
}

TEST_F(SmokeMapTest, TexturedCratesCarryLandmarksThePlainPillarNone) {
  // Landmarks within 0.15 m of the pillar (plain) vs. of crate_e1 (textured), which have
  // comparable exposed areas.
  auto near_geom = [&](const char* name) {
    const std::ptrdiff_t g = mj_name2id(model_, mjOBJ_GEOM, name);
    EXPECT_GE(g, 0) << name;
    if (g < 0) return -1;
    const Eigen::Vector3d c(data_->geom_xpos + 3 * g);
    const Eigen::Vector3d h(model_->geom_size + 3 * g);
    int n = 0;
    for (const auto& lm : map_->landmarks()) {
      const Eigen::Vector3d q = (lm.p_W - c).cwiseAbs() - h;
      n += q.cwiseMax(0.0).norm() < 0.15;
    }
    return n;
  };
  const int pillar = near_geom("pillar");
  const int crate = near_geom("crate_e1");
  std::cout << "[ figure   ] landmarks on the plain pillar " << pillar << ", on textured crate_e1 " << crate << "\n";
  EXPECT_GT(crate, 500);
  EXPECT_LT(pillar * 20, crate);
}

// Each landmark's detectability is its detections out of the survey frames that had it in view:
// never more detections than chances, and the chances counted from the survey's own frames
// (the survey has more views of every landmark than the two it takes to keep one).
TEST_F(SmokeMapTest, EveryLandmarkWasInViewAtLeastAsOftenAsItWasDetected) {
  int more_chances = 0;
  for (const planner::Landmark& lm : map_->landmarks()) {
    ASSERT_GE(lm.opportunities, lm.observations);
    ASSERT_LE(lm.opportunities, stats_.frames);
    more_chances += lm.opportunities > lm.observations ? 1 : 0;
  }
  std::cout << "[ figure   ] smoke map: mean detectability " << stats_.mean_detectability << " over "
            << stats_.landmarks << " landmarks\n";
  EXPECT_GT(more_chances, static_cast<int>(map_->landmarks().size()) / 2);
  EXPECT_GT(stats_.mean_detectability, 0.05);
  EXPECT_LT(stats_.mean_detectability, 1.0);
}

TEST_F(SmokeMapTest, FlightHeightSliceMatchesTheGeometry) {
  const double res = 0.1;
  const double z = scene_->flight_height_m;
  const planner::OccupancyGrid2D grid = planner::sliceOccupancy(*map_, scene_->bounds_min_m.head<2>(),
                                                                scene_->bounds_max_m.head<2>(), z - 0.3, z + 0.3, res);
  int wrong_free = 0, wrong_occupied = 0, free_cells = 0, solid_cells = 0;
  for (int iy = 0; iy < grid.height; ++iy) {
    for (int ix = 0; ix < grid.width; ++ix) {
      const Eigen::Vector2d c = grid.centreOf(ix, iy);
      // Distance to geometry over the band (the smallest over three heights).
      double sd = 1e9;
      for (double dz : {-0.3, 0.0, 0.3}) sd = std::min(sd, geometry_->signedDistance({c.x(), c.y(), z + dz}));
      if (sd < -res) {
        ++solid_cells;
        wrong_free += !grid.isOccupied(ix, iy);
      } else if (sd > res) {
        ++free_cells;
        wrong_occupied += grid.isOccupied(ix, iy);
      }
    }
  }
  std::cout << "[ figure   ] smoke slice at flight height: " << wrong_free << "/" << solid_cells
            << " solid cells free, " << wrong_occupied << "/" << free_cells << " free cells occupied\n";
  EXPECT_EQ(wrong_free, 0);
  EXPECT_LE(wrong_occupied, free_cells / 100);
}

}  // namespace
}  // namespace tgnav::harness
