// Trajectory metrics: Umeyama alignment (exact, noisy, degenerate), ATE aligned and anchored, RPE
// per distance (scale drift, yaw drift), association by timestamp, goal error and path length;
// evo's definitions for any trajectory pair: every alignment (se3, sim3, posyaw, origin, none) on
// hand-made offsets, rotations and scales, evo's statistics, RPE per frame and per metre.
#include "vo/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace tgnav::vo {
namespace {

Eigen::Isometry3d pose(const Eigen::Vector3d& t, double yaw_rad = 0.0) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X.translation() = t;
  return X;
}

Eigen::Isometry3d randomTransform(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> angle(0.0, M_PI);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(angle(rng), Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized()).toRotationMatrix();
  T.translation() = 10.0 * Eigen::Vector3d(n(rng), n(rng), n(rng));
  return T;
}

double rotationAngle(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(Eigen::Quaterniond(R)).angle(); }

// Error between two rigid transforms: rotation angle (rad) and translation distance (m).
void expectNear(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double rot_tol, double trans_tol) {
  EXPECT_LT(rotationAngle(a.linear().transpose() * b.linear()), rot_tol);
  EXPECT_LT((a.translation() - b.translation()).norm(), trans_tol);
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no std::invalid_argument)";
}

TEST(Umeyama, RecoversKnownRigidTransform) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Isometry3d T = randomTransform(rng);
    std::vector<Eigen::Vector3d> est, gt;
    for (int i = 0; i < 100; ++i) {
      est.emplace_back(u(rng), u(rng), u(rng));
      gt.push_back(T * est.back());
    }
    const Eigen::Isometry3d A = umeyamaAlignment(est, gt);
    EXPECT_LT((A.linear() - T.linear()).norm(), 1e-9) << trial;
    EXPECT_LT((A.translation() - T.translation()).norm(), 1e-9) << trial;
    EXPECT_NEAR(A.linear().determinant(), 1.0, 1e-12) << trial;
  }
}

TEST(Umeyama, RotationNearHalfTurnIsRecovered) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(8, -9, 10);
  std::vector<Eigen::Vector3d> est, gt;
  for (int i = 0; i < 100; ++i) {
    est.emplace_back(u(rng), u(rng), u(rng));
    gt.push_back(T * est.back());
  }
  const Eigen::Isometry3d A = umeyamaAlignment(est, gt);
  EXPECT_LT((A.linear() - T.linear()).norm(), 1e-9);
  EXPECT_LT((A.translation() - T.translation()).norm(), 1e-9);
}

TEST(Umeyama, RecoversTransformFromNoisyPoints) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::Isometry3d T = randomTransform(rng);
    std::vector<Eigen::Vector3d> est, gt;
    for (int i = 0; i < 100; ++i) {
      est.emplace_back(u(rng), u(rng), u(rng));
      gt.push_back(T * est.back() + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
    }
    // 1 cm noise on 100 points spread over 10 m: about 3e-4 rad and 2 mm.
    expectNear(umeyamaAlignment(est, gt), T, 2e-3, 1e-2);
  }
}

TEST(Umeyama, PlanarPointsGiveTheRotation) {
  // Rank-2 cross-covariance (all points in one plane) still fixes the rotation; no reflection.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  const Eigen::Isometry3d T = randomTransform(rng);
  std::vector<Eigen::Vector3d> est, gt;
  for (int i = 0; i < 20; ++i) {
    est.emplace_back(u(rng), u(rng), 0.0);
    gt.push_back(T * est.back());
  }
  const Eigen::Isometry3d A = umeyamaAlignment(est, gt);
  EXPECT_LT((A.linear() - T.linear()).norm(), 1e-9);
  EXPECT_LT((A.translation() - T.translation()).norm(), 1e-9);
}

