#pragma once
// The bundle adjustment's model, shared by its two solvers (vo/bundle_adjustment.cpp: Ceres;
// vo/ba_schur.cpp: Levenberg-Marquardt on the Schur complement): the pose parameters, the
// analytic residuals of one observation, the outlier thresholds. Not an API.
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "vo/bundle_adjustment.h"

namespace tgnav::vo::ba_detail {

// Chi-square 95 % points for 2 and 3 degrees of freedom (ORB-SLAM2's outlier thresholds).
constexpr double kChi2Mono = 5.991;
constexpr double kChi2Stereo = 7.815;

inline Eigen::Matrix3d skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d S;
  S << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return S;
}

// What every observation of one pose needs: R(r) and R(r) J_r(r), with J_r the right Jacobian of
// SO(3), J_r(r) = I - (1 - cos th) / th^2 [r]x + (th - sin th) / th^3 [r]x^2 (its series near 0).
struct PoseTerms {
  Eigen::Matrix3d R;
  Eigen::Matrix3d RJ;
};

inline PoseTerms poseTerms(const double* pose) {
  const Eigen::Map<const Eigen::Vector3d> r(pose);
  const double theta = r.norm();
  PoseTerms terms;
  terms.R = theta > 0.0 ? Eigen::AngleAxisd(theta, r / theta).toRotationMatrix() : Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d S = skew(r);
  double a = 0.5, b = 1.0 / 6.0;
  if (theta > 1e-4) {
    const double theta2 = theta * theta;
    a = (1.0 - std::cos(theta)) / theta2;
    b = (theta - std::sin(theta)) / (theta2 * theta);
  }
  terms.RJ = terms.R * (Eigen::Matrix3d::Identity() - a * S + b * S * S);
  return terms;
}

// PoseTerms of one keyframe's pose, recomputed only when the pose's values change: Ceres
// evaluates all of a pose's observations at the same values, hundreds of them, and the
// trigonometry was the larger part of each. Not thread-safe: the solver runs on one thread.
class PoseTermsCache {
 public:
  const PoseTerms& at(const double* pose) {
    if (!valid_ || !std::equal(pose, pose + 6, key_.begin())) {
      std::copy(pose, pose + 6, key_.begin());
      terms_ = poseTerms(pose);
      valid_ = true;
    }
    return terms_;
  }

 private:
  bool valid_ = false;
  std::array<double, 6> key_{};
  PoseTerms terms_;
};

// Residuals of one observation, weighted by 1/sigma: (u, v) and, with depth, the disparity.
// The pose parameters are the angle-axis r of R_CW, then t_CW; the point is p_W.
//   q = R(r) p_W + t,   dq/dr = -R [p_W]x J_r(r),   dq/dt = I,   dq/dp_W = R,
// with J_r the right Jacobian of SO(3) (R(r + d) = R(r) Exp(J_r(r) d) to first order), so
// dq/dr = -[R p_W]x R J_r.
// Analytic: automatic differentiation (9 dual numbers per value) took a third of the BA's time.
struct ObservationResidual {
  ObservationResidual(const CameraIntrinsics& c, const BaObservation& o, double bf, double depth_sigma_px)
      : fx(c.fx),
        fy(c.fy),
        cx(c.cx),
        cy(c.cy),
        u(o.uv.x()),
        v(o.uv.y()),
        bf(bf),
        inv_sigma(1.0 / o.sigma_px),
        inv_sigma_depth(1.0 / depth_sigma_px) {
    with_depth = std::isfinite(o.depth_m) && o.depth_m > 0.0;
    disparity = with_depth ? bf / o.depth_m : 0.0;
  }

  int size() const { return with_depth ? 3 : 2; }

  // The residuals (size()) and, where the pointers are not null, their row-major Jacobians
  // (size() x 6 by the pose, size() x 3 by the point). Returns the point's depth in the camera.
  double evaluate(const PoseTerms& terms, const double* pose, const double* point, double* residual, double* J_pose,
                  double* J_point) const {
    const Eigen::Map<const Eigen::Vector3d> t(pose + 3), p(point);
    const Eigen::Matrix3d& R = terms.R;
    const Eigen::Vector3d Rp = R * p;
    const Eigen::Vector3d q = Rp + t;
    const double inv_z = 1.0 / q.z();
    residual[0] = (fx * q.x() * inv_z + cx - u) * inv_sigma;
    residual[1] = (fy * q.y() * inv_z + cy - v) * inv_sigma;
    if (with_depth) residual[2] = (bf * inv_z - disparity) * inv_sigma_depth;
    if (J_pose == nullptr && J_point == nullptr) return q.z();

    // d(residual)/dq, one row per residual.
    Eigen::Matrix<double, 3, 3> D = Eigen::Matrix<double, 3, 3>::Zero();
    D(0, 0) = fx * inv_z * inv_sigma;
    D(0, 2) = -fx * q.x() * inv_z * inv_z * inv_sigma;
    D(1, 1) = fy * inv_z * inv_sigma;
    D(1, 2) = -fy * q.y() * inv_z * inv_z * inv_sigma;
    D(2, 2) = -bf * inv_z * inv_z * inv_sigma_depth;
    const int n = size();
    if (J_pose != nullptr) {
      Eigen::Matrix<double, 3, 6> dq;
      dq.leftCols<3>() = -skew(Rp) * terms.RJ;
      dq.rightCols<3>().setIdentity();
      const Eigen::Matrix<double, 3, 6> J = D * dq;
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>>(J_pose, n, 6) = J.topRows(n);
    }
    if (J_point != nullptr) {
      const Eigen::Matrix3d J = D * R;
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(J_point, n, 3) = J.topRows(n);
    }
    return q.z();
  }

  double fx, fy, cx, cy, u, v, bf, inv_sigma, inv_sigma_depth;
  bool with_depth = false;
  double disparity = 0.0;
};

// One solver pass over the observations marked active: the poses (angle-axis of R_CW, then
// t_CW; those marked fixed stay), the landmarks, and with `robust` a Cauchy loss of scale
// sqrt(chi-square 95 %) on each observation's squared residual (kChi2Mono or kChi2Stereo).
struct PassProblem {
  std::vector<std::array<double, 6>>* poses = nullptr;
  const std::vector<bool>* fixed = nullptr;
  std::vector<Eigen::Vector3d>* points = nullptr;
  const std::vector<ObservationResidual>* residuals = nullptr;
  const std::vector<BaObservation>* observations = nullptr;  // which pose and point each is of
  const std::vector<bool>* active = nullptr;
  bool robust = false;
  int max_iterations = 10;
};

struct PassResult {
  double initial_cost = 0.0;  // 1/2 sum of the (robustified) squared residuals
  double final_cost = 0.0;
  int iterations = 0;      // Ceres's count: the evaluation at the start and each step tried
  bool converged = false;  // a tolerance was met (not the iteration limit, not a failure)
};

// Levenberg-Marquardt with the landmarks eliminated (Schur complement on the free poses), after
// Ceres's trust-region rules: Jacobi scaling, the same radius updates and tolerances, the robust
// loss applied as Ceres applies a Cauchy loss (each residual and its Jacobian scaled by
// sqrt(rho'), rho'' < 0). vo/ba_schur.cpp.
PassResult solveSchurPass(const PassProblem& p);

}  // namespace tgnav::vo::ba_detail
