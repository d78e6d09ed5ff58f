// Levenberg-Marquardt for the local bundle adjustment, with the landmarks eliminated: each
// landmark's 3x3 block is inverted and folded into the poses' reduced system (the Schur
// complement), which is solved dense, and the landmarks' steps follow by back-substitution.
// Every block has a fixed size (observations padded to 3 rows), which is what makes it faster
// than Ceres's DENSE_SCHUR here: its eliminator has no specialisation for rows of 2 and 3 mixed.
//
// The trust-region rules are Ceres's (TrustRegionMinimizer with LevenbergMarquardtStrategy, its
// default options), so that the two solvers take the same steps up to rounding: Jacobi scaling
// of the columns fixed at the first iteration, the regularisation diag(J'J) clamped to
// [1e-6, 1e32] over the radius (initially 1e4), a step accepted when the cost falls by more than
// 1e-3 of the model's prediction, the radius then divided by max(1/3, 1 - (2 rho - 1)^3) and
// otherwise halved with a doubling factor, and convergence on a step below 1e-8 (|x| + 1e-8), a
// cost change below 1e-6 of the cost, or a gradient below 1e-10. The robust loss is Cauchy, which
// Ceres applies by scaling each residual and its Jacobian by sqrt(rho'), since rho'' < 0.
#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "vo/ba_residual.h"

namespace tgnav::vo::ba_detail {

namespace {

constexpr double kInitialRadius = 1e4;
constexpr double kMaxRadius = 1e16;
constexpr double kMinRadius = 1e-32;
constexpr double kMinDiagonal = 1e-6;
constexpr double kMaxDiagonal = 1e32;
constexpr double kMinRelativeDecrease = 1e-3;
constexpr double kFunctionTolerance = 1e-6;
constexpr double kGradientTolerance = 1e-10;
constexpr double kParameterTolerance = 1e-8;

using Vec3 = Eigen::Vector3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat3 = Eigen::Matrix3d;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat36 = Eigen::Matrix<double, 3, 6, Eigen::RowMajor>;
using Mat33R = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
using Mat63 = Eigen::Matrix<double, 6, 3>;

// Which parameters move: the free poses and the landmarks with an active observation, each with
// its index among them, and each landmark's active observations.
struct Layout {
  std::vector<int> pose_slot;                     // pose -> free pose index, -1: fixed or unobserved
  std::vector<int> point_slot;                    // point -> solver landmark index, -1: none
  std::vector<int> points;                        // solver landmark -> point
  std::vector<std::vector<int>> observations_of;  // solver landmark -> its active observations
  int free_poses = 0;
};

Layout makeLayout(const PassProblem& p) {
  Layout l;
  l.pose_slot.assign(p.poses->size(), -1);
  l.point_slot.assign(p.points->size(), -1);
  for (std::size_t i = 0; i < p.observations->size(); ++i) {
    if (!(*p.active)[i]) continue;
    const BaObservation& o = (*p.observations)[i];
    const auto k = static_cast<std::size_t>(o.keyframe);
    if (!(*p.fixed)[k] && l.pose_slot[k] < 0) l.pose_slot[k] = l.free_poses++;
    int& slot = l.point_slot[static_cast<std::size_t>(o.landmark)];
    if (slot < 0) {
      slot = static_cast<int>(l.points.size());
      l.points.push_back(o.landmark);
      l.observations_of.emplace_back();
    }
    l.observations_of[static_cast<std::size_t>(slot)].push_back(static_cast<int>(i));
  }
  return l;
}

// The robust loss of an observation's squared residual s: Cauchy of scale^2 = b, rho(s) =
// b log(1 + s / b), and rho'(s) = 1 / (1 + s / b).
double chi2Point(const ObservationResidual& r) { return r.with_depth ? kChi2Stereo : kChi2Mono; }

// The problem at one point of parameter space: per active observation, its (weighted) residual
// and Jacobians, padded to 3 rows.
struct Linearisation {
  std::vector<Vec3> r;
  std::vector<Mat36> J_pose;
  std::vector<Mat33R> J_point;
};

class Solver {
 public:
  explicit Solver(const PassProblem& p) : p_(p), layout_(makeLayout(p)) {
    const std::size_t n = p.observations->size();
    lin_.r.assign(n, Vec3::Zero());
    lin_.J_pose.assign(n, Mat36::Zero());
    lin_.J_point.assign(n, Mat33R::Zero());
  }

  PassResult run();