TEST(Umeyama, DegenerateInputsGiveTranslationOnly) {
  const Eigen::Isometry3d T = pose({1, 2, 3}, 0.7);
  // No points: identity.
  EXPECT_TRUE(umeyamaAlignment({}, {}).isApprox(Eigen::Isometry3d::Identity()));
  // One point: the rotation is free; the translation moves it onto its partner.
  {
    const Eigen::Isometry3d A = umeyamaAlignment({{1, 1, 1}}, {T * Eigen::Vector3d(1, 1, 1)});
    EXPECT_TRUE(A.linear().isIdentity(0.0));
    EXPECT_LT((A.translation() - (T * Eigen::Vector3d(1, 1, 1) - Eigen::Vector3d(1, 1, 1))).norm(), 1e-12);
  }
  // Two points, and five on a line: difference of the centroids.
  for (const int n : {2, 5}) {
    std::vector<Eigen::Vector3d> est, gt;
    Eigen::Vector3d mu_est = Eigen::Vector3d::Zero(), mu_gt = Eigen::Vector3d::Zero();
    for (int i = 0; i < n; ++i) {
      est.push_back(Eigen::Vector3d(1, 0, 0) + i * Eigen::Vector3d(0.5, 1, 2));
      gt.push_back(T * est.back());
      mu_est += est.back() / n;
      mu_gt += gt.back() / n;
    }
    const Eigen::Isometry3d A = umeyamaAlignment(est, gt);
    EXPECT_TRUE(A.linear().isIdentity(0.0)) << n;
    EXPECT_LT((A.translation() - (mu_gt - mu_est)).norm(), 1e-12) << n;
  }
  // Non-collinear estimate against a collinear ground truth: rank 1 too.
  {
    const Eigen::Isometry3d A = umeyamaAlignment({{0, 0, 0}, {1, 1, 0}, {2, 0, 0}}, {{0, 0, 1}, {1, 0, 1}, {2, 0, 1}});
    EXPECT_TRUE(A.linear().isIdentity(0.0));
    EXPECT_LT((A.translation() - Eigen::Vector3d(0, -1.0 / 3, 1)).norm(), 1e-12);
  }
  // All points the same: no rotation either.
  {
    const Eigen::Isometry3d A = umeyamaAlignment({{1, 2, 3}, {1, 2, 3}, {1, 2, 3}}, {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}});
    EXPECT_TRUE(A.linear().isIdentity(0.0));
    EXPECT_LT((A.translation() - Eigen::Vector3d(-1, -2, -3)).norm(), 1e-12);
  }
}

TEST(Umeyama, BadInputThrows) {
  EXPECT_THROW(umeyamaAlignment({{0, 0, 0}}, {}), std::invalid_argument);
  EXPECT_THROW(umeyamaAlignment({{0, 0, NAN}, {1, 0, 0}, {0, 1, 0}}, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}),
               std::invalid_argument);
}

// A wavy 3D ground-truth path with turning yaw, sampled every 0.1 s.
std::vector<Eigen::Isometry3d> wavyPath(int n) {
  std::vector<Eigen::Isometry3d> X;
  for (int i = 0; i < n; ++i) {
    const double s = 0.1 * i;
    X.push_back(pose({2.0 * std::cos(s), 3.0 * std::sin(0.7 * s), 1.0 + 0.5 * std::sin(1.3 * s)}, 0.4 * s));
  }
  return X;
}

std::vector<PosePair> pairsOf(const std::vector<Eigen::Isometry3d>& est, const std::vector<Eigen::Isometry3d>& gt) {
  std::vector<PosePair> pairs;
  for (std::size_t i = 0; i < gt.size(); ++i) pairs.push_back(PosePair{0.1 * i, est[i], gt[i]});
  return pairs;
}

TEST(Ate, RigidlyMovedEstimateHasZeroError) {
  std::mt19937 rng(2);
  const Eigen::Isometry3d T = randomTransform(rng);
  const auto gt = wavyPath(80);
  std::vector<Eigen::Isometry3d> est;
  for (const auto& X : gt) est.push_back(T * X);
  const auto pairs = pairsOf(est, gt);
  for (const bool align : {true, false}) {
    const AteResult r = absoluteTrajectoryError(pairs, align);
    EXPECT_EQ(r.pairs, 80);
    EXPECT_LT(r.rmse_m, 1e-9) << align;
    EXPECT_LT(r.max_m, 1e-9) << align;
    expectNear(r.alignment, T.inverse(), 1e-9, 1e-9);
  }
}

TEST(Ate, AnchoredErrorIsTheFirstPoseOffset) {
  // Only the first estimate is off (by d): anchoring on it shifts every later pose by -d; aligning
  // all of them leaves only a small error.
  const auto gt = wavyPath(50);
  auto est = gt;
  const Eigen::Vector3d d(0.3, -0.4, 0.0);  // |d| = 0.5
  est[0].translation() += d;
  const auto pairs = pairsOf(est, gt);
  const AteResult anchored = absoluteTrajectoryError(pairs, false);
  EXPECT_EQ(anchored.pairs, 50);
  EXPECT_NEAR(anchored.max_m, 0.5, 1e-12);
  EXPECT_NEAR(anchored.mean_m, 0.5 * 49 / 50, 1e-12);
  EXPECT_NEAR(anchored.rmse_m, 0.5 * std::sqrt(49.0 / 50), 1e-12);
  EXPECT_LT((anchored.alignment.translation() + d).norm(), 1e-12);
  const AteResult aligned = absoluteTrajectoryError(pairs, true);
  EXPECT_LT(aligned.rmse_m, 0.5 / std::sqrt(50.0));
  EXPECT_GT(aligned.rmse_m, 0.0);
}

