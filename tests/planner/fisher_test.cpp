// Bearing Fisher information (paper Sec. V-D, eqs. 5-6): the Jacobian against finite
// differences under fisher.h's left world-frame perturbation, the rank and symmetry of one
// landmark's information, the camera-centred closed form against the world-frame sum, how
// information grows with landmarks and shrinks with distance, and the regularised log det.
#include "planner/fisher.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <iostream>
#include <limits>
#include <random>
#include <vector>

namespace tgnav::planner {
namespace {

Eigen::Isometry3d randomPose(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = q.toRotationMatrix();
  X.translation() = Eigen::Vector3d(u(rng), u(rng), u(rng));
  return X;
}

// A landmark 0.5 - 6 m from the camera centre in a random direction.
Eigen::Vector3d randomLandmark(const Eigen::Isometry3d& X_WC, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> r(0.5, 6.0);
  const Eigen::Vector3d dir = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
  return X_WC.translation() + r(rng) * dir;
}

Eigen::Matrix3d expSO3(const Eigen::Vector3d& w) {
  const double a = w.norm();
  if (a < 1e-300) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(a, w / a).toRotationMatrix();
}

// X <- Exp(xi) X, xi = (dp, dtheta): rotation about the world origin, then translation.
Eigen::Isometry3d perturb(const Eigen::Isometry3d& X, const Eigen::Matrix<double, 6, 1>& xi) {
  const Eigen::Matrix3d dR = expSO3(xi.tail<3>());
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = dR * X.linear();
  out.translation() = dR * X.translation() + xi.head<3>();
  return out;
}

Eigen::Vector3d bearing(const Eigen::Isometry3d& X_WC, const Eigen::Vector3d& l_W) {
  return (X_WC.inverse() * l_W).normalized();
}

double logDetExact(const Matrix6d& info, double eps) {
  const Eigen::SelfAdjointEigenSolver<Matrix6d> es(info);
  double s = 0.0;
  for (int i = 0; i < 6; ++i) s += std::log(es.eigenvalues()(i) + eps);
  return s;
}

TEST(Fisher, BearingJacobianMatchesCentralDifferences) {
  std::mt19937_64 rng(11);
  const double h = 1e-6;
  double worst = 0.0;
  for (int trial = 0; trial < 500; ++trial) {
    const Eigen::Isometry3d X = randomPose(rng);
    const Eigen::Vector3d l = randomLandmark(X, rng);
    const Matrix36d J = bearingJacobian(X, l);
    Matrix36d fd;
    for (int k = 0; k < 6; ++k) {
      Eigen::Matrix<double, 6, 1> xi = Eigen::Matrix<double, 6, 1>::Zero();
      xi(k) = h;
      fd.col(k) = (bearing(perturb(X, xi), l) - bearing(perturb(X, -xi), l)) / (2.0 * h);
    }
    const double err = (J - fd).cwiseAbs().maxCoeff();
    worst = std::max(worst, err);
    ASSERT_LT(err, 1e-6) << "trial " << trial << "\nJ =\n" << J << "\nfd =\n" << fd;
  }
  // The first-order form of the perturbation: p' = p + dp + dtheta x p (same for the landmark
  // in the camera frame: l_C' = l_C + R^T (-dp - dtheta x l)).
  const Eigen::Isometry3d X = randomPose(rng);
  Eigen::Matrix<double, 6, 1> xi;
  xi << 1e-7, -2e-7, 3e-7, -1e-7, 2e-7, 1e-7;
  const Eigen::Vector3d p1 = perturb(X, xi).translation();
  const Eigen::Vector3d p1_lin = X.translation() + xi.head<3>() + xi.tail<3>().cross(X.translation());
  EXPECT_LT((p1 - p1_lin).norm(), 1e-12);
  std::cout << "[ figure   ] bearing Jacobian vs central differences: worst abs error " << worst << " (500 poses)\n";
}

TEST(Fisher, LandmarkInformationIsSymmetricPsdRankTwo) {
  std::mt19937_64 rng(12);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Isometry3d X = randomPose(rng);
    const Eigen::Vector3d l = randomLandmark(X, rng);
    const double sigma = 0.5 + 0.01 * trial;
    const Matrix36d J = bearingJacobian(X, l);
    const Matrix6d I = landmarkInformation(X, l, sigma);
    EXPECT_LT((I - J.transpose() * J / (sigma * sigma)).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + I.cwiseAbs().maxCoeff()));
    EXPECT_LT((I - I.transpose()).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + I.cwiseAbs().maxCoeff()));
    const Eigen::SelfAdjointEigenSolver<Matrix6d> es(I);
    const auto& ev = es.eigenvalues();  // ascending
    const double top = ev(5);
    ASSERT_GT(top, 0.0);
    for (int i = 0; i < 4; ++i)
      EXPECT_LT(std::abs(ev(i)), 1e-10 * top) << "trial " << trial << " ev " << ev.transpose();
    EXPECT_GT(ev(4), 1e-6 * top) << "trial " << trial;
    EXPECT_GT(ev(5), 0.0);
  }
}

