#include "planner/trajectory_generator.h"

#include <LBFGS.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "planner/check.h"
#include "planner/topological_planner.h"

namespace tgnav::planner {

namespace {

constexpr double kTwoPi = 2.0 * M_PI;
// The optimiser aims this much beyond the clearance target: a penalty only balances other
// terms at a small violation of its own threshold.
constexpr double kMarginBuffer_m = 0.05;

// ---------------------------------------------------------------------------------------------
// The path as a reference r(t): points with unwrapped yaw and their nominal times.

struct Reference {
  // A stretch of the path flown at one go (its pace ramps up from rest and back down) or a turn
  // on the spot (at the nominal yaw rate throughout).
  struct Phase {
    double sigma0 = 0.0;  // nominal time span of the phase
    double sigma1 = 0.0;
    double t0 = 0.0;  // start and duration in real time
    double duration = 0.0;
    bool travel = true;
  };
  std::vector<Eigen::Vector3d> p;
  std::vector<double> yaw;    // unwrapped: consecutive values differ by at most pi
  std::vector<double> sigma;  // nominal time of each point (no ramps)
  std::vector<Phase> phases;
  double ramp_s = 0.0;      // time to reach the nominal pace
  double duration_s = 0.0;  // with the ramps

  // A travel phase's pace dsigma/dt rises from 0 to its peak q <= 1 in q * ramp_s along the
  // minimum-jerk step 10x^3 - 15x^4 + 6x^5 (acceleration starts and ends at zero: a reference
  // with a kink in speed would be smoothed with an undershoot, the vehicle backing up before it
  // sets off), holds, and falls back the same way. q < 1 when the phase is too short to reach
  // full pace.
  double peakPace(double span) const { return std::min(1.0, std::sqrt(span / ramp_s)); }
  double travelTime(double span) const {
    const double q = peakPace(span);
    return span / q + q * ramp_s;
  }
  // Nominal time reached at time t.
  double sigmaAt(double t) const {
    if (phases.empty()) return 0.0;
    t = std::clamp(t, 0.0, duration_s);
    const auto it =
        std::upper_bound(phases.begin(), phases.end(), t, [](double x, const Phase& ph) { return x < ph.t0; });
    const Phase& ph = *(it == phases.begin() ? it : it - 1);
    const double tau = std::clamp(t - ph.t0, 0.0, ph.duration);
    const double span = ph.sigma1 - ph.sigma0;
    if (!ph.travel) return ph.sigma0 + span * tau / ph.duration;
    const double q = peakPace(span);
    const double rise = q * ramp_s;
    auto ramp = [&](double r) {  // nominal time covered r into the rise
      const double x = r / rise;
      return q * rise * x * x * x * x * (2.5 - 3.0 * x + x * x);
    };
    if (tau <= rise) return ph.sigma0 + ramp(tau);
    if (tau >= ph.duration - rise) return ph.sigma1 - ramp(ph.duration - tau);
    return ph.sigma0 + 0.5 * q * rise + q * (tau - rise);
  }
  // Position and yaw at nominal time s (linear between points).
  void at(double s, Eigen::Vector3d* pos, double* psi) const {
    const auto it = std::upper_bound(sigma.begin(), sigma.end(), s);
    if (it == sigma.begin()) {
      *pos = p.front();
      *psi = yaw.front();
      return;
    }
    if (it == sigma.end()) {
      *pos = p.back();
      *psi = yaw.back();
      return;
    }
    const std::size_t k = static_cast<std::size_t>(it - sigma.begin());
    const double f = (s - sigma[k - 1]) / (sigma[k] - sigma[k - 1]);
    *pos = p[k - 1] + f * (p[k] - p[k - 1]);
    *psi = yaw[k - 1] + f * (yaw[k] - yaw[k - 1]);
  }
};

// Step 1 of the header, on the points' nominal times: the ramps, and the phases in real time.
void allocateTime(const TrajectoryConfig& config, Reference* ref) {
  // A B-spline pinned at rest with zero acceleration needs a few knot intervals to get going:
  // a ramp shorter than that would only be caught up with by a speed bump.
  const double knot_s = config.knot_spacing_m / config.nominal_speed_mps;
  ref->ramp_s = std::max(config.nominal_speed_mps / config.nominal_accel_mps2, 3.0 * knot_s);
  // Phases: runs of steps that move, and turns on the spot between them (the vehicle comes to rest
  // for a turn, so the next run ramps up from rest again).
  for (std::size_t k = 1; k < ref->p.size(); ++k) {
    const bool travel = (ref->p[k] - ref->p[k - 1]).norm() >= 1e-6;
    if (ref->phases.empty() || ref->phases.back().travel != travel) {
      Reference::Phase ph;
      ph.sigma0 = ph.sigma1 = ref->sigma[k - 1];
      ph.travel = travel;
      ref->phases.push_back(ph);
    }
    ref->phases.back().sigma1 = ref->sigma[k];
  }
  double t = 0.0;
  for (Reference::Phase& ph : ref->phases) {
    ph.t0 = t;
    ph.duration = ph.travel ? ref->travelTime(ph.sigma1 - ph.sigma0) : ph.sigma1 - ph.sigma0;
    t += ph.duration;
  }
  ref->duration_s = t;
}

// The path's points with unwrapped yaw (repeats dropped) and their nominal times, then timed.
Reference makeReference(const TrajectoryRequest& request, const TrajectoryConfig& config) {
  Reference ref;
  auto add = [&](const Eigen::Vector3d& p, double yaw) {
    if (ref.p.empty()) {
      ref.p.push_back(p);
      ref.yaw.push_back(yaw);
      ref.sigma.push_back(0.0);
      return;
    }
    const double dyaw = std::remainder(yaw - ref.yaw.back(), kTwoPi);
    const double ds = (p - ref.p.back()).norm();
    if (ds < 1e-6 && std::abs(dyaw) < 1e-9) return;  // repeated point
    ref.p.push_back(p);
    ref.yaw.push_back(ref.yaw.back() + dyaw);
    ref.sigma.push_back(ref.sigma.back() +
                        std::max(ds / config.nominal_speed_mps, std::abs(dyaw) / config.nominal_yaw_rate_rad_s));
  };
  if (std::isfinite(request.start_yaw_rad)) add(request.path.front().p_WB, request.start_yaw_rad);
  for (const Pose4& pose : request.path) add(pose.p_WB, pose.yaw_rad);
  ref.p.back() = request.path.back().p_WB;  // exactly at the goal (a dropped repeat is < 1 um away)
  allocateTime(config, &ref);
  return ref;
}

// The clearance to aim for at p: the margin, except near a start or goal that lies closer to an
// obstacle than that (the trajectory must begin and end there): their own clearance plus a fifth
// of the distance from them. Without this the pinned ends fight the clearance term (seen: a loop
// around the goal of the smoke scene, which is 0.41 m from two crates).
struct ClearanceTarget {
  static constexpr double kEndpointSlope = 0.2;
  double margin = 0.0;
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  Eigen::Vector3d goal = Eigen::Vector3d::Zero();
  double start_clearance = 0.0;
  double goal_clearance = 0.0;