TEST(Ate, HandComputedExamples) {
  // Unit square; the estimate is it scaled by 1.1 about its centre. By symmetry the best rigid
  // alignment is the identity, leaving 0.1 * sqrt(0.5) at every corner.
  {
    const std::vector<Eigen::Vector3d> sq = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const Eigen::Vector3d c(0.5, 0.5, 0);
    std::vector<PosePair> pairs;
    for (const auto& p : sq) pairs.push_back(PosePair{0.0, pose(c + 1.1 * (p - c)), pose(p)});
    const AteResult r = absoluteTrajectoryError(pairs, true);
    const double e = 0.1 * std::sqrt(0.5);
    EXPECT_NEAR(r.rmse_m, e, 1e-12);
    EXPECT_NEAR(r.mean_m, e, 1e-12);
    EXPECT_NEAR(r.max_m, e, 1e-12);
    EXPECT_TRUE(r.alignment.isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  }
  // Straight ground truth, the middle estimate 0.1 m off to the side.
  {
    std::vector<PosePair> pairs = {{0.0, pose({0, 0, 0}), pose({0, 0, 0})},
                                   {1.0, pose({1, 0.1, 0}), pose({1, 0, 0})},
                                   {2.0, pose({2, 0, 0}), pose({2, 0, 0})}};
    // Anchored (first poses agree): errors 0, 0.1, 0.
    const AteResult anchored = absoluteTrajectoryError(pairs, false);
    EXPECT_NEAR(anchored.rmse_m, std::sqrt(0.01 / 3), 1e-12);
    EXPECT_NEAR(anchored.mean_m, 0.1 / 3, 1e-12);
    EXPECT_NEAR(anchored.max_m, 0.1, 1e-12);
    // Aligned: the ground truth is a line, so translation-only, by -(0, 0.1/3, 0): errors 1/30,
    // 2/30, 1/30.
    const AteResult aligned = absoluteTrajectoryError(pairs, true);
    EXPECT_NEAR(aligned.rmse_m, std::sqrt(6.0 / 2700), 1e-12);
    EXPECT_NEAR(aligned.mean_m, 4.0 / 90, 1e-12);
    EXPECT_NEAR(aligned.max_m, 2.0 / 30, 1e-12);
  }
}

TEST(Ate, NoPairs) {
  const AteResult r = absoluteTrajectoryError({}, true);
  EXPECT_EQ(r.pairs, 0);
  EXPECT_EQ(r.rmse_m, 0.0);
  EXPECT_EQ(absoluteTrajectoryError({}, false).pairs, 0);
}

TEST(Rpe, ConstantScaleDriftOfOnePercent) {
  // Straight line along a diagonal in 0.125 m steps; the estimate runs 1% long.
  const Eigen::Vector3d dir = Eigen::Vector3d(1, 2, 2) / 3.0;
  std::vector<PosePair> pairs;
  for (int i = 0; i <= 200; ++i) {
    const double s = 0.125 * i;
    pairs.push_back(PosePair{0.1 * i, pose(1.01 * s * dir, 0.3), pose(s * dir, 0.3)});
  }
  // delta just under 1 m so that rounding in the path length cannot push j one step further.
  const RpeResult r = relativePoseError(pairs, 0.999);
  EXPECT_EQ(r.delta_m, 0.999);
  EXPECT_EQ(r.pairs, 201 - 8);  // j = i + 8 (1 m on) for i up to 192
  EXPECT_NEAR(r.trans_rmse_m, 0.01, 1e-9);
  EXPECT_NEAR(r.trans_mean_m, 0.01, 1e-9);
  EXPECT_NEAR(r.trans_rmse_percent, 1.0 / 0.999, 1e-7);
  EXPECT_NEAR(r.rot_rmse_rad, 0.0, 1e-12);
  // A perfect estimate has none.
  for (auto& p : pairs) p.X_WC_est = p.X_WC_gt;
  EXPECT_NEAR(relativePoseError(pairs, 1.0).trans_rmse_m, 0.0, 1e-12);
}

TEST(Rpe, YawDriftGivesRotationError) {
  // Ground truth goes straight without turning; the estimate's yaw drifts 0.02 rad per metre.
  std::vector<PosePair> pairs;
  for (int i = 0; i <= 100; ++i) {
    const double s = 0.25 * i;
    pairs.push_back(PosePair{0.1 * i, pose({s, 0, 1}, 0.02 * s), pose({s, 0, 1})});
  }
  const RpeResult r = relativePoseError(pairs, 2.0);
  EXPECT_EQ(r.pairs, 101 - 8);
  EXPECT_NEAR(r.rot_rmse_rad, 0.04, 1e-12);
  // The estimate's steps are rotated by the drifted yaw: |R(-0.02 s_i) (2, 0, 0) - (2, 0, 0)|
  // varies with i; at least it is not zero.
  EXPECT_GT(r.trans_rmse_m, 0.0);
}

TEST(Rpe, SparseSamplesUseTheFirstPoseAtOrBeyondDelta) {
  // Steps of 0.75 m, delta 1 m: every pair spans 1.5 m, so a 10% scale error is 0.15 m (15%).
  std::vector<PosePair> pairs;
  for (int i = 0; i < 5; ++i) pairs.push_back(PosePair{1.0 * i, pose({1.1 * 0.75 * i, 0, 0}), pose({0.75 * i, 0, 0})});
  const RpeResult r = relativePoseError(pairs, 1.0);
  EXPECT_EQ(r.pairs, 3);
  EXPECT_NEAR(r.trans_rmse_m, 0.15, 1e-12);
  EXPECT_NEAR(r.trans_rmse_percent, 15.0, 1e-10);
}

TEST(Rpe, TooShortOrBadDelta) {
  std::vector<PosePair> pairs = {{0.0, pose({0, 0, 0}), pose({0, 0, 0})}, {1.0, pose({1, 0, 0}), pose({0.5, 0, 0})}};
  const RpeResult r = relativePoseError(pairs, 1.0);
  EXPECT_EQ(r.pairs, 0);
  EXPECT_EQ(r.trans_rmse_m, 0.0);
  EXPECT_EQ(relativePoseError({}, 1.0).pairs, 0);
  EXPECT_THROW(relativePoseError(pairs, 0.0), std::invalid_argument);
  EXPECT_THROW(relativePoseError(pairs, -1.0), std::invalid_argument);
  EXPECT_THROW(relativePoseError(pairs, NAN), std::invalid_argument);
}

std::vector<StampedPose> stamped(const std::vector<double>& times) {
  std::vector<StampedPose> poses;
  for (const double t : times) poses.push_back(StampedPose{t, pose({t, 0, 0})});
  return poses;
}

TEST(Associate, NearestWithinToleranceWithJitterAndGaps) {
  // Ground truth at 100 Hz over 0..3 s with a gap from 1.0 to 1.5 s; estimates at 30 Hz over
  // 0..3.2 s with +-4 ms jitter.
  std::vector<double> gt_t;
  for (int k = 0; k <= 300; ++k) {
    if (k <= 100 || k >= 150) gt_t.push_back(0.01 * k);
  }
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> jitter(-0.004, 0.004);
  std::vector<double> est_t;
  for (int k = 0; k < 96; ++k) est_t.push_back(k / 30.0 + 0.002 + jitter(rng));
  const auto est = stamped(est_t), gt = stamped(gt_t);
  const auto pairs = associate(est, gt, 0.02);
  std::size_t expected = 0;
  std::size_t p = 0;
  for (const double t : est_t) {
    double nearest = gt_t.front();
    for (const double g : gt_t) {
      if (std::abs(g - t) < std::abs(nearest - t)) nearest = g;
    }
    if (std::abs(nearest - t) > 0.02) continue;
    ++expected;
    ASSERT_LT(p, pairs.size());
    EXPECT_EQ(pairs[p].t_s, t);
    EXPECT_EQ(pairs[p].X_WC_est.translation().x(), t);  // the estimate's own pose
    EXPECT_EQ(pairs[p].X_WC_gt.translation().x(), nearest);
    ++p;
  }
  EXPECT_EQ(pairs.size(), expected);
  // The gap and the estimates past the end of the ground truth are skipped, nothing else.
  int in_gap = 0, past_end = 0;
  for (const double t : est_t) {
    in_gap += t > 1.02 && t < 1.47;
    past_end += t > 3.02;
  }
  EXPECT_GT(in_gap, 10);
  EXPECT_GT(past_end, 3);
  EXPECT_EQ(pairs.size(), est_t.size() - in_gap - past_end);
}

// evo's rule (evo.core.sync): each pose of the shorter trajectory with the nearest in time of the
// other, within the tolerance; of equally near ones, the first in its file.
TEST(Associate, TheShorterIsPairedAndTiesGoToTheFirstInTheFile) {
  const auto gt = stamped({1.0, 2.0, 3.0});
  // The estimate is shorter: 1.5 is equally far from 1 and 2 (the first in the file, 1); 2.75 is
  // 0.25 from 3.
  auto pairs = associate(stamped({1.5, 2.75}), gt, 0.5);
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0].t_s, 1.5);
  EXPECT_EQ(pairs[0].X_WC_gt.translation().x(), 1.0);
  EXPECT_EQ(pairs[1].X_WC_gt.translation().x(), 3.0);
  // The estimate is longer: each ground-truth pose takes its nearest estimate instead (1 is as far
  // from 0.5 as from 1.5: the first, 0.5; 3 as far from 2.75 as from 3.25: 2.75). Pairs follow the
  // ground truth's order and keep the estimate's time.
  pairs = associate(stamped({0.5, 1.5, 2.75, 3.25}), gt, 0.5);
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0].t_s, 0.5);
  EXPECT_EQ(pairs[1].t_s, 1.5);
  EXPECT_EQ(pairs[2].t_s, 2.75);
  EXPECT_EQ(pairs[2].X_WC_gt.translation().x(), 3.0);
  EXPECT_EQ(associate(stamped({0.5, 1.5, 2.75, 3.25}), gt, 0.25).size(), 1u);  // only 3 - 2.75
  EXPECT_TRUE(associate({}, gt).empty());
  EXPECT_TRUE(associate(gt, {}).empty());
  // As long: the estimate is paired. Exact matches with zero tolerance.
  EXPECT_EQ(associate(gt, gt, 0.0).size(), 3u);
}

