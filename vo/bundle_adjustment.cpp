#include "vo/bundle_adjustment.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "vo/check.h"

namespace tgnav::vo {

namespace {

// Chi-square 95 % points for 2 and 3 degrees of freedom (ORB-SLAM2's outlier thresholds).
constexpr double kChi2Mono = 5.991;
constexpr double kChi2Stereo = 7.815;

// Residuals of one observation, weighted by 1/sigma: (u, v) and, with depth, u_R.
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

  // pose: angle-axis of R_CW, then t_CW; point: p_W.
  template <typename T>
  bool operator()(const T* const pose, const T* const point, T* residual) const {
    T q[3];
    ceres::AngleAxisRotatePoint(pose, point, q);
    q[0] += pose[3];
    q[1] += pose[4];
    q[2] += pose[5];
    const T inv_z = T(1.0) / q[2];
    const T u_pred = T(fx) * q[0] * inv_z + T(cx);
    residual[0] = (u_pred - T(u)) * T(inv_sigma);
    residual[1] = (T(fy) * q[1] * inv_z + T(cy) - T(v)) * T(inv_sigma);
    if (with_depth) residual[2] = (T(bf) * inv_z - T(disparity)) * T(inv_sigma_depth);
    return true;
  }

  double fx, fy, cx, cy, u, v, bf, inv_sigma, inv_sigma_depth;
  bool with_depth = false;
  double disparity = 0.0;
};

std::array<double, 6> toParameters(const Eigen::Isometry3d& X_CW) {
  std::array<double, 6> p{};
  const Eigen::AngleAxisd aa(X_CW.linear());
  const Eigen::Vector3d r = aa.angle() * aa.axis();
  for (int i = 0; i < 3; ++i) {
    p[static_cast<std::size_t>(i)] = r[i];
    p[static_cast<std::size_t>(i + 3)] = X_CW.translation()[i];
  }
  return p;
}

Eigen::Isometry3d fromParameters(const std::array<double, 6>& p) {
  const Eigen::Vector3d r(p[0], p[1], p[2]);
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  const double angle = r.norm();
  if (angle > 0.0) X.linear() = Eigen::AngleAxisd(angle, r / angle).toRotationMatrix();
  X.translation() = Eigen::Vector3d(p[3], p[4], p[5]);
  return X;
}

// The weighted squared residual of observation `o` (its chi-square value), and whether the
// landmark is in front of the camera.
double chiSquare(const ObservationResidual& r, const std::array<double, 6>& pose, const Eigen::Vector3d& p_W,
                 bool* in_front) {
  std::array<double, 3> res{};
  r(pose.data(), p_W.data(), res.data());
  double q[3];
  ceres::AngleAxisRotatePoint(pose.data(), p_W.data(), q);
  *in_front = q[2] + pose[5] > 0.0;
  return res[0] * res[0] + res[1] * res[1] + (r.with_depth ? res[2] * res[2] : 0.0);
}

}  // namespace

void BundleAdjustmentConfig::validate() const {
  require(std::isfinite(virtual_baseline_m) && virtual_baseline_m > 0.0, "ba.virtual_baseline_m", virtual_baseline_m,
          "must be > 0");
  require(std::isfinite(depth_sigma_px) && depth_sigma_px > 0.0, "ba.depth_sigma_px", depth_sigma_px, "must be > 0");
  require(max_iterations >= 1, "ba.max_iterations", max_iterations, "must be >= 1");
  require(fixed_keyframes >= 1, "ba.fixed_keyframes", fixed_keyframes, "must be >= 1 (the gauge)");
}

