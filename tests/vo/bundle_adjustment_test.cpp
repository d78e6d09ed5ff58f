// Local bundle adjustment on synthetic windows: keyframes along a path looking at landmarks
// spread in front of them, observed exactly (pixels and depth); perturbed poses and landmarks
// must come back to the truth, outliers must be found, the gauge must not move.
#include "vo/bundle_adjustment.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

namespace tgnav::vo {
namespace {

const CameraIntrinsics kCamera{640, 480, 500.0, 500.0, 319.5, 239.5};

struct Window {
  std::vector<Eigen::Isometry3d> X_CW_true;
  std::vector<Eigen::Vector3d> p_W_true;
  BaProblem problem;
};

// `keyframes` cameras 0.3 m apart along world x, looking along +z; landmarks 2-6 m ahead; every
// landmark each keyframe sees in its image is observed (with depth when `depth`).
Window makeWindow(int keyframes, int landmarks, bool depth, unsigned seed) {
  Window w;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> x(-2.0, 3.0), y(-1.5, 1.5), z(2.0, 6.0);
  for (int k = 0; k < keyframes; ++k) {
    Eigen::Isometry3d X_WC = Eigen::Isometry3d::Identity();
    X_WC.translation() = Eigen::Vector3d(0.3 * k, 0.02 * k, 0.0);
    X_WC.linear() = Eigen::AngleAxisd(0.03 * k, Eigen::Vector3d::UnitY()).toRotationMatrix();
    w.X_CW_true.push_back(X_WC.inverse());
  }
  for (int l = 0; l < landmarks; ++l) w.p_W_true.emplace_back(x(rng), y(rng), z(rng));
  for (int k = 0; k < keyframes; ++k) {
    for (int l = 0; l < landmarks; ++l) {
      const Eigen::Vector3d q = w.X_CW_true[static_cast<std::size_t>(k)] * w.p_W_true[static_cast<std::size_t>(l)];
      if (q.z() < 0.5) continue;
      const Eigen::Vector2d uv(kCamera.fx * q.x() / q.z() + kCamera.cx, kCamera.fy * q.y() / q.z() + kCamera.cy);
      if (uv.x() < 0 || uv.y() < 0 || uv.x() > kCamera.width_px - 1 || uv.y() > kCamera.height_px - 1) continue;
      BaObservation o;
      o.keyframe = k;
      o.landmark = l;
      o.uv = uv;
      o.depth_m = depth ? q.z() : 0.0;
      w.problem.observations.push_back(o);
    }
  }
  w.problem.X_CW = w.X_CW_true;
  w.problem.fixed.assign(static_cast<std::size_t>(keyframes), false);
  w.problem.fixed[0] = true;
  w.problem.p_W = w.p_W_true;
  return w;
}

// Moves every free pose by ~`t` m and ~`r` rad and every landmark by ~`p` m.
void perturb(BaProblem* problem, double t, double r, double p, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  for (std::size_t k = 0; k < problem->X_CW.size(); ++k) {
    if (problem->fixed[k]) continue;
    Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
    d.translation() = t * Eigen::Vector3d(n(rng), n(rng), n(rng));
    d.linear() = Eigen::AngleAxisd(r, Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized()).toRotationMatrix();
    problem->X_CW[k] = d * problem->X_CW[k];
  }
  for (Eigen::Vector3d& q : problem->p_W) q += p * Eigen::Vector3d(n(rng), n(rng), n(rng));
}

double poseError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.inverse().translation() - b.inverse().translation()).norm();
}

// Each test of the optimiser runs with both solvers: the Schur-complement one written for this
// problem (the default) and Ceres (the reference).
class BundleAdjustmentSolvers : public ::testing::TestWithParam<BaSolver> {
 protected:
  BundleAdjustmentConfig config() const {
    BundleAdjustmentConfig c;
    c.solver = GetParam();
    return c;
  }
};
INSTANTIATE_TEST_SUITE_P(Solvers, BundleAdjustmentSolvers, ::testing::Values(BaSolver::kSchur, BaSolver::kCeres),
                         [](const ::testing::TestParamInfo<BaSolver>& info) {
                           return info.param == BaSolver::kSchur ? std::string("schur") : std::string("ceres");
                         });