  double aim(const Eigen::Vector3d& p, double extra) const {
    return std::min({margin + extra, start_clearance + kEndpointSlope * (p - start).norm(),
                     goal_clearance + kEndpointSlope * (p - goal).norm()});
  }
  // What the result must keep: the margin, and where the aim is relaxed, no less than the nearer
  // end's own clearance (how fast clearance can grow on leaving it depends on the obstacles).
  double required(const Eigen::Vector3d& p) const {
    const double a = start_clearance + kEndpointSlope * (p - start).norm();
    const double b = goal_clearance + kEndpointSlope * (p - goal).norm();
    if (std::min(a, b) >= margin) return margin;
    return a <= b ? start_clearance : goal_clearance;
  }
};

// ---------------------------------------------------------------------------------------------
// One B-spline fit: the first and last three control points are fixed, the rest free.

struct FitSample {
  double t = 0.0;
  Eigen::VectorXd value;
};

class SplineFit {
 public:
  // Rows of `q` with `fixed` set stay as they are (at least the first and last three: rest to rest).
  SplineFit(Eigen::MatrixXd q, double dt, const std::vector<bool>& fixed) : q_(std::move(q)), dt_(dt) {
    for (int i = 0; i < static_cast<int>(q_.rows()); ++i) {
      if (!fixed[static_cast<std::size_t>(i)]) free_.push_back(i);
    }
  }

  std::vector<FitSample> reference;  // r(t) samples, `ref_h` apart
  double ref_h = 1.0;
  double w_ref = 1.0;                                      // smoothness has weight 1
  double v_max = std::numeric_limits<double>::infinity();  // on |(Q_{i+1} - Q_i) / dt|
  double a_max = std::numeric_limits<double>::infinity();  // on |(Q_{i+2} - 2 Q_{i+1} + Q_i) / dt^2|
  double w_feas = 0.0;                                     // on the relative excess (|V|^2 / v_max^2 - 1)^2, integrated
  const ClearanceField* field = nullptr;                   // position only
  ClearanceTarget target;
  double target_extra = 0.0;  // aim this far beyond the target's margin
  double w_clear = 0.0;
  int clearance_samples_per_span = 4;

  int freeRows() const { return static_cast<int>(free_.size()); }
  Eigen::VectorXd freeVector() const {
    Eigen::VectorXd x(freeRows() * q_.cols());
    for (int i = 0; i < freeRows(); ++i) x.segment(i * q_.cols(), q_.cols()) = q_.row(free_[i]).transpose();
    return x;
  }
  void setFree(const Eigen::VectorXd& x) {
    for (int i = 0; i < freeRows(); ++i) q_.row(free_[i]) = x.segment(i * q_.cols(), q_.cols()).transpose();
  }
  const Eigen::MatrixXd& controlPoints() const { return q_; }

