#include "vo/bundle_adjustment.h"

#include <ceres/ceres.h>

#include <algorithm>
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

Eigen::Matrix3d skew(const Eigen::Vector3d& a) {
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

PoseTerms poseTerms(const double* pose) {
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

// Ceres's view of an observation: 3 residuals with depth, 2 without.
template <int kResiduals>
class ObservationCost : public ceres::SizedCostFunction<kResiduals, 6, 3> {
 public:
  ObservationCost(const ObservationResidual& r, PoseTermsCache* cache) : r_(r), cache_(cache) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double z = r_.evaluate(cache_->at(parameters[0]), parameters[0], parameters[1], residuals,
                                 jacobians ? jacobians[0] : nullptr, jacobians ? jacobians[1] : nullptr);
    return std::isfinite(z) && z != 0.0;
  }

 private:
  ObservationResidual r_;
  PoseTermsCache* cache_;
};

std::array<double, 6> toParameters(const Eigen::Isometry3d& X_CW) {
  std::array<double, 6> p{};
  const Eigen::AngleAxisd aa(X_CW.linear());
  const Eigen::Vector3d r = aa.angle() * aa.axis();
  for (int i = 0; i < 3; ++i) {
    p[static_cast<std::size_t>(i)] = r[i];
    p[static_cast<std::size_t>(i) + 3] = X_CW.translation()[i];
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
  *in_front = r.evaluate(poseTerms(pose.data()), pose.data(), p_W.data(), res.data(), nullptr, nullptr) > 0.0;
  return res[0] * res[0] + res[1] * res[1] + (r.with_depth ? res[2] * res[2] : 0.0);
}

}  // namespace

void BundleAdjustmentConfig::validate() const {
  require(std::isfinite(virtual_baseline_m) && virtual_baseline_m > 0.0, "ba.virtual_baseline_m", virtual_baseline_m,
          "must be > 0");
  require(std::isfinite(depth_sigma_px) && depth_sigma_px > 0.0, "ba.depth_sigma_px", depth_sigma_px, "must be > 0");
  require(robust_iterations >= 1, "ba.robust_iterations", robust_iterations, "must be >= 1");
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
  std::vector<int> observations_of(P.p_W.size(), 0);
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
    ++observations_of[static_cast<std::size_t>(o.landmark)];
  }
  // A landmark observed once cannot inform a pose: its three coordinates fit its two or three
  // residuals exactly, so its term in the Schur complement on the poses is zero. It stays out of
  // the solver (half the landmarks of a window, a quarter of the observations) and is placed
  // on its observation afterwards, where the solver would have converged.
  const auto shared = [&](std::size_t i) {
    return observations_of[static_cast<std::size_t>(P.observations[i].landmark)] > 1;
  };
  bool any_free = false;
  for (std::size_t i = 0; i < P.observations.size(); ++i) {
    if (shared(i) && !P.fixed[static_cast<std::size_t>(P.observations[i].keyframe)]) any_free = true;
  }
  if (!any_free) return report;
  const std::vector<std::array<double, 6>> initial_poses = poses;

  // Two passes on one problem: robust (Cauchy), then plain least squares without the outliers
  // the first exposed (their blocks removed, the loss wrappers emptied). One loss per kind of
  // observation, shared by its residuals.
  ceres::LossFunctionWrapper loss_mono(new ceres::CauchyLoss(std::sqrt(kChi2Mono)), ceres::TAKE_OWNERSHIP);
  ceres::LossFunctionWrapper loss_stereo(new ceres::CauchyLoss(std::sqrt(kChi2Stereo)), ceres::TAKE_OWNERSHIP);
  std::vector<PoseTermsCache> caches(poses.size());
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.enable_fast_removal = true;
  ceres::Problem ceres_problem(problem_options);
  std::vector<ceres::ResidualBlockId> blocks(residuals.size(), nullptr);
  for (std::size_t i = 0; i < residuals.size(); ++i) {
    if (!shared(i)) continue;
    const BaObservation& o = P.observations[i];
    const auto k = static_cast<std::size_t>(o.keyframe);
    PoseTermsCache* cache = &caches[k];
    ceres::CostFunction* cost = residuals[i].with_depth
                                    ? static_cast<ceres::CostFunction*>(new ObservationCost<3>(residuals[i], cache))
                                    : new ObservationCost<2>(residuals[i], cache);
    blocks[i] = ceres_problem.AddResidualBlock(cost, residuals[i].with_depth ? &loss_stereo : &loss_mono,
                                               poses[k].data(), P.p_W[static_cast<std::size_t>(o.landmark)].data());
  }
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (std::size_t k = 0; k < poses.size(); ++k) {
    double* pose = poses[k].data();
    if (!ceres_problem.HasParameterBlock(pose)) continue;
    ordering->AddElementToGroup(pose, 1);
    if (P.fixed[k]) ceres_problem.SetParameterBlockConstant(pose);
  }
  for (Eigen::Vector3d& p : P.p_W) {
    if (ceres_problem.HasParameterBlock(p.data())) ordering->AddElementToGroup(p.data(), 0);
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;
  options.linear_solver_ordering = ordering;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  for (int pass = 0; pass < 2; ++pass) {
    if (pass == 1) {
      loss_mono.Reset(nullptr, ceres::TAKE_OWNERSHIP);
      loss_stereo.Reset(nullptr, ceres::TAKE_OWNERSHIP);
      for (std::size_t i = 0; i < residuals.size(); ++i) {
        if (report.outlier[i] && blocks[i] != nullptr) {
          ceres_problem.RemoveResidualBlock(blocks[i]);
          blocks[i] = nullptr;
        }
      }
      if (ceres_problem.NumResidualBlocks() == 0) break;
    }
    options.max_num_iterations = pass == 0 ? config.robust_iterations : config.max_iterations;
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
      if (!shared(i)) continue;
      const BaObservation& o = P.observations[i];
      bool in_front = false;
      const double chi2 = chiSquare(residuals[i], poses[static_cast<std::size_t>(o.keyframe)],
                                    P.p_W[static_cast<std::size_t>(o.landmark)], &in_front);
      report.outlier[i] = !in_front || chi2 > (residuals[i].with_depth ? kChi2Stereo : kChi2Mono);
      outliers += report.outlier[i] ? 1 : 0;
    }
    report.outliers = outliers;
    // The final pass also finishes what the robust pass's few iterations left unconverged.
    if (outliers == 0 && summary.termination_type == ceres::CONVERGENCE) break;
  }
  for (std::size_t k = 0; k < poses.size(); ++k) {
    if (!P.fixed[k]) P.X_CW[k] = fromParameters(poses[k]);
  }
  // The landmarks observed once: on their observation's ray from the adjusted pose, at the
  // observed depth, or without one at the depth they had in the keyframe before.
  for (std::size_t i = 0; i < residuals.size(); ++i) {
    if (shared(i)) continue;
    const BaObservation& o = P.observations[i];
    const auto k = static_cast<std::size_t>(o.keyframe);
    Eigen::Vector3d& p_W = P.p_W[static_cast<std::size_t>(o.landmark)];
    const double z = residuals[i].with_depth ? o.depth_m : (fromParameters(initial_poses[k]) * p_W).z();
    if (!(z > 0.0)) {
      report.outlier[i] = true;  // behind the camera
      ++report.outliers;
      continue;
    }
    const Eigen::Vector3d p_C((o.uv.x() - camera.cx) * z / camera.fx, (o.uv.y() - camera.cy) * z / camera.fy, z);
    p_W = P.X_CW[k].inverse() * p_C;
  }
  return report;
}

