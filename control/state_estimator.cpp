#include "control/state_estimator.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <stdexcept>
#include <string>

#include "control/check.h"

namespace tgnav::control {

namespace {

using Vector9d = Eigen::Matrix<double, 9, 1>;
using Matrix9d = Eigen::Matrix<double, 9, 9>;

// Rotation vector -> unit quaternion; the series keeps small angles (and exactly zero) exact.
Eigen::Quaterniond expMap(const Eigen::Vector3d& theta) {
  const double angle = theta.norm();
  const double half = 0.5 * angle;
  const double k = angle < 1e-8 ? 0.5 - angle * angle / 48.0 : std::sin(half) / angle;
  return Eigen::Quaterniond(std::cos(half), k * theta.x(), k * theta.y(), k * theta.z());
}

// Unit quaternion -> rotation vector of the shortest rotation, angle in [0, pi].
Eigen::Vector3d logMap(const Eigen::Quaterniond& q_in) {
  const Eigen::Quaterniond q = q_in.w() < 0.0 ? Eigen::Quaterniond(-q_in.w(), -q_in.x(), -q_in.y(), -q_in.z()) : q_in;
  const double s = q.vec().norm();
  const double k = s < 1e-8 ? 2.0 / q.w() : 2.0 * std::atan2(s, q.w()) / s;
  return k * q.vec();
}

// Transition over dt without input: p += v dt - b dt^2/2, v -= b dt (the bias is taken off the
// measured acceleration), b constant. F(s) F(t) = F(s + t).
Matrix9d transition(double dt_s) {
  Matrix9d F = Matrix9d::Identity();
  F.block<3, 3>(0, 3).diagonal().setConstant(dt_s);
  F.block<3, 3>(0, 6).diagonal().setConstant(-0.5 * dt_s * dt_s);
  F.block<3, 3>(3, 6).diagonal().setConstant(-dt_s);
  return F;
}

Matrix9d symmetric(const Matrix9d& P) { return 0.5 * (P + P.transpose()); }

}  // namespace

void EstimatorConfig::validate() const {
  require(accel_noise_m_s2 > 0.0, "accel_noise_m_s2", accel_noise_m_s2, "must be > 0");
  require(position_sigma_m > 0.0, "position_sigma_m", position_sigma_m, "must be > 0");
  require(attitude_gain > 0.0 && attitude_gain <= 1.0, "attitude_gain", attitude_gain, "must be in (0, 1]");
  require(gyro_bias_gain >= 0.0 && gyro_bias_gain < 1.0, "gyro_bias_gain", gyro_bias_gain, "must be in [0, 1)");
  require(max_position_innovation_m > 0.0, "max_position_innovation_m", max_position_innovation_m, "must be > 0");
  require(history_s > 0.0, "history_s", history_s, "must be > 0");
  require(accel_bias_walk_m_s2_sqrt_s >= 0.0 && std::isfinite(accel_bias_walk_m_s2_sqrt_s),
          "accel_bias_walk_m_s2_sqrt_s", accel_bias_walk_m_s2_sqrt_s, "must be >= 0");
  require(max_vo_step_error_m >= 0.0 && std::isfinite(max_vo_step_error_m), "max_vo_step_error_m", max_vo_step_error_m,
          "must be >= 0 (0: off)");
}

StateEstimator::StateEstimator(const EstimatorConfig& config, double gravity_m_s2)
    : config_(config), gravity_m_s2_(gravity_m_s2) {
  config_.validate();
  require(gravity_m_s2 > 0.0, "gravity_m_s2", gravity_m_s2, "must be > 0");
  reset(VehicleState{}, 0.0);
}

void StateEstimator::reset(const VehicleState& initial, double t_s) {
  t_s_ = t_s;
  x_ << initial.p_WB, initial.v_WB, Eigen::Vector3d::Zero();
  // The start is known (the vehicle stands where the trial put it); uncertainty comes from the IMU
  // (and the bias from its random walk).
  P_.setZero();
  q_WB_ = initial.q_WB.normalized();
  gyro_bias_.setZero();
  gyro_B_ = initial.w_B;
  last_fused_t_s_ = t_s;
  has_fused_ = false;
  fused_ = 0;
  rejected_ = 0;
  has_vo_ = false;
  vo_offset_.setZero();
  jumps_ = 0;
  history_.clear();
  history_.push_back(Snapshot{t_s_, x_, P_, q_WB_});
}

void StateEstimator::propagate(const ImuSample& imu) {
  const double dt = imu.t_s - t_s_;
  if (!(dt > 0.0)) {
    throw std::invalid_argument("StateEstimator::propagate: imu.t_s = " + std::to_string(imu.t_s) +
                                ": must be later than the last time " + std::to_string(t_s_));
  }
  gyro_B_ = imu.w_B;
  const Eigen::Vector3d w_B = imu.w_B - gyro_bias_;
  // The specific force is the mean over the interval; the midpoint attitude rotates it into W with
  // an error of second order in the rotation over the step.
  const Eigen::Quaterniond q_mid = (q_WB_ * expMap(0.5 * dt * w_B)).normalized();
  q_WB_ = (q_WB_ * expMap(dt * w_B)).normalized();
  const Eigen::Vector3d a_W = q_mid * imu.f_B - Eigen::Vector3d(0.0, 0.0, gravity_m_s2_);

  // Discrete white acceleration, sigma per sample: G = [dt^2/2 I; dt I; 0], Q = G G^T sigma^2, and
  // the bias's random walk, walk^2 dt.
  Eigen::Matrix<double, 9, 3> G;
  G << 0.5 * dt * dt * Eigen::Matrix3d::Identity(), dt * Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Zero();
  const Matrix9d F = transition(dt);
  x_ = F * x_ + G * a_W;
  const double var = config_.accel_noise_m_s2 * config_.accel_noise_m_s2;
  P_ = F * P_ * F.transpose() + var * G * G.transpose();
  P_.bottomRightCorner<3, 3>().diagonal().array() +=
      config_.accel_bias_walk_m_s2_sqrt_s * config_.accel_bias_walk_m_s2_sqrt_s * dt;
  P_ = symmetric(P_);
  t_s_ = imu.t_s;

  history_.push_back(Snapshot{t_s_, x_, P_, q_WB_});
  while (history_.front().t_s < t_s_ - config_.history_s) history_.pop_front();
}

bool StateEstimator::fusePose(double t_meas_s, const Eigen::Isometry3d& X_WB) {
  auto reject = [this] {
    ++rejected_;
    return false;
  };
  // The snapshot nearest t_meas_s; a measurement more than half a step before the oldest one, or
  // after now, has none.
  const double half_step = history_.size() > 1 ? 0.5 * (history_[1].t_s - history_[0].t_s) : 0.0;
  constexpr double kTimeEps = 1e-9;
  if (!std::isfinite(t_meas_s) || t_meas_s < history_.front().t_s - half_step || t_meas_s > t_s_ + kTimeEps) {
    return reject();
  }
  if (has_fused_ && t_meas_s < last_fused_t_s_) return reject();
  if (!X_WB.matrix().allFinite()) return reject();
  const auto it = history_.begin() + static_cast<std::ptrdiff_t>(nearest(t_meas_s));
  const Snapshot& m = *it;

  Eigen::Vector3d p_meas = X_WB.translation();
  if (config_.max_vo_step_error_m > 0.0) {
    // The step since the last VO pose against the estimate's over the same time. A previous pose
    // older than the history is no reference: the step is then taken as it is.
    if (has_vo_ && last_vo_t_s_ >= history_.front().t_s - half_step) {
      const Eigen::Vector3d error =
          (p_meas - last_vo_p_) - (m.x.head<3>() - history_[nearest(last_vo_t_s_)].x.head<3>());
      if (error.norm() > config_.max_vo_step_error_m) {
        vo_offset_ += error;
        ++jumps_;
      }
    }
    last_vo_p_ = p_meas;
    last_vo_t_s_ = t_meas_s;
    has_vo_ = true;
    p_meas -= vo_offset_;
  }

  const Eigen::Vector3d y = p_meas - m.x.head<3>();
  if (!(y.norm() <= config_.max_position_innovation_m)) return reject();

  // Kalman update at the snapshot, H = [I 0]: P H^T is P's left block column.
  const double r = config_.position_sigma_m * config_.position_sigma_m;
  const Eigen::Matrix3d S = m.P.topLeftCorner<3, 3>() + r * Eigen::Matrix3d::Identity();
  const Eigen::Matrix<double, 9, 3> K = m.P.leftCols<3>() * S.inverse();
  const Vector9d dx = K * y;
  Matrix9d I_KH = Matrix9d::Identity();
  I_KH.leftCols<3>() -= K;
  const Matrix9d P_post = I_KH * m.P * I_KH.transpose() + r * K * K.transpose();  // Joseph form
  const Matrix9d dP = m.P - P_post;

  // Attitude: a fraction of the body-frame error at t_meas, applied as the rotation in W that
  // re-integrating the gyro from the corrected snapshot attitude would give at every later time.
  const Eigen::Quaterniond q_meas(X_WB.linear());
  const Eigen::Vector3d dtheta_B = logMap(m.q_WB.conjugate() * q_meas.normalized());
  const Eigen::Quaterniond dq_W = (m.q_WB * expMap(config_.attitude_gain * dtheta_B) * m.q_WB.conjugate()).normalized();

  // Gyro bias: a bias b turns the attitude by -b per second of integration, so the error rate since
  // the last fused pose (measurement times) estimates it; an integral term on the attitude loop.
  if (config_.gyro_bias_gain > 0.0 && has_fused_ && t_meas_s > last_fused_t_s_) {
    gyro_bias_ -= config_.gyro_bias_gain * dtheta_B / (t_meas_s - last_fused_t_s_);
  }

  // The transition is linear and independent of the state, so adding F dx and subtracting
  // F dP F^T at every later snapshot is what re-running the filter from t_m would give.
  const double t_m = m.t_s;
  for (auto j = it; j != history_.end(); ++j) {
    const Matrix9d F = transition(j->t_s - t_m);
    j->x += F * dx;
    j->P = symmetric(j->P - F * dP * F.transpose());
    j->q_WB = (dq_W * j->q_WB).normalized();
  }
  const Snapshot& now = history_.back();
  x_ = now.x;
  P_ = now.P;
  q_WB_ = now.q_WB;

  last_fused_t_s_ = t_meas_s;
  has_fused_ = true;
  ++fused_;
  return true;
}

std::size_t StateEstimator::nearest(double t_s) const {
  auto it =
      std::lower_bound(history_.begin(), history_.end(), t_s, [](const Snapshot& s, double t) { return s.t_s < t; });
  if (it == history_.end() || (it != history_.begin() && t_s - std::prev(it)->t_s < it->t_s - t_s)) --it;
  return static_cast<std::size_t>(it - history_.begin());
}

VehicleState StateEstimator::state() const {
  VehicleState s;
  s.p_WB = x_.head<3>();
  s.v_WB = x_.segment<3>(3);
  s.q_WB = q_WB_;
  s.w_B = gyro_B_ - gyro_bias_;
  return s;
}

}  // namespace tgnav::control
