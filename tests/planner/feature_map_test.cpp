// Visibility in the occlusion-aware feature map, on a hand-built map: a wall hides what is
// behind it, the vertical and horizontal FoV and the range limit what a camera can see.
#include "planner/feature_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "planner/voxel_map.h"
#include "tests/planner/synthetic_world.h"

namespace tgnav::planner {
namespace {

constexpr double kRes = 0.1;

// Marks the axis-aligned box [lo, hi] occupied and the rest of [-5, 5]^2 x [0, 3] free.
void fillBox(octomap::OcTree& tree, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  for (double x = -5 + kRes / 2; x < 5; x += kRes) {
    for (double y = -5 + kRes / 2; y < 5; y += kRes) {
      for (double z = kRes / 2; z < 3; z += kRes) {
        const bool inside = x > lo.x() && x < hi.x() && y > lo.y() && y < hi.y() && z > lo.z() && z < hi.z();
        tree.updateNode(octomap::point3d(x, y, z), inside);
      }
    }
  }
}

Landmark at(double x, double y, double z, const Eigen::Vector3d& seen_from) {
  Landmark lm;
  lm.p_W = Eigen::Vector3d(x, y, z);
  lm.ref_kf_p_W = seen_from;
  return lm;
}

class FeatureMapTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // A wall in the plane x = 0 (0.2 m thick, y in [-2, 2], z in [0, 2.5]).
    fillBox(map_.occupancy(), {-0.1, -2.0, 0.0}, {0.1, 2.0, 2.5});
    const Eigen::Vector3d west(-2, 0, 1), east(2, 0, 1);
    map_.setLandmarks({
        at(-0.1, 0.0, 1.0, west),  // 0: west face, centre
        at(-0.1, 1.0, 1.0, west),  // 1: west face, left
        at(0.1, 0.0, 1.0, east),   // 2: east face, centre
        at(0.1, -1.0, 1.0, east),  // 3: east face
        at(-0.1, 0.0, 2.0, west),  // 4: west face, high up (28 deg above the horizon from west)
        at(-1.5, 0.0, 1.0, west),  // 5: floating in free space: no surface, dropped
    });
    dropped_ = map_.embedLandmarks(0.15);
  }
  FeatureMap map_{kRes};
  int dropped_ = 0;
};

TEST_F(FeatureMapTest, LandmarksEmbedInTheSurfaceVoxelTheirKeyframeSees) {
  EXPECT_EQ(dropped_, 1);
  ASSERT_EQ(map_.landmarks().size(), 5u);
  for (int i = 0; i < 5; ++i) {
    EXPECT_TRUE(map_.isOccupied(map_.landmarkVoxel(i)));
    EXPECT_LT((map_.landmarkVoxel(i) - map_.landmarks()[i].p_W).norm(), kRes);
  }
  EXPECT_LT(map_.landmarkVoxel(0).x(), 0.0);  // west face voxel
  EXPECT_GT(map_.landmarkVoxel(2).x(), 0.0);  // east face voxel
}

TEST_F(FeatureMapTest, WallHidesTheFarSide) {
  VisibilityConfig config;
  EXPECT_EQ(map_.visibleFrom({-2.0, 0.0, 1.0}, config), (std::vector<int>{0, 1, 4}));
  EXPECT_EQ(map_.visibleFrom({2.0, 0.0, 1.0}, config), (std::vector<int>{2, 3}));
}

TEST_F(FeatureMapTest, VerticalFovAndRangeLimitVisibility) {
  VisibilityConfig config;
  config.vfov_rad = 40 * M_PI / 180;  // landmark 4 is 28 deg up: outside +-20 deg
  EXPECT_EQ(map_.visibleFrom({-2.0, 0.0, 1.0}, config), (std::vector<int>{0, 1}));
  config = VisibilityConfig{};
  config.max_range_m = 1.5;
  EXPECT_TRUE(map_.visibleFrom({-2.0, 0.0, 1.0}, config).empty());
}

TEST_F(FeatureMapTest, HorizontalFovSelectsByYaw) {
  VisibilityConfig config;
  const Eigen::Vector3d p(-2.0, 0.0, 1.0);
  const std::vector<int> all = map_.visibleFrom(p, config);
  EXPECT_EQ(map_.inHorizontalFov(p, 0.0, all, config), (std::vector<int>{0, 1, 4}));
  EXPECT_TRUE(map_.inHorizontalFov(p, M_PI, all, config).empty());
  // Looking 40 deg to the left: landmark 1 (bearing 26.6 deg) stays, 0 and 4 (0 deg) are at
  // the edge of a 75 deg FoV (half 37.6 deg): out.
  EXPECT_EQ(map_.inHorizontalFov(p, 40 * M_PI / 180, all, config), (std::vector<int>{1}));
}