TEST(Fisher, CentredInformationHasTheWorldFrameDeterminantForAnyRotation) {
  std::mt19937_64 rng(13);
  double worst = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Isometry3d X = randomPose(rng);
    const int n = 3 + trial % 8;
    const double sigma = 0.2 + 0.01 * (trial % 50);
    Matrix6d world = Matrix6d::Zero();
    Matrix6d centred = Matrix6d::Zero();
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector3d l = randomLandmark(X, rng);
      const double w = 1.0 + (k % 3);
      world += w * landmarkInformation(X, l, sigma);
      addCentredInformation(X.translation(), l, w, sigma, &centred);
    }
    const double dw = world.determinant();
    const double dc = centred.determinant();
    ASSERT_GT(dc, 0.0) << "trial " << trial;
    const double rel = std::abs(dw - dc) / std::abs(dc);
    worst = std::max(worst, rel);
    EXPECT_LT(rel, 1e-9) << "trial " << trial << " det world " << dw << " centred " << dc;
    // Stronger: the world-frame information is the congruence T^T I_c T with
    // T = [[I, -[p]x], [0, I]] (unimodular): moving the origin to the camera.
    const Eigen::Vector3d p = X.translation();
    Eigen::Matrix3d px;
    px << 0, -p.z(), p.y(), p.z(), 0, -p.x(), -p.y(), p.x(), 0;
    Matrix6d T = Matrix6d::Identity();
    T.topRightCorner<3, 3>() = -px;
    const Matrix6d back = T.transpose() * centred * T;
    EXPECT_LT((back - world).cwiseAbs().maxCoeff(), 1e-9 * world.cwiseAbs().maxCoeff()) << "trial " << trial;
  }
  // The centred form has no rotation: the same landmarks under two camera rotations give the
  // same world-frame determinant.
  const Eigen::Vector3d c(1.0, -2.0, 0.5);
  std::vector<Eigen::Vector3d> ls;
  Eigen::Isometry3d X0 = Eigen::Isometry3d::Identity();
  X0.translation() = c;
  for (int k = 0; k < 6; ++k) ls.push_back(randomLandmark(X0, rng));
  Matrix6d centred = Matrix6d::Zero();
  for (const auto& l : ls) addCentredInformation(c, l, 1.0, 1.0, &centred);
  for (int r = 0; r < 10; ++r) {
    Eigen::Isometry3d X = randomPose(rng);
    X.translation() = c;
    Matrix6d world = Matrix6d::Zero();
    for (const auto& l : ls) world += landmarkInformation(X, l, 1.0);
    EXPECT_NEAR(world.determinant() / centred.determinant(), 1.0, 1e-9);
    // (The regularised score is not frame-invariant: + eps I does not commute with the congruence.)
  }
  std::cout << "[ figure   ] centred vs world-frame det: worst relative difference " << worst << " (200 poses)\n";
}