  // Cost and gradient (LBFGSpp's functor interface); remembers the best point seen.
  double operator()(const Eigen::VectorXd& x, Eigen::VectorXd& grad) {
    setFree(x);
    Eigen::MatrixXd g = Eigen::MatrixXd::Zero(q_.rows(), q_.cols());
    const double f = cost(&g);
    for (int i = 0; i < freeRows(); ++i) grad.segment(i * q_.cols(), q_.cols()) = g.row(free_[i]).transpose();
    if (f < best_f_) {
      best_f_ = f;
      best_x_ = x;
    }
    return f;
  }
  // Runs L-BFGS from the current control points; keeps the best point even if the line search
  // gives up (it throws on a kink of the penalties). Returns the iterations used.
  int optimise(int max_iterations) {
    if (freeRows() <= 0) return 0;
    LBFGSpp::LBFGSParam<double> param;
    param.max_iterations = max_iterations;
    param.epsilon = 1e-6;
    param.epsilon_rel = 1e-5;
    param.past = 3;
    param.delta = 1e-5;
    param.max_linesearch = 40;
    LBFGSpp::LBFGSSolver<double> solver(param);
    Eigen::VectorXd x = freeVector();
    best_x_ = x;
    best_f_ = std::numeric_limits<double>::infinity();
    double fx = 0.0;
    int iterations = max_iterations;
    try {
      iterations = solver.minimize(*this, x, fx);
    } catch (const std::runtime_error&) {
      // Line search failure at a penalty kink: the best point so far stands.
    } catch (const std::logic_error&) {
      // Numerically not a descent direction: the same.
    }
    setFree(best_x_);
    return iterations;
  }

 private:
  double cost(Eigen::MatrixXd* g) const {
    const int n = static_cast<int>(q_.rows());
    const int spans = n - 3;
    double f = 0.0;
    // Smoothness: integral of |jerk|^2, jerk constant per span.
    const double js = 1.0 / std::pow(dt_, 5);
    for (int i = 0; i + 3 < n; ++i) {
      const Eigen::RowVectorXd j = q_.row(i + 3) - 3.0 * q_.row(i + 2) + 3.0 * q_.row(i + 1) - q_.row(i);
      f += js * j.squaredNorm();
      const Eigen::RowVectorXd d = 2.0 * js * j;
      g->row(i) -= d;
      g->row(i + 1) += 3.0 * d;
      g->row(i + 2) -= 3.0 * d;
      g->row(i + 3) += d;
    }
    // Closeness to the reference.
    for (const FitSample& s : reference) {
      int i = 0;
      double u = 0.0;
      UniformBSpline::locate(s.t, dt_, spans, &i, &u);
      const Eigen::Vector4d b = UniformBSpline::basis(u, 0);
      const Eigen::RowVectorXd e = b.transpose() * q_.middleRows(i, 4) - s.value.transpose();
      f += w_ref * ref_h * e.squaredNorm();
      for (int k = 0; k < 4; ++k) g->row(i + k) += 2.0 * w_ref * ref_h * b[k] * e;
    }
    // Clearance.
    if (field && w_clear > 0.0) {
      const double h = dt_ / clearance_samples_per_span;
      for (int i = 0; i < spans; ++i) {
        for (int k = 0; k < clearance_samples_per_span; ++k) {
          const Eigen::Vector4d b = UniformBSpline::basis(static_cast<double>(k) / clearance_samples_per_span, 0);
          const Eigen::Vector3d p = (b.transpose() * q_.middleRows(i, 4)).transpose();
          Eigen::Vector3d grad_d;
          const double d = field->clearance(p, &grad_d);
          const double want = target.aim(p, target_extra);
          if (d >= want) continue;
          const double e = want - d;
          f += w_clear * h * e * e;
          for (int m = 0; m < 4; ++m) g->row(i + m) -= 2.0 * w_clear * h * e * b[m] * grad_d.transpose();
        }
      }
    }
    // Feasibility: velocity and acceleration control points.
    if (w_feas > 0.0 && std::isfinite(v_max)) {
      for (int i = 0; i + 1 < n; ++i) {
        const Eigen::RowVectorXd v = (q_.row(i + 1) - q_.row(i)) / dt_;
        const double e = v.squaredNorm() / (v_max * v_max) - 1.0;
        if (e <= 0.0) continue;
        f += w_feas * dt_ * e * e;
        const Eigen::RowVectorXd d = w_feas * dt_ * 2.0 * e * 2.0 * v / (v_max * v_max * dt_);
        g->row(i + 1) += d;
        g->row(i) -= d;
      }
    }
    if (w_feas > 0.0 && std::isfinite(a_max)) {
      for (int i = 0; i + 2 < n; ++i) {
        const Eigen::RowVectorXd a = (q_.row(i + 2) - 2.0 * q_.row(i + 1) + q_.row(i)) / (dt_ * dt_);
        const double e = a.squaredNorm() / (a_max * a_max) - 1.0;
        if (e <= 0.0) continue;
        f += w_feas * dt_ * e * e;
        const Eigen::RowVectorXd d = w_feas * dt_ * 2.0 * e * 2.0 * a / (a_max * a_max * dt_ * dt_);
        g->row(i + 2) += d;
        g->row(i + 1) -= 2.0 * d;
        g->row(i) += d;
      }
    }
    return f;
  }