TEST_F(FeatureMapTest, SaveLoadRoundTrip) {
  const auto dir = std::filesystem::temp_directory_path() / "tgnav_feature_map_roundtrip";
  std::filesystem::create_directories(dir);
  map_.save(dir);
  const FeatureMap back = FeatureMap::load(dir);
  ASSERT_EQ(back.landmarks().size(), map_.landmarks().size());
  EXPECT_EQ(back.visibleFrom({-2.0, 0.0, 1.0}, VisibilityConfig{}), (std::vector<int>{0, 1, 4}));
  EXPECT_DOUBLE_EQ(back.resolution(), kRes);
}

TEST_F(FeatureMapTest, OpportunitiesRoundTripAndOldMapsLoadWithout) {
  std::vector<Landmark> lms = map_.landmarks();
  lms[0].observations = 3;
  lms[0].opportunities = 12;
  FeatureMap with(kRes);
  fillBox(with.occupancy(), {-0.1, -2.0, 0.0}, {0.1, 2.0, 2.5});
  with.setLandmarks(lms);
  with.embedLandmarks(0.15);
  const auto dir = std::filesystem::temp_directory_path() / "tgnav_feature_map_opportunities";
  std::filesystem::create_directories(dir);
  with.save(dir);
  const FeatureMap back = FeatureMap::load(dir);
  EXPECT_EQ(back.landmarks()[0].opportunities, 12);
  EXPECT_DOUBLE_EQ(back.landmarks()[0].detectability(), 0.25);
  EXPECT_DOUBLE_EQ(back.landmarks()[1].detectability(), 1.0);  // never counted: unknown

  // The same file without the opportunities column (a map saved before it): detectability 1.
  std::ifstream in(dir / "landmarks.csv");
  std::stringstream old;
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    std::string field;
    while (std::getline(ss, field, ',')) f.push_back(field);
    f.erase(f.begin() + 5);
    for (std::size_t k = 0; k < f.size(); ++k) old << (k ? "," : "") << f[k];
    old << '\n';
  }
  in.close();
  std::ofstream(dir / "landmarks.csv") << old.str();
  const FeatureMap legacy = FeatureMap::load(dir);
  ASSERT_EQ(legacy.landmarks().size(), back.landmarks().size());
  EXPECT_EQ(legacy.landmarks()[0].observations, 3);
  EXPECT_EQ(legacy.landmarks()[0].opportunities, 0);
  EXPECT_DOUBLE_EQ(legacy.landmarks()[0].detectability(), 1.0);
  EXPECT_EQ(legacy.landmarks()[0].p_W, back.landmarks()[0].p_W);
  EXPECT_EQ(legacy.landmarks()[0].ref_kf_p_W, back.landmarks()[0].ref_kf_p_W);
}

