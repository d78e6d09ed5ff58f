// Trajectory generation: the uniform cubic B-spline (partition of unity, C2 continuity at the
// knots, derivatives against finite differences, re-timing), and generateTrajectory on random
// grid maps (every trajectory optimised, within speed, acceleration and yaw-rate limits at 1 kHz,
// clear of obstacles by the margin, in the homology class of the planned path, rest to rest),
// yaw across +-pi and half turns, degenerate paths, paths grazing or crossing obstacles, the
// stop-and-go fallback, bad input and determinism.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "planner/bspline.h"
#include "planner/topological_planner.h"
#include "planner/trajectory_generator.h"

namespace tgnav::planner {
namespace {

constexpr double kRes = 0.1;
constexpr double kFlightZ = 1.0;

OccupancyGrid2D room(double w_m, double h_m) {
  return OccupancyGrid2D(static_cast<int>(std::lround(w_m / kRes)), static_cast<int>(std::lround(h_m / kRes)), kRes,
                         Eigen::Vector2d::Zero());
}

// Marks the cells whose centres lie strictly inside the rectangle.
void block(OccupancyGrid2D& g, double x0, double y0, double x1, double y1) {
  for (int y = 0; y < g.height; ++y) {
    for (int x = 0; x < g.width; ++x) {
      const Eigen::Vector2d c = g.centreOf(x, y);
      if (c.x() > x0 && c.x() < x1 && c.y() > y0 && c.y() < y1) g.set(x, y, true);
    }
  }
}

Pose4 pose(double x, double y, double yaw) { return Pose4{Eigen::Vector3d(x, y, kFlightZ), yaw}; }

// A 2D path lifted to the flight height, each point looking along the segment that leaves it
// (the last one keeps the previous heading).
std::vector<Pose4> lift(const std::vector<Eigen::Vector2d>& path) {
  std::vector<Pose4> out;
  double yaw = 0.0;
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (i + 1 < path.size()) {
      const Eigen::Vector2d d = path[i + 1] - path[i];
      yaw = std::atan2(d.y(), d.x());
    }
    out.push_back(pose(path[i].x(), path[i].y(), yaw));
  }
  return out;
}

// Trajectory::at at exactly 1 kHz (t = i ms), and at the end.
std::vector<TrajectorySample> sampleAt1kHz(const Trajectory& trajectory) {
  const double T = trajectory.duration();
  const int n = static_cast<int>(std::floor(T * 1000.0));
  std::vector<TrajectorySample> out;
  out.reserve(static_cast<std::size_t>(n) + 2);
  for (int i = 0; i <= n; ++i) out.push_back(trajectory.at(i * 1e-3));
  if (T > n * 1e-3) out.push_back(trajectory.at(T));
  return out;
}

// What a 1 kHz controller sees of a trajectory.
struct Flight {
  std::vector<TrajectorySample> samples;
  std::vector<Eigen::Vector2d> xy;
  double max_speed = 0.0;
  double max_accel = 0.0;
  double max_yaw_rate = 0.0;
  double min_clearance = std::numeric_limits<double>::infinity();
};

Flight fly(const Trajectory& trajectory, const ClearanceField& field) {
  Flight f;
  f.samples = sampleAt1kHz(trajectory);
  for (const TrajectorySample& s : f.samples) {
    f.xy.push_back(s.p_W.head<2>());
    f.max_speed = std::max(f.max_speed, s.v_W.norm());
    f.max_accel = std::max(f.max_accel, s.a_W.norm());
    f.max_yaw_rate = std::max(f.max_yaw_rate, std::abs(s.yaw_rate_rad_s));
    f.min_clearance = std::min(f.min_clearance, field.clearance(s.p_W, nullptr));
  }
  return f;
}

void expectWithinLimits(const Flight& f, const TrajectoryConfig& config, const std::string& what) {
  EXPECT_LE(f.max_speed, config.max_speed_mps * (1.0 + 1e-9)) << what;
  EXPECT_LE(f.max_accel, config.max_accel_mps2 * (1.0 + 1e-9)) << what;
  EXPECT_LE(f.max_yaw_rate, config.max_yaw_rate_rad_s * (1.0 + 1e-9)) << what;
}

void expectRestToRest(const Trajectory& trajectory, const Pose4& first, const Pose4& last, const std::string& what) {
  const TrajectorySample s0 = trajectory.at(0.0);
  const TrajectorySample s1 = trajectory.at(trajectory.duration());
  EXPECT_LT((s0.p_W - first.p_WB).norm(), 1e-6) << what;
  EXPECT_LT((s1.p_W - last.p_WB).norm(), 1e-6) << what;
  EXPECT_LT(s0.v_W.norm(), 1e-9) << what;
  EXPECT_LT(s1.v_W.norm(), 1e-9) << what;
  EXPECT_LT(s0.a_W.norm(), 1e-9) << what;
  EXPECT_LT(s1.a_W.norm(), 1e-9) << what;
  EXPECT_LT(std::abs(s0.yaw_rate_rad_s), 1e-9) << what;
  EXPECT_LT(std::abs(s1.yaw_rate_rad_s), 1e-9) << what;
}

double wrapped(double a) { return std::remainder(a, 2.0 * M_PI); }

// ---------------------------------------------------------------------------------------------
// Uniform cubic B-spline.

Eigen::MatrixXd randomControlPoints(std::mt19937& rng, int n, int dims) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd q(n, dims);
  for (int i = 0; i < n; ++i) {
    for (int d = 0; d < dims; ++d) q(i, d) = u(rng);
  }
  return q;
}