  Eigen::MatrixXd q_;
  double dt_;
  std::vector<int> free_;  // rows being optimised
  Eigen::VectorXd best_x_;
  double best_f_ = std::numeric_limits<double>::infinity();
};

// ---------------------------------------------------------------------------------------------
// Fallback: the path point to point, each step a minimum-jerk move from rest to rest.

class StopAndGoTrajectory final : public Trajectory {
 public:
  StopAndGoTrajectory(const Reference& ref, const TrajectoryConfig& config) : p_(ref.p), yaw_(ref.yaw) {
    start_.push_back(0.0);
    for (std::size_t k = 1; k < p_.size(); ++k) {
      const double len = (p_[k] - p_[k - 1]).norm();
      const double turn = std::abs(yaw_[k] - yaw_[k - 1]);
      // Peaks of s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5: s' 1.875, |s''| 5.7735 (tau = T/2 +- 0.29 T).
      const double duration =
          std::max({1.875 * len / config.max_speed_mps, std::sqrt(5.7735 * len / config.max_accel_mps2),
                    1.875 * turn / config.max_yaw_rate_rad_s, 1e-3});
      start_.push_back(start_.back() + duration);
    }
  }
  double duration() const override { return start_.back(); }
  TrajectorySample at(double t_s) const override {
    TrajectorySample s;
    s.t_s = t_s;
    const double t = std::clamp(t_s, 0.0, duration());
    const auto it = std::upper_bound(start_.begin(), start_.end(), t);
    if (it == start_.end() || p_.size() == 1) {
      s.p_W = p_.back();
      s.yaw_rad = yaw_.back();
      return s;
    }
    const std::size_t k = static_cast<std::size_t>(it - start_.begin());  // move k-1 -> k
    const double T = start_[k] - start_[k - 1];
    const double tau = (t - start_[k - 1]) / T;
    const double s0 = tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
    const double s1 = 30.0 * tau * tau * (1.0 - tau) * (1.0 - tau) / T;
    const double s2 = (60.0 * tau - 180.0 * tau * tau + 120.0 * tau * tau * tau) / (T * T);
    const Eigen::Vector3d d = p_[k] - p_[k - 1];
    const double dyaw = yaw_[k] - yaw_[k - 1];
    s.p_W = p_[k - 1] + s0 * d;
    s.v_W = s1 * d;
    s.a_W = s2 * d;
    s.yaw_rad = yaw_[k - 1] + s0 * dyaw;
    s.yaw_rate_rad_s = s1 * dyaw;
    return s;
  }

