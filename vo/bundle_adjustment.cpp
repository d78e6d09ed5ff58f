#include "vo/bundle_adjustment.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "vo/ba_residual.h"
#include "vo/check.h"

namespace tgnav::vo {

using namespace ba_detail;  // NOLINT(google-build-using-namespace): this file's own model

namespace {

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

// The outliers at the current solution, among all shared observations (a landmark behind the
// camera, or a chi-square beyond the 95 % point); returns their count.
int flagOutliers(const std::vector<ObservationResidual>& residuals, const std::vector<bool>& shared,
                 const std::vector<std::array<double, 6>>& poses, const BaProblem& P, std::vector<bool>* outlier) {
  int outliers = 0;
  for (std::size_t i = 0; i < residuals.size(); ++i) {
    if (!shared[i]) continue;
    const BaObservation& o = P.observations[i];
    bool in_front = false;
    const double chi2 = chiSquare(residuals[i], poses[static_cast<std::size_t>(o.keyframe)],
                                  P.p_W[static_cast<std::size_t>(o.landmark)], &in_front);
    (*outlier)[i] = !in_front || chi2 > (residuals[i].with_depth ? kChi2Stereo : kChi2Mono);
    outliers += (*outlier)[i] ? 1 : 0;
  }
  return outliers;
}

// The two passes with Ceres (ba.solver ceres, the reference): one problem, robust (Cauchy), then
// plain least squares without the outliers the first exposed (their blocks removed, the loss
// wrappers emptied). One loss per kind of observation, shared by its residuals.
void solveWithCeres(const std::vector<ObservationResidual>& residuals, const std::vector<bool>& shared,
                    const BundleAdjustmentConfig& config, std::vector<std::array<double, 6>>* poses_in,
                    BaProblem* problem, BaReport* report_in) {
  std::vector<std::array<double, 6>>& poses = *poses_in;
  BaProblem& P = *problem;
  BaReport& report = *report_in;
  ceres::LossFunctionWrapper loss_mono(new ceres::CauchyLoss(std::sqrt(kChi2Mono)), ceres::TAKE_OWNERSHIP);
  ceres::LossFunctionWrapper loss_stereo(new ceres::CauchyLoss(std::sqrt(kChi2Stereo)), ceres::TAKE_OWNERSHIP);
  std::vector<PoseTermsCache> caches(poses.size());
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.enable_fast_removal = true;
  ceres::Problem ceres_problem(problem_options);
  std::vector<ceres::ResidualBlockId> blocks(residuals.size(), nullptr);
  for (std::size_t i = 0; i < residuals.size(); ++i) {
    if (!shared[i]) continue;
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
    const int outliers = flagOutliers(residuals, shared, poses, P, &report.outlier);
    report.outliers = outliers;
    // The final pass also finishes what the robust pass's few iterations left unconverged.
    if (outliers == 0 && summary.termination_type == ceres::CONVERGENCE) break;
  }
}

// The two passes with the Schur-complement solver (ba.solver schur): robust (Cauchy), then plain
// least squares without the outliers the first exposed, as with Ceres.
void solveWithSchur(const std::vector<ObservationResidual>& residuals, const std::vector<bool>& shared,
                    const BundleAdjustmentConfig& config, std::vector<std::array<double, 6>>* poses, BaProblem* problem,
                    BaReport* report) {
  std::vector<bool> active = shared;
  PassProblem pass;
  pass.poses = poses;
  pass.fixed = &problem->fixed;
  pass.points = &problem->p_W;
  pass.residuals = &residuals;
  pass.observations = &problem->observations;
  pass.active = &active;
  for (int i = 0; i < 2; ++i) {
    if (i == 1) {
      for (std::size_t o = 0; o < active.size(); ++o) active[o] = active[o] && !report->outlier[o];
      if (std::none_of(active.begin(), active.end(), [](bool a) { return a; })) break;
    }
    pass.robust = i == 0;
    pass.max_iterations = i == 0 ? config.robust_iterations : config.max_iterations;
    const PassResult result = solveSchurPass(pass);
    if (i == 0) report->initial_cost = result.initial_cost;
    report->final_cost = result.final_cost;
    report->iterations += result.iterations;
    report->solved = true;
    report->outliers = flagOutliers(residuals, shared, *poses, *problem, &report->outlier);
    if (report->outliers == 0 && result.converged) break;
  }
}

}  // namespace

void BundleAdjustmentConfig::validate() const {
  require(std::isfinite(virtual_baseline_m) && virtual_baseline_m > 0.0, "ba.virtual_baseline_m", virtual_baseline_m,
          "must be > 0");
  require(std::isfinite(depth_sigma_px) && depth_sigma_px > 0.0, "ba.depth_sigma_px", depth_sigma_px, "must be > 0");
  require(robust_iterations >= 1, "ba.robust_iterations", robust_iterations, "must be >= 1");
  require(max_iterations >= 1, "ba.max_iterations", max_iterations, "must be >= 1");
  require(fixed_keyframes >= 1, "ba.fixed_keyframes", fixed_keyframes, "must be >= 1 (the gauge)");
  require(latency_frames >= 0 && latency_frames <= 100, "ba.latency_frames", latency_frames, "must be in [0, 100]");
  require(every_keyframes >= 1 && every_keyframes <= 100, "ba.every_keyframes", every_keyframes, "must be in [1, 100]");
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
  std::vector<bool> shared(P.observations.size(), false);
  bool any_free = false;
  for (std::size_t i = 0; i < P.observations.size(); ++i) {
    shared[i] = observations_of[static_cast<std::size_t>(P.observations[i].landmark)] > 1;
    if (shared[i] && !P.fixed[static_cast<std::size_t>(P.observations[i].keyframe)]) any_free = true;
  }
  if (!any_free) return report;
  const std::vector<std::array<double, 6>> initial_poses = poses;

  if (config.solver == BaSolver::kCeres) {
    solveWithCeres(residuals, shared, config, &poses, &P, &report);
  } else {
    solveWithSchur(residuals, shared, config, &poses, &P, &report);
  }
  for (std::size_t k = 0; k < poses.size(); ++k) {
    if (!P.fixed[k]) P.X_CW[k] = fromParameters(poses[k]);
  }
  // The landmarks observed once: on their observation's ray from the adjusted pose, at the
  // observed depth, or without one at the depth they had in the keyframe before.
  for (std::size_t i = 0; i < residuals.size(); ++i) {
    if (shared[i]) continue;
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
