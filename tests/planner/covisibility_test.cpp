// Path segment extraction by co-visibility (paper Sec. V-C, eqs. 1-2): the ratio on hand sets,
// recursive splitting against a synthetic visibility function with a known jump, and against
// brute-force sampling of the voxel map's visibility past a wall's end.
#include "planner/covisibility.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <set>
#include <stdexcept>
#include <string>

#include "planner/perception.h"
#include "planner/voxel_map.h"
#include "tests/planner/synthetic_world.h"

namespace tgnav::planner {
namespace {

TEST(Covisibility, RatioOnHandSets) {
  std::vector<int> cv{99, 98};  // cleared by the call
  EXPECT_DOUBLE_EQ(covisibilityRatio({1, 2, 3}, {2, 3, 4}, &cv), 0.5);
  EXPECT_EQ(cv, (std::vector<int>{2, 3}));
  EXPECT_DOUBLE_EQ(covisibilityRatio({}, {}, &cv), 0.0);  // both blind: 0 by convention
  EXPECT_TRUE(cv.empty());
  EXPECT_DOUBLE_EQ(covisibilityRatio({1, 2}, {}, &cv), 0.0);
  EXPECT_DOUBLE_EQ(covisibilityRatio({}, {5}, &cv), 0.0);
  EXPECT_DOUBLE_EQ(covisibilityRatio({1, 5, 9}, {1, 5, 9}, &cv), 1.0);
  EXPECT_EQ(cv, (std::vector<int>{1, 5, 9}));
  EXPECT_DOUBLE_EQ(covisibilityRatio({1, 3, 5}, {2, 4, 6}, &cv), 0.0);
  EXPECT_TRUE(cv.empty());
  EXPECT_DOUBLE_EQ(covisibilityRatio({1, 2, 3, 4}, {4}, &cv), 0.25);
  EXPECT_EQ(cv, (std::vector<int>{4}));
  EXPECT_DOUBLE_EQ(covisibilityRatio({0, 10, 20, 30, 40}, {10, 20, 30, 50, 60, 70, 80}, &cv), 3.0 / 9.0);
}

std::vector<int> range(int lo, int hi) {
  std::vector<int> v;
  for (int i = lo; i < hi; ++i) v.push_back(i);
  return v;
}

// Checks the invariants every extraction must keep; returns the segments.
void expectWellFormed(const std::vector<Eigen::Vector3d>& path, const std::vector<PathSegment>& segs,
                      const SegmentConfig& config, const VisibilityQuery& visible) {
  const double length = polylineLength3(path);
  ASSERT_FALSE(segs.empty());
  EXPECT_EQ(segs.front().s_begin_m, 0.0);
  EXPECT_NEAR(segs.back().s_end_m, length, 1e-12);
  for (std::size_t i = 0; i < segs.size(); ++i) {
    const PathSegment& s = segs[i];
    EXPECT_LT(s.s_begin_m, s.s_end_m) << "segment " << i;
    if (i > 0) {
      EXPECT_EQ(s.s_begin_m, segs[i - 1].s_end_m) << "segment " << i;  // contiguous, in order
    }
    EXPECT_LT((s.p_begin - pointAt(path, s.s_begin_m)).norm(), 1e-12);
    EXPECT_LT((s.p_end - pointAt(path, s.s_end_m)).norm(), 1e-12);
    EXPECT_TRUE(s.ratio >= config.covisibility_ratio || s.s_end_m - s.s_begin_m <= config.min_length_m)
        << "segment " << i << " [" << s.s_begin_m << ", " << s.s_end_m << "] CR " << s.ratio;
    // The stored CV and CR are those of its end points.
    std::vector<int> cv;
    EXPECT_DOUBLE_EQ(s.ratio, covisibilityRatio(visible(s.p_begin), visible(s.p_end), &cv));
    EXPECT_EQ(s.covisible, cv);
  }
}

TEST(Covisibility, SplitFallsAtTheVisibilityJump) {
  const SegmentConfig config;  // l_min 0.5, eta 0.5
  const std::vector<int> a = range(0, 40);
  const std::vector<int> b = range(100, 130);
  int worst_queries = 0;
  for (double jump : {3.7, 0.2, 5.0, 6.66, 9.9}) {
    // A polyline along x (a kink-free vertex at 2.5 to exercise pointAt).
    const std::vector<Eigen::Vector3d> path{{0, 0, 1}, {2.5, 0, 1}, {10, 0, 1}};
    std::vector<double> asked;
    const VisibilityQuery visible = [&](const Eigen::Vector3d& p) {
      asked.push_back(p.x());
      return p.x() < jump ? a : b;
    };
    int queries = -1;
    const std::vector<PathSegment> segs = extractSegments(path, config, visible, &queries);
    const std::vector<double> asked_by_extraction = asked;
    const VisibilityQuery quiet = [&](const Eigen::Vector3d& p) { return p.x() < jump ? a : b; };
    expectWellFormed(path, segs, config, quiet);
    // Exactly one segment straddles the jump; it has CR 0 and is no longer than l_min, and both
    // its ends are within l_min of the jump. Every other segment has CR 1.
    int straddling = 0;
    for (const PathSegment& s : segs) {
      if (s.ratio < config.covisibility_ratio) {
        ++straddling;
        EXPECT_LE(s.s_begin_m, jump);
        EXPECT_GE(s.s_end_m, jump);
        EXPECT_LE(s.s_end_m - s.s_begin_m, config.min_length_m);
        EXPECT_LE(jump - s.s_begin_m, config.min_length_m);
        EXPECT_LE(s.s_end_m - jump, config.min_length_m);
        EXPECT_DOUBLE_EQ(s.ratio, 0.0);
        EXPECT_TRUE(s.covisible.empty());
      } else {
        EXPECT_DOUBLE_EQ(s.ratio, 1.0);
      }
    }
    EXPECT_EQ(straddling, 1) << "jump " << jump;
    // One query per distinct point: the two ends and every split point.
    const std::set<double> distinct(asked_by_extraction.begin(), asked_by_extraction.end());
    EXPECT_EQ(static_cast<std::size_t>(queries), asked_by_extraction.size());
    EXPECT_EQ(distinct.size(), asked_by_extraction.size()) << "a point was asked twice";
    EXPECT_EQ(queries, static_cast<int>(segs.size() - 1) + 2) << "jump " << jump;
    worst_queries = std::max(worst_queries, queries);
    if (jump == 3.7) {
      for (const PathSegment& s : segs) {
        if (s.ratio < config.covisibility_ratio) {
          std::cout << "[ figure   ] jump at x = 3.7: split segment [" << s.s_begin_m << ", " << s.s_end_m << "], "
                    << segs.size() << " segments, " << queries << " visibility queries\n";
        }
      }
    }
  }
  EXPECT_LE(worst_queries, 12);
}

TEST(Covisibility, BlindAndDegeneratePaths) {
  const SegmentConfig config;
  const VisibilityQuery blind = [](const Eigen::Vector3d&) { return std::vector<int>{}; };
  int queries = 0;
  // Nothing seen anywhere: CR 0 everywhere, split down to l_min: 10 m -> 32 segments of 0.3125 m.
  const std::vector<Eigen::Vector3d> path{{0, 0, 0}, {10, 0, 0}};
  const auto segs = extractSegments(path, config, blind, &queries);
  EXPECT_EQ(segs.size(), 32u);
  EXPECT_EQ(queries, 33);
  expectWellFormed(path, segs, config, blind);
  // Everything constant: one segment, two queries.
  const VisibilityQuery same = [](const Eigen::Vector3d&) { return std::vector<int>{1, 2, 3}; };
  const auto one = extractSegments(path, config, same, &queries);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(queries, 2);
  EXPECT_DOUBLE_EQ(one[0].ratio, 1.0);
  // Zero length: one segment, one query.
  const auto point = extractSegments({{1, 2, 3}, {1, 2, 3}}, config, same, &queries);
  ASSERT_EQ(point.size(), 1u);
  EXPECT_EQ(queries, 1);
  EXPECT_DOUBLE_EQ(point[0].ratio, 1.0);
  EXPECT_TRUE(extractSegments({}, config, same, &queries).empty());
  // A slowly drifting view: CR stays >= eta on every segment longer than l_min.
  const VisibilityQuery drift = [](const Eigen::Vector3d& p) {
    const int first = static_cast<int>(std::floor(10.0 * p.x()));
    return range(first, first + 30);  // a 3 m window sliding along
  };
  const auto drifted = extractSegments(path, config, drift, &queries);
  expectWellFormed(path, drifted, config, drift);
  for (const PathSegment& s : drifted) EXPECT_GE(s.ratio, config.covisibility_ratio);
}

// A textured wall (face y = 3, x in [0, 4]) beside a straight path along y = 1.45; a thin
// occluder at y in [1.6, 1.7] starting at x = 4 hides the wall once the camera passes under it,
// so V(p) collapses within a few centimetres after x = 4.
testing::SyntheticWorld wallBehindOccluder(double texture_spacing_m) {
  testing::SyntheticWorld w;
  w.min_W = {0.0, 0.0, 0.0};
  w.max_W = {10.0, 3.5, 2.5};
  const Eigen::AlignedBox3d wall(Eigen::Vector3d(0.0, 3.0, 0.0), Eigen::Vector3d(4.0, 3.3, 2.5));
  const Eigen::AlignedBox3d occluder(Eigen::Vector3d(4.0, 1.6, 0.0), Eigen::Vector3d(10.0, 1.7, 2.5));
  w.solids = {wall, occluder};
  w.texture(wall, Eigen::Vector3d(0, -1, 0), texture_spacing_m);
  return w;
}

TEST(Covisibility, SplitMatchesBruteForceVisibilityOnTheVoxelMap) {
  const testing::SyntheticWorld w = wallBehindOccluder(0.1);
  const FeatureMap map = w.build();
  ASSERT_EQ(map.landmarks().size(), 1000u);
  const VoxelMap voxels(map, w.min_W, w.max_W);
  const VisibilityConfig vis;
  const VisibilityQuery visible = [&](const Eigen::Vector3d& p) { return voxels.visibleFrom(p, vis); };
  const std::vector<Eigen::Vector3d> path{{0.5, 1.45, 1.0}, {9.5, 1.45, 1.0}};
  const SegmentConfig config;

  // Brute force: V along the path every 0.05 m. The view drifts slowly while the wall is in
  // range (the vertical FoV takes in more of it from further away), then the wall vanishes
  // behind the occluder: the change is the first sample that sees none of it.
  const std::vector<int> v0 = visible(path.front());
  ASSERT_GT(v0.size(), 100u);
  double change = -1.0;
  std::size_t before = 0;
  for (double s = 0.0; s <= 9.0 + 1e-9; s += 0.05) {
    const std::vector<int> v = visible(pointAt(path, s));
    if (v.empty()) {
      change = path.front().x() + s;
      break;
    }
    before = v.size();
  }
  ASSERT_GT(change, 0.0);
  EXPECT_GT(change, 4.0);  // the world is what this test thinks it is
  EXPECT_LT(change, 4.4);
  EXPECT_GT(before, 50u);  // and the change is abrupt

  int queries = 0;
  const std::vector<PathSegment> segs = extractSegments(path, config, visible, &queries);
  expectWellFormed(path, segs, config, visible);
  const PathSegment* first_drop = nullptr;
  for (const PathSegment& s : segs) {
    if (s.ratio < config.covisibility_ratio) {
      first_drop = &s;
      break;
    }
  }
  ASSERT_NE(first_drop, nullptr);
  const double x0 = path.front().x() + first_drop->s_begin_m;
  const double x1 = path.front().x() + first_drop->s_end_m;
  EXPECT_LE(x1 - x0, config.min_length_m);
  EXPECT_GE(x0, change - config.min_length_m);
  EXPECT_LE(x1, change + config.min_length_m);
  EXPECT_LT(x0, change);
  // Before the drop the wall is seen from both ends of every segment.
  for (const PathSegment& s : segs) {
    if (&s == first_drop) break;
    EXPECT_GE(s.ratio, config.covisibility_ratio);
    EXPECT_FALSE(s.covisible.empty());
  }
  // V(p) by voxel (VoxelMap::visibleSlots) is the same set: the points aggregated from the
  // slots equal those aggregated from the ids, bit for bit, everywhere along the path.
  for (double s = 0.0; s <= 9.0 + 1e-9; s += 0.25) {
    const Eigen::Vector3d p = pointAt(path, s);
    const std::vector<WeightedPoint> by_id = aggregateByVoxel(voxels, voxels.visibleFrom(p, vis));
    const std::vector<WeightedPoint> by_slot = aggregateSlots(voxels, voxels.visibleSlots(p, vis));
    ASSERT_EQ(by_id.size(), by_slot.size()) << "s = " << s;
    for (std::size_t i = 0; i < by_id.size(); ++i) {
      EXPECT_EQ(by_id[i].p_W, by_slot[i].p_W);
      EXPECT_EQ(by_id[i].weight, by_slot[i].weight);
      EXPECT_EQ(by_id[i].normal_W, by_slot[i].normal_W);
      EXPECT_EQ(by_id[i].detections, by_slot[i].detections);
    }
  }
  std::cout << "[ figure   ] wall end: brute-force visibility change at x = " << change << " (" << before
            << " landmarks seen 0.05 m before), first CR drop in [" << x0 << ", " << x1 << "], " << segs.size()
            << " segments, " << queries << " queries\n";
}

void expectRejected(const SegmentConfig& config, const std::string& field) {
  try {
    config.validate();
    ADD_FAILURE() << "accepted, expected a complaint about " << field;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

TEST(Covisibility, ConfigValidationNamesTheField) {
  SegmentConfig c;
  EXPECT_NO_THROW(c.validate());
  c.covisibility_ratio = 0.0;
  EXPECT_NO_THROW(c.validate());
  c.covisibility_ratio = 1.0;
  EXPECT_NO_THROW(c.validate());
  c.covisibility_ratio = -0.1;
  expectRejected(c, "covisibility_ratio");
  c.covisibility_ratio = 1.5;
  expectRejected(c, "covisibility_ratio");
  c = SegmentConfig{};
  c.min_length_m = 0.0;
  expectRejected(c, "min_length_m");
  c.min_length_m = -1.0;
  expectRejected(c, "min_length_m");
}

// The planner's query: V(p) as landmark voxels (VoxelMap::visibleSlots), each weighted by its
// landmarks. The segments are those over ids: the same split points, ratios, and co-visible sets
// (as voxels). The wall carries several landmarks per voxel so that the weights count.
TEST(Covisibility, VoxelSlotsWeightedByLandmarksSplitAsIds) {
  const testing::SyntheticWorld w = wallBehindOccluder(0.04);  // the wall of the test above, denser
  const FeatureMap map = w.build();
  const VoxelMap voxels(map, w.min_W, w.max_W);
  ASSERT_LT(voxels.landmarkVoxels().size(), map.landmarks().size() / 2);  // several per voxel
  const VisibilityConfig vis;
  const SegmentConfig config;
  for (const std::vector<Eigen::Vector3d>& path :
       {std::vector<Eigen::Vector3d>{{0.5, 1.45, 1.0}, {9.5, 1.45, 1.0}},
        std::vector<Eigen::Vector3d>{{0.5, 0.5, 0.6}, {3.0, 2.2, 1.8}, {9.0, 1.0, 1.2}}}) {
    const std::vector<PathSegment> by_ids =
        extractSegments(path, config, [&](const Eigen::Vector3d& p) { return voxels.visibleFrom(p, vis); });
    ASSERT_GT(by_ids.size(), 4u);
    // Segments over voxel slots weighted by their landmarks (the planner's query) are those over
    // ids: the same split points, ratios, and co-visible sets (as voxels).
    const std::vector<PathSegment> by_slots = extractSegments(
        path, config, [&](const Eigen::Vector3d& p) { return voxels.visibleSlots(p, vis); }, nullptr,
        [&](int slot) { return voxels.landmarksIn(slot); });
    ASSERT_EQ(by_slots.size(), by_ids.size());
    bool weights_matter = false;
    for (std::size_t k = 0; k < by_ids.size(); ++k) {
      EXPECT_EQ(by_slots[k].s_begin_m, by_ids[k].s_begin_m);
      EXPECT_EQ(by_slots[k].s_end_m, by_ids[k].s_end_m);
      EXPECT_EQ(by_slots[k].ratio, by_ids[k].ratio);
      EXPECT_EQ(by_slots[k].covisible_landmarks, static_cast<int>(by_ids[k].covisible.size()));
      EXPECT_EQ(by_ids[k].covisible_landmarks, static_cast<int>(by_ids[k].covisible.size()));
      std::vector<int> ids;
      for (int slot : by_slots[k].covisible) {
        const std::vector<int>& in = voxels.landmarkVoxels()[static_cast<std::size_t>(slot)].ids;
        ids.insert(ids.end(), in.begin(), in.end());
      }
      std::sort(ids.begin(), ids.end());
      EXPECT_EQ(ids, by_ids[k].covisible);
      weights_matter = weights_matter || by_slots[k].covisible.size() != by_ids[k].covisible.size();
    }
    EXPECT_TRUE(weights_matter);  // voxels hold several landmarks here, so the weights are tested
  }
}

}  // namespace
}  // namespace tgnav::planner