BaReport bundleAdjust(BaProblem* problem, const CameraIntrinsics& camera, const BundleAdjustmentConfig& config) {
  BaProblem& P = *problem;
  if (P.fixed.size() != P.X_CW.size()) {
    throw std::invalid_argument("bundleAdjust: " + std::to_string(P.fixed.size()) + " fixed flags for " +
                                std::to_string(P.X_CW.size()) + " keyframes");
  }
  BaReport report;
  report.observations = static_cast<int>(P.observations.size());
  report.outlier.assign(P.observations.size(), false);
  const double bf = camera.fx * config.virtual_baseline_m;

  std::vector<std::array<double, 6>> poses;
  poses.reserve(P.X_CW.size());
  for (const Eigen::Isometry3d& X : P.X_CW) poses.push_back(toParameters(X));
  std::vector<ObservationResidual> residuals;
  residuals.reserve(P.observations.size());
  bool any_free = false;
  for (std::size_t i = 0; i < P.observations.size(); ++i) {
    const BaObservation& o = P.observations[i];
    if (o.keyframe < 0 || o.keyframe >= static_cast<int>(P.X_CW.size()) || o.landmark < 0 ||
        o.landmark >= static_cast<int>(P.p_W.size())) {
      throw std::invalid_argument("bundleAdjust: observation " + std::to_string(i) + " refers to keyframe " +
                                  std::to_string(o.keyframe) + ", landmark " + std::to_string(o.landmark) +
                                  " out of range");
    }
    if (!(o.sigma_px > 0.0) || !o.uv.allFinite()) {
      throw std::invalid_argument("bundleAdjust: observation " + std::to_string(i) + " has a bad pixel or sigma");
    }
    residuals.emplace_back(camera, o, bf, config.depth_sigma_px);
    if (!P.fixed[static_cast<std::size_t>(o.keyframe)]) any_free = true;
  }
  if (!any_free) return report;

  // Two passes: robust (Cauchy), then plain least squares without the outliers the first exposed.
  // One loss object per kind of observation, shared by its residuals.
  ceres::CauchyLoss loss_mono(std::sqrt(kChi2Mono));
  ceres::CauchyLoss loss_stereo(std::sqrt(kChi2Stereo));
  for (int pass = 0; pass < 2; ++pass) {
    ceres::Problem::Options problem_options;
    problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem ceres_problem(problem_options);
    auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
    int blocks = 0;
    for (std::size_t i = 0; i < residuals.size(); ++i) {
      if (report.outlier[i]) continue;
      const BaObservation& o = P.observations[i];
      double* pose = poses[static_cast<std::size_t>(o.keyframe)].data();
      double* point = P.p_W[static_cast<std::size_t>(o.landmark)].data();
      ceres::CostFunction* cost =
          residuals[i].with_depth
              ? static_cast<ceres::CostFunction*>(new ceres::AutoDiffCostFunction<ObservationResidual, 3, 6, 3>(
                    new ObservationResidual(residuals[i])))
              : new ceres::AutoDiffCostFunction<ObservationResidual, 2, 6, 3>(new ObservationResidual(residuals[i]));
      ceres::LossFunction* loss = pass == 0 ? (residuals[i].with_depth ? &loss_stereo : &loss_mono) : nullptr;
      ceres_problem.AddResidualBlock(cost, loss, pose, point);
      ++blocks;
    }
    if (blocks == 0) break;
    for (std::size_t k = 0; k < poses.size(); ++k) {
      double* pose = poses[k].data();
      if (!ceres_problem.HasParameterBlock(pose)) continue;
      ordering->AddElementToGroup(pose, 1);
      if (P.fixed[k]) ceres_problem.SetParameterBlockConstant(pose);
    }
    for (std::size_t l = 0; l < P.p_W.size(); ++l) {
      if (ceres_problem.HasParameterBlock(P.p_W[l].data())) ordering->AddElementToGroup(P.p_W[l].data(), 0);
    }
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_SCHUR;
    options.linear_solver_ordering = ordering;
    options.max_num_iterations = config.max_iterations;
    options.num_threads = 1;
    options.logging_type = ceres::SILENT;
    options.minimizer_progress_to_stdout = false;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &ceres_problem, &summary);
    if (pass == 0) report.initial_cost = summary.initial_cost;
    report.final_cost = summary.final_cost;
    report.iterations += static_cast<int>(summary.iterations.size());
    report.solved = true;

    // Outliers at this solution, among all observations: one flagged by the robust pass may fit
    // the final solution (a landmark a mismatch had pulled off) and comes back.
    int outliers = 0;
    for (std::size_t i = 0; i < residuals.size(); ++i) {
      const BaObservation& o = P.observations[i];
      bool in_front = false;
      const double chi2 = chiSquare(residuals[i], poses[static_cast<std::size_t>(o.keyframe)],
                                    P.p_W[static_cast<std::size_t>(o.landmark)], &in_front);
      report.outlier[i] = !in_front || chi2 > (residuals[i].with_depth ? kChi2Stereo : kChi2Mono);
      outliers += report.outlier[i] ? 1 : 0;
    }
    report.outliers = outliers;
    if (outliers == 0) break;
  }
  for (std::size_t k = 0; k < poses.size(); ++k) {
    if (!P.fixed[k]) P.X_CW[k] = fromParameters(poses[k]);
  }
  return report;
}

}  // namespace tgnav::vo
