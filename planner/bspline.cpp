#include "planner/bspline.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "planner/check.h"

namespace tgnav::planner {

UniformBSpline::UniformBSpline(Eigen::MatrixXd control_points, double dt) : q_(std::move(control_points)) {
  require(q_.rows() >= 4, "control_points", static_cast<double>(q_.rows()), "a cubic B-spline needs at least 4");
  setKnotInterval(dt);
}

void UniformBSpline::setKnotInterval(double dt) {
  require(std::isfinite(dt) && dt > 0.0, "knot_interval_s", dt, "must be > 0");
  dt_ = dt;
}

Eigen::Vector4d UniformBSpline::basis(double u, int derivative) {
  const double u2 = u * u;
  const double u3 = u2 * u;
  const double w = 1.0 - u;
  switch (derivative) {
    case 0:
      return Eigen::Vector4d(w * w * w, 3.0 * u3 - 6.0 * u2 + 4.0, -3.0 * u3 + 3.0 * u2 + 3.0 * u + 1.0, u3) / 6.0;
    case 1:
      return Eigen::Vector4d(-w * w, 3.0 * u2 - 4.0 * u, -3.0 * u2 + 2.0 * u + 1.0, u2) / 2.0;
    case 2:
      return Eigen::Vector4d(w, 3.0 * u - 2.0, 1.0 - 3.0 * u, u);
    case 3:
      return Eigen::Vector4d(-1.0, 3.0, -3.0, 1.0);
    default:
      throw std::invalid_argument("B-spline derivative order " + std::to_string(derivative) + " is not 0..3");
  }
}

void UniformBSpline::locate(double t, double dt, int spans, int* span, double* u) {
  const double x = std::clamp(t / dt, 0.0, static_cast<double>(spans));
  const int i = std::min(static_cast<int>(std::floor(x)), spans - 1);
  *span = i;
  *u = x - i;
}

Eigen::VectorXd UniformBSpline::evaluate(double t, int derivative) const {
  int i = 0;
  double u = 0.0;
  locate(t, &i, &u);
  const Eigen::Vector4d b = basis(u, derivative) / std::pow(dt_, derivative);
  return (q_.middleRows(i, 4).transpose() * b);
}

}  // namespace tgnav::planner