 private:
  double cost(const std::vector<std::array<double, 6>>& poses, const std::vector<Vec3>& points) const;
  void linearise();
  bool solveStep(double radius, Eigen::VectorXd* step_scaled);
  double modelCostChange(const Eigen::VectorXd& step_scaled) const;
  void candidate(const Eigen::VectorXd& step, std::vector<std::array<double, 6>>* poses,
                 std::vector<Vec3>* points) const;
  int dims() const { return 6 * layout_.free_poses + 3 * static_cast<int>(layout_.points.size()); }
  int poseColumn(int slot) const { return 6 * slot; }
  int pointColumn(int slot) const { return 6 * layout_.free_poses + 3 * slot; }
  int poseSlot(int observation) const {
    return layout_
        .pose_slot[static_cast<std::size_t>((*p_.observations)[static_cast<std::size_t>(observation)].keyframe)];
  }

  const PassProblem& p_;
  Layout layout_;
  Linearisation lin_;
  Eigen::VectorXd scale_;            // Jacobi scaling per column, fixed at the first linearisation
  Eigen::VectorXd diagonal_;         // diag(J_s' J_s), clamped
  Eigen::VectorXd gradient_;         // J_s' r
  std::vector<Mat6> pose_blocks_;    // per free pose: J_s' J_s (scaled columns)
  std::vector<Mat3> point_blocks_;   // per landmark
  std::vector<Mat63> cross_blocks_;  // per observation of a free pose: its pose-landmark block
  std::vector<Mat3> point_inverse_;  // per landmark: its regularised block's inverse (scratch)
};

// 1/2 sum of rho(s) over the active observations; +inf where a point lands on the camera plane
// or a value is not finite (Ceres's failed evaluation).
double Solver::cost(const std::vector<std::array<double, 6>>& poses, const std::vector<Vec3>& points) const {
  std::vector<PoseTerms> terms(poses.size());
  std::vector<bool> have(poses.size(), false);
  double total = 0.0;
  for (const std::vector<int>& obs : layout_.observations_of) {
    for (int i : obs) {
      const BaObservation& o = (*p_.observations)[static_cast<std::size_t>(i)];
      const auto k = static_cast<std::size_t>(o.keyframe);
      if (!have[k]) {
        terms[k] = poseTerms(poses[k].data());
        have[k] = true;
      }
      const ObservationResidual& r = (*p_.residuals)[static_cast<std::size_t>(i)];
      std::array<double, 3> res{};
      const double z = r.evaluate(terms[k], poses[k].data(), points[static_cast<std::size_t>(o.landmark)].data(),
                                  res.data(), nullptr, nullptr);
      if (!std::isfinite(z) || z == 0.0) return std::numeric_limits<double>::infinity();
      const double s = res[0] * res[0] + res[1] * res[1] + (r.with_depth ? res[2] * res[2] : 0.0);
      const double b = chi2Point(r);
      total += p_.robust ? b * std::log1p(s / b) : s;
    }
  }
  return std::isfinite(total) ? 0.5 * total : std::numeric_limits<double>::infinity();
}

// Residuals and Jacobians at the current parameters (weighted by sqrt(rho') when robust), the
// gradient and the normal equations' blocks, in the scaled columns.
void Solver::linearise() {
  const std::vector<std::array<double, 6>>& poses = *p_.poses;
  std::vector<PoseTerms> terms(poses.size());
  for (std::size_t k = 0; k < poses.size(); ++k) terms[k] = poseTerms(poses[k].data());
  const int n = dims();
  Eigen::VectorXd column_sq = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd grad = Eigen::VectorXd::Zero(n);
  pose_blocks_.assign(static_cast<std::size_t>(layout_.free_poses), Mat6::Zero());
  point_blocks_.assign(layout_.points.size(), Mat3::Zero());
  cross_blocks_.assign(p_.observations->size(), Mat63::Zero());
  for (std::size_t j = 0; j < layout_.points.size(); ++j) {
    const Vec3& point = (*p_.points)[static_cast<std::size_t>(layout_.points[j])];
    const int pc = pointColumn(static_cast<int>(j));
    for (int i : layout_.observations_of[j]) {
      const auto ui = static_cast<std::size_t>(i);
      const BaObservation& o = (*p_.observations)[ui];
      const auto k = static_cast<std::size_t>(o.keyframe);
      const ObservationResidual& r = (*p_.residuals)[ui];
      Vec3& res = lin_.r[ui];
      Mat36& Jp = lin_.J_pose[ui];
      Mat33R& Jl = lin_.J_point[ui];
      res.setZero();
      Jp.setZero();
      Jl.setZero();
      r.evaluate(terms[k], poses[k].data(), point.data(), res.data(), Jp.data(), Jl.data());
      if (p_.robust) {
        const double s = res.squaredNorm();
        const double w = std::sqrt(1.0 / (1.0 + s / chi2Point(r)));
        res *= w;
        Jp *= w;
        Jl *= w;
      }
      point_blocks_[j] += Jl.transpose() * Jl;
      grad.segment<3>(pc) += Jl.transpose() * res;
      column_sq.segment<3>(pc) += Jl.colwise().squaredNorm().transpose();
      const int slot = layout_.pose_slot[k];
      if (slot < 0) continue;
      const int c = poseColumn(slot);
      pose_blocks_[static_cast<std::size_t>(slot)] += Jp.transpose() * Jp;  // scaled below
      grad.segment<6>(c) += Jp.transpose() * res;
      column_sq.segment<6>(c) += Jp.colwise().squaredNorm().transpose();
      cross_blocks_[ui] = Jp.transpose() * Jl;
    }
  }
  if (scale_.size() != n) scale_ = (1.0 + column_sq.array().sqrt()).inverse().matrix();
  gradient_ = scale_.cwiseProduct(grad);
  diagonal_ = scale_.cwiseProduct(scale_).cwiseProduct(column_sq);
  for (int c = 0; c < n; ++c) diagonal_[c] = std::clamp(diagonal_[c], kMinDiagonal, kMaxDiagonal);
  // The blocks in the scaled columns.
  for (int a = 0; a < layout_.free_poses; ++a) {
    const Vec6 sp = scale_.segment<6>(poseColumn(a));
    pose_blocks_[static_cast<std::size_t>(a)] =
        sp.asDiagonal() * pose_blocks_[static_cast<std::size_t>(a)] * sp.asDiagonal();
  }
  for (std::size_t j = 0; j < layout_.points.size(); ++j) {
    const Vec3 sl = scale_.segment<3>(pointColumn(static_cast<int>(j)));
    point_blocks_[j] = sl.asDiagonal() * point_blocks_[j] * sl.asDiagonal();
    for (int i : layout_.observations_of[j]) {
      const auto ui = static_cast<std::size_t>(i);
      const int slot = poseSlot(i);
      if (slot >= 0) {
        cross_blocks_[ui] = scale_.segment<6>(poseColumn(slot)).asDiagonal() * cross_blocks_[ui] * sl.asDiagonal();
      }
    }
  }
}

// The Levenberg-Marquardt step in scaled columns: (J_s' J_s + diag / radius) d = -J_s' r, the
// landmarks eliminated. False when the reduced system is not positive definite.
bool Solver::solveStep(double radius, Eigen::VectorXd* step_scaled) {
  const int poses_dims = 6 * layout_.free_poses;
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(poses_dims, poses_dims);
  Eigen::VectorXd rhs = -gradient_.head(poses_dims);
  const Eigen::VectorXd lm = diagonal_ / radius;
  for (int a = 0; a < layout_.free_poses; ++a) {
    const int c = poseColumn(a);
    S.block<6, 6>(c, c) = pose_blocks_[static_cast<std::size_t>(a)];
    S.block<6, 6>(c, c).diagonal() += lm.segment<6>(c);
  }
  point_inverse_.resize(layout_.points.size());
  std::vector<Mat63> W;  // per observation of the landmark: H_pl H_ll^-1
  for (std::size_t j = 0; j < layout_.points.size(); ++j) {
    const int pc = pointColumn(static_cast<int>(j));
    Mat3 H = point_blocks_[j];
    H.diagonal() += lm.segment<3>(pc);
    point_inverse_[j] = H.inverse();
    const std::vector<int>& obs = layout_.observations_of[j];
    W.resize(obs.size());
    for (std::size_t a = 0; a < obs.size(); ++a) {
      const int slot_a = poseSlot(obs[a]);
      if (slot_a < 0) continue;
      const int ca = poseColumn(slot_a);
      W[a] = cross_blocks_[static_cast<std::size_t>(obs[a])] * point_inverse_[j];
      rhs.segment<6>(ca) += W[a] * gradient_.segment<3>(pc);
      for (std::size_t b = 0; b <= a; ++b) {
        const int slot_b = poseSlot(obs[b]);
        if (slot_b < 0) continue;
        const int cb = poseColumn(slot_b);
        const Mat6 block = W[a] * cross_blocks_[static_cast<std::size_t>(obs[b])].transpose();
        S.block<6, 6>(ca, cb) -= block;
        if (ca != cb) S.block<6, 6>(cb, ca) -= block.transpose();
      }
    }
  }
  Eigen::VectorXd d_pose;
  if (poses_dims > 0) {
    const Eigen::LLT<Eigen::MatrixXd> llt(S);
    if (llt.info() != Eigen::Success) return false;
    d_pose = llt.solve(rhs);
  }
  step_scaled->resize(dims());
  step_scaled->head(poses_dims) = d_pose;
  for (std::size_t j = 0; j < layout_.points.size(); ++j) {
    const int pc = pointColumn(static_cast<int>(j));
    Vec3 b = -gradient_.segment<3>(pc);
    for (int i : layout_.observations_of[j]) {
      const int slot = poseSlot(i);
      if (slot >= 0) b -= cross_blocks_[static_cast<std::size_t>(i)].transpose() * d_pose.segment<6>(poseColumn(slot));
    }
    step_scaled->segment<3>(pc) = point_inverse_[j] * b;
  }
  return step_scaled->allFinite();
}

// The linear model's cost change for a step: -(r' J d + |J d|^2 / 2), in scaled columns.
double Solver::modelCostChange(const Eigen::VectorXd& d) const {
  double change = 0.0;
  for (std::size_t j = 0; j < layout_.points.size(); ++j) {
    const int pc = pointColumn(static_cast<int>(j));
    const Vec3 dl = scale_.segment<3>(pc).cwiseProduct(d.segment<3>(pc));
    for (int i : layout_.observations_of[j]) {
      const auto ui = static_cast<std::size_t>(i);
      Vec3 Jd = lin_.J_point[ui] * dl;
      const int slot = poseSlot(i);
      if (slot >= 0) {
        const int c = poseColumn(slot);
        Jd += lin_.J_pose[ui] * scale_.segment<6>(c).cwiseProduct(d.segment<6>(c));
      }
      change -= lin_.r[ui].dot(Jd) + 0.5 * Jd.squaredNorm();
    }
  }
  return change;
}

void Solver::candidate(const Eigen::VectorXd& step, std::vector<std::array<double, 6>>* poses,
                       std::vector<Vec3>* points) const {
  *poses = *p_.poses;
  *points = *p_.points;
  for (std::size_t k = 0; k < poses->size(); ++k) {
    const int slot = layout_.pose_slot[k];
    if (slot < 0) continue;
    for (int e = 0; e < 6; ++e) (*poses)[k][static_cast<std::size_t>(e)] += step[poseColumn(slot) + e];
  }
  for (std::size_t j = 0; j < layout_.points.size(); ++j) {
    (*points)[static_cast<std::size_t>(layout_.points[j])] += step.segment<3>(pointColumn(static_cast<int>(j)));
  }
}

PassResult Solver::run() {
  PassResult result;
  result.iterations = 1;  // the evaluation at the start
  double x_cost = cost(*p_.poses, *p_.points);
  result.initial_cost = result.final_cost = x_cost;
  if (!std::isfinite(x_cost) || layout_.points.empty()) return result;
  double radius = kInitialRadius, decrease_factor = 2.0;
  linearise();
  std::vector<std::array<double, 6>> poses;
  std::vector<Vec3> points;
  Eigen::VectorXd step_scaled;
  while (true) {
    if (gradient_.cwiseQuotient(scale_).lpNorm<Eigen::Infinity>() <= kGradientTolerance) {
      result.converged = true;
      break;
    }
    if (result.iterations > p_.max_iterations || radius < kMinRadius) break;
    ++result.iterations;
    const bool valid = solveStep(radius, &step_scaled);
    const double model_change = valid ? modelCostChange(step_scaled) : 0.0;
    if (!valid || !(model_change > 0.0)) {  // an invalid step counts as a rejected one
      radius /= decrease_factor;
      decrease_factor *= 2.0;
      continue;
    }
    const Eigen::VectorXd step = scale_.cwiseProduct(step_scaled);
    double x_norm_sq = 0.0;
    for (std::size_t k = 0; k < p_.poses->size(); ++k) {
      if (layout_.pose_slot[k] >= 0) x_norm_sq += Eigen::Map<const Vec6>((*p_.poses)[k].data()).squaredNorm();
    }
    for (int point : layout_.points) x_norm_sq += (*p_.points)[static_cast<std::size_t>(point)].squaredNorm();
    // Converged within a step: Ceres does not count that step among its iterations.
    if (step.norm() <= kParameterTolerance * (std::sqrt(x_norm_sq) + kParameterTolerance)) {
      result.converged = true;
      --result.iterations;
      break;
    }
    candidate(step, &poses, &points);
    const double candidate_cost = cost(poses, points);
    if (std::isfinite(candidate_cost) && std::abs(x_cost - candidate_cost) <= kFunctionTolerance * x_cost) {
      result.converged = true;
      --result.iterations;
      break;
    }
    const double relative_decrease = (x_cost - candidate_cost) / model_change;
    if (std::isfinite(candidate_cost) && relative_decrease > kMinRelativeDecrease) {
      *p_.poses = poses;
      *p_.points = points;
      x_cost = candidate_cost;
      radius = std::min(kMaxRadius, radius / std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * relative_decrease - 1.0, 3)));
      decrease_factor = 2.0;
      linearise();
    } else {
      radius /= decrease_factor;
      decrease_factor *= 2.0;
    }
  }
  result.final_cost = x_cost;
  return result;
}

}  // namespace

PassResult solveSchurPass(const PassProblem& p) { return Solver(p).run(); }

}  // namespace tgnav::vo::ba_detail