TEST(Fisher, InformationGrowsWithLandmarksAndShrinksWithDistance) {
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Vector3d cam(0.5, 0.2, 1.0);
  // A cloud of 20 points around a centre 2 m in front of the camera.
  std::vector<Eigen::Vector3d> offsets;
  for (int k = 0; k < 20; ++k) offsets.emplace_back(2.0 + 0.5 * u(rng), u(rng), 0.6 * u(rng));
  auto info = [&](int n, double scale) {
    Matrix6d m = Matrix6d::Zero();
    for (int k = 0; k < n; ++k) addCentredInformation(cam, cam + scale * offsets[k], 1.0, 1.0, &m);
    return m;
  };
  const double eps = 1e-2;
  const double ten = logDetInformation(info(10, 1.0), eps);
  const double twenty = logDetInformation(info(20, 1.0), eps);
  EXPECT_GT(twenty, ten);
  std::cout << "[ figure   ] log det with 10 landmarks " << ten << ", with 20 " << twenty << "\n";

  double previous = std::numeric_limits<double>::infinity();
  const double base = std::log(info(20, 1.0).determinant());
  for (double scale : {0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0}) {
    const Matrix6d m = info(20, scale);
    const double ld = logDetInformation(m, eps);
    EXPECT_LT(ld, previous) << "scale " << scale;
    previous = ld;
    // Scaling every distance by s scales the translation block by 1/s: det falls as s^-6.
    EXPECT_NEAR(std::log(m.determinant()), base - 6.0 * std::log(scale), 1e-6) << "scale " << scale;
    std::cout << "[ figure   ] landmark cloud at " << 2.0 * scale << " m: log det " << ld << "\n";
  }
  // Same with the world-frame form under a rotated camera.
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  X.translation() = cam;
  double prev_world = std::numeric_limits<double>::infinity();
  for (double scale : {1.0, 2.0, 4.0}) {
    Matrix6d m = Matrix6d::Zero();
    for (const auto& o : offsets) m += landmarkInformation(X, cam + scale * o, 1.0);
    const double ld = logDetInformation(m, eps);
    EXPECT_LT(ld, prev_world);
    prev_world = ld;
  }
}

TEST(Fisher, RegularisedLogDetOfRankDeficientInformation) {
  const double eps = 1e-2;
  // No landmark: exactly the floor 6 ln(eps).
  const double none = logDetInformation(Matrix6d::Zero(), eps);
  // Within a few ulps, not bit for bit: the Cholesky route sums 2 log sqrt(eps) six times
  // (3.6e-15 off for eps = 0.01).
  EXPECT_DOUBLE_EQ(none, 6.0 * std::log(eps));
  for (double e : {1e-6, 1e-3, 1.0, 7.5}) EXPECT_NEAR(logDetInformation(Matrix6d::Zero(), e), 6.0 * std::log(e), 1e-12);

  std::mt19937_64 rng(15);
  for (int trial = 0; trial < 100; ++trial) {
    const Eigen::Isometry3d X = randomPose(rng);
    const Eigen::Vector3d l = randomLandmark(X, rng);
    // One landmark: rank 2, det 0, but the regularised score is finite and exact.
    const Matrix6d world = landmarkInformation(X, l, 1.0);
    Matrix6d centred = Matrix6d::Zero();
    addCentredInformation(X.translation(), l, 1.0, 1.0, &centred);
    for (const Matrix6d* m : std::vector<const Matrix6d*>{&world, &centred}) {
      const double ld = logDetInformation(*m, eps);
      ASSERT_TRUE(std::isfinite(ld)) << "trial " << trial;
      EXPECT_NEAR(ld, logDetExact(*m, eps), 1e-8) << "trial " << trial;
      EXPECT_GT(ld, 6.0 * std::log(eps));  // one landmark adds information
    }
    // Two landmarks: rank 4, still finite and exact.
    Matrix6d two = centred;
    addCentredInformation(X.translation(), randomLandmark(X, rng), 2.0, 1.0, &two);
    EXPECT_NEAR(logDetInformation(two, eps), logDetExact(two, eps), 1e-8);
  }
  // A landmark at the camera centre has no bearing: it adds nothing (and no NaN).
  Matrix6d m = Matrix6d::Zero();
  addCentredInformation(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(1, 2, 3), 1.0, 1.0, &m);
  EXPECT_TRUE(m.isZero(0.0));
}

}  // namespace
}  // namespace tgnav::planner