TEST_P(BundleAdjustmentSolvers, RecoversPerturbedPosesAndLandmarksWithDepth) {
  Window w = makeWindow(5, 300, /*depth=*/true, 1);
  perturb(&w.problem, 0.05, 0.02, 0.05, 2);
  const Eigen::Isometry3d fixed_before = w.problem.X_CW[0];
  const BaReport report = bundleAdjust(&w.problem, kCamera, config());
  ASSERT_TRUE(report.solved);
  EXPECT_EQ(report.outliers, 0);
  EXPECT_LT(report.final_cost, 1e-6 * report.initial_cost);
  EXPECT_TRUE(w.problem.X_CW[0].matrix() == fixed_before.matrix());  // the gauge, bit for bit
  for (std::size_t k = 1; k < w.X_CW_true.size(); ++k) {
    EXPECT_LT(poseError(w.problem.X_CW[k], w.X_CW_true[k]), 1e-4) << "keyframe " << k;
    EXPECT_LT(Eigen::AngleAxisd(w.problem.X_CW[k].linear() * w.X_CW_true[k].linear().transpose()).angle(), 1e-5);
  }
  std::vector<bool> observed(w.p_W_true.size(), false);
  for (const BaObservation& o : w.problem.observations) observed[static_cast<std::size_t>(o.landmark)] = true;
  for (std::size_t l = 0; l < w.p_W_true.size(); ++l) {
    if (!observed[l]) continue;  // not in the problem: left as it was
    EXPECT_LT((w.problem.p_W[l] - w.p_W_true[l]).norm(), 1e-3) << "landmark " << l;
  }
}

// Without depth, two fixed keyframes set the scale (monocular BA's gauge).
TEST_P(BundleAdjustmentSolvers, ReprojectionAloneConvergesWithTwoFixedKeyframes) {
  Window w = makeWindow(5, 300, /*depth=*/false, 3);
  w.problem.fixed[1] = true;
  perturb(&w.problem, 0.02, 0.01, 0.02, 4);
  BundleAdjustmentConfig config = this->config();
  config.max_iterations = 50;
  const BaReport report = bundleAdjust(&w.problem, kCamera, config);
  ASSERT_TRUE(report.solved);
  for (std::size_t k = 2; k < w.X_CW_true.size(); ++k) {
    EXPECT_LT(poseError(w.problem.X_CW[k], w.X_CW_true[k]), 1e-3) << "keyframe " << k;
  }
}

// Observations moved 40 px off (mismatches) are flagged and do not pull the poses.
TEST_P(BundleAdjustmentSolvers, FlagsGrossOutliersAndIgnoresThem) {
  Window w = makeWindow(5, 300, /*depth=*/true, 5);
  std::vector<bool> corrupted(w.problem.observations.size(), false);
  for (std::size_t i = 7; i < w.problem.observations.size(); i += 25) {
    w.problem.observations[i].uv += Eigen::Vector2d(40.0, -25.0);
    corrupted[i] = true;
  }
  perturb(&w.problem, 0.03, 0.01, 0.0, 6);
  const BaReport report = bundleAdjust(&w.problem, kCamera, config());
  ASSERT_TRUE(report.solved);
  int caught = 0, false_alarms = 0;
  for (std::size_t i = 0; i < corrupted.size(); ++i) {
    if (report.outlier[i] && corrupted[i]) ++caught;
    if (report.outlier[i] && !corrupted[i]) ++false_alarms;
  }
  const int planted = static_cast<int>(std::count(corrupted.begin(), corrupted.end(), true));
  EXPECT_EQ(caught, planted) << "iterations " << report.iterations << " cost " << report.initial_cost << " -> "
                             << report.final_cost;
  EXPECT_LE(false_alarms, planted / 10);
  EXPECT_EQ(report.outliers, caught + false_alarms);
  for (std::size_t k = 1; k < w.X_CW_true.size(); ++k) {
    EXPECT_LT(poseError(w.problem.X_CW[k], w.X_CW_true[k]), 2e-3) << "keyframe " << k;
  }
}

// A keypoint on a coarse pyramid level (large sigma) weighs less: the same pixel error is not an
// outlier there.
TEST_P(BundleAdjustmentSolvers, CoarseKeypointsAreWeightedByTheirScale) {
  Window w = makeWindow(3, 200, /*depth=*/true, 7);
  for (BaObservation& o : w.problem.observations) {
    if (o.keyframe == 2 && o.landmark % 2 == 0) {
      o.uv += Eigen::Vector2d(3.0, 0.0);
      o.sigma_px = 1.2 * 1.2 * 1.2 * 1.2 * 1.2 * 1.2;  // octave 6
    }
  }
  const BaReport report = bundleAdjust(&w.problem, kCamera, config());
  ASSERT_TRUE(report.solved);
  EXPECT_EQ(report.outliers, 0);
}

TEST_P(BundleAdjustmentSolvers, NothingToDoWithoutAFreeKeyframe) {
  Window w = makeWindow(3, 50, true, 8);
  w.problem.fixed.assign(3, true);
  const BaReport report = bundleAdjust(&w.problem, kCamera, config());
  EXPECT_FALSE(report.solved);
  EXPECT_EQ(report.outliers, 0);
}