TEST(BSpline, BasisIsAPartitionOfUnityAndDerivativeBasesSumToZero) {
  for (int i = 0; i <= 100; ++i) {
    const double u = i / 100.0;
    const Eigen::Vector4d b = UniformBSpline::basis(u, 0);
    EXPECT_NEAR(b.sum(), 1.0, 1e-15) << "u = " << u;
    EXPECT_GE(b.minCoeff(), 0.0) << "u = " << u;
    for (int k = 1; k <= 3; ++k) {
      EXPECT_NEAR(UniformBSpline::basis(u, k).sum(), 0.0, 1e-14) << "u = " << u << " k = " << k;
    }
  }
  // The derivative bases are the derivatives of the basis (central differences in u).
  const double h = 1e-6;
  for (double u : {0.1, 0.37, 0.5, 0.82}) {
    for (int k = 1; k <= 3; ++k) {
      const Eigen::Vector4d fd =
          (UniformBSpline::basis(u + h, k - 1) - UniformBSpline::basis(u - h, k - 1)) / (2.0 * h);
      EXPECT_LT((fd - UniformBSpline::basis(u, k)).norm(), 1e-8) << "u = " << u << " k = " << k;
    }
  }
  EXPECT_THROW(UniformBSpline::basis(0.5, 4), std::invalid_argument);
}

TEST(BSpline, PositionVelocityAccelerationAreContinuousAtKnotsAndJerkIsConstantPerSpan) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 4 + trial;
    const double dt = 0.3 + 0.05 * trial;
    const UniformBSpline spline(randomControlPoints(rng, n, 3), dt);
    ASSERT_EQ(spline.spans(), n - 3);
    EXPECT_NEAR(spline.duration(), dt * (n - 3), 1e-12);
    for (int k = 1; k < spline.spans(); ++k) {
      const double t = k * dt;
      for (int d = 0; d <= 2; ++d) {
        const Eigen::VectorXd left = spline.evaluate(t - 1e-9, d);
        const Eigen::VectorXd right = spline.evaluate(t + 1e-9, d);
        EXPECT_LT((left - right).norm(), 1e-6) << "trial " << trial << " knot " << k << " derivative " << d;
      }
    }
    for (int i = 0; i < spline.spans(); ++i) {
      const Eigen::VectorXd jerk = spline.evaluate((i + 0.5) * dt, 3);
      const Eigen::VectorXd a0 = spline.evaluate((i + 0.1) * dt, 2);
      const Eigen::VectorXd a1 = spline.evaluate((i + 0.9) * dt, 2);
      for (double f : {0.01, 0.25, 0.75, 0.99}) {
        EXPECT_LT((spline.evaluate((i + f) * dt, 3) - jerk).norm(), 1e-9) << "trial " << trial << " span " << i;
      }
      // Acceleration is linear within the span, with that slope.
      EXPECT_LT(((a1 - a0) / (0.8 * dt) - jerk).norm(), 1e-6 * (1.0 + jerk.norm()))
          << "trial " << trial << " span " << i;
    }
    // A cubic: the jerk differs from span to span for random control points.
    if (spline.spans() >= 2) {
      EXPECT_GT((spline.evaluate(0.5 * dt, 3) - spline.evaluate(1.5 * dt, 3)).norm(), 1e-6) << "trial " << trial;
    }
  }
}

TEST(BSpline, DerivativesMatchCentralFiniteDifferences) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> frac(0.02, 0.98);  // away from the knots
  for (int trial = 0; trial < 10; ++trial) {
    const double dt = 0.4 + 0.1 * trial;
    const UniformBSpline spline(randomControlPoints(rng, 10, 2), dt);
    for (int i = 0; i < spline.spans(); ++i) {
      const double t = (i + frac(rng)) * dt;
      const double h = 1e-4;
      const Eigen::VectorXd p_minus = spline.evaluate(t - h, 0);
      const Eigen::VectorXd p = spline.evaluate(t, 0);
      const Eigen::VectorXd p_plus = spline.evaluate(t + h, 0);
      const Eigen::VectorXd v = spline.evaluate(t, 1);
      const Eigen::VectorXd a = spline.evaluate(t, 2);
      EXPECT_LT(((p_plus - p_minus) / (2.0 * h) - v).norm(), 1e-6 * (1.0 + v.norm()))
          << "trial " << trial << " t " << t;
      EXPECT_LT(((p_plus - 2.0 * p + p_minus) / (h * h) - a).norm(), 1e-5 * (1.0 + a.norm()))
          << "trial " << trial << " t " << t;
    }
  }
}