 private:
  std::vector<Eigen::Vector3d> p_;
  std::vector<double> yaw_;
  std::vector<double> start_;  // start time of each move; back() = duration
};

// ---------------------------------------------------------------------------------------------
// Checks.

struct Measured {
  double min_clearance = std::numeric_limits<double>::infinity();
  double min_slack = std::numeric_limits<double>::infinity();  // clearance less its target
  Eigen::Vector3d closest = Eigen::Vector3d::Zero();           // where
  double max_speed = 0.0;
  double max_accel = 0.0;
  double max_yaw_rate = 0.0;
  double length = 0.0;
};

// Speed, acceleration, yaw rate and length sampled at 1 kHz; clearance stepped along the curve
// as far as the 1-Lipschitz distance allows (never more than 1 ms apart within the margin + the
// distance covered in 1 ms), so the minimum near any close pass is measured at 1 kHz and far
// stretches cost little.
Measured measure(const Trajectory& trajectory, const ClearanceField& field, const ClearanceTarget& target) {
  Measured m;
  const double T = trajectory.duration();
  const int n = std::max(1, static_cast<int>(std::ceil(T * 1000.0)));
  Eigen::Vector3d last = trajectory.at(0.0).p_W;
  for (int i = 0; i <= n; ++i) {
    const TrajectorySample s = trajectory.at(T * i / n);
    m.max_speed = std::max(m.max_speed, s.v_W.norm());
    m.max_accel = std::max(m.max_accel, s.a_W.norm());
    m.max_yaw_rate = std::max(m.max_yaw_rate, std::abs(s.yaw_rate_rad_s));
    m.length += (s.p_W - last).norm();
    last = s.p_W;
  }
  // A B-spline's acceleration is linear in each span: its largest norm is at a knot, exactly.
  if (const auto* spline = dynamic_cast<const BSplineTrajectory*>(&trajectory)) {
    const double dt = spline->position().knotInterval();
    for (int k = 0; k <= spline->position().spans(); ++k) {
      const Eigen::VectorXd a = spline->position().evaluate(k * dt, 2);
      m.max_accel = std::max(m.max_accel, a.norm());
    }
  }
  // Speed bound for the stepping (the 1 kHz maximum, with room for what falls between samples).
  const double v_bound = 1.05 * m.max_speed + 1e-6;
  const double min_step = T / n;
  for (double t = 0.0;;) {
    const Eigen::Vector3d p = trajectory.at(t).p_W;
    const double d = field.clearance(p, nullptr);
    if (d < m.min_clearance) {
      m.min_clearance = d;
      m.closest = p;
    }
    m.min_slack = std::min(m.min_slack, d - target.required(p));
    if (t >= T) break;
    t = std::min(T, t + std::max(min_step, (d - target.margin) / v_bound));
  }
  return m;
}

std::vector<Eigen::Vector2d> planar(const Trajectory& trajectory, double rate_hz) {
  std::vector<Eigen::Vector2d> xy;
  for (const TrajectorySample& s : sampleTrajectory(trajectory, rate_hz)) xy.push_back(s.p_W.head<2>());
  return xy;
}

std::string where(const Eigen::Vector3d& p) {
  std::ostringstream out;
  out.precision(3);
  out << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return out.str();
}

void fillReport(const Measured& m, TrajectoryReport* report) {
  report->duration_s = report->trajectory->duration();
  report->length_m = m.length;
  report->min_clearance_m = m.min_clearance;
  report->margin_met = m.min_slack >= -1e-9;
  report->max_speed_mps = m.max_speed;
  report->max_accel_mps2 = m.max_accel;
  report->max_yaw_rate_rad_s = m.max_yaw_rate;
}

// ---------------------------------------------------------------------------------------------
// The steps of generateTrajectory.

void checkRequest(const TrajectoryRequest& request, const TrajectoryConfig& config) {
  config.validate();
  if (request.path.empty()) throw std::invalid_argument("path: empty (a trajectory needs at least the start)");
  for (std::size_t i = 0; i < request.path.size(); ++i) {
    const Pose4& p = request.path[i];
    if (!p.p_WB.allFinite() || !std::isfinite(p.yaw_rad)) {
      throw std::invalid_argument("path: point " + std::to_string(i) + " is not finite");
    }
  }
}

// The path's clearance, sampled every 1 cm along its segments, and where it is smallest.
void pathClearance(const std::vector<Eigen::Vector3d>& path, const ClearanceField& field, double* clearance,
                   Eigen::Vector3d* closest) {
  for (std::size_t k = 0; k < path.size(); ++k) {
    const Eigen::Vector3d& a = path[k];
    const Eigen::Vector3d b = k + 1 < path.size() ? path[k + 1] : a;
    const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / 0.01)));
    for (int i = 0; i < steps; ++i) {
      const Eigen::Vector3d p = a + (b - a) * (static_cast<double>(i) / steps);
      const double d = field.clearance(p, nullptr);
      if (d < *clearance) {
        *clearance = d;
        *closest = p;
      }
    }
  }
}

// A request, and what generateTrajectory derives from it before optimising.
struct Problem {
  Problem(const TrajectoryRequest& request, const ClearanceField& field, const TrajectoryConfig& config);

  const TrajectoryRequest& request;
  const ClearanceField& field;
  const TrajectoryConfig& config;
  Reference ref;
  // The path's own safety decides whether there is a fallback.
  double path_clearance = std::numeric_limits<double>::infinity();
  Eigen::Vector3d path_closest;  // where the path is closest to an obstacle
  bool path_safe = false;
  ClearanceTarget target;
  std::vector<double> signature;  // the path's winding angles (H-signature), given obstacle points
};

Problem::Problem(const TrajectoryRequest& request, const ClearanceField& field, const TrajectoryConfig& config)
    : request(request), field(field), config(config), ref(makeReference(request, config)), path_closest(ref.p.front()) {
  pathClearance(ref.p, field, &path_clearance, &path_closest);
  path_safe = path_clearance >= config.robot_radius_m - 1e-3;
  target.margin = config.margin_m();
  target.start = ref.p.front();
  target.goal = ref.p.back();
  target.start_clearance = field.clearance(target.start, nullptr);
  target.goal_clearance = field.clearance(target.goal, nullptr);
  if (request.obstacle_points) {
    std::vector<Eigen::Vector2d> xy;
    for (const auto& p : ref.p) xy.push_back(p.head<2>());
    signature = windingAngles(xy, *request.obstacle_points);
  }
}

// The path itself flown point to point (StopAndGoTrajectory), measured into `report`.
TrajectoryReport flyPath(const Problem& problem, TrajectoryStatus status, TrajectoryReport report) {
  report.status = status;
  report.trajectory = std::make_shared<StopAndGoTrajectory>(problem.ref, problem.config);
  fillReport(measure(*report.trajectory, problem.field, problem.target), &report);
  report.homology_checked = problem.request.obstacle_points != nullptr;
  report.same_homology = true;  // the path itself
  report.time_scale = 1.0;
  return report;
}

// Step 4's fallback, with the reason: the path itself (safe where the path is), or kFailed where
// the path itself comes closer than the robot radius.
TrajectoryReport fallBack(const Problem& problem, TrajectoryReport report, const std::string& reason) {
  report.reason = reason;
  if (!problem.path_safe) {
    std::ostringstream msg;
    msg << reason << "; and the path itself comes within " << std::max(0.0, problem.path_clearance)
        << " m of an obstacle at " << where(problem.path_closest) << " (robot radius " << problem.config.robot_radius_m
        << " m)";
    report.status = TrajectoryStatus::kFailed;
    report.reason = msg.str();
    report.trajectory.reset();
    return report;
  }
  return flyPath(problem, TrajectoryStatus::kFallback, std::move(report));
}