int observationResiduals(const CameraIntrinsics& camera, const BaObservation& observation,
                         const BundleAdjustmentConfig& config, const Eigen::Matrix<double, 6, 1>& pose,
                         const Eigen::Vector3d& p_W, Eigen::Vector3d* residual, Eigen::Matrix<double, 3, 6>* J_pose,
                         Eigen::Matrix3d* J_point) {
  const ObservationResidual r(camera, observation, camera.fx * config.virtual_baseline_m, config.depth_sigma_px);
  Eigen::Matrix<double, 3, 6, Eigen::RowMajor> jp = Eigen::Matrix<double, 3, 6, Eigen::RowMajor>::Zero();
  Eigen::Matrix<double, 3, 3, Eigen::RowMajor> jl = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>::Zero();
  residual->setZero();
  r.evaluate(poseTerms(pose.data()), pose.data(), p_W.data(), residual->data(), jp.data(), jl.data());
  // evaluate() writes size() rows, packed: unpack them into the fixed 3-row matrices.
  const int n = r.size();
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>> packed_pose(jp.data(), n, 6);
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> packed_point(jl.data(), n, 3);
  J_pose->setZero();
  J_point->setZero();
  J_pose->topRows(n) = packed_pose;
  J_point->topRows(n) = packed_point;
  return n;
}

}  // namespace tgnav::vo