// TUM's fr2/desk ground truth repeats a timestamp on consecutive lines; files may also go back.
TEST(Associate, RepeatedAndUnorderedTimestamps) {
  // gt: x = its line. 0.1 twice (lines 1 and 2), then back to 0.05.
  const std::vector<StampedPose> gt = {{0.0, pose({0, 0, 0})},
                                       {0.1, pose({1, 0, 0})},
                                       {0.1, pose({2, 0, 0})},
                                       {0.05, pose({3, 0, 0})},
                                       {0.2, pose({4, 0, 0})}};
  const auto pairs = associate(stamped({0.1, 0.06, 0.19}), gt, 0.02);
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0].X_WC_gt.translation().x(), 1.0);  // the first of the repeated stamp
  EXPECT_EQ(pairs[1].X_WC_gt.translation().x(), 3.0);  // 0.05, written after 0.1
  EXPECT_EQ(pairs[2].X_WC_gt.translation().x(), 4.0);
  // Equally near on both sides, the later time written first: the first in the file wins.
  const std::vector<StampedPose> two = {{0.2, pose({1, 0, 0})}, {0.0, pose({2, 0, 0})}};
  const auto tie = associate(stamped({0.1}), two, 0.5);
  ASSERT_EQ(tie.size(), 1u);
  EXPECT_EQ(tie[0].X_WC_gt.translation().x(), 1.0);
  EXPECT_EQ(nonIncreasingTimes(gt), 2);
  EXPECT_EQ(nonIncreasingTimes(stamped({0.0, 0.1, 0.2})), 0);
}

