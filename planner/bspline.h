#pragma once
// Uniform cubic B-spline in any number of dimensions (position: 3, yaw: 1).
//
// Control points Q_0 .. Q_{M+2} (rows of a matrix) and knot interval dt define the curve on
// [0, M dt]: span i (t in [i dt, (i+1) dt), u = t/dt - i) blends Q_i .. Q_{i+3}. The curve is
// C2: position, velocity and acceleration are continuous at the knots; jerk is constant in each
// span. Convex-hull property used by the trajectory optimiser: velocity is a quadratic B-spline
// of V_i = (Q_{i+1} - Q_i)/dt and acceleration a linear one of A_i = (Q_{i+2} - 2 Q_{i+1} + Q_i)/dt^2,
// so |v| <= max |V_i| and |a| <= max |A_i| (acceleration peaks exactly at a knot).
#include <Eigen/Core>

namespace tgnav::planner {

class UniformBSpline {
 public:
  UniformBSpline() = default;
  // At least 4 control points, dt > 0 (std::invalid_argument otherwise).
  UniformBSpline(Eigen::MatrixXd control_points, double dt);

  int spans() const { return static_cast<int>(q_.rows()) - 3; }
  int dims() const { return static_cast<int>(q_.cols()); }
  double knotInterval() const { return dt_; }
  double duration() const { return dt_ * spans(); }
  const Eigen::MatrixXd& controlPoints() const { return q_; }
  // Same curve shape, new timing (every derivative of order k scales by (old/new)^k).
  void setKnotInterval(double dt);

  // Derivative of order 0..3 at t (clamped to [0, duration()]).
  Eigen::VectorXd evaluate(double t, int derivative = 0) const;

  // Weights of Q_i .. Q_{i+3} for d^k/du^k at u in [0, 1] (divide by dt^k for time derivatives).
  static Eigen::Vector4d basis(double u, int derivative);
  // Span and u of time t (clamped to the curve).
  void locate(double t, int* span, double* u) const { locate(t, dt_, spans(), span, u); }
  // The same for any uniform spline of `spans` spans, `dt` apart.
  static void locate(double t, double dt, int spans, int* span, double* u);

 private:
  Eigen::MatrixXd q_;
  double dt_ = 1.0;
};

}  // namespace tgnav::planner
