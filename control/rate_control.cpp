#include "control/rate_control.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "control/check.h"

namespace tgnav::control {

void RateControlConfig::validate() const {
  const char* names[] = {"roll", "pitch", "yaw"};
  for (int a = 0; a < 3; ++a) {
    auto check = [&](double v, const char* what) {
      require(v >= 0.0 && std::isfinite(v), std::string("rate.") + what + "." + names[a], v, "must be finite and >= 0");
    };
    check(p[a], "p");
    check(i[a], "i");
    check(d[a], "d");
    check(ff[a], "ff");
    check(integrator_limit[a], "integrator_limit");
  }
  require(dterm_cutoff_hz > 0.0, "rate.dterm_cutoff_hz", dterm_cutoff_hz, "must be > 0");
}

RateControl::RateControl(const RateControlConfig& config) : config_(config) { config_.validate(); }

void RateControl::reset() {
  integral_.setZero();
  w_dot_.setZero();
  w_prev_.setZero();
  has_prev_ = false;
  saturation_ = Saturation{};
}

Eigen::Vector3d RateControl::update(const Eigen::Vector3d& rate_sp, const Eigen::Vector3d& w_B, double dt_s) {
  if (has_prev_ && dt_s > 0.0) {
    const double alpha = dt_s / (dt_s + 1.0 / (2.0 * M_PI * config_.dterm_cutoff_hz));
    w_dot_ += alpha * ((w_B - w_prev_) / dt_s - w_dot_);
  }
  w_prev_ = w_B;
  has_prev_ = true;

  const Eigen::Vector3d error = rate_sp - w_B;
  Eigen::Vector3d torque =
      config_.p.cwiseProduct(error) + integral_ - config_.d.cwiseProduct(w_dot_) + config_.ff.cwiseProduct(rate_sp);

  for (int a = 0; a < 3; ++a) {
    double e = error[a];
    if ((saturation_.positive[a] && e > 0.0) || (saturation_.negative[a] && e < 0.0)) e = 0.0;
    // Large errors (flips, hard manoeuvres) should not wind up the integrator: scale down
    // quadratically to zero at 400 deg/s, as PX4 does.
    const double rel = e / (400.0 * M_PI / 180.0);
    const double i_factor = std::max(0.0, 1.0 - rel * rel);
    const double next = integral_[a] + i_factor * config_.i[a] * e * dt_s;
    if (std::isfinite(next)) {
      integral_[a] = std::clamp(next, -config_.integrator_limit[a], config_.integrator_limit[a]);
    }
  }
  return torque;
}

}  // namespace tgnav::control