// Against numpy's argmin over |t_i - t| written out (what evo runs), on times drawn from a coarse
// grid so that repeats and ties are common, in shuffled order, both ways round.
TEST(Associate, MatchesTheBruteForceArgmin) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> tick(0, 40);
  auto draw = [&](int n) {
    std::vector<StampedPose> poses(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i)
      poses[static_cast<std::size_t>(i)] = {0.025 * tick(rng), pose({static_cast<double>(i), 0, 0})};
    return poses;
  };
  int ties = 0;
  for (int round = 0; round < 200; ++round) {
    const auto est = draw(1 + round % 17);
    const auto gt = draw(1 + (round * 7) % 23);
    const double max_dt = 0.01 * (round % 5);
    const bool est_longer = est.size() > gt.size();
    const auto& shorter = est_longer ? gt : est;
    const auto& longer = est_longer ? est : gt;
    std::vector<std::pair<double, double>> expected;  // (est x, gt x)
    for (const StampedPose& s : shorter) {
      std::size_t best = 0;
      for (std::size_t j = 1; j < longer.size(); ++j) {
        if (std::abs(longer[j].t_s - s.t_s) < std::abs(longer[best].t_s - s.t_s)) best = j;
      }
      for (std::size_t j = best + 1; j < longer.size(); ++j) {
        ties += std::abs(longer[j].t_s - s.t_s) == std::abs(longer[best].t_s - s.t_s) ? 1 : 0;
      }
      if (!(std::abs(longer[best].t_s - s.t_s) <= max_dt)) continue;
      const double lx = longer[best].X_WC.translation().x();
      const double sx = s.X_WC.translation().x();
      expected.emplace_back(est_longer ? lx : sx, est_longer ? sx : lx);
    }
    const auto pairs = associate(est, gt, max_dt);
    ASSERT_EQ(pairs.size(), expected.size()) << "round " << round;
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      EXPECT_EQ(pairs[k].X_WC_est.translation().x(), expected[k].first) << "round " << round << ", pair " << k;
      EXPECT_EQ(pairs[k].X_WC_gt.translation().x(), expected[k].second) << "round " << round << ", pair " << k;
    }
  }
  EXPECT_GT(ties, 100);  // the rule for ties was exercised
}

TEST(Associate, BadTimestampsNameSequenceAndIndex) {
  const auto ok = stamped({0.0, 0.1, 0.2});
  const std::string nan = errorOf([&] { associate(ok, stamped({0.0, NAN})); });
  EXPECT_NE(nan.find("gt[1]"), std::string::npos) << nan;
  EXPECT_NE(nan.find("non-finite"), std::string::npos) << nan;
  const std::string inf = errorOf([&] { associate(stamped({INFINITY}), ok); });
  EXPECT_NE(inf.find("est[0]"), std::string::npos) << inf;
  EXPECT_THROW(associate(ok, ok, -0.1), std::invalid_argument);
  EXPECT_THROW(associate(ok, ok, NAN), std::invalid_argument);
}

TEST(GoalAndDistance, HandExamples) {
  // Ground truth: 3-4-5 right angle, then 1 m up: 3 + 4 + 1 = 8 m.
  std::vector<PosePair> pairs = {{0.0, pose({10, 10, 0}, M_PI / 2), pose({0, 0, 0})},
                                 {1.0, pose({10, 13, 0}, M_PI / 2), pose({3, 0, 0})},
                                 {2.0, pose({6, 13, 0}, M_PI / 2), pose({3, 4, 0})},
                                 {3.0, pose({6, 13, 1.5}, M_PI / 2), pose({3, 4, 1})}};
  EXPECT_NEAR(distanceTravelled(pairs), 8.0, 1e-12);
  // The estimate, started at (10, 10, 0) facing +y, maps onto the ground truth by a -90 deg yaw
  // about its start: its end (6, 13, 1.5) becomes (3, 4, 1.5), 0.5 m above the true end.
  EXPECT_NEAR(goalError(pairs), 0.5, 1e-12);
  EXPECT_EQ(goalError({}), 0.0);
  EXPECT_EQ(distanceTravelled({}), 0.0);
  EXPECT_EQ(distanceTravelled({pairs.front()}), 0.0);
  EXPECT_EQ(goalError({pairs.front()}), 0.0);
}