// Knots on the reference's time line and the control points the fits start from.
struct SplineStart {
  int spans = 0;
  double dt = 0.0;  // knot interval
  Eigen::MatrixXd qp;
  Eigen::MatrixXd qy;
  std::vector<bool> fixed_p;  // control points the fits leave as they are
  std::vector<bool> fixed_y;
};

// Fixes the position throughout every span that lies within a turn on the spot (smoothing would
// otherwise let it creep while turning and back up before setting off, like any low-pass filter
// rings).
void holdStillWhileTurning(const Reference& ref, SplineStart* s) {
  const int n = static_cast<int>(s->qp.rows());
  for (const Reference::Phase& ph : ref.phases) {
    if (ph.travel) continue;
    Eigen::Vector3d spot;
    double unused = 0.0;
    ref.at(ph.sigma0, &spot, &unused);
    const int first = static_cast<int>(std::ceil(ph.t0 / s->dt - 1e-9));
    const int last = static_cast<int>(std::floor((ph.t0 + ph.duration) / s->dt + 1e-9)) - 1;  // spans inside
    for (int j = first; j <= last; ++j) {
      for (int k = j; k < j + 4 && k < n; ++k) {
        s->fixed_p[static_cast<std::size_t>(k)] = true;
        s->qp.row(k) = spot.transpose();
      }
    }
  }
}

// Knots knot_spacing_m / v_nom apart (at least 6 spans) and the control points from the
// reference; fixed: the ends (rest to rest) and the position while turning on the spot.
SplineStart startSplines(const Reference& ref, const TrajectoryConfig& config) {
  SplineStart s;
  const double T0 = ref.duration_s;
  s.spans = std::max(6, static_cast<int>(std::ceil(T0 / (config.knot_spacing_m / config.nominal_speed_mps))));
  s.dt = T0 / s.spans;
  const int n = s.spans + 3;
  s.qp.resize(n, 3);
  s.qy.resize(n, 1);
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d p;
    double psi = 0.0;
    const double t = i <= 2 ? 0.0 : i >= s.spans ? T0 : (i - 1) * s.dt;
    ref.at(ref.sigmaAt(t), &p, &psi);
    s.qp.row(i) = p.transpose();
    s.qy(i, 0) = psi;
  }
  s.fixed_p.assign(static_cast<std::size_t>(n), false);
  s.fixed_y.assign(static_cast<std::size_t>(n), false);
  for (int i : {0, 1, 2, n - 3, n - 2, n - 1}) {
    s.fixed_p[static_cast<std::size_t>(i)] = s.fixed_y[static_cast<std::size_t>(i)] = true;
  }
  holdStillWhileTurning(ref, &s);
  return s;
}

constexpr int kReferenceSamplesPerSpan = 2;

// Reference samples for the closeness term, kReferenceSamplesPerSpan per span.
void sampleReference(const Reference& ref, const SplineStart& s, std::vector<FitSample>* ref_p,
                     std::vector<FitSample>* ref_y) {
  for (int j = 0; j <= s.spans * kReferenceSamplesPerSpan; ++j) {
    const double t = j * s.dt / kReferenceSamplesPerSpan;
    Eigen::Vector3d p;
    double psi = 0.0;
    ref.at(ref.sigmaAt(t), &p, &psi);
    ref_p->push_back({t, p});
    ref_y->push_back({t, Eigen::VectorXd::Constant(1, psi)});
  }
}

// A fit on the start's knots with the terms position and yaw share: closeness to the reference
// (weight w_r of the header) and feasibility.
SplineFit makeFit(const Eigen::MatrixXd& q, const std::vector<bool>& fixed, double dt, std::vector<FitSample> reference,
                  const TrajectoryConfig& config) {
  SplineFit fit(q, dt, fixed);
  fit.reference = std::move(reference);
  fit.ref_h = dt / kReferenceSamplesPerSpan;
  fit.w_ref = std::pow(kTwoPi * config.nominal_speed_mps / config.smoothing_length_m, 6);
  // Feasibility on the relative excess, scaled to the closeness term's m^2 by the knot spacing.
  fit.w_feas = config.feasibility_weight * fit.w_ref * config.knot_spacing_m * config.knot_spacing_m;
  return fit;
}