TEST(BSpline, StretchingTheKnotIntervalScalesTheDerivatives) {
  std::mt19937 rng(3);
  const double dt = 0.5;
  UniformBSpline spline(randomControlPoints(rng, 12, 3), dt);
  std::vector<double> times;
  for (int i = 0; i <= 40; ++i) times.push_back(spline.duration() * i / 40.0);
  std::vector<Eigen::VectorXd> p, v, a;
  for (double t : times) {
    p.push_back(spline.evaluate(t, 0));
    v.push_back(spline.evaluate(t, 1));
    a.push_back(spline.evaluate(t, 2));
  }
  for (double s : {0.5, 1.7, 3.0}) {
    UniformBSpline stretched = spline;
    stretched.setKnotInterval(s * dt);
    EXPECT_NEAR(stretched.knotInterval(), s * dt, 1e-15);
    EXPECT_NEAR(stretched.duration(), s * spline.duration(), 1e-12);
    for (std::size_t i = 0; i < times.size(); ++i) {
      const double t = s * times[i];
      EXPECT_LT((stretched.evaluate(t, 0) - p[i]).norm(), 1e-9) << "s " << s << " t " << t;
      EXPECT_LT((stretched.evaluate(t, 1) - v[i] / s).norm(), 1e-9) << "s " << s << " t " << t;
      EXPECT_LT((stretched.evaluate(t, 2) - a[i] / (s * s)).norm(), 1e-9) << "s " << s << " t " << t;
    }
  }
}

TEST(BSpline, ConstructorRejectsTooFewControlPointsAndBadKnotIntervals) {
  EXPECT_THROW(UniformBSpline(Eigen::MatrixXd::Zero(3, 2), 1.0), std::invalid_argument);
  EXPECT_THROW(UniformBSpline(Eigen::MatrixXd::Zero(0, 1), 1.0), std::invalid_argument);
  EXPECT_THROW(UniformBSpline(Eigen::MatrixXd::Zero(4, 2), 0.0), std::invalid_argument);
  EXPECT_THROW(UniformBSpline(Eigen::MatrixXd::Zero(4, 2), -0.1), std::invalid_argument);
  EXPECT_THROW(UniformBSpline(Eigen::MatrixXd::Zero(4, 2), std::numeric_limits<double>::quiet_NaN()),
               std::invalid_argument);
  EXPECT_NO_THROW(UniformBSpline(Eigen::MatrixXd::Zero(4, 2), 0.1));
  UniformBSpline ok(Eigen::MatrixXd::Zero(4, 1), 0.1);
  EXPECT_THROW(ok.setKnotInterval(0.0), std::invalid_argument);
  EXPECT_EQ(ok.knotInterval(), 0.1);
}

// ---------------------------------------------------------------------------------------------
// Random grid maps.

struct Rect {
  double x0, y0, x1, y1;
};

double gap(const Rect& a, const Rect& b) {
  const double dx = std::max({0.0, a.x0 - b.x1, b.x0 - a.x1});
  const double dy = std::max({0.0, a.y0 - b.y1, b.y0 - a.y1});
  return std::hypot(dx, dy);
}

// 30 x 20 m at 0.1 m: up to 25 rectangles of 0.5-3 m per side, >= 1.3 m apart and >= 1.2 m
// inside the edge; start and goal with clearance >= 0.6 m, >= 12 m apart.
struct RandomMap {
  OccupancyGrid2D grid;
  Eigen::Vector2d start, goal;
  double start_yaw = 0.0;
  int rectangles = 0;
};