// VoxelMap::lineOfSight answers most blocked rays from the voxel the segment enters the target
// from; it must give the walk's answer for every ray: random solids and viewpoints, and
// viewpoints on the voxel lattice's planes, edges and centres, whose rays tie between axes.
TEST(VoxelMapLineOfSight, AgreesWithTheWalkEverywhere) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int rays = 0;
  int seen = 0;
  int lattice = 0;
  for (int world = 0; world < 6; ++world) {
    testing::SyntheticWorld w;
    w.max_W = {6.0, 5.0, 2.0};
    for (int b = 0; b < 8; ++b) {
      const Eigen::Vector3d lo(0.1 * std::floor(55 * u(rng)), 0.1 * std::floor(45 * u(rng)), 0.0);
      const Eigen::Vector3d size(0.1 + 0.1 * std::floor(12 * u(rng)), 0.1 + 0.1 * std::floor(12 * u(rng)),
                                 world % 2 ? 2.0 : 0.1 * (1 + std::floor(19 * u(rng))));
      const Eigen::AlignedBox3d box(lo, (lo + size).cwiseMin(w.max_W));
      w.solids.push_back(box);
      for (const Eigen::Vector3d& n :
           {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, -1, 0)}) {
        w.texture(box, n, 0.25);
      }
    }
    const FeatureMap map = w.build();
    const VoxelMap voxels(map, w.min_W, w.max_W);
    ASSERT_GT(voxels.landmarkVoxels().size(), 50u);
    for (int v = 0; v < 60; ++v) {
      Eigen::Vector3d p(6.0 * u(rng), 5.0 * u(rng), 2.0 * u(rng));
      if (v % 3 == 1) p = (p / 0.1).array().round() * 0.1;           // lattice corners
      if (v % 3 == 2) p = ((p / 0.1).array().floor() + 0.5) * 0.1;   // voxel centres
      if (v % 6 == 1) p.z() = 0.05 + 0.1 * std::floor(p.z() / 0.1);  // and a mix of the two
      lattice += v % 3 != 0;
      for (const LandmarkVoxel& lv : voxels.landmarkVoxels()) {
        const bool walked = voxels.lineOfSightWalked(p, lv.index);
        ASSERT_EQ(voxels.lineOfSight(p, lv.index), walked)
            << "world " << world << " p " << p.transpose() << " voxel " << lv.centre_W.transpose();
        ++rays;
        seen += walked;
      }
    }
  }
  EXPECT_GT(seen, rays / 20);  // both answers are common
  EXPECT_LT(seen, rays - rays / 20);
  std::cout << "[ figure   ] " << rays << " rays (" << lattice << " of 360 viewpoints on the lattice), " << seen
            << " see their voxel\n";
}

// A wall's landmarks seen along the wall: the segment to a voxel's centre runs through the wall's
// next voxel within about 45 deg of the wall's plane (lineOfSight), the one to the free voxel in
// front of its face does not (lineOfSightToFace). From behind the wall, neither sees them.
TEST(VoxelMapLineOfSight, ToTheFaceSeesAWallAlongItsPlaneNotFromBehind) {
  testing::SyntheticWorld w;
  w.max_W = {6.0, 5.0, 2.0};
  const Eigen::AlignedBox3d wall(Eigen::Vector3d(3.0, 0.5, 0.0), Eigen::Vector3d(3.3, 4.5, 2.0));
  w.solids.push_back(wall);
  w.texture(wall, Eigen::Vector3d(-1, 0, 0), 0.1);
  const FeatureMap map = w.build();
  const VoxelMap voxels(map, w.min_W, w.max_W);
  const Eigen::Vector3d front(1.5, 0.6, 1.0);  // in front of the wall's south end, 1.5 m away
  const Eigen::Vector3d behind(4.5, 2.5, 1.0);
  int total = 0;
  int centre = 0;
  int face = 0;
  int steep = 0;  // seen within 45 deg of the normal
  for (const LandmarkVoxel& lv : voxels.landmarkVoxels()) {
    const Eigen::Vector3d d = lv.centre_W - front;
    if (std::abs(d.z()) > 0.5) continue;  // near the camera's height: the angle to the plane is the bearing's
    ++total;
    const bool by_centre = voxels.lineOfSight(front, lv.index);
    const bool by_face = voxels.lineOfSightToFace(front, lv.index);
    centre += by_centre;
    face += by_face;
    steep += std::abs(d.y()) < std::abs(d.x());
    EXPECT_TRUE(by_face || !by_centre) << lv.centre_W.transpose();
    EXPECT_FALSE(voxels.lineOfSightToFace(behind, lv.index)) << lv.centre_W.transpose();
    EXPECT_FALSE(voxels.lineOfSight(behind, lv.index)) << lv.centre_W.transpose();
  }
  ASSERT_GT(total, 100);
  EXPECT_EQ(face, total);
  EXPECT_LE(centre, steep + total / 20);  // the centre's test: hardly any beyond 45 deg
  EXPECT_LT(centre, total / 2);
  VisibilityConfig config;
  config.sight_to_face = true;
  EXPECT_GE(static_cast<int>(voxels.visibleSlots(front, config).size()), face);  // these and the rest
  std::cout << "[ figure   ] wall voxels near the camera's height seen from 1.5 m, along the wall: " << centre
            << " to their centre, " << face << " to their face, of " << total << " (" << steep
            << " within 45 deg of the normal)\n";
}