// Steps 2 and 3 of the header: position (with clearance) and yaw fitted on the same knots.
// Closer than the robot radius: the clearance term stiffened (twice at most). The margin beyond
// the radius stays a soft target (a passage narrower than twice the margin cannot have it).
// `m` gets the result measured; `iterations` adds the L-BFGS iterations.
std::shared_ptr<BSplineTrajectory> optimise(const Problem& problem, Measured* m, int* iterations) {
  const TrajectoryConfig& config = problem.config;
  const SplineStart s = startSplines(problem.ref, config);
  std::vector<FitSample> ref_p;
  std::vector<FitSample> ref_y;
  sampleReference(problem.ref, s, &ref_p, &ref_y);

  SplineFit pos = makeFit(s.qp, s.fixed_p, s.dt, std::move(ref_p), config);
  pos.v_max = config.max_speed_mps;
  pos.a_max = config.max_accel_mps2;
  pos.field = &problem.field;
  pos.target = problem.target;
  pos.target_extra = kMarginBuffer_m;
  pos.w_clear = config.clearance_weight * pos.w_ref;
  *iterations += pos.optimise(config.max_iterations);

  SplineFit yaw = makeFit(s.qy, s.fixed_y, s.dt, std::move(ref_y), config);
  yaw.v_max = config.max_yaw_rate_rad_s;
  *iterations += yaw.optimise(config.max_iterations);

  auto spline = [&] {
    return std::make_shared<BSplineTrajectory>(UniformBSpline(pos.controlPoints(), s.dt),
                                               UniformBSpline(yaw.controlPoints(), s.dt));
  };
  std::shared_ptr<BSplineTrajectory> trajectory = spline();
  *m = measure(*trajectory, problem.field, problem.target);
  for (int round = 0; round < 2 && m->min_clearance < config.robot_radius_m; ++round) {
    pos.w_clear *= 10.0;
    *iterations += pos.optimise(config.max_iterations);
    trajectory = spline();
    *m = measure(*trajectory, problem.field, problem.target);
  }
  return trajectory;
}

// Step 4's checks of the shape, which re-timing cannot change: clearance >= robot radius and,
// given obstacle points, the path's homology class. Returns why it failed (empty if it passed).
std::string checkShape(const Problem& problem, const Trajectory& trajectory, const Measured& m,
                       TrajectoryReport* report) {
  if (m.min_clearance < problem.config.robot_radius_m) {
    std::ostringstream msg;
    msg << "optimised trajectory comes within " << std::max(0.0, m.min_clearance) << " m of an obstacle at "
        << where(m.closest) << " (robot radius " << problem.config.robot_radius_m << " m)";
    return msg.str();
  }
  if (problem.request.obstacle_points) {
    report->homology_checked = true;
    report->same_homology = TopologicalPlanner::sameClass(
        windingAngles(planar(trajectory, problem.config.sample_rate_hz), *problem.request.obstacle_points),
        problem.signature);
    if (!report->same_homology) return "optimised trajectory left the path's homology class";
  }
  return "";
}

// Re-time until the limits hold: stretching the knot interval by s divides velocity by s,
// acceleration by s^2, and leaves the shape alone.
void retime(const Problem& problem, BSplineTrajectory* trajectory, Measured* m, int* retimes) {
  const TrajectoryConfig& config = problem.config;
  for (int round = 0; round < 4; ++round) {
    const double scale =
        std::max({1.0, m->max_speed / config.max_speed_mps, std::sqrt(m->max_accel / config.max_accel_mps2),
                  m->max_yaw_rate / config.max_yaw_rate_rad_s});
    if (scale <= 1.0) break;
    ++*retimes;
    trajectory->setKnotInterval(trajectory->position().knotInterval() * scale * 1.01);
    *m = measure(*trajectory, problem.field, problem.target);
  }
}