// --- evo's definitions: alignments, statistics, RPE in frames (tgnav eval) ------------------------

// A wavy path's poses (wavyPath) with each estimate mapped by `f` (position and rotation).
std::vector<PosePair> mappedPairs(int n, const std::function<Eigen::Isometry3d(const Eigen::Isometry3d&)>& f) {
  const auto gt = wavyPath(n);
  std::vector<Eigen::Isometry3d> est;
  for (const auto& X : gt) est.push_back(f(X));
  return pairsOf(est, gt);
}

Eigen::Matrix3d rotZ(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }
Eigen::Matrix3d rotX(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix(); }

TEST(Alignment, NamesRoundTripAndUnknownIsRejected) {
  for (const char* name : {"se3", "sim3", "posyaw", "origin", "none"})
    EXPECT_STREQ(toString(parseAlignment(name)), name);
  const std::string msg = errorOf([] { parseAlignment("SE3"); });
  EXPECT_NE(msg.find("'SE3' is not an alignment; expected se3, sim3, posyaw, origin or none"), std::string::npos)
      << msg;
}

TEST(ErrorStatistics, HandComputedAsNumpy) {
  const ErrorStatistics s = errorStatistics({4.0, 1.0, 3.0, 2.0});
  EXPECT_EQ(s.n, 4);
  EXPECT_DOUBLE_EQ(s.sse, 30.0);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);           // even n: mean of the middle two
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));  // population (ddof = 0)
  EXPECT_EQ(s.min, 1.0);
  EXPECT_EQ(s.max, 4.0);
  EXPECT_EQ(errorStatistics({3.0, 1.0, 2.0}).median, 2.0);
  const ErrorStatistics none = errorStatistics({});
  EXPECT_EQ(none.n, 0);
  EXPECT_EQ(none.sse, 0.0);
  for (const double v : {none.rmse, none.mean, none.median, none.std, none.min, none.max}) EXPECT_TRUE(std::isnan(v));
}

TEST(Ape, PureTranslationOffset) {
  // The estimate is the ground truth moved by d = (0.3, -0.4, 1.2), |d| = 1.3: every rigid or
  // similarity alignment removes it; none leaves |d| at every pair.
  const Eigen::Vector3d d(0.3, -0.4, 1.2);
  const auto pairs = mappedPairs(60, [&](const Eigen::Isometry3d& X) {
    Eigen::Isometry3d Y = X;
    Y.translation() += d;
    return Y;
  });
  for (const Alignment a : {Alignment::kSe3, Alignment::kSim3, Alignment::kPosYaw, Alignment::kOrigin}) {
    const ApeResult r = absolutePoseError(pairs, a);
    EXPECT_EQ(r.stats_m.n, 60);
    EXPECT_LT(r.stats_m.max, 1e-9) << toString(a);
    EXPECT_LT((r.alignment.t + d).norm(), 1e-9) << toString(a);
    EXPECT_NEAR(r.alignment.scale, 1.0, 1e-12) << toString(a);
  }
  const ApeResult none = absolutePoseError(pairs, Alignment::kNone);
  ASSERT_EQ(none.errors_m.size(), 60u);
  for (const double e : none.errors_m) EXPECT_NEAR(e, 1.3, 1e-12);
  for (const double v :
       {none.stats_m.rmse, none.stats_m.mean, none.stats_m.median, none.stats_m.min, none.stats_m.max}) {
    EXPECT_NEAR(v, 1.3, 1e-12);
  }
  EXPECT_NEAR(none.stats_m.std, 0.0, 1e-12);
  EXPECT_NEAR(none.stats_m.sse, 60 * 1.69, 1e-9);
  EXPECT_TRUE(none.alignment.R.isIdentity(0.0));
}

TEST(Ape, RotationAboutAnyAxis) {
  // A rigid motion with roll, pitch and yaw: se3, sim3 and origin undo it; posyaw cannot (it only
  // turns about z) and none does not try.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(1.0, Eigen::Vector3d(1, 1, 0.2).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(2, -1, 3);
  const auto pairs = mappedPairs(80, [&](const Eigen::Isometry3d& X) { return T * X; });
  for (const Alignment a : {Alignment::kSe3, Alignment::kSim3, Alignment::kOrigin}) {
    const ApeResult r = absolutePoseError(pairs, a);
    EXPECT_LT(r.stats_m.rmse, 1e-9) << toString(a);
    EXPECT_LT((r.alignment.R - T.linear().transpose()).norm(), 1e-9) << toString(a);
    // The aligned estimate's poses, rotations included, are the ground truth's.
    for (const PosePair& p : alignedPairs(pairs, r.alignment)) expectNear(p.X_WC_est, p.X_WC_gt, 1e-9, 1e-9);
  }
  EXPECT_GT(absolutePoseError(pairs, Alignment::kPosYaw).stats_m.rmse, 0.1);
  EXPECT_GT(absolutePoseError(pairs, Alignment::kNone).stats_m.rmse, 1.0);
}

