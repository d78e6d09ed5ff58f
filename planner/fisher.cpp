#include "planner/fisher.h"

#include <Eigen/Cholesky>
#include <cmath>

namespace tgnav::planner {

namespace {
Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return s;
}
}  // namespace

Matrix36d bearingJacobian(const Eigen::Isometry3d& X_WC, const Eigen::Vector3d& l_W) {
  const Eigen::Vector3d l_C = X_WC.inverse() * l_W;
  const double d = l_C.norm();
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() / d - l_C * l_C.transpose() / (d * d * d);
  Matrix36d A;
  A << -Eigen::Matrix3d::Identity(), skew(l_W);
  return P * X_WC.linear().transpose() * A;
}

Matrix6d landmarkInformation(const Eigen::Isometry3d& X_WC, const Eigen::Vector3d& l_W, double sigma_rad) {
  const Matrix36d J = bearingJacobian(X_WC, l_W);
  return J.transpose() * J / (sigma_rad * sigma_rad);
}

void addCentredInformation(const Eigen::Vector3d& p_W, const Eigen::Vector3d& l_W, double weight, double sigma_rad,
                           Matrix6d* info) {
  const Eigen::Vector3d r = l_W - p_W;
  const double d = r.norm();
  if (!(d > 1e-9)) return;  // a landmark at the camera centre has no bearing
  const Eigen::Vector3d u = r / d;
  const double w = weight / (sigma_rad * sigma_rad);
  const Eigen::Matrix3d M = Eigen::Matrix3d::Identity() - u * u.transpose();
  const Eigen::Matrix3d S = skew(u) * (w / d);
  info->topLeftCorner<3, 3>() += M * (w / (d * d));
  info->topRightCorner<3, 3>() -= S;
  info->bottomLeftCorner<3, 3>() += S;
  info->bottomRightCorner<3, 3>() += M * w;
}

double logDetInformation(const Matrix6d& info, double epsilon) {
  const Eigen::LLT<Matrix6d> llt(info + epsilon * Matrix6d::Identity());
  const auto& L = llt.matrixLLT();
  double s = 0.0;
  for (int i = 0; i < 6; ++i) s += std::log(L(i, i));
  return 2.0 * s;
}

}  // namespace tgnav::planner