bool exceedsLimits(const Measured& m, const TrajectoryConfig& config) {
  return m.max_speed > config.max_speed_mps || m.max_accel > config.max_accel_mps2 ||
         m.max_yaw_rate > config.max_yaw_rate_rad_s;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

double VoxelClearance::clearance(const Eigen::Vector3d& p_W, Eigen::Vector3d* gradient) const {
  return map_.clearance(p_W, gradient);
}

double PlanarClearance::clearance(const Eigen::Vector3d& p_W, Eigen::Vector3d* gradient) const {
  Eigen::Vector2d g;
  const double d = field_.clearance(p_W.head<2>(), gradient ? &g : nullptr);
  if (gradient) *gradient << g, 0.0;
  return d;
}

void TrajectoryConfig::validate() const {
  auto positive = [](double v, const char* field) { require(std::isfinite(v) && v > 0.0, field, v, "must be > 0"); };
  positive(nominal_speed_mps, "trajectory.nominal_speed_mps");
  positive(nominal_accel_mps2, "trajectory.nominal_accel_mps2");
  positive(nominal_yaw_rate_rad_s, "trajectory.nominal_yaw_rate_rad_s");
  positive(max_speed_mps, "trajectory.max_speed_mps");
  positive(max_accel_mps2, "trajectory.max_accel_mps2");
  positive(max_yaw_rate_rad_s, "trajectory.max_yaw_rate_rad_s");
  positive(knot_spacing_m, "trajectory.knot_spacing_m");
  positive(smoothing_length_m, "trajectory.smoothing_length_m");
  positive(sample_rate_hz, "trajectory.sample_rate_hz");
  require(nominal_speed_mps <= max_speed_mps, "trajectory.nominal_speed_mps", nominal_speed_mps,
          "must be <= trajectory.max_speed_mps");
  require(nominal_accel_mps2 <= max_accel_mps2, "trajectory.nominal_accel_mps2", nominal_accel_mps2,
          "must be <= trajectory.max_accel_mps2");
  require(nominal_yaw_rate_rad_s <= max_yaw_rate_rad_s, "trajectory.nominal_yaw_rate_rad_s", nominal_yaw_rate_rad_s,
          "must be <= trajectory.max_yaw_rate_rad_s");
  require(std::isfinite(robot_radius_m) && robot_radius_m >= 0.0, "robot_radius_m", robot_radius_m, "must be >= 0");
  require(std::isfinite(safety_margin_m) && safety_margin_m >= 0.0, "trajectory.safety_margin_m", safety_margin_m,
          "must be >= 0");
  require(std::isfinite(clearance_weight) && clearance_weight >= 0.0, "trajectory.clearance_weight", clearance_weight,
          "must be >= 0");
  require(std::isfinite(feasibility_weight) && feasibility_weight >= 0.0, "trajectory.feasibility_weight",
          feasibility_weight, "must be >= 0");
  require(max_iterations >= 1, "trajectory.max_iterations", max_iterations, "must be >= 1");
}

const char* toString(TrajectoryStatus status) {
  switch (status) {
    case TrajectoryStatus::kOptimised:
      return "optimised";
    case TrajectoryStatus::kFallback:
      return "fallback";
    case TrajectoryStatus::kFailed:
      return "failed";
  }
  return "?";
}

BSplineTrajectory::BSplineTrajectory(UniformBSpline position, UniformBSpline yaw)
    : position_(std::move(position)), yaw_(std::move(yaw)) {
  if (position_.dims() != 3 || yaw_.dims() != 1 || position_.spans() != yaw_.spans() ||
      position_.knotInterval() != yaw_.knotInterval()) {
    throw std::invalid_argument("BSplineTrajectory: position (3D) and yaw (1D) need the same knots");
  }
}

void BSplineTrajectory::setKnotInterval(double dt) {
  position_.setKnotInterval(dt);
  yaw_.setKnotInterval(dt);
}

TrajectorySample BSplineTrajectory::at(double t_s) const {
  int i = 0;
  double u = 0.0;
  position_.locate(t_s, &i, &u);
  const double dt = position_.knotInterval();
  const Eigen::Vector4d b0 = UniformBSpline::basis(u, 0);
  const Eigen::Vector4d b1 = UniformBSpline::basis(u, 1) / dt;
  const Eigen::Vector4d b2 = UniformBSpline::basis(u, 2) / (dt * dt);
  const auto q = position_.controlPoints().middleRows(i, 4);
  const auto y = yaw_.controlPoints().middleRows(i, 4);
  TrajectorySample s;
  s.t_s = t_s;
  s.p_W = q.transpose() * b0;
  s.v_W = q.transpose() * b1;
  s.a_W = q.transpose() * b2;
  s.yaw_rad = y.col(0).dot(b0);
  s.yaw_rate_rad_s = y.col(0).dot(b1);
  return s;
}

std::vector<TrajectorySample> sampleTrajectory(const Trajectory& trajectory, double rate_hz) {
  require(std::isfinite(rate_hz) && rate_hz > 0.0, "sample_rate_hz", rate_hz, "must be > 0");
  const double T = trajectory.duration();
  const int n = static_cast<int>(std::floor(T * rate_hz + 1e-9));
  std::vector<TrajectorySample> out;
  out.reserve(static_cast<std::size_t>(n) + 2);
  for (int i = 0; i <= n; ++i) out.push_back(trajectory.at(i / rate_hz));
  if (T - n / rate_hz > 1e-9) out.push_back(trajectory.at(T));
  for (TrajectorySample& s : out) {
    s.yaw_rad = std::remainder(s.yaw_rad, kTwoPi);
    if (s.yaw_rad >= M_PI) s.yaw_rad = -M_PI;
  }
  return out;
}

TrajectoryReport generateTrajectory(const TrajectoryRequest& request, const ClearanceField& field,
                                    const TrajectoryConfig& config) {
  checkRequest(request, config);
  const Problem problem(request, field, config);
  TrajectoryReport report;
  if (problem.ref.p.size() == 1) return flyPath(problem, TrajectoryStatus::kOptimised, report);  // nothing to do: stay

  Measured m;
  const std::shared_ptr<BSplineTrajectory> trajectory = optimise(problem, &m, &report.iterations);
  const std::string failure = checkShape(problem, *trajectory, m, &report);
  if (!failure.empty()) return fallBack(problem, report, failure);
  retime(problem, trajectory.get(), &m, &report.retimes);
  if (exceedsLimits(m, config)) {
    return fallBack(problem, report, "re-timing did not bring speed, acceleration and yaw rate within limits");
  }
  report.status = TrajectoryStatus::kOptimised;
  report.trajectory = trajectory;
  report.time_scale = trajectory->duration() / problem.ref.duration_s;
  fillReport(m, &report);
  return report;
}

}  // namespace tgnav::planner