TEST(Ape, ScaleIsRecoveredBySim3Only) {
  // The estimate is the ground truth at half scale, turned and moved (a monocular VO's output):
  // sim3 finds the scale 2 back and leaves no error; se3 cannot scale.
  const Eigen::Matrix3d R0 = rotZ(0.8) * rotX(0.3);
  const Eigen::Vector3d t0(5, -2, 1);
  const auto pairs = mappedPairs(80, [&](const Eigen::Isometry3d& X) {
    Eigen::Isometry3d Y = Eigen::Isometry3d::Identity();
    Y.linear() = R0 * X.linear();
    Y.translation() = R0 * (0.5 * X.translation()) + t0;
    return Y;
  });
  const ApeResult sim3 = absolutePoseError(pairs, Alignment::kSim3);
  EXPECT_NEAR(sim3.alignment.scale, 2.0, 1e-9);
  EXPECT_LT((sim3.alignment.R - R0.transpose()).norm(), 1e-9);
  EXPECT_LT((sim3.alignment.t + 2.0 * R0.transpose() * t0).norm(), 1e-9);
  EXPECT_LT(sim3.stats_m.max, 1e-9);
  const ApeResult se3 = absolutePoseError(pairs, Alignment::kSe3);
  EXPECT_EQ(se3.alignment.scale, 1.0);
  EXPECT_GT(se3.stats_m.rmse, 0.3);
  // Relative motions of the scaled estimate are half as long: RPE sees the scale unless the
  // sim3-aligned pairs are used.
  const RpeStatistics raw = rpeStatistics(pairs, 1, RpeUnit::kFrames);
  const RpeStatistics aligned = rpeStatistics(alignedPairs(pairs, sim3.alignment), 1, RpeUnit::kFrames);
  EXPECT_GT(raw.trans_m.rmse, 0.05);
  EXPECT_LT(aligned.trans_m.rmse, 1e-9);
  EXPECT_LT(aligned.rot_rad.rmse, 1e-7);
}

TEST(Ape, PosYawRecoversYawAndTranslationButNotRoll) {
  const Eigen::Vector3d t0(1.5, -0.5, 0.25);
  auto moved = [&](const Eigen::Matrix3d& R) {
    return mappedPairs(80, [&](const Eigen::Isometry3d& X) {
      Eigen::Isometry3d Y = Eigen::Isometry3d::Identity();
      Y.linear() = R * X.linear();
      Y.translation() = R * X.translation() + t0;
      return Y;
    });
  };
  // Yaw 2 rad (beyond +-pi/2, so atan2's quadrant matters) and a translation.
  const ApeResult yaw = absolutePoseError(moved(rotZ(2.0)), Alignment::kPosYaw);
  EXPECT_LT(yaw.stats_m.max, 1e-9);
  EXPECT_LT((yaw.alignment.R - rotZ(-2.0)).norm(), 1e-12);
  EXPECT_LT((yaw.alignment.t + rotZ(-2.0) * t0).norm(), 1e-9);
  // A roll of 0.2 rad: posyaw leaves an error that se3 removes.
  const auto rolled = moved(rotX(0.2));
  EXPECT_GT(absolutePoseError(rolled, Alignment::kPosYaw).stats_m.rmse, 0.05);
  EXPECT_LT(absolutePoseError(rolled, Alignment::kSe3).stats_m.rmse, 1e-9);
  const Similarity3 S = posYawAlignment(std::vector<Eigen::Vector3d>{}, {});
  EXPECT_TRUE(S.R.isIdentity(0.0));
  EXPECT_THROW(posYawAlignment({{0, 0, 0}}, {}), std::invalid_argument);
  EXPECT_THROW(posYawAlignment({{0, 0, NAN}}, {{0, 0, 0}}), std::invalid_argument);
}

TEST(Ape, KeepsTheTrialCodesNumbers) {
  // absoluteTrajectoryError is absolutePoseError with se3 (align) or origin (anchored).
  const auto gt = wavyPath(50);
  auto est = gt;
  std::mt19937 rng(6);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (auto& X : est) X.translation() += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  const auto pairs = pairsOf(est, gt);
  for (const bool align : {true, false}) {
    const AteResult old = absoluteTrajectoryError(pairs, align);
    const ApeResult ape = absolutePoseError(pairs, align ? Alignment::kSe3 : Alignment::kOrigin);
    EXPECT_EQ(old.rmse_m, ape.stats_m.rmse);
    EXPECT_EQ(old.mean_m, ape.stats_m.mean);
    EXPECT_EQ(old.max_m, ape.stats_m.max);
    EXPECT_TRUE(old.alignment.linear() == ape.alignment.R);
  }
  const RpeResult old = relativePoseError(pairs, 0.5);
  const RpeStatistics rpe = rpeStatistics(pairs, 0.5, RpeUnit::kMetres);
  EXPECT_EQ(old.pairs, rpe.trans_m.n);
  EXPECT_EQ(old.trans_rmse_m, rpe.trans_m.rmse);
  EXPECT_EQ(old.rot_rmse_rad, rpe.rot_rad.rmse);
}

