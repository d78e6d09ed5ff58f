#include "vo/pose_refine.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

namespace tgnav::vo {

namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// The depth residual of point i at camera-frame depth z, if it has a measured depth.
struct DepthResidual {
  const PoseDepth& depth;
  bool has(std::size_t i) const {
    if (depth.depth_m == nullptr) return false;
    const double z = (*depth.depth_m)[i];
    return std::isfinite(z) && z > 0.0;
  }
  double at(std::size_t i, double z) const {
    return (depth.bf_px / z - depth.bf_px / (*depth.depth_m)[i]) / depth.depth_sigma_px;
  }
};

struct Cost {
  double pixels = 0.0;  // sum of squared reprojection errors
  double total = 0.0;   // with the depth residuals'
};

// The cost at X_CW; +inf where a point lands on the camera plane.
Cost poseCost(const std::vector<cv::Point3d>& p_W, const std::vector<cv::Point2d>& uv, const CameraIntrinsics& c,
              const DepthResidual& depth, const Eigen::Isometry3d& X_CW) {
  const Eigen::Matrix3d R = X_CW.linear();
  const Eigen::Vector3d t = X_CW.translation();
  Cost cost;
  double d2 = 0.0;
  for (std::size_t i = 0; i < p_W.size(); ++i) {
    const Eigen::Vector3d q = R * Eigen::Vector3d(p_W[i].x, p_W[i].y, p_W[i].z) + t;
    if (q.z() == 0.0) return Cost{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
    const double du = c.fx * q.x() / q.z() + c.cx - uv[i].x;
    const double dv = c.fy * q.y() / q.z() + c.cy - uv[i].y;
    cost.pixels += du * du + dv * dv;
    if (depth.has(i)) {
      const double r = depth.at(i, q.z());
      d2 += r * r;
    }
  }
  cost.total = cost.pixels + d2;
  if (!std::isfinite(cost.total)) cost.total = std::numeric_limits<double>::infinity();
  return cost;
}

// The normal equations at X_CW for a step d = (w, v) applied on the left, X' = (Exp(w), v) X:
// dq/dw = -[q]x, dq/dv = I at d = 0.
void normalEquations(const std::vector<cv::Point3d>& p_W, const std::vector<cv::Point2d>& uv, const CameraIntrinsics& c,
                     const DepthResidual& depth, const Eigen::Isometry3d& X_CW, Mat6* H, Vec6* g) {
  H->setZero();
  g->setZero();
  const Eigen::Matrix3d R = X_CW.linear();
  const Eigen::Vector3d t = X_CW.translation();
  for (std::size_t i = 0; i < p_W.size(); ++i) {
    const Eigen::Vector3d q = R * Eigen::Vector3d(p_W[i].x, p_W[i].y, p_W[i].z) + t;
    const double iz = 1.0 / q.z();
    const Eigen::Vector2d r(c.fx * q.x() * iz + c.cx - uv[i].x, c.fy * q.y() * iz + c.cy - uv[i].y);
    Eigen::Matrix<double, 2, 3> dpi;  // d(pixel)/dq
    dpi << c.fx * iz, 0.0, -c.fx * q.x() * iz * iz, 0.0, c.fy * iz, -c.fy * q.y() * iz * iz;
    Eigen::Matrix<double, 3, 6> dq;
    dq << 0.0, q.z(), -q.y(), 1.0, 0.0, 0.0,  //
        -q.z(), 0.0, q.x(), 0.0, 1.0, 0.0,    //
        q.y(), -q.x(), 0.0, 0.0, 0.0, 1.0;
    const Eigen::Matrix<double, 2, 6> J = dpi * dq;
    H->noalias() += J.transpose() * J;
    g->noalias() += J.transpose() * r;
    if (depth.has(i)) {
      // d(residual)/dq = (0, 0, -bf / z^2) / sigma.
      const Eigen::Matrix<double, 1, 6> Jd = (-depth.depth.bf_px * iz * iz / depth.depth.depth_sigma_px) * dq.row(2);
      H->noalias() += Jd.transpose() * Jd;
      g->noalias() += Jd.transpose() * depth.at(i, q.z());
    }
  }
}

Eigen::Isometry3d applyStep(const Vec6& d, const Eigen::Isometry3d& X) {
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d w = d.head<3>();
  const double angle = w.norm();
  if (angle > 0.0) step.linear() = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
  step.translation() = d.tail<3>();
  return step * X;
}

}  // namespace

PoseRefinement refinePoseLm(const std::vector<cv::Point3d>& p_W, const std::vector<cv::Point2d>& uv,
                            const CameraIntrinsics& camera, Eigen::Isometry3d* X_CW, int max_iterations,
                            const PoseDepth& pose_depth) {
  PoseRefinement result;
  if (p_W.size() != uv.size() || p_W.size() < 3 || !X_CW->matrix().allFinite()) return result;
  if (pose_depth.depth_m != nullptr && pose_depth.depth_m->size() != p_W.size()) return result;
  const DepthResidual depth{pose_depth};
  Eigen::Isometry3d X = *X_CW;
  Cost at = poseCost(p_W, uv, camera, depth, X);
  double cost = at.total;
  if (!std::isfinite(cost)) return result;
  double lambda = 1e-3;
  Mat6 H;
  Vec6 g;
  for (int it = 0; it < max_iterations; ++it) {
    normalEquations(p_W, uv, camera, depth, X, &H, &g);
    ++result.iterations;
    bool moved = false, converged = false;
    while (lambda < 1e12) {
      Mat6 A = H;
      A.diagonal() += lambda * H.diagonal().cwiseMax(1e-12);
      const Vec6 d = A.ldlt().solve(-g);
      if (!d.allFinite()) break;
      const Eigen::Isometry3d candidate = applyStep(d, X);
      const Cost candidate_at = poseCost(p_W, uv, camera, depth, candidate);
      const double candidate_cost = candidate_at.total;
      if (candidate_cost < cost) {
        converged = d.norm() <= 1e-10 * (1.0 + X.translation().norm()) || cost - candidate_cost <= 1e-14 * cost;
        X = candidate;
        cost = candidate_cost;
        at = candidate_at;
        lambda = std::max(lambda * 0.1, 1e-12);
        moved = true;
        break;
      }
      lambda *= 10.0;
    }
    if (!moved || converged) break;  // no step lowers the cost: at the minimum (to rounding)
  }
  if (!X.matrix().allFinite()) return result;
  *X_CW = X;
  result.ok = true;
  result.rms_px = std::sqrt(at.pixels / static_cast<double>(p_W.size()));
  return result;
}

}  // namespace tgnav::vo