TEST(BundleAdjustment, RefusesBadIndicesAndConfigs) {
  Window w = makeWindow(3, 50, true, 9);
  w.problem.observations[0].landmark = 50;
  EXPECT_THROW(bundleAdjust(&w.problem, kCamera, BundleAdjustmentConfig{}), std::invalid_argument);
  w = makeWindow(3, 50, true, 9);
  w.problem.fixed.pop_back();
  EXPECT_THROW(bundleAdjust(&w.problem, kCamera, BundleAdjustmentConfig{}), std::invalid_argument);
  BundleAdjustmentConfig bad;
  bad.virtual_baseline_m = 0.0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  bad = BundleAdjustmentConfig{};
  bad.depth_sigma_px = -1.0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  bad = BundleAdjustmentConfig{};
  bad.fixed_keyframes = 0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

// A landmark observed once is placed on its observation from the adjusted pose (at the observed
// depth, or without depth at the depth it had), and does not move the poses.
TEST_P(BundleAdjustmentSolvers, LandmarksObservedOnceArePlacedOnTheirObservation) {
  Window w = makeWindow(5, 200, true, 21);
  perturb(&w.problem, 0.03, 0.01, 0.03, 22);
  Window without = w;
  // Two more landmarks, each seen by keyframe 3 only: one with depth, one without.
  const std::size_t k = 3;
  for (bool depth : {true, false}) {
    BaObservation o;
    o.keyframe = static_cast<int>(k);
    o.landmark = static_cast<int>(w.problem.p_W.size());
    o.uv = Eigen::Vector2d(depth ? 100.0 : 500.0, 300.0);
    o.depth_m = depth ? 4.0 : 0.0;
    w.problem.observations.push_back(o);
    // Off its ray by ~0.1 m, at 3.5 m in front of the (perturbed) keyframe.
    w.problem.p_W.push_back(w.problem.X_CW[k].inverse() * Eigen::Vector3d(depth ? -1.3 : 1.2, 0.5, 3.5));
  }
  const Eigen::Vector3d before_mono = w.problem.X_CW[k] * w.problem.p_W.back();
  const BaReport report = bundleAdjust(&w.problem, kCamera, config());
  bundleAdjust(&without.problem, kCamera, config());
  ASSERT_TRUE(report.solved);
  EXPECT_EQ(report.outliers, 0);
  for (std::size_t j = 0; j < w.problem.X_CW.size(); ++j) {
    EXPECT_TRUE(w.problem.X_CW[j].matrix() == without.problem.X_CW[j].matrix()) << "keyframe " << j;
  }
  for (std::size_t i = w.problem.observations.size() - 2; i < w.problem.observations.size(); ++i) {
    const BaObservation& o = w.problem.observations[i];
    const Eigen::Vector3d& p_W = w.problem.p_W[static_cast<std::size_t>(o.landmark)];
    const Eigen::Vector3d q = w.problem.X_CW[k] * p_W;
    const double u = kCamera.fx * q.x() / q.z() + kCamera.cx, v = kCamera.fy * q.y() / q.z() + kCamera.cy;
    EXPECT_NEAR(u, o.uv.x(), 1e-9);
    EXPECT_NEAR(v, o.uv.y(), 1e-9);
    EXPECT_NEAR(q.z(), o.depth_m > 0.0 ? o.depth_m : before_mono.z(), 1e-9);
  }
}

// The analytic Jacobians equal central differences, at rotations of every size (zero, below the
// series threshold, large), with and without depth, at a coarse octave.
TEST(BundleAdjustment, AnalyticJacobiansMatchFiniteDifferences) {
  BundleAdjustmentConfig config;
  const Eigen::Vector3d axes[] = {Eigen::Vector3d(0.3, -0.5, 0.8).normalized(), Eigen::Vector3d(1, 0, 0)};
  for (double angle : {0.0, 1e-6, 3e-4, 0.4, 2.9}) {
    for (const Eigen::Vector3d& axis : axes) {
      for (bool depth : {true, false}) {
        Eigen::Matrix<double, 6, 1> pose;
        pose << angle * axis, 0.2, -0.1, 0.3;
        const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
        // A landmark 3 m in front of the camera, off its axis.
        const Eigen::Vector3d p_W = R.transpose() * (Eigen::Vector3d(0.7, -0.4, 3.0) - pose.tail<3>());
        BaObservation o;
        o.uv = Eigen::Vector2d(400.0, 200.0);
        o.depth_m = depth ? 2.9 : 0.0;
        o.sigma_px = 1.44;
        Eigen::Vector3d r;
        Eigen::Matrix<double, 3, 6> J_pose;
        Eigen::Matrix3d J_point;
        const int n = observationResiduals(kCamera, o, config, pose, p_W, &r, &J_pose, &J_point);
        ASSERT_EQ(n, depth ? 3 : 2);
        Eigen::Matrix<double, 3, 6> N_pose;
        Eigen::Matrix3d N_point;
        Eigen::Matrix<double, 3, 6> unused_pose;
        Eigen::Matrix3d unused_point;
        const double h = 1e-6;
        for (int i = 0; i < 9; ++i) {
          Eigen::Matrix<double, 6, 1> pp = pose, pm = pose;
          Eigen::Vector3d lp = p_W, lm = p_W;
          if (i < 6) {
            pp[i] += h;
            pm[i] -= h;
          } else {
            lp[i - 6] += h;
            lm[i - 6] -= h;
          }
          Eigen::Vector3d rp, rm;
          observationResiduals(kCamera, o, config, pp, lp, &rp, &unused_pose, &unused_point);
          observationResiduals(kCamera, o, config, pm, lm, &rm, &unused_pose, &unused_point);
          const Eigen::Vector3d d = (rp - rm) / (2.0 * h);
          if (i < 6) {
            N_pose.col(i) = d;
          } else {
            N_point.col(i - 6) = d;
          }
        }
        const double scale = std::max(1.0, N_pose.cwiseAbs().maxCoeff());
        EXPECT_LT((J_pose - N_pose).cwiseAbs().maxCoeff(), 1e-5 * scale) << "angle " << angle << " depth " << depth;
        EXPECT_LT((J_point - N_point).cwiseAbs().maxCoeff(), 1e-5 * scale) << "angle " << angle << " depth " << depth;
        if (!depth) {
          EXPECT_EQ(J_pose.row(2).norm(), 0.0);
        }
      }
    }
  }
}

// The same problem gives the same result, bit for bit (one thread, fixed ordering).
TEST_P(BundleAdjustmentSolvers, Deterministic) {
  Window a = makeWindow(5, 200, true, 10);
  perturb(&a.problem, 0.05, 0.02, 0.05, 11);
  Window b = a;
  bundleAdjust(&a.problem, kCamera, config());
  bundleAdjust(&b.problem, kCamera, config());
  for (std::size_t k = 0; k < a.problem.X_CW.size(); ++k) {
    EXPECT_TRUE(a.problem.X_CW[k].matrix() == b.problem.X_CW[k].matrix());
  }
  for (std::size_t l = 0; l < a.problem.p_W.size(); ++l) EXPECT_TRUE(a.problem.p_W[l] == b.problem.p_W[l]);
}

// The Schur solver takes Ceres's steps: on windows with and without depth, one or two fixed
// keyframes, planted mismatches and perturbed starts, both end at the same poses and landmarks
// (to rounding), with the same outliers, iterations and costs.
TEST(BundleAdjustment, SchurSolverAgreesWithCeres) {
  for (unsigned seed = 30; seed < 36; ++seed) {
    const bool depth = seed % 3 != 0;
    Window w = makeWindow(6, 250, depth, seed);
    if (!depth) w.problem.fixed[1] = true;
    for (std::size_t i = seed % 7; i < w.problem.observations.size(); i += 31) {
      w.problem.observations[i].uv += Eigen::Vector2d(25.0, 30.0);
    }
    for (std::size_t i = 0; i < w.problem.observations.size(); i += 5) w.problem.observations[i].depth_m = 0.0;
    perturb(&w.problem, 0.04, 0.015, 0.04, seed + 100);
    BaProblem schur = w.problem, ceres = w.problem;
    BundleAdjustmentConfig config;
    config.solver = BaSolver::kSchur;
    const BaReport a = bundleAdjust(&schur, kCamera, config);
    config.solver = BaSolver::kCeres;
    const BaReport b = bundleAdjust(&ceres, kCamera, config);
    ASSERT_TRUE(a.solved && b.solved) << "seed " << seed;
    EXPECT_EQ(a.outlier, b.outlier) << "seed " << seed;
    EXPECT_EQ(a.iterations, b.iterations) << "seed " << seed;
    EXPECT_NEAR(a.initial_cost, b.initial_cost, 1e-9 * b.initial_cost) << "seed " << seed;
    EXPECT_NEAR(a.final_cost, b.final_cost, 1e-6 * b.final_cost + 1e-12) << "seed " << seed;
    for (std::size_t k = 0; k < schur.X_CW.size(); ++k) {
      EXPECT_LT(poseError(schur.X_CW[k], ceres.X_CW[k]), 1e-8) << "seed " << seed << " keyframe " << k;
    }
    for (std::size_t l = 0; l < schur.p_W.size(); ++l) {
      EXPECT_LT((schur.p_W[l] - ceres.p_W[l]).norm(), 1e-7) << "seed " << seed << " landmark " << l;
    }
  }
}

}  // namespace
}  // namespace tgnav::vo