TEST(Ape, MissingTimestampsAndDifferentRates) {
  // Ground truth at 100 Hz over 0..4 s with nothing from 1.5 to 2.5 s; the estimate at 20 Hz,
  // 3 ms late, 0.5 m off in x. The estimates in the gap have no partner.
  std::vector<StampedPose> gt, est;
  for (int k = 0; k <= 400; ++k) {
    if (k > 150 && k < 250) continue;
    const double t = 0.01 * k;
    gt.push_back(StampedPose{t, pose({t, std::sin(t), 0.1 * t * t}, 0.3 * t)});
  }
  for (int k = 0; k <= 80; ++k) {
    const double t = 0.05 * k;
    est.push_back(StampedPose{t + 0.003, pose({t + 0.5, std::sin(t), 0.1 * t * t}, 0.3 * t)});
  }
  const auto pairs = associate(est, gt, 0.02);
  // 81 estimates, of which those at 1.55 .. 2.45 s (19) fall in the gap.
  ASSERT_EQ(pairs.size(), 81u - 19u);
  for (const PosePair& p : pairs) EXPECT_NEAR(p.X_WC_gt.translation().x(), p.t_s - 0.003, 1e-12);
  const ApeResult none = absolutePoseError(pairs, Alignment::kNone);
  EXPECT_NEAR(none.stats_m.min, 0.5, 1e-12);
  EXPECT_NEAR(none.stats_m.max, 0.5, 1e-12);
  EXPECT_LT(absolutePoseError(pairs, Alignment::kSe3).stats_m.max, 1e-9);
  // A tighter tolerance than the 3 ms delay pairs nothing.
  EXPECT_TRUE(associate(est, gt, 0.002).empty());
}

TEST(RpeStatistics, FramesAndMetresOnAStraightLine) {
  // Ground truth steps 0.1 m along x; the estimate steps 0.11 m: 0.01 m error per step.
  std::vector<PosePair> pairs;
  for (int i = 0; i <= 50; ++i) pairs.push_back(PosePair{0.1 * i, pose({0.11 * i, 0, 1}), pose({0.1 * i, 0, 1})});
  const RpeStatistics one = rpeStatistics(pairs, 1, RpeUnit::kFrames);
  EXPECT_EQ(one.trans_m.n, 50);
  EXPECT_NEAR(one.trans_m.rmse, 0.01, 1e-12);
  EXPECT_NEAR(one.trans_m.max, 0.01, 1e-12);
  EXPECT_NEAR(one.rot_rad.max, 0.0, 1e-12);
  const RpeStatistics five = rpeStatistics(pairs, 5, RpeUnit::kFrames);
  EXPECT_EQ(five.trans_m.n, 46);  // (i, i + 5) for i = 0 .. 45
  EXPECT_NEAR(five.trans_m.rmse, 0.05, 1e-12);
  EXPECT_NEAR(five.trans_m.std, 0.0, 1e-12);
  // 5 frames are 0.5 m of ground truth (just under, so rounding cannot push j one further).
  const RpeStatistics half = rpeStatistics(pairs, 0.4999, RpeUnit::kMetres);
  EXPECT_EQ(half.trans_m.n, 46);
  EXPECT_NEAR(half.trans_m.rmse, 0.05, 1e-12);
  EXPECT_EQ(half.unit, RpeUnit::kMetres);
  EXPECT_EQ(half.delta, 0.4999);
  // Longer than the path: no pairs.
  EXPECT_EQ(rpeStatistics(pairs, 51, RpeUnit::kFrames).trans_m.n, 0);
  EXPECT_TRUE(std::isnan(rpeStatistics(pairs, 6.0, RpeUnit::kMetres).trans_m.rmse));
  for (const double bad : {0.0, 1.5, -2.0, double(NAN), double(INFINITY)}) {
    const std::string msg = errorOf([&] { rpeStatistics(pairs, bad, RpeUnit::kFrames); });
    EXPECT_NE(msg.find("whole number"), std::string::npos) << bad << ": " << msg;
  }
  EXPECT_THROW(rpeStatistics(pairs, 0.0, RpeUnit::kMetres), std::invalid_argument);
}

TEST(PathLength, SumOfSteps) {
  EXPECT_EQ(pathLength({}), 0.0);
  EXPECT_NEAR(pathLength(stamped({0.0, 1.0, 3.5})), 3.5, 1e-15);
}

}  // namespace
}  // namespace tgnav::vo