// An online planner may plan through space it has not observed: with unknown_free, unknown
// voxels are free (for clearance too), observed ones keep their state.
TEST(VoxelMapUnknownSpace, UnknownBlocksByDefaultAndIsFreeWhenAsked) {
  FeatureMap map(kRes);
  // Observed: a free patch around (-2, 0, 1) and an occupied voxel at (0, 0, 1); the rest unknown.
  for (double x = -3 + kRes / 2; x < -1; x += kRes) {
    for (double y = -1 + kRes / 2; y < 1; y += kRes) {
      for (double z = kRes / 2; z < 2; z += kRes) map.occupancy().updateNode(octomap::point3d(x, y, z), false);
    }
  }
  map.occupancy().updateNode(octomap::point3d(0.05f, 0.05f, 1.05f), true);
  const Eigen::Vector3d lo(-4, -2, 0), hi(4, 2, 2);
  const VoxelMap blocked(map, lo, hi);
  const VoxelMap optimistic(map, lo, hi, -1e9, 1e9, /*unknown_free=*/true);
  const Eigen::Vector3d seen(-2.05, 0.05, 1.05), unseen(2.05, 0.05, 1.05), wall(0.05, 0.05, 1.05);
  EXPECT_EQ(blocked.state(seen), VoxelState::kFree);
  EXPECT_EQ(blocked.state(unseen), VoxelState::kUnknown);
  EXPECT_EQ(blocked.clearance(unseen), 0.0);
  EXPECT_EQ(optimistic.state(seen), VoxelState::kFree);
  EXPECT_EQ(optimistic.state(unseen), VoxelState::kFree);
  EXPECT_GT(optimistic.clearance(unseen), 0.5);
  EXPECT_EQ(optimistic.state(wall), VoxelState::kOccupied);
  EXPECT_EQ(optimistic.clearance(wall), 0.0);
}

// A vehicle that came too close to a wall plans from the nearest point that clears it.
TEST(VoxelMapNearestClear, StepsStraightAwayFromTheNearestObstacle) {
  FeatureMap map(kRes);
  fillBox(map.occupancy(), {-0.1, -2.0, 0.0}, {0.1, 2.0, 2.5});  // a wall: its west face at x = -0.1
  const VoxelMap voxels(map, Eigen::Vector3d(-4, -4, 0), Eigen::Vector3d(4, 4, 3));
  const Eigen::Vector3d near(-0.3, 0.05, 1.05);  // 0.2 m from the face
  EXPECT_NEAR(voxels.clearance(near), 0.2, 1e-9);
  const std::optional<Eigen::Vector3d> out = voxels.nearestClear(near, 0.4, 0.4);
  ASSERT_TRUE(out.has_value());
  EXPECT_GE(voxels.clearance(*out), 0.4);
  EXPECT_NEAR(out->x(), -0.5, 0.03);  // straight west, on the nearest ring (a quarter voxel apart) that clears it
  EXPECT_NEAR(out->y(), near.y(), 1e-6);
  EXPECT_EQ(out->z(), near.z());
  // A point that already clears it is its own answer; one too deep for the distance allowed has none.
  EXPECT_EQ(voxels.nearestClear(*out, 0.4, 0.4), out);
  EXPECT_FALSE(voxels.nearestClear(near, 0.4, 0.15).has_value());
  EXPECT_FALSE(voxels.nearestClear(Eigen::Vector3d(0.0, 0.05, 1.05), 0.4, 0.3).has_value());  // in the wall
}

TEST(Detectability, ObservationsOutOfOpportunitiesAtMostOne) {
  Landmark lm;
  lm.observations = 2;
  EXPECT_DOUBLE_EQ(lm.detectability(), 1.0);  // unknown
  lm.opportunities = 8;
  EXPECT_DOUBLE_EQ(lm.detectability(), 0.25);
  lm.opportunities = 1;  // two keypoints of one frame merged into it
  EXPECT_DOUBLE_EQ(lm.detectability(), 1.0);
}

TEST(FeatureMapLoad, MissingFilesAreNamed) {
  try {
    FeatureMap::load("/nonexistent/map");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/map/map.bt"), std::string::npos);
  }
}

TEST(Hamming, CountsBits) {
  std::array<std::uint8_t, 32> a{}, b{};
  b[0] = 0xff;
  b[31] = 0x01;
  EXPECT_EQ(hammingDistance(a, b), 9);
  EXPECT_EQ(hammingDistance(b, b), 0);
}

}  // namespace
}  // namespace tgnav::planner