RandomMap randomMap(int seed) {
  constexpr double kW = 30.0, kH = 20.0, kEdge = 1.2, kGap = 1.3;
  std::mt19937 rng(static_cast<std::uint32_t>(seed));
  std::uniform_real_distribution<double> side(0.5, 3.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Rect> rects;
  for (int attempt = 0; attempt < 1000 && rects.size() < 25; ++attempt) {
    const double w = side(rng), h = side(rng);
    const double x0 = kEdge + unit(rng) * (kW - 2.0 * kEdge - w);
    const double y0 = kEdge + unit(rng) * (kH - 2.0 * kEdge - h);
    const Rect r{x0, y0, x0 + w, y0 + h};
    bool ok = true;
    for (const Rect& o : rects) ok = ok && gap(r, o) >= kGap;
    if (ok) rects.push_back(r);
  }
  RandomMap m;
  m.grid = room(kW, kH);
  for (const Rect& r : rects) block(m.grid, r.x0, r.y0, r.x1, r.y1);
  m.rectangles = static_cast<int>(rects.size());
  const DistanceField field(m.grid);
  std::uniform_real_distribution<double> x(0.0, kW), y(0.0, kH);
  auto freePoint = [&] {
    for (;;) {
      const Eigen::Vector2d p(x(rng), y(rng));
      if (field.clearance(p) >= 0.6) return p;
    }
  };
  m.start = freePoint();
  do {
    m.goal = freePoint();
  } while ((m.goal - m.start).norm() < 12.0);
  m.start_yaw = std::uniform_real_distribution<double>(-M_PI, M_PI)(rng);
  return m;
}

TrajectoryConfig fastConfig() {
  TrajectoryConfig c;
  c.nominal_speed_mps = 1.5;
  c.max_speed_mps = 1.95;
  c.nominal_accel_mps2 = 1.0;
  c.max_accel_mps2 = 1.5;
  return c;
}

// A solved map with its planner (which owns the distance field the clearance refers to).
struct PlannedMap {
  RandomMap map;
  std::unique_ptr<TopologicalPlanner> planner;
  TopoPlan plan;
  std::vector<Eigen::Vector2d> path2d;
  TrajectoryRequest request;
};

std::unique_ptr<PlannedMap> planMap(int seed) {
  auto pm = std::make_unique<PlannedMap>();
  pm->map = randomMap(seed);
  pm->planner = std::make_unique<TopologicalPlanner>(pm->map.grid, TopoPlannerConfig{});
  pm->plan = pm->planner->solve(pm->map.start, pm->map.goal);
  if (pm->plan.status != PlanStatus::kSolved) return pm;
  pm->path2d = pm->plan.classes[pm->plan.chosen].path;
  pm->request.path = lift(pm->path2d);
  pm->request.start_yaw_rad = pm->map.start_yaw;
  pm->request.obstacle_points = &pm->plan.obstacle_points;
  return pm;
}

TEST(TrajectoryGrid, RandomMapsGiveFeasibleClearTrajectoriesInThePathsHomologyClass) {
  struct Tally {
    int n = 0;
    double ratio_sum = 0.0, ratio_max = 0.0, min_clearance = 1e9, max_speed = 0.0;
  };
  const TrajectoryConfig configs[2] = {TrajectoryConfig{}, fastConfig()};
  const char* names[2] = {"default", "fast"};
  Tally tally[2];
  for (int seed = 0; seed < 50; ++seed) {
    const auto pm = planMap(seed);
    ASSERT_EQ(pm->plan.status, PlanStatus::kSolved) << "seed " << seed;
    ASSERT_GE(pm->path2d.size(), 2u) << "seed " << seed;
    const PlanarClearance field(pm->planner->field());
    const std::vector<double> path_winding = windingAngles(pm->path2d, pm->plan.obstacle_points);
    for (int c = 0; c < 2; ++c) {
      const TrajectoryConfig& config = configs[c];
      const std::string what = std::string("seed ") + std::to_string(seed) + " " + names[c];
      const TrajectoryReport report = generateTrajectory(pm->request, field, config);
      ASSERT_EQ(report.status, TrajectoryStatus::kOptimised) << what << ": " << report.reason;
      ASSERT_TRUE(report.trajectory) << what;
      EXPECT_TRUE(report.reason.empty()) << what;
      const Flight f = fly(*report.trajectory, field);
      expectWithinLimits(f, config, what);
      EXPECT_GE(f.min_clearance, config.margin_m()) << what;
      EXPECT_TRUE(TopologicalPlanner::sameClass(windingAngles(f.xy, pm->plan.obstacle_points), path_winding)) << what;
      expectRestToRest(*report.trajectory, pm->request.path.front(), pm->request.path.back(), what);
      EXPECT_NEAR(wrapped(report.trajectory->at(0.0).yaw_rad - pm->map.start_yaw), 0.0, 1e-9) << what;
      EXPECT_NEAR(
          wrapped(report.trajectory->at(report.trajectory->duration()).yaw_rad - pm->request.path.back().yaw_rad), 0.0,
          1e-9)
          << what;
      EXPECT_TRUE(report.homology_checked && report.same_homology) << what;
      EXPECT_TRUE(report.margin_met) << what;
      Tally& t = tally[c];
      ++t.n;
      t.ratio_sum += report.time_scale;
      t.ratio_max = std::max(t.ratio_max, report.time_scale);
      t.min_clearance = std::min(t.min_clearance, f.min_clearance);
      t.max_speed = std::max(t.max_speed, f.max_speed);
    }
  }
  for (int c = 0; c < 2; ++c) {
    const Tally& t = tally[c];
    std::printf(
        "[ figure   ] trajectory %s (v_max %.2f): %d maps, duration / allocated mean %.3f max %.3f, "
        "min clearance %.3f m (margin %.2f), max speed %.3f m/s\n",
        names[c], configs[c].max_speed_mps, t.n, t.ratio_sum / std::max(1, t.n), t.ratio_max, t.min_clearance,
        configs[c].margin_m(), t.max_speed);
    RecordProperty(std::string(names[c]) + "_mean_duration_ratio", std::to_string(t.ratio_sum / std::max(1, t.n)));
  }
}

TEST(TrajectoryGrid, OptimisedSplineIsContinuousAtEveryKnot) {
  const auto pm = planMap(0);
  ASSERT_EQ(pm->plan.status, PlanStatus::kSolved);
  const PlanarClearance field(pm->planner->field());
  for (const TrajectoryConfig& config : {TrajectoryConfig{}, fastConfig()}) {
    const TrajectoryReport report = generateTrajectory(pm->request, field, config);
    ASSERT_EQ(report.status, TrajectoryStatus::kOptimised) << report.reason;
    const auto* spline = dynamic_cast<const BSplineTrajectory*>(report.trajectory.get());
    ASSERT_NE(spline, nullptr);
    const double dt = spline->position().knotInterval();
    ASSERT_GE(spline->position().spans(), 6);
    EXPECT_NEAR(spline->duration(), dt * spline->position().spans(), 1e-9);
    for (int k = 1; k < spline->position().spans(); ++k) {
      const TrajectorySample l = spline->at(k * dt - 1e-9);
      const TrajectorySample r = spline->at(k * dt + 1e-9);
      EXPECT_LT((l.p_W - r.p_W).norm(), 1e-8) << "knot " << k;
      EXPECT_LT((l.v_W - r.v_W).norm(), 1e-7) << "knot " << k;
      EXPECT_LT((l.a_W - r.a_W).norm(), 1e-6) << "knot " << k;
      EXPECT_LT(std::abs(l.yaw_rad - r.yaw_rad), 1e-8) << "knot " << k;
      EXPECT_LT(std::abs(l.yaw_rate_rad_s - r.yaw_rate_rad_s), 1e-7) << "knot " << k;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Yaw.

// An empty 10 x 6 m room (the map's edge is the only obstacle).
struct EmptyRoom {
  OccupancyGrid2D grid = room(10.0, 6.0);
  DistanceField distance{grid};
  PlanarClearance field{distance};
};

TEST(TrajectoryYaw, CrossingPlusMinusPiTurnsTheShortWay) {
  const EmptyRoom world;
  TrajectoryRequest request;
  request.path = {pose(2.0, 3.0, 2.9), pose(4.0, 3.0, 3.05), pose(6.0, 3.0, -3.1), pose(8.0, 3.0, -2.95)};
  const TrajectoryConfig config;
  const TrajectoryReport report = generateTrajectory(request, world.field, config);
  ASSERT_EQ(report.status, TrajectoryStatus::kOptimised) << report.reason;
  const Flight f = fly(*report.trajectory, world.field);
  const double total = f.samples.back().yaw_rad - f.samples.front().yaw_rad;
  EXPECT_NEAR(total, 2.0 * M_PI - 5.85, 1e-9);  // +0.433, not -5.85
  double min_step = 1e9;
  for (std::size_t i = 1; i < f.samples.size(); ++i) {
    min_step = std::min(min_step, f.samples[i].yaw_rad - f.samples[i - 1].yaw_rad);
  }
  EXPECT_GE(min_step, -1e-12) << "yaw goes back somewhere";
  EXPECT_LT(f.max_yaw_rate, 0.25 * config.max_yaw_rate_rad_s);
  expectWithinLimits(f, config, "yaw across pi");
  // Written out wrapped to [-pi, pi): both sides of the cut appear.
  const std::vector<TrajectorySample> out = sampleTrajectory(*report.trajectory, config.sample_rate_hz);
  bool positive = false, negative = false;
  for (const TrajectorySample& s : out) {
    EXPECT_GE(s.yaw_rad, -M_PI);
    EXPECT_LT(s.yaw_rad, M_PI);
    positive = positive || s.yaw_rad > 3.0;
    negative = negative || s.yaw_rad < -3.0;
  }
  EXPECT_TRUE(positive && negative);
  EXPECT_NEAR(out.front().yaw_rad, 2.9, 1e-9);
  EXPECT_NEAR(out.back().yaw_rad, -2.95, 1e-9);
  EXPECT_NEAR(out.back().t_s, report.trajectory->duration(), 1e-12);
}

TEST(TrajectoryYaw, HalfTurnsTurnByPiNotThreePi) {
  const EmptyRoom world;
  const TrajectoryConfig config;
  std::vector<std::vector<Pose4>> paths;
  // A half turn on the spot in the middle of the path.
  paths.push_back({pose(2.0, 3.0, 0.0), pose(5.0, 3.0, 0.0), pose(5.0, 3.0, M_PI), pose(8.0, 3.0, M_PI)});
  // A half turn between distant points.
  paths.push_back({pose(2.0, 3.0, 0.0), pose(5.0, 3.0, 0.0), pose(8.0, 3.0, M_PI)});
  // The same backwards.
  paths.push_back({pose(8.0, 3.0, M_PI), pose(5.0, 3.0, M_PI), pose(5.0, 3.0, 0.0), pose(2.0, 3.0, 0.0)});
  for (std::size_t k = 0; k < paths.size(); ++k) {
    TrajectoryRequest request;
    request.path = paths[k];
    const TrajectoryReport report = generateTrajectory(request, world.field, config);
    ASSERT_EQ(report.status, TrajectoryStatus::kOptimised) << "path " << k << ": " << report.reason;
    const Flight f = fly(*report.trajectory, world.field);
    expectWithinLimits(f, config, "path " + std::to_string(k));
    const double total = f.samples.back().yaw_rad - f.samples.front().yaw_rad;
    EXPECT_NEAR(std::abs(total), M_PI, 1e-9) << "path " << k;
    double lo = 1e9, hi = -1e9;
    for (const TrajectorySample& s : f.samples) {
      lo = std::min(lo, s.yaw_rad - f.samples.front().yaw_rad);
      hi = std::max(hi, s.yaw_rad - f.samples.front().yaw_rad);
    }
    EXPECT_LT(hi - lo, M_PI + 0.05) << "path " << k << ": the yaw swings beyond the half turn";
    expectRestToRest(*report.trajectory, request.path.front(), request.path.back(), "path " + std::to_string(k));
  }
}

// ---------------------------------------------------------------------------------------------
// Degenerate paths, obstacles, fallback, bad input.

bool identical(const std::vector<TrajectorySample>& a, const std::vector<TrajectorySample>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].t_s != b[i].t_s || a[i].p_W != b[i].p_W || a[i].v_W != b[i].v_W || a[i].a_W != b[i].a_W ||
        a[i].yaw_rad != b[i].yaw_rad || a[i].yaw_rate_rad_s != b[i].yaw_rate_rad_s) {
      return false;
    }
  }
  return true;
}

TEST(TrajectoryEdge, RepeatedPointsChangeNothing) {
  const EmptyRoom world;
  const TrajectoryConfig config;
  TrajectoryRequest plain;
  plain.path = {pose(1.5, 1.5, 0.3), pose(4.0, 2.0, 0.5), pose(6.0, 4.5, 1.2), pose(8.5, 4.0, -0.2)};
  TrajectoryRequest repeated;
  repeated.path = {plain.path[0], plain.path[0], plain.path[1], plain.path[1],
                   plain.path[1], plain.path[2], plain.path[3], plain.path[3]};
  const TrajectoryReport a = generateTrajectory(plain, world.field, config);
  const TrajectoryReport b = generateTrajectory(repeated, world.field, config);
  ASSERT_EQ(a.status, TrajectoryStatus::kOptimised) << a.reason;
  ASSERT_EQ(b.status, TrajectoryStatus::kOptimised) << b.reason;
  EXPECT_EQ(a.trajectory->duration(), b.trajectory->duration());
  EXPECT_GT(a.trajectory->duration(), 0.0);
  EXPECT_TRUE(identical(sampleAt1kHz(*a.trajectory), sampleAt1kHz(*b.trajectory)));
}

TEST(TrajectoryEdge, TwoPointAndOnePointPaths) {
  const EmptyRoom world;
  const TrajectoryConfig config;
  {  // Two points: optimised, rest to rest, exact ends.
    TrajectoryRequest request;
    request.path = {pose(2.0, 2.0, 0.0), pose(7.0, 4.0, 0.4)};
    const TrajectoryReport report = generateTrajectory(request, world.field, config);
    ASSERT_EQ(report.status, TrajectoryStatus::kOptimised) << report.reason;
    expectRestToRest(*report.trajectory, request.path.front(), request.path.back(), "two points");
    EXPECT_NEAR(report.trajectory->at(report.trajectory->duration()).yaw_rad, 0.4, 1e-12);
    expectWithinLimits(fly(*report.trajectory, world.field), config, "two points");
  }
  {  // One point, the vehicle looking elsewhere: a turn on the spot.
    TrajectoryRequest request;
    request.path = {pose(5.0, 3.0, 1.0)};
    request.start_yaw_rad = -0.5;
    const TrajectoryReport report = generateTrajectory(request, world.field, config);
    ASSERT_EQ(report.status, TrajectoryStatus::kOptimised) << report.reason;
    ASSERT_TRUE(report.trajectory);
    EXPECT_GT(report.trajectory->duration(), 1.5 / config.max_yaw_rate_rad_s);
    const Flight f = fly(*report.trajectory, world.field);
    double moved = 0.0;
    for (const TrajectorySample& s : f.samples) moved = std::max(moved, (s.p_W - request.path[0].p_WB).norm());
    EXPECT_LT(moved, 1e-9);
    EXPECT_NEAR(f.samples.front().yaw_rad, -0.5, 1e-12);
    EXPECT_NEAR(wrapped(f.samples.back().yaw_rad - 1.0), 0.0, 1e-12);
    expectWithinLimits(f, config, "turn on the spot");
    EXPECT_LT(std::abs(f.samples.back().yaw_rate_rad_s), 1e-9);
  }
  {  // One point, already looking its way: nothing to do.
    TrajectoryRequest request;
    request.path = {pose(5.0, 3.0, 1.0)};
    request.start_yaw_rad = 1.0;
    const TrajectoryReport report = generateTrajectory(request, world.field, config);
    EXPECT_EQ(report.status, TrajectoryStatus::kOptimised) << report.reason;
    ASSERT_TRUE(report.trajectory);
    EXPECT_EQ(report.trajectory->duration(), 0.0);
    const std::vector<TrajectorySample> out = sampleTrajectory(*report.trajectory, config.sample_rate_hz);
    ASSERT_GE(out.size(), 1u);
    EXPECT_LT((out.front().p_W - request.path[0].p_WB).norm(), 1e-12);
    EXPECT_NEAR(out.front().yaw_rad, 1.0, 1e-12);
    EXPECT_EQ(out.front().v_W.norm(), 0.0);
  }
}

// A 10 x 6 m room with a 2 x 0.8 m box; straight paths along y = 3 from x = 1 to 9.
// A turn on the spot before setting off (or on the way) brings the vehicle to rest: the next
// stretch ramps up from rest, so the smoothed position neither backs up nor overshoots.
TEST(TrajectoryEdge, TurnOnTheSpotThenGoDoesNotBackUp) {
  const EmptyRoom world;
  for (const TrajectoryConfig& config : {TrajectoryConfig{}, fastConfig()}) {
    TrajectoryRequest request;
    request.path = {pose(2.0, 3.0, 0.0), pose(5.0, 3.0, 0.0), pose(5.0, 3.0, 1.5), pose(5.0, 5.0, 1.5)};
    request.start_yaw_rad = 1.0;
    const TrajectoryReport report = generateTrajectory(request, world.field, config);
    ASSERT_EQ(report.status, TrajectoryStatus::kOptimised) << report.reason;
    const Flight f = fly(*report.trajectory, world.field);
    double min_x = 1e9, max_x = -1e9, min_y = 1e9;
    for (const TrajectorySample& s : f.samples) {
      min_x = std::min(min_x, s.p_W.x());
      max_x = std::max(max_x, s.p_W.x());
      min_y = std::min(min_y, s.p_W.y());
    }
    EXPECT_GT(min_x, 2.0 - 2e-3) << "backed up before leaving, v_nom " << config.nominal_speed_mps;
    EXPECT_LT(max_x, 5.0 + 2e-2) << "overshot the turn, v_nom " << config.nominal_speed_mps;
    EXPECT_GT(min_y, 3.0 - 2e-2) << "dipped below the line, v_nom " << config.nominal_speed_mps;
    expectWithinLimits(f, config, "turn then go");
  }
}

struct BoxRoom {
  OccupancyGrid2D grid;
  std::unique_ptr<DistanceField> distance;
  std::unique_ptr<PlanarClearance> field;
  std::vector<Eigen::Vector2d> obstacle_points;

  BoxRoom(double y0, double y1) : grid(room(10.0, 6.0)) {
    block(grid, 4.0, y0, 6.0, y1);
    distance = std::make_unique<DistanceField>(grid);
    field = std::make_unique<PlanarClearance>(*distance);
    obstacle_points = {Eigen::Vector2d(5.0, 0.5 * (y0 + y1))};
  }
};

TEST(TrajectoryEdge, PathGrazingAnObstacleIsPushedClear) {
  const BoxRoom world(3.2, 4.0);  // the path passes 0.2 m below the box: within the robot radius
  const TrajectoryConfig config;
  TrajectoryRequest request;
  request.path = {pose(1.0, 3.0, 0.0), pose(9.0, 3.0, 0.0)};
  request.obstacle_points = &world.obstacle_points;
  ASSERT_NEAR(world.field->clearance(request.path[0].p_WB + Eigen::Vector3d(4.0, 0.0, 0.0), nullptr), 0.2, 1e-9);
  const TrajectoryReport report = generateTrajectory(request, *world.field, config);
  ASSERT_EQ(report.status, TrajectoryStatus::kOptimised) << report.reason;
  const Flight f = fly(*report.trajectory, *world.field);
  EXPECT_GE(f.min_clearance, config.margin_m());
  EXPECT_TRUE(report.margin_met);
  expectWithinLimits(f, config, "grazing");
  const std::vector<Eigen::Vector2d> path2d = {Eigen::Vector2d(1.0, 3.0), Eigen::Vector2d(9.0, 3.0)};
  EXPECT_TRUE(TopologicalPlanner::sameClass(windingAngles(f.xy, world.obstacle_points),
                                            windingAngles(path2d, world.obstacle_points)));
  expectRestToRest(*report.trajectory, request.path.front(), request.path.back(), "grazing");
}

TEST(TrajectoryEdge, PathThroughAnObstacleFails) {
  const BoxRoom world(2.4, 4.0);  // y = 3 crosses the box below its reference point (5, 3.2)
  const TrajectoryConfig config;
  TrajectoryRequest request;
  request.path = {pose(1.0, 3.0, 0.0), pose(9.0, 3.0, 0.0)};
  request.obstacle_points = &world.obstacle_points;
  const TrajectoryReport report = generateTrajectory(request, *world.field, config);
  EXPECT_EQ(report.status, TrajectoryStatus::kFailed);
  EXPECT_FALSE(report.trajectory);
  EXPECT_NE(report.reason.find("obstacle"), std::string::npos) << report.reason;
  EXPECT_NE(report.reason.find("the path itself"), std::string::npos) << report.reason;
}

// A 2 x 2 m box in a 10 x 10 m room and an L-shaped path round its lower right corner, 0.31 m
// from its faces (just over the robot radius). Without the clearance term the B-spline cuts the
// corner and comes within 0.28 m of the box.
struct CornerRoom {
  OccupancyGrid2D grid = room(10.0, 10.0);
  std::unique_ptr<DistanceField> distance;
  std::unique_ptr<PlanarClearance> field;
  std::vector<Pose4> path;

  CornerRoom() {
    block(grid, 3.0, 3.0, 5.0, 5.0);
    distance = std::make_unique<DistanceField>(grid);
    field = std::make_unique<PlanarClearance>(*distance);
    path = {pose(1.0, 2.69, 0.0), pose(5.31, 2.69, M_PI / 2), pose(5.31, 8.0, M_PI / 2)};
  }
};

// True if the samples pass through every path point, in order (position within 1e-6 m, yaw
// within 1e-3 rad).
void expectThroughEveryPoint(const std::vector<TrajectorySample>& samples, const std::vector<Pose4>& path,
                             const std::string& what) {
  std::size_t from = 0;
  for (std::size_t k = 0; k < path.size(); ++k) {
    double best = std::numeric_limits<double>::infinity();
    std::size_t at = from;
    for (std::size_t i = from; i < samples.size(); ++i) {
      const double d = (samples[i].p_W - path[k].p_WB).norm();
      if (d < best) {
        best = d;
        at = i;
      }
    }
    EXPECT_LT(best, 1e-6) << what << ": point " << k;
    EXPECT_NEAR(wrapped(samples[at].yaw_rad - path[k].yaw_rad), 0.0, 1e-3) << what << ": point " << k;
    from = at;
  }
}

TEST(TrajectoryEdge, FailedOptimisationFallsBackToStopAndGoAlongThePath) {
  const CornerRoom world;
  TrajectoryRequest request;
  request.path = world.path;
  // With the clearance term the corner is optimised.
  const TrajectoryReport optimised = generateTrajectory(request, *world.field, TrajectoryConfig{});
  EXPECT_EQ(optimised.status, TrajectoryStatus::kOptimised) << optimised.reason;
  // Without it the spline cuts the corner: the path itself (0.31 m clear) is flown instead.
  for (int iterations : {1, 300}) {
    TrajectoryConfig config;
    config.clearance_weight = 0.0;
    config.max_iterations = iterations;
    const std::string what = "max_iterations " + std::to_string(iterations);
    const TrajectoryReport report = generateTrajectory(request, *world.field, config);
    ASSERT_EQ(report.status, TrajectoryStatus::kFallback) << what << ": " << report.reason;
    ASSERT_TRUE(report.trajectory) << what;
    EXPECT_NE(report.reason.find("obstacle"), std::string::npos) << what << ": " << report.reason;
    EXPECT_EQ(dynamic_cast<const BSplineTrajectory*>(report.trajectory.get()), nullptr) << what;
    const Flight f = fly(*report.trajectory, *world.field);
    expectWithinLimits(f, config, what);
    EXPECT_GE(f.min_clearance, config.robot_radius_m) << what;
    EXPECT_NEAR(report.min_clearance_m, f.min_clearance, 1e-3) << what;
    expectRestToRest(*report.trajectory, request.path.front(), request.path.back(), what);
    expectThroughEveryPoint(f.samples, request.path, what);
  }
}

TEST(TrajectoryEdge, BadInputIsRefused) {
  const EmptyRoom world;
  const TrajectoryConfig config;
  TrajectoryRequest empty;
  EXPECT_THROW(generateTrajectory(empty, world.field, config), std::invalid_argument);
  TrajectoryRequest nan;
  nan.path = {pose(2.0, 3.0, 0.0), pose(std::numeric_limits<double>::quiet_NaN(), 3.0, 0.0), pose(8.0, 3.0, 0.0)};
  EXPECT_THROW(generateTrajectory(nan, world.field, config), std::invalid_argument);
  nan.path = {pose(2.0, 3.0, 0.0), pose(8.0, 3.0, std::numeric_limits<double>::infinity())};
  EXPECT_THROW(generateTrajectory(nan, world.field, config), std::invalid_argument);

  auto message = [](const TrajectoryConfig& c) -> std::string {
    try {
      c.validate();
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(message(config), "");
  TrajectoryConfig c = config;
  c.max_speed_mps = 0.0;
  EXPECT_NE(message(c).find("trajectory.max_speed_mps"), std::string::npos) << message(c);
  c = config;
  c.nominal_speed_mps = 1.5;  // > max_speed_mps 1.0
  EXPECT_NE(message(c).find("trajectory.nominal_speed_mps"), std::string::npos) << message(c);
  EXPECT_NE(message(c).find("trajectory.max_speed_mps"), std::string::npos) << message(c);
  c = config;
  c.max_iterations = 0;
  EXPECT_NE(message(c).find("trajectory.max_iterations"), std::string::npos) << message(c);
  c = config;
  c.safety_margin_m = -0.1;
  EXPECT_NE(message(c).find("trajectory.safety_margin_m"), std::string::npos) << message(c);
  c = config;
  c.robot_radius_m = -0.1;  // the top-level robot radius (one robot for every planner)
  EXPECT_NE(message(c).find("robot_radius_m"), std::string::npos) << message(c);
  // generateTrajectory refuses a bad config too.
  TrajectoryRequest request;
  request.path = {pose(2.0, 3.0, 0.0), pose(8.0, 3.0, 0.0)};
  c = config;
  c.max_iterations = 0;
  EXPECT_THROW(generateTrajectory(request, world.field, c), std::invalid_argument);
}

TEST(TrajectoryEdge, SameRequestGivesBitIdenticalSamples) {
  const auto pm = planMap(1);
  ASSERT_EQ(pm->plan.status, PlanStatus::kSolved);
  const PlanarClearance field(pm->planner->field());
  const TrajectoryConfig config = fastConfig();
  const TrajectoryReport a = generateTrajectory(pm->request, field, config);
  const TrajectoryReport b = generateTrajectory(pm->request, field, config);
  ASSERT_EQ(a.status, TrajectoryStatus::kOptimised) << a.reason;
  ASSERT_EQ(b.status, a.status);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.trajectory->duration(), b.trajectory->duration());
  EXPECT_TRUE(identical(sampleTrajectory(*a.trajectory, 1000.0), sampleTrajectory(*b.trajectory, 1000.0)));
  EXPECT_TRUE(identical(sampleAt1kHz(*a.trajectory), sampleAt1kHz(*b.trajectory)));
}

}  // namespace
}  // namespace tgnav::planner
