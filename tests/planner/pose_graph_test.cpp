// 4-DoF pose graph (paper Sec. V-D): the layered-DAG dynamic programme against brute force,
// and the pose graph search on a synthetic corridor (determinism, clearance, yaw-rate limit,
// layer spacing, end points, perception pulling the yaw towards the textured wall, the straight
// reference line without perception), the order kept among gated poses, the moves checked
// between layers, plus config validation.
#include "planner/pose_graph.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>

#include "tests/planner/synthetic_world.h"

namespace tgnav::planner {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------------------------
// Layered DAG: exact DP vs. enumeration of every node sequence.

struct Brute {
  bool found = false;
  double cost = kInf;
};

// Cost of a node sequence (node0 + e0 + node1 + e1 + ... in layer order); +inf if not a path.
double sequenceCost(const LayeredDag& dag, const std::vector<int>& nodes) {
  double c = dag.node_cost[0][static_cast<std::size_t>(nodes[0])];
  for (std::size_t j = 0; j + 1 < nodes.size(); ++j) {
    double best_edge = kInf;
    for (const auto& e : dag.edges[j]) {
      if (e.from == nodes[j] && e.to == nodes[j + 1]) best_edge = std::min(best_edge, e.cost);
    }
    c += best_edge;
    c += dag.node_cost[j + 1][static_cast<std::size_t>(nodes[j + 1])];
  }
  return c;
}

Brute bruteForce(const LayeredDag& dag) {
  Brute b;
  const std::size_t layers = dag.node_cost.size();
  std::vector<int> nodes(layers, 0);
  while (true) {
    const double c = sequenceCost(dag, nodes);
    if (c < b.cost) {
      b.cost = c;
      b.found = true;
    }
    std::size_t j = 0;
    while (j < layers && ++nodes[j] == static_cast<int>(dag.node_cost[j].size())) nodes[j++] = 0;
    if (j == layers) break;
  }
  return b;
}

TEST(LayeredDag, DynamicProgrammeEqualsBruteForceOnRandomDags) {
  std::mt19937_64 rng(21);
  std::uniform_int_distribution<int> n_layers(2, 5), n_nodes(1, 4);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int with_path = 0;
  int without_path = 0;
  for (int g = 0; g < 300; ++g) {
    LayeredDag dag;
    const int layers = g < 10 ? 1 + g % 2 : n_layers(rng);  // a few one- and two-layer graphs first
    const double p_edge = 0.2 + 0.7 * unit(rng);
    const double p_inf = 0.25 * unit(rng);
    dag.node_cost.resize(static_cast<std::size_t>(layers));
    dag.edges.resize(static_cast<std::size_t>(std::max(0, layers - 1)));
    for (int j = 0; j < layers; ++j) {
      const int n = n_nodes(rng);
      for (int k = 0; k < n; ++k) {
        // Negative costs too: the planner's node costs are -lambda_p log det / N.
        dag.node_cost[static_cast<std::size_t>(j)].push_back(unit(rng) < p_inf ? kInf : 4.0 * unit(rng) - 2.0);
      }
    }
    for (int j = 0; j + 1 < layers; ++j) {
      for (int a = 0; a < static_cast<int>(dag.node_cost[static_cast<std::size_t>(j)].size()); ++a) {
        for (int b = 0; b < static_cast<int>(dag.node_cost[static_cast<std::size_t>(j + 1)].size()); ++b) {
          if (unit(rng) < p_edge) dag.edges[static_cast<std::size_t>(j)].push_back({a, b, 3.0 * unit(rng)});
          if (unit(rng) < 0.1) dag.edges[static_cast<std::size_t>(j)].push_back({a, b, 3.0 * unit(rng)});  // parallel
        }
      }
      std::shuffle(dag.edges[static_cast<std::size_t>(j)].begin(), dag.edges[static_cast<std::size_t>(j)].end(), rng);
    }
    const Brute expected = bruteForce(dag);
    const DagPath got = shortestLayeredPath(dag);
    ASSERT_EQ(got.found, expected.found) << "graph " << g;
    if (!expected.found) {
      ++without_path;
      continue;
    }
    ++with_path;
    EXPECT_NEAR(got.cost, expected.cost, 1e-12) << "graph " << g;
    ASSERT_EQ(got.nodes.size(), static_cast<std::size_t>(layers)) << "graph " << g;
    for (int j = 0; j < layers; ++j) {
      ASSERT_GE(got.nodes[static_cast<std::size_t>(j)], 0);
      ASSERT_LT(got.nodes[static_cast<std::size_t>(j)],
                static_cast<int>(dag.node_cost[static_cast<std::size_t>(j)].size()));
    }
    // The returned sequence is a path (every step an edge) whose cost is the reported one.
    EXPECT_NEAR(sequenceCost(dag, got.nodes), got.cost, 1e-12) << "graph " << g;
  }
  EXPECT_GT(with_path, 100);
  EXPECT_GT(without_path, 10);
  std::cout << "[ figure   ] layered DAGs checked against brute force: " << with_path << " with a path, "
            << without_path << " without\n";
}

// The search's lazy rounds raise the cost of edges and solve again from the first layer whose
// edges changed, keeping the costs to reach the layers before it: the same path and cost as a
// solve from scratch, ties included.
TEST(LayeredDag, SolvingAgainFromTheFirstChangedLayerEqualsSolvingFromScratch) {
  std::mt19937_64 rng(22);
  std::uniform_int_distribution<int> n_layers(2, 7), n_nodes(1, 5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int compared = 0;
  for (int g = 0; g < 200; ++g) {
    LayeredDag dag;
    const int layers = n_layers(rng);
    dag.node_cost.resize(static_cast<std::size_t>(layers));
    dag.edges.resize(static_cast<std::size_t>(layers - 1));
    for (auto& layer : dag.node_cost) {
      const int n = n_nodes(rng);
      for (int k = 0; k < n; ++k) layer.push_back(unit(rng) < 0.1 ? kInf : std::round(4.0 * unit(rng)) - 2.0);
    }
    for (int j = 0; j + 1 < layers; ++j) {
      for (int a = 0; a < static_cast<int>(dag.node_cost[static_cast<std::size_t>(j)].size()); ++a) {
        for (int b = 0; b < static_cast<int>(dag.node_cost[static_cast<std::size_t>(j + 1)].size()); ++b) {
          // Whole-number costs: many ties.
          if (unit(rng) < 0.7) dag.edges[static_cast<std::size_t>(j)].push_back({a, b, std::round(3.0 * unit(rng))});
        }
      }
    }
    DagMemo memo;
    DagPath got = shortestLayeredPath(dag, &memo, 0);
    for (int round = 0; round < 5; ++round) {
      const auto first = static_cast<std::size_t>(std::uniform_int_distribution<int>(0, layers - 2)(rng));
      for (std::size_t j = first; j + 1 < static_cast<std::size_t>(layers); ++j) {
        for (LayeredDag::Edge& e : dag.edges[j]) {
          if (unit(rng) < 0.3) e.cost += std::round(2.0 * unit(rng));
        }
      }
      got = shortestLayeredPath(dag, &memo, first);
      const DagPath fresh = shortestLayeredPath(dag);
      ASSERT_EQ(got.found, fresh.found) << "graph " << g << " round " << round;
      EXPECT_EQ(got.cost, fresh.cost) << "graph " << g << " round " << round;
      EXPECT_EQ(got.nodes, fresh.nodes) << "graph " << g << " round " << round;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 1000);
}

TEST(LayeredDag, TiesGoToTheLowerIndexAndEmptyGraphsHaveNoPath) {
  LayeredDag dag;
  dag.node_cost = {{0.0, 0.0}, {1.0, 1.0, 1.0}, {0.0, 0.0}};
  dag.edges = {{{1, 2, 0.5}, {0, 2, 0.5}, {1, 1, 0.5}}, {{2, 1, 0.0}, {1, 1, 0.0}, {2, 0, 0.0}, {1, 0, 0.0}}};
  const DagPath p = shortestLayeredPath(dag);
  ASSERT_TRUE(p.found);
  EXPECT_DOUBLE_EQ(p.cost, 1.5);
  EXPECT_EQ(p.nodes, (std::vector<int>{1, 1, 0}));  // 1 before 2 in layer 1, then 1 before 0 in layer 0
  EXPECT_FALSE(shortestLayeredPath(LayeredDag{}).found);
  LayeredDag blocked;
  blocked.node_cost = {{0.0}, {kInf}};
  blocked.edges = {{{0, 0, 1.0}}};
  EXPECT_FALSE(shortestLayeredPath(blocked).found);
}

// ---------------------------------------------------------------------------------------------
// Pose graph on a corridor 8 m long along x, 1 m wide (y in [1, 2]), 2.5 m high: walls are
// solids 0.3 m thick; the flight line is y = 1.5, z = 1. Robot radius 0.3 and R_sample 0.4
// leave some samples in collision, so the clearance checks bite.

constexpr double kZ = 1.0;

struct Corridor {
  VoxelMap voxels;
  std::vector<Eigen::Vector3d> path;
};

// side: +1 textures the +y wall (its face towards the corridor), -1 the -y wall, 0 none.
std::unique_ptr<Corridor> corridor(int side) {
  testing::SyntheticWorld w;
  w.min_W = {0.0, 0.7, 0.0};
  w.max_W = {8.0, 2.3, 2.5};
  const Eigen::AlignedBox3d lo(Eigen::Vector3d(0.0, 0.7, 0.0), Eigen::Vector3d(8.0, 1.0, 2.5));
  const Eigen::AlignedBox3d hi(Eigen::Vector3d(0.0, 2.0, 0.0), Eigen::Vector3d(8.0, 2.3, 2.5));
  w.solids = {lo, hi};
  if (side > 0) w.texture(hi, Eigen::Vector3d(0, -1, 0), 0.1);
  if (side < 0) w.texture(lo, Eigen::Vector3d(0, 1, 0), 0.1);
  // Reference keyframes 0.5 m in front of the face (1 m would put them inside the other wall,
  // and embedLandmarks() would drop them).
  for (Landmark& lm : w.landmarks) lm.ref_kf_p_W = lm.p_W + 0.5 * (lm.ref_kf_p_W - lm.p_W);
  const FeatureMap map = w.build();
  EXPECT_EQ(map.landmarks().size(), side == 0 ? 0u : 2000u);
  auto c = std::unique_ptr<Corridor>(new Corridor{VoxelMap(map, w.min_W, w.max_W), {}});
  c->path = {{0.5, 1.5, kZ}, {4.0, 1.5, kZ}, {7.5, 1.5, kZ}};
  return c;
}

const Corridor& texturedCorridor(int side) {
  static std::unique_ptr<Corridor> plus = corridor(+1);
  static std::unique_ptr<Corridor> minus = corridor(-1);
  return side > 0 ? *plus : *minus;
}

// The synthetic corridor's landmarks are a sparse grid, dozens in view where a rendered map holds
// thousands: the default gate on expected detections (min_detections, calibrated on rendered
// maps) would call every pose blind. The search's own behaviour is what these tests check.
InformationConfig syntheticInformation() {
  InformationConfig info;
  info.min_detections = 0.0;
  return info;
}

PoseGraphResult search(const Corridor& c, const PoseGraphConfig& config, std::uint64_t seed,
                       double start_yaw = std::nan("")) {
  const VisibilityConfig vis;
  const std::vector<PathSegment> segments = extractSegments(
      c.path, SegmentConfig{}, [&](const Eigen::Vector3d& p) { return c.voxels.visibleSlots(p, vis); }, nullptr,
      [&](int slot) { return c.voxels.landmarksIn(slot); });
  return searchPoseGraph(c.path, segments, c.voxels, vis, syntheticInformation(), config, start_yaw, seed);
}

double wrap(double a) { return std::remainder(a, 2.0 * M_PI); }

void expectFeasible(const Corridor& c, const PoseGraphResult& r, const PoseGraphConfig& config) {
  ASSERT_TRUE(r.found);
  const double length = polylineLength3(c.path);
  const std::size_t n = r.path.size();
  ASSERT_EQ(r.layer_s.size(), n);
  ASSERT_EQ(r.scores.size(), n);
  EXPECT_EQ(static_cast<int>(n),
            static_cast<int>(std::ceil(length / (config.nominal_speed_mps * config.time_step_s) - 1e-9)) + 1);
  EXPECT_LT((r.path.front().p_WB - c.path.front()).norm(), 1e-12);
  EXPECT_LT((r.path.back().p_WB - c.path.back()).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(r.layer_s.front(), 0.0);
  EXPECT_NEAR(r.layer_s.back(), length, 1e-12);
  double c_d = 0.0;
  double score_sum = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    EXPECT_GE(c.voxels.clearance(r.path[j].p_WB), config.robot_radius_m) << "layer " << j;
    // Each node lies on its layer's plane, within R_sample of the path point.
    const Eigen::Vector3d centre = pointAt(c.path, r.layer_s[j]);
    EXPECT_NEAR(r.path[j].p_WB.x(), centre.x(), 1e-9) << "layer " << j;
    EXPECT_LE((r.path[j].p_WB - centre).norm(), config.sample_radius_m + 1e-9) << "layer " << j;
    score_sum += r.scores[j];
    if (j == 0) continue;
    const double spacing = r.layer_s[j] - r.layer_s[j - 1];
    EXPECT_GT(spacing, 0.0);
    EXPECT_LE(spacing, config.nominal_speed_mps * config.time_step_s + 1e-12) << "layer " << j;
    EXPECT_TRUE(c.voxels.segmentClear(r.path[j - 1].p_WB, r.path[j].p_WB, config.robot_radius_m)) << "layer " << j;
    EXPECT_LE(std::abs(wrap(r.path[j].yaw_rad - r.path[j - 1].yaw_rad)),
              config.yaw_rate_limit_rad_s * config.time_step_s + 1e-9)
        << "layer " << j;
    c_d += (r.path[j].p_WB - r.path[j - 1].p_WB).norm();
  }
  EXPECT_NEAR(r.c_d, c_d, 1e-9);
  EXPECT_NEAR(r.c_p, score_sum / static_cast<double>(n), 1e-9);
  EXPECT_NEAR(r.cost, config.distance_weight * r.c_d - config.perception_weight * r.c_p, 1e-9);
}

TEST(PoseGraph, CorridorSearchIsDeterministicFeasibleAndRateLimited) {
  const Corridor& c = texturedCorridor(+1);
  const PoseGraphConfig config;
  const PoseGraphResult a = search(c, config, 7);
  const PoseGraphResult b = search(c, config, 7);
  expectFeasible(c, a, config);
  ASSERT_EQ(a.path.size(), b.path.size());
  for (std::size_t j = 0; j < a.path.size(); ++j) {
    EXPECT_EQ(a.path[j].p_WB, b.path[j].p_WB) << "layer " << j;
    EXPECT_EQ(a.path[j].yaw_rad, b.path[j].yaw_rad) << "layer " << j;
  }
  EXPECT_EQ(a.cost, b.cost);
  EXPECT_EQ(a.nodes, b.nodes);
  EXPECT_EQ(a.edges, b.edges);
  // Some samples collide (the corridor leaves 0.2 m of lateral play for 0.4 m of R_sample).
  const int layers = static_cast<int>(a.path.size());
  const int all_nodes = (2 + (layers - 2) * config.position_samples) * config.yaw_samples;
  EXPECT_LT(a.nodes, all_nodes);
  EXPECT_GT(a.nodes, 2 * config.yaw_samples);
  // Another seed, other samples, still feasible.
  expectFeasible(c, search(c, config, 8), config);
  // A fixed start yaw is kept.
  const PoseGraphResult fixed = search(c, config, 7, 0.3);
  expectFeasible(c, fixed, config);
  EXPECT_NEAR(fixed.path.front().yaw_rad, 0.3, 1e-12);
  std::cout << "[ figure   ] corridor pose graph: " << layers << " layers, " << a.nodes << " of " << all_nodes
            << " nodes collision-free, " << a.edges << " edges, c_d " << a.c_d << " m, c_p " << a.c_p << "\n";
}

TEST(PoseGraph, TheLatticeIgnoresTheSeedAndRandomPositionsDoNot) {
  const Corridor& c = texturedCorridor(+1);
  const PoseGraphConfig lattice;
  ASSERT_FALSE(lattice.random_positions);
  const PoseGraphResult a = search(c, lattice, 7);
  const PoseGraphResult b = search(c, lattice, 12345);
  expectFeasible(c, a, lattice);
  ASSERT_EQ(a.path.size(), b.path.size());
  for (std::size_t j = 0; j < a.path.size(); ++j) {
    EXPECT_EQ(a.path[j].p_WB, b.path[j].p_WB) << "layer " << j;
    EXPECT_EQ(a.path[j].yaw_rad, b.path[j].yaw_rad) << "layer " << j;
  }
  EXPECT_EQ(a.cost, b.cost);
  // Every lattice point lies on the disk of R_sample around the reference path's point.
  for (std::size_t j = 0; j < a.path.size(); ++j) {
    EXPECT_LE((a.path[j].p_WB - pointAt(c.path, a.layer_s[j])).norm(), lattice.sample_radius_m + 1e-9) << j;
  }
  PoseGraphConfig random = lattice;
  random.random_positions = true;
  const PoseGraphResult r7 = search(c, random, 7);
  const PoseGraphResult r8 = search(c, random, 8);
  expectFeasible(c, r7, random);
  expectFeasible(c, r8, random);
  bool differ = false;
  for (std::size_t j = 0; j < r7.path.size() && j < r8.path.size(); ++j) differ |= r7.path[j].p_WB != r8.path[j].p_WB;
  EXPECT_TRUE(differ || r7.path.size() != r8.path.size());
}

TEST(PoseGraph, PerceptionPullsTheYawTowardsTheTexturedWall) {
  const PoseGraphConfig config;
  for (int side : {+1, -1}) {
    const Corridor& c = texturedCorridor(side);
    const PoseGraphResult r = search(c, config, 3);
    expectFeasible(c, r, config);
    double mean_sin = 0.0;
    int towards = 0;
    for (const Pose4& p : r.path) {
      mean_sin += std::sin(p.yaw_rad) / static_cast<double>(r.path.size());
      towards += side * std::sin(p.yaw_rad) > 0.2;
    }
    EXPECT_GT(side * mean_sin, 0.5) << "side " << side;
    EXPECT_GE(towards, static_cast<int>(0.9 * static_cast<double>(r.path.size()))) << "side " << side;
    std::cout << "[ figure   ] textured wall on side " << side << ": mean sin(yaw) " << mean_sin << ", " << towards
              << "/" << r.path.size() << " poses facing it, c_p " << r.c_p << "\n";
  }
}

TEST(PoseGraph, WithoutPerceptionThePathIsTheReferenceLine) {
  const Corridor& c = texturedCorridor(+1);
  PoseGraphConfig config;
  config.perception_weight = 0.0;
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const PoseGraphResult r = search(c, config, seed);
    expectFeasible(c, r, config);
    for (std::size_t j = 0; j < r.path.size(); ++j) {
      EXPECT_LT((r.path[j].p_WB - pointAt(c.path, r.layer_s[j])).norm(), 1e-12) << "seed " << seed << " layer " << j;
    }
    EXPECT_NEAR(r.c_d, polylineLength3(c.path), 1e-9);
  }
  // With perception, the path leaves the line for a better view (so the check above can fail).
  const PoseGraphResult p = search(c, PoseGraphConfig{}, 1);
  double off = 0.0;
  for (std::size_t j = 0; j < p.path.size(); ++j)
    off = std::max(off, (p.path[j].p_WB - pointAt(c.path, p.layer_s[j])).norm());
  std::cout << "[ figure   ] largest departure from the reference line with perception: " << off << " m\n";
}

// The graph's per-node information (summed per yaw over an azimuth window) agrees with the
// direct per-pose computation of perception.h for every chosen pose, whatever the start yaw; so do
// the inner detections a learned model reads (counted per yaw from the image position), gated
// where the model's probability falls short.
TEST(PoseGraph, ChosenScoresMatchPoseScore) {
  const Corridor& c = texturedCorridor(+1);
  const VisibilityConfig vis;
  InformationConfig plain;
  plain.min_image_coverage = 0.0;  // information alone (the coverage limit: ImageCoverageGatesOnWhatTheCameraSees)
  InformationConfig learned = plain;
  auto model = std::make_shared<TrackModel>();
  model->terms = {{TrackFeature::kLogInnerDetections, 3.0, 1.0, 2.0},
                  {TrackFeature::kLogInnerNearDetections, 2.0, 1.0, 1.0}};
  learned.model = model;
  learned.min_track_probability = 0.5;
  const std::vector<PathSegment> segments = extractSegments(
      c.path, SegmentConfig{}, [&](const Eigen::Vector3d& p) { return c.voxels.visibleSlots(p, vis); }, nullptr,
      [&](int slot) { return c.voxels.landmarksIn(slot); });
  const double blind = 6.0 * std::log(plain.epsilon);
  // The camera off the body's centre (exaggerated to tell the two apart): a pose is scored from
  // its camera.
  VisibilityConfig mounted = vis;
  mounted.camera_forward_m = 0.3;
  mounted.camera_up_m = 0.1;
  int checked = 0;
  int gated = 0;
  int passed = 0;
  int moved = 0;  // poses the mounted camera scores otherwise than the body's centre would
  for (const VisibilityConfig& camera : {vis, mounted}) {
    for (const InformationConfig& info : {plain, learned}) {
      for (double start_yaw : {std::nan(""), 0.0, 3.0, -2.9, 1.234}) {
        const PoseGraphResult r =
            searchPoseGraph(c.path, segments, c.voxels, camera, info, PoseGraphConfig{}, start_yaw, 5);
        ASSERT_TRUE(r.found);
        for (std::size_t j = 0; j < r.path.size(); ++j) {
          const auto& seg = segments[static_cast<std::size_t>(r.layer_segment[j])];
          const std::vector<WeightedPoint> points = aggregateSlots(c.voxels, seg.covisible);
          const double yaw = r.path[j].yaw_rad;
          const double direct = poseScore(cameraPosition(r.path[j].p_WB, yaw, camera), yaw, points, camera, info);
          EXPECT_NEAR(r.scores[j], direct, 1e-9 * std::max(1.0, std::abs(direct)))
              << "start yaw " << start_yaw << " layer " << j << " camera ahead " << camera.camera_forward_m;
          EXPECT_LE(seg.s_begin_m, r.layer_s[j] + 1e-12);
          EXPECT_GE(seg.s_end_m, r.layer_s[j] - 1e-12);
          ++checked;
          if (info.model && direct <= blind + 1e-9) ++gated;
          if (info.model && direct > blind + 1e-9) ++passed;
          if (cameraOffset(camera) && std::abs(direct - poseScore(r.path[j].p_WB, yaw, points, camera, info)) > 1e-6) {
            ++moved;
          }
        }
      }
    }
  }
  EXPECT_GT(checked, 200);
  EXPECT_GT(gated, 0);  // the model decides somewhere, both ways
  EXPECT_GT(passed, 0);
  EXPECT_GT(moved, 0);
}

// Two textured panels facing each other across the start of a path along +x, 2.5 m to either
// side: A at +y (sparse) and B at -y (denser).
struct FacingPanels {
  VoxelMap voxels;
  std::vector<Eigen::Vector3d> path;
};

const FacingPanels& facingPanels() {
  static const FacingPanels panels = [] {
    testing::SyntheticWorld w;
    w.min_W = {0.0, 1.5, 0.0};
    w.max_W = {9.0, 8.5, 2.5};
    const Eigen::AlignedBox3d a(Eigen::Vector3d(2.0, 7.5, 0.0), Eigen::Vector3d(4.0, 7.8, 2.5));
    const Eigen::AlignedBox3d b(Eigen::Vector3d(2.0, 2.2, 0.0), Eigen::Vector3d(4.0, 2.5, 2.5));
    w.solids = {a, b};
    w.texture(a, Eigen::Vector3d(0, -1, 0), 0.2);
    w.texture(b, Eigen::Vector3d(0, 1, 0), 0.07);
    const FeatureMap map = w.build();
    return FacingPanels{VoxelMap(map, w.min_W, w.max_W), {{3.0, 5.0, kZ}, {7.0, 5.0, kZ}}};
  }();
  return panels;
}

// The turn on the spot at the start (guard_start_turn): two textured panels face each other
// across the start, 2.5 m to either side of a path along +x; the one behind the vehicle's yaw (-y)
// is denser, so the unguarded search turns the MAV half round to it, sweeping the blind views
// along the path. Guarded, every view the turn sweeps (the shorter way, on the yaw lattice)
// scores at least c_p,thr.
TEST(PoseGraph, StartTurnNeverSweepsABlindView) {
  const FacingPanels& panels = facingPanels();
  const VoxelMap& voxels = panels.voxels;
  const std::vector<Eigen::Vector3d>& path = panels.path;
  const VisibilityConfig vis;
  const InformationConfig info;
  const std::vector<PathSegment> segments = extractSegments(
      path, SegmentConfig{}, [&](const Eigen::Vector3d& p) { return voxels.visibleSlots(p, vis); }, nullptr,
      [&](int slot) { return voxels.landmarksIn(slot); });
  const std::vector<WeightedPoint> from_start = aggregateByVoxel(voxels, voxels.visibleFrom(path.front(), vis));
  auto view = [&](double yaw) { return poseScore(path.front(), yaw, from_start, vis, info); };
  const double vehicle_yaw = M_PI / 2;
  const double floor = 6.0;
  ASSERT_GE(view(vehicle_yaw), floor);  // facing panel A
  ASSERT_LT(view(0.0), floor);          // along the path: neither panel in the FoV
  ASSERT_LT(view(M_PI), floor);
  // The weakest view the turn from the vehicle's yaw to `yaw` sweeps, the shorter way round.
  auto weakest_turn = [&](double yaw) {
    const double step = 2.0 * M_PI / PoseGraphConfig{}.yaw_samples;
    const double turn = wrap(yaw - vehicle_yaw);
    const int steps = static_cast<int>(std::lround(std::abs(turn) / step));
    double weakest = view(vehicle_yaw);
    for (int k = 1; k <= steps; ++k) weakest = std::min(weakest, view(vehicle_yaw + std::copysign(k * step, turn)));
    return weakest;
  };

  PoseGraphConfig unguarded;
  unguarded.guard_start_turn = false;
  const PoseGraphResult u = searchPoseGraph(path, segments, voxels, vis, info, unguarded, std::nan(""), 1, vehicle_yaw);
  ASSERT_TRUE(u.found);
  EXPECT_LT(std::sin(u.path.front().yaw_rad), 0.0) << "the denser panel B should win unguarded";
  EXPECT_LT(weakest_turn(u.path.front().yaw_rad), floor);

  PoseGraphConfig guarded;
  guarded.turn_floor = floor;
  const PoseGraphResult g = searchPoseGraph(path, segments, voxels, vis, info, guarded, std::nan(""), 1, vehicle_yaw);
  ASSERT_TRUE(g.found);
  EXPECT_GE(weakest_turn(g.path.front().yaw_rad), floor) << "first yaw " << g.path.front().yaw_rad;
  EXPECT_GT(std::sin(g.path.front().yaw_rad), 0.0);
  // Without the vehicle's yaw there is nothing to guard: the same answer as unguarded.
  const PoseGraphResult n = searchPoseGraph(path, segments, voxels, vis, info, guarded, std::nan(""), 1);
  ASSERT_TRUE(n.found);
  std::cout << "[ figure   ] first yaw unguarded " << u.path.front().yaw_rad << " rad (turn sweeps "
            << weakest_turn(u.path.front().yaw_rad) << "), guarded " << g.path.front().yaw_rad << " rad (turn sweeps "
            << weakest_turn(g.path.front().yaw_rad) << "); c_p " << u.c_p << " -> " << g.c_p << "\n";
}

// turn_substeps: a plain box 0.6 m north of the start leaves the views of two narrow windows of
// yaws (about 84-87 and 93-96 deg) too little of the textured walls beyond its edges; both lie
// between yaws of the lattice (from the vehicle's 150 deg: 105, 90, 75). On the lattice alone the
// guard lets the MAV turn east, to the path's heading, and the camera sweeps a window. Checked at 4
// views per step the guard sees it: the turn it allows sweeps no view below the floor (checked at
// 1 deg), and the MAV turns the other way round, to the textured west wall.
TEST(PoseGraph, StartTurnSubstepsSeeABlindWindowBetweenLatticeYaws) {
  testing::SyntheticWorld w;
  w.min_W = {0.0, 0.0, 0.0};
  w.max_W = {7.0, 7.0, 2.5};
  const Eigen::AlignedBox3d north(Eigen::Vector3d(0.0, 6.7, 0.0), Eigen::Vector3d(7.0, 7.0, 2.5));
  const Eigen::AlignedBox3d south(Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(7.0, 0.3, 2.5));
  const Eigen::AlignedBox3d west(Eigen::Vector3d(0.0, 0.3, 0.0), Eigen::Vector3d(0.3, 6.7, 2.5));
  const Eigen::AlignedBox3d east(Eigen::Vector3d(6.7, 0.3, 0.0), Eigen::Vector3d(7.0, 6.7, 2.5));
  // plain, from the start (3.5, 3.5): 59.5 to 120.5 deg
  const Eigen::AlignedBox3d plain(Eigen::Vector3d(3.146, 4.1, 0.0), Eigen::Vector3d(3.853, 5.1, 2.5));
  w.solids = {north, south, west, east, plain};
  w.texture(north, Eigen::Vector3d(0, -1, 0), 0.1);
  w.texture(west, Eigen::Vector3d(1, 0, 0), 0.1);
  w.texture(east, Eigen::Vector3d(-1, 0, 0), 0.1);
  const FeatureMap map = w.build();
  const VoxelMap voxels(map, w.min_W, w.max_W);
  const std::vector<Eigen::Vector3d> path = {{3.5, 3.5, kZ}, {6.0, 3.5, kZ}};
  const VisibilityConfig vis;
  const InformationConfig info = syntheticInformation();
  const std::vector<PathSegment> segments = extractSegments(
      path, SegmentConfig{}, [&](const Eigen::Vector3d& p) { return voxels.visibleSlots(p, vis); }, nullptr,
      [&](int slot) { return voxels.landmarksIn(slot); });
  const std::vector<WeightedPoint> from_start = aggregateByVoxel(voxels, voxels.visibleFrom(path.front(), vis));
  auto view = [&](double yaw) { return poseScore(path.front(), yaw, from_start, vis, info); };
  const double deg = M_PI / 180.0;
  const double vehicle_yaw = 150.0 * deg;
  const double floor = 6.0;
  ASSERT_LT(view(95.0 * deg), floor);
  ASSERT_LT(view(86.0 * deg), floor);
  for (int a : {150, 135, 120, 105, 90, 75, 60, 45, 30, 15, 0}) ASSERT_GE(view(a * deg), floor) << a << " deg";
  // The weakest view the turn to `yaw` sweeps, the shorter way round, at 1 deg.
  auto weakest_turn = [&](double yaw) {
    const double turn = wrap(yaw - vehicle_yaw);
    const int steps = static_cast<int>(std::lround(std::abs(turn) / deg));
    double weakest = view(vehicle_yaw);
    for (int k = 1; k <= steps; ++k) weakest = std::min(weakest, view(vehicle_yaw + std::copysign(k * deg, turn)));
    return weakest;
  };
  PoseGraphConfig lattice;
  lattice.turn_floor = floor;
  lattice.turn_substeps = 1;
  const PoseGraphResult a = searchPoseGraph(path, segments, voxels, vis, info, lattice, std::nan(""), 1, vehicle_yaw);
  PoseGraphConfig fine = lattice;
  fine.turn_substeps = 4;
  const PoseGraphResult b = searchPoseGraph(path, segments, voxels, vis, info, fine, std::nan(""), 1, vehicle_yaw);
  ASSERT_TRUE(a.found);
  ASSERT_TRUE(b.found);
  EXPECT_LT(weakest_turn(a.path.front().yaw_rad), floor) << "the lattice's guard should let the turn east pass";
  EXPECT_GE(weakest_turn(b.path.front().yaw_rad), floor) << "first yaw " << b.path.front().yaw_rad / deg << " deg";
  std::cout << "[ figure   ] first yaw on the lattice " << a.path.front().yaw_rad / deg << " deg (weakest view swept "
            << weakest_turn(a.path.front().yaw_rad) << "), at 4 views per step " << b.path.front().yaw_rad / deg
            << " deg (" << weakest_turn(b.path.front().yaw_rad) << ")\n";
}

// failure_weight, with a learned model: the world of StartTurnNeverSweepsABlindView, unguarded.
// Without the weight the search turns the MAV half round to the denser panel B, sweeping the views
// along the path that the model gives little chance; with it, that turn's expected failure
// (-ln p of every view swept) outweighs B's information and the MAV keeps facing panel A. The
// chosen path's summed -ln p (nodes and turn) cannot grow with the weight.
TEST(PoseGraph, FailureWeightAvoidsAStartTurnTheModelDoubts) {
  const FacingPanels& panels = facingPanels();
  const VoxelMap& voxels = panels.voxels;
  const std::vector<Eigen::Vector3d>& path = panels.path;
  const VisibilityConfig vis;
  InformationConfig info;
  auto model = std::make_shared<TrackModel>();
  model->terms = {{TrackFeature::kLogInnerDetections, std::log1p(20.0), 0.5, 2.0}};  // p = 0.5 at 20
  info.model = model;
  info.min_track_probability = 0.5;
  const std::vector<PathSegment> segments = extractSegments(
      path, SegmentConfig{}, [&](const Eigen::Vector3d& p) { return voxels.visibleSlots(p, vis); }, nullptr,
      [&](int slot) { return voxels.landmarksIn(slot); });
  const std::vector<WeightedPoint> from_start = aggregateByVoxel(voxels, voxels.visibleFrom(path.front(), vis));
  auto failure = [&](const std::vector<WeightedPoint>& points, const Eigen::Vector3d& p, double yaw) {
    ViewSupport support;
    poseInformation(p, yaw, points, vis, info, &support);
    return failureCost(model->probability(support));
  };
  const double vehicle_yaw = M_PI / 2;
  const double step = 2.0 * M_PI / PoseGraphConfig{}.yaw_samples;
  // The chosen path's -ln p: its nodes (each with its segment's points, as the search scores
  // them) and the views its start turn sweeps after the vehicle's own (with all visible).
  auto path_failure = [&](const PoseGraphResult& r) {
    double sum = 0.0;
    for (std::size_t j = 0; j < r.path.size(); ++j) {
      const auto& seg = segments[static_cast<std::size_t>(r.layer_segment[j])];
      sum += failure(aggregateSlots(voxels, seg.covisible), r.path[j].p_WB, r.path[j].yaw_rad);
    }
    const double turn = wrap(r.path.front().yaw_rad - vehicle_yaw);
    const int steps = static_cast<int>(std::lround(std::abs(turn) / step));
    for (int k = 1; k <= steps; ++k)
      sum += failure(from_start, path.front(), vehicle_yaw + std::copysign(k * step, turn));
    return sum;
  };
  ASSERT_GT(failure(from_start, path.front(), 0.0), 5.0);  // along the path: neither panel in view
  ASSERT_LT(failure(from_start, path.front(), vehicle_yaw), 0.1);

  PoseGraphConfig config;
  config.guard_start_turn = false;
  config.between_checks = 0;  // the search alone: its optimum, whose -ln p cannot grow with the weight
  double last = std::numeric_limits<double>::infinity();
  std::vector<double> first_yaw;
  for (double weight : {0.0, 0.01, 0.1, 1.0, 10.0}) {
    config.failure_weight = weight;
    const PoseGraphResult r = searchPoseGraph(path, segments, voxels, vis, info, config, std::nan(""), 1, vehicle_yaw);
    ASSERT_TRUE(r.found);
    const double f = path_failure(r);
    EXPECT_LE(f, last + 1e-9) << "weight " << weight;
    last = f;
    first_yaw.push_back(r.path.front().yaw_rad);
    std::cout << "[ figure   ] failure_weight " << weight << ": first yaw " << r.path.front().yaw_rad
              << " rad, path -ln p " << f << ", c_p " << r.c_p << "\n";
  }
  EXPECT_LT(std::sin(first_yaw.front()), 0.0) << "without the weight the denser panel B should win";
  EXPECT_GT(std::sin(first_yaw.back()), 0.0) << "with it the MAV should keep facing panel A";
}

// With min_image_coverage, a chosen node scores its co-visible information where the camera's
// view (the landmarks visible from the layer's path point) covers enough of the image, and blind
// where it does not.
TEST(PoseGraph, ImageCoverageGatesOnWhatTheCameraSees) {
  const Corridor& c = texturedCorridor(+1);
  const VisibilityConfig vis;
  InformationConfig info;
  info.min_image_coverage = 0.3;
  const std::vector<PathSegment> segments = extractSegments(
      c.path, SegmentConfig{}, [&](const Eigen::Vector3d& p) { return c.voxels.visibleSlots(p, vis); }, nullptr,
      [&](int slot) { return c.voxels.landmarksIn(slot); });
  const PoseGraphResult r = searchPoseGraph(c.path, segments, c.voxels, vis, info, PoseGraphConfig{}, 0.0, 5);
  ASSERT_TRUE(r.found);
  const double blind = 6.0 * std::log(info.epsilon);
  InformationConfig ungated = info;
  ungated.min_image_coverage = 0.0;
  int gated = 0;
  for (std::size_t j = 0; j < r.path.size(); ++j) {
    const std::vector<WeightedPoint> seen =
        aggregateByVoxel(c.voxels, c.voxels.visibleFrom(pointAt(c.path, r.layer_s[j]), vis));
    ViewSupport support;
    poseInformation(r.path[j].p_WB, r.path[j].yaw_rad, seen, vis, info, &support);
    const auto& seg = segments[static_cast<std::size_t>(r.layer_segment[j])];
    const double direct =
        poseScore(r.path[j].p_WB, r.path[j].yaw_rad, aggregateSlots(c.voxels, seg.covisible), vis, ungated);
    if (support.coverage() < info.min_image_coverage) {
      EXPECT_DOUBLE_EQ(r.scores[j], blind) << "layer " << j;
      ++gated;
    } else {
      EXPECT_NEAR(r.scores[j], direct, 1e-9 * std::max(1.0, std::abs(direct))) << "layer " << j;
    }
  }
  // The first pose is held at yaw 0 along the corridor: its textured wall fills the left of the image only.
  std::cout << "[ figure   ] corridor, min_image_coverage 0.3: " << gated << " of " << r.path.size()
            << " chosen poses gated blind\n";
}

// Where every pose is gated blind (here: the corridor's landmarks promise far fewer detections
// than asked), every pose scores 6 ln eps, yet the search still prefers the views that miss the
// gate by least: the yaw turns to the textured wall as it does with the gate off.
TEST(PoseGraph, WhereEveryPoseIsGatedTheYawStillFacesTheTexture) {
  for (int side : {+1, -1}) {
    const Corridor& c = texturedCorridor(side);
    const VisibilityConfig vis;
    InformationConfig info = syntheticInformation();
    info.min_detections = 5000.0;  // more than the corridor's 2000 landmarks
    const std::vector<PathSegment> segments = extractSegments(
        c.path, SegmentConfig{}, [&](const Eigen::Vector3d& p) { return c.voxels.visibleSlots(p, vis); }, nullptr,
        [&](int slot) { return c.voxels.landmarksIn(slot); });
    const PoseGraphConfig config;
    const PoseGraphResult r = searchPoseGraph(c.path, segments, c.voxels, vis, info, config, std::nan(""), 3);
    expectFeasible(c, r, config);
    const double blind = 6.0 * std::log(info.epsilon);
    for (std::size_t j = 0; j < r.path.size(); ++j) EXPECT_DOUBLE_EQ(r.scores[j], blind) << "layer " << j;
    EXPECT_EQ(r.between_checked, 0);  // a move between blind poses has nothing to lose
    int towards = 0;
    for (const Pose4& p : r.path) towards += side * std::sin(p.yaw_rad) > 0.2;
    EXPECT_GE(towards, static_cast<int>(0.9 * static_cast<double>(r.path.size()))) << "side " << side;
    std::cout << "[ figure   ] every pose gated, textured wall on side " << side << ": " << towards << "/"
              << r.path.size() << " poses facing it\n";
  }
}

// Two poses that pass the gates can have a blind stretch between them. A camera 1.5 m from a wall
// looks at it (yaw pi/2) from x = 0 and x = 0.4: a narrow textured strip S1 sits at the left edge
// of the first view, a denser one S2 at the right edge of the second, and the view halfway sees
// neither. Turning 15 degrees left instead keeps S1 in view all the way, with less information
// at the end than S2 would give. Without the checks the search takes S2 and flies blind between
// the poses; with them it keeps S1; where it has no choice, the move's lower end is marked blind.
TEST(PoseGraph, MovesThatGoBlindBetweenTheirPosesAreAvoidedOrMarked) {
  const VisibilityConfig vis;
  const double wall_y = 1.5;
  const double w = wall_y * std::tan(0.5 * vis.hfov_rad);  // half width of a view on the wall
  testing::SyntheticWorld world;
  world.min_W = {-3.0, -1.0, 0.0};
  world.max_W = {3.5, 2.0, 2.0};
  const Eigen::AlignedBox3d s1(Eigen::Vector3d(-w + 0.02, wall_y, 0.0), Eigen::Vector3d(-w + 0.12, wall_y + 0.2, 2.0));
  const Eigen::AlignedBox3d s2(Eigen::Vector3d(0.4 + w - 0.12, wall_y, 0.0),
                               Eigen::Vector3d(0.4 + w - 0.02, wall_y + 0.2, 2.0));
  world.solids = {s1, s2};
  world.texture(s1, Eigen::Vector3d(0, -1, 0), 0.05);
  world.texture(s2, Eigen::Vector3d(0, -1, 0), 0.025);
  for (Landmark& lm : world.landmarks) lm.ref_kf_p_W = lm.p_W + 0.5 * (lm.ref_kf_p_W - lm.p_W);
  const FeatureMap map = world.build();
  const VoxelMap voxels(map, world.min_W, world.max_W);
  const std::vector<Eigen::Vector3d> path{{0.0, 0.0, kZ}, {0.4, 0.0, kZ}};
  PathSegment all;
  all.s_end_m = 0.4;
  all.p_begin = path.front();
  all.p_end = path.back();
  for (std::size_t slot = 0; slot < voxels.landmarkVoxels().size(); ++slot) {
    all.covisible.push_back(static_cast<int>(slot));
  }
  InformationConfig info = syntheticInformation();
  info.min_image_coverage = 0.0;
  info.min_detections = 20.0;
  const std::vector<WeightedPoint> points = aggregateSlots(voxels, all.covisible);
  auto score = [&](double x, double yaw) { return poseScore({x, 0.0, kZ}, yaw, points, vis, info); };
  const double blind = 6.0 * std::log(info.epsilon);
  const double step = 2.0 * M_PI / PoseGraphConfig{}.yaw_samples;
  ASSERT_GT(score(0.0, M_PI / 2), blind);         // S1
  ASSERT_GT(score(0.4, M_PI / 2), blind);         // S2
  ASSERT_DOUBLE_EQ(score(0.2, M_PI / 2), blind);  // neither
  ASSERT_GT(score(0.4, M_PI / 2 + step), blind);  // S1, turned left
  ASSERT_GT(score(0.2, M_PI / 2 + 0.5 * step), blind);
  ASSERT_GT(score(0.4, M_PI / 2), score(0.4, M_PI / 2 + step));  // S2 is worth more

  PoseGraphConfig config;
  config.position_samples = 1;
  config.between_checks = 0;  // the paper's search
  const PoseGraphResult paper = searchPoseGraph(path, {all}, voxels, vis, info, config, M_PI / 2, 1);
  ASSERT_TRUE(paper.found);
  ASSERT_EQ(paper.path.size(), 2u);
  EXPECT_NEAR(paper.path[1].yaw_rad, M_PI / 2, 1e-9);
  EXPECT_EQ(paper.between_blind, 0);

  config.between_checks = 3;
  const PoseGraphResult checked = searchPoseGraph(path, {all}, voxels, vis, info, config, M_PI / 2, 1);
  ASSERT_TRUE(checked.found);
  EXPECT_NEAR(checked.path[1].yaw_rad, M_PI / 2 + step, 1e-9);
  EXPECT_EQ(checked.between_blind, 0);
  EXPECT_GE(checked.between_rounds, 2);
  EXPECT_NEAR(checked.scores[1], score(0.4, M_PI / 2 + step), 1e-9);
  EXPECT_NEAR(checked.cost, config.distance_weight * checked.c_d - config.perception_weight * checked.c_p, 1e-9);

  // No choice (the yaw cannot turn): the blind move stays, and its lower end scores blind.
  config.yaw_samples = 1;
  const PoseGraphResult forced = searchPoseGraph(path, {all}, voxels, vis, info, config, M_PI / 2, 1);
  ASSERT_TRUE(forced.found);
  EXPECT_EQ(forced.between_blind, 1);
  const double first = score(0.0, M_PI / 2);
  const double last = score(0.4, M_PI / 2);
  EXPECT_DOUBLE_EQ(forced.scores[first <= last ? 0 : 1], blind);
  EXPECT_NEAR(forced.scores[first <= last ? 1 : 0], std::max(first, last), 1e-9);
  EXPECT_NEAR(forced.c_p, 0.5 * (blind + std::max(first, last)), 1e-9);
  std::cout << "[ figure   ] blind between two poses: paper's search ends at yaw " << paper.path[1].yaw_rad << " (c_p "
            << paper.c_p << "), checked " << checked.path[1].yaw_rad << " (c_p " << checked.c_p << ", "
            << checked.between_rounds << " rounds, " << checked.between_checked << " moves checked); forced c_p "
            << forced.c_p << "\n";
}

// A layer is one time step Ts (layers are at most v_nom Ts apart), so whenever validate() passes
// (2 pi / yaw_samples <= yaw_rate_limit * Ts) the yaw can turn by at least one interval between
// layers, on any path length. Regression: the allowed turn used to scale with the layer spacing
// (length / ceil(length / (v_nom Ts))), which froze the yaw on paths whose spacing fell short.
// Measured by the edge count against a graph whose yaw is frozen (rate limit ~0).
TEST(PoseGraph, YawCanTurnOnEveryPathWhenTheConfigValidates) {
  const Corridor& c = texturedCorridor(+1);
  const VisibilityConfig vis;
  const PoseGraphConfig defaults;
  ASSERT_NO_THROW(defaults.validate());
  PoseGraphConfig frozen = defaults;
  frozen.yaw_rate_limit_rad_s = 1e-6;
  for (double length : {2.9, 2.41, 1.25, 0.81}) {
    const std::vector<Eigen::Vector3d> path{{0.5, 1.5, kZ}, {0.5 + length, 1.5, kZ}};
    const std::vector<PathSegment> segments = extractSegments(
        path, SegmentConfig{}, [&](const Eigen::Vector3d& p) { return c.voxels.visibleSlots(p, vis); }, nullptr,
        [&](int slot) { return c.voxels.landmarksIn(slot); });
    const PoseGraphResult a =
        searchPoseGraph(path, segments, c.voxels, vis, InformationConfig{}, defaults, std::nan(""), 9);
    const PoseGraphResult b =
        searchPoseGraph(path, segments, c.voxels, vis, InformationConfig{}, frozen, std::nan(""), 9);
    ASSERT_TRUE(a.found);
    ASSERT_EQ(a.nodes, b.nodes);
    const double spacing = a.layer_s[1] - a.layer_s[0];
    std::cout << "[ figure   ] path " << length << " m: layer spacing " << spacing << " m, allowed turn per layer "
              << defaults.yaw_rate_limit_rad_s * defaults.time_step_s << " rad vs yaw step "
              << 2.0 * M_PI / defaults.yaw_samples << " rad; edges " << a.edges << " (frozen yaw: " << b.edges << ")\n";
    EXPECT_GT(a.edges, b.edges) << "path of " << length << " m: the yaw cannot change between any two layers";
  }
  // yaw_samples = 21 (2 pi / 21 = 0.2992 <= 0.3) validates: the 7 m corridor's yaw can turn too.
  PoseGraphConfig fine = defaults;
  fine.yaw_samples = 21;
  ASSERT_NO_THROW(fine.validate());
  PoseGraphConfig fine_frozen = fine;
  fine_frozen.yaw_rate_limit_rad_s = 1e-6;
  const std::vector<PathSegment> segments = extractSegments(
      c.path, SegmentConfig{}, [&](const Eigen::Vector3d& p) { return c.voxels.visibleSlots(p, vis); }, nullptr,
      [&](int slot) { return c.voxels.landmarksIn(slot); });
  const PoseGraphResult a =
      searchPoseGraph(c.path, segments, c.voxels, vis, InformationConfig{}, fine, std::nan(""), 9);
  const PoseGraphResult b =
      searchPoseGraph(c.path, segments, c.voxels, vis, InformationConfig{}, fine_frozen, std::nan(""), 9);
  ASSERT_TRUE(a.found);
  std::cout << "[ figure   ] 7 m corridor, 21 yaw samples: edges " << a.edges << " (frozen yaw: " << b.edges << ")\n";
  EXPECT_GT(a.edges, b.edges) << "7 m path, 21 yaw samples: the yaw cannot change between any two layers";
}

// A textured wall at the west end (x = 0.3, facing east), the rest bare. The world is observed up
// to x = 6; the voxel map reaches x = 10, and the space beyond 6 is unknown (free for the search,
// as an online plan sees it). The path runs east from x = 1 to x = 8, into the unknown, from a
// start that faces the wall.
TEST(PoseGraph, WhereTheWayAheadIsUnknownItScoresTheViewTheLookAheadFlies) {
  testing::SyntheticWorld w;
  w.min_W = {0.0, 0.0, 0.0};
  w.max_W = {6.0, 3.0, 2.5};
  const Eigen::AlignedBox3d wall(Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(0.3, 3.0, 2.5));
  w.solids = {wall};
  w.texture(wall, Eigen::Vector3d(1, 0, 0), 0.1);
  const FeatureMap map = w.build();
  const VoxelMap voxels(map, w.min_W, Eigen::Vector3d(10.0, 3.0, 2.5), -1e9, 1e9, /*unknown_free=*/true);
  EXPECT_TRUE(voxels.observed({5.9, 1.5, kZ}));
  EXPECT_FALSE(voxels.observed({6.1, 1.5, kZ}));
  EXPECT_EQ(voxels.state({6.1, 1.5, kZ}), VoxelState::kFree);  // unknown, free for collision
  const std::vector<Eigen::Vector3d> path{{1.0, 1.5, kZ}, {8.0, 1.5, kZ}};
  const VisibilityConfig vis;
  const std::vector<PathSegment> segments = extractSegments(
      path, SegmentConfig{}, [&](const Eigen::Vector3d& p) { return voxels.visibleSlots(p, vis); }, nullptr,
      [&](int slot) { return voxels.landmarksIn(slot); });
  PoseGraphConfig config;
  const PoseGraphResult own = searchPoseGraph(path, segments, voxels, vis, syntheticInformation(), config, M_PI, 1);
  config.look_unknown_m = 0.8;
  const PoseGraphResult look = searchPoseGraph(path, segments, voxels, vis, syntheticInformation(), config, M_PI, 1);
  ASSERT_TRUE(own.found);
  ASSERT_TRUE(look.found);
  ASSERT_EQ(own.scores.size(), look.scores.size());
  const double blind = logDetInformation(Matrix6d::Zero(), syntheticInformation().epsilon);
  int looking = 0;
  for (std::size_t j = 1; j + 1 < look.scores.size(); ++j) {
    const double x = pointAt(path, look.layer_s[j]).x();
    // At their own yaws the poses face the wall behind them, all the way.
    EXPECT_GT(own.scores[j], blind + 1.0) << "layer " << j << " at x " << x;
    if (x + 0.8 + 0.1 < 6.0) {
      // The way ahead is observed: nothing turns, and the graph faces the wall as before.
      EXPECT_GT(look.scores[j], blind + 1.0) << "layer " << j << " at x " << x;
    } else if (x + 0.4 > 6.0 + 0.1) {
      // The look-ahead turns the camera within 27.6 deg of east, away from the only texture.
      EXPECT_LE(look.scores[j], blind + 1e-9) << "layer " << j << " at x " << x;
      ++looking;
    }
  }
  EXPECT_GE(looking, 4);
  // The yaws stay on the lattice and within the rate limit; the look-ahead turns them when flown.
  for (std::size_t j = 1; j < look.path.size(); ++j) {
    EXPECT_LE(std::abs(wrap(look.path[j].yaw_rad - look.path[j - 1].yaw_rad)),
              config.yaw_rate_limit_rad_s * config.time_step_s + 1e-9);
  }
  EXPECT_NEAR(lookAheadHalfFov(vis), 0.5 * vis.hfov_rad - 10.0 * M_PI / 180.0, 1e-12);
  std::cout << "[ figure   ] into unknown space: c_p " << own.c_p << " at the graph's own yaws, " << look.c_p
            << " at the look-ahead's (" << looking << " layers look ahead)\n";
}

void expectRejected(const PoseGraphConfig& config, const std::string& field) {
  try {
    config.validate();
    ADD_FAILURE() << "accepted, expected a complaint about " << field;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

TEST(PoseGraph, ConfigValidationNamesTheField) {
  EXPECT_NO_THROW(PoseGraphConfig{}.validate());
  PoseGraphConfig c;
  c.yaw_samples = 4;  // 2 pi / 4 = 1.57 rad > 0.3 rad/s * 1 s
  expectRejected(c, "yaw_samples");
  c = PoseGraphConfig{};
  c.yaw_samples = 20;  // 0.314 > 0.3
  expectRejected(c, "yaw_samples");
  c.yaw_samples = 21;  // 0.299 <= 0.3
  EXPECT_NO_THROW(c.validate());
  c = PoseGraphConfig{};
  c.distance_weight = -0.1;
  expectRejected(c, "distance_weight");
  c = PoseGraphConfig{};
  c.perception_weight = -1.0;
  expectRejected(c, "perception_weight");
  c = PoseGraphConfig{};
  c.position_samples = 0;
  expectRejected(c, "position_samples");
  c = PoseGraphConfig{};
  c.between_checks = -1;
  expectRejected(c, "between_checks");
  c.between_checks = 21;
  expectRejected(c, "between_checks");
  c = PoseGraphConfig{};
  c.max_between_rounds = 0;
  expectRejected(c, "max_between_rounds");
  c = PoseGraphConfig{};
  c.turn_substeps = 0;
  expectRejected(c, "turn_substeps");
  c.turn_substeps = 17;
  expectRejected(c, "turn_substeps");
  c.turn_substeps = 16;
  EXPECT_NO_THROW(c.validate());
  c = PoseGraphConfig{};
  c.look_unknown_m = -0.1;
  expectRejected(c, "look_unknown_m");
}

}  // namespace
}  // namespace tgnav::planner
