// The visual-inertial estimator against physics: an exact IMU at rest stays put and dead-reckons
// an analytic flight; biases drift as b T^2/2 (accelerometer) and g b T^3/6 (gyro); the flight
// with a noisy IMU and late VO poses is tracked to centimetres while dead reckoning drifts away;
// late fusion equals in-time fusion; the gate leaves the state untouched; the covariance stays
// symmetric positive definite; the attitude error decays by (1 - attitude_gain) per pose; the
// gyro bias is learnt; the gravity a tilted VO attitude leaks is learnt as an acceleration bias;
// a VO jump is found by its step against the IMU's and taken off the poses after it.
#include "control/state_estimator.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace tgnav::control {
namespace {

constexpr double kG = 9.81;
constexpr double kDt = 0.002;                      // IMU at 500 Hz
constexpr int kStepsPerFrame = 25;                 // camera at 20 Hz
constexpr double kLatency = kStepsPerFrame * kDt;  // VO pose fused one camera period late
constexpr double kDeg = M_PI / 180.0;

using Matrix6d = Eigen::Matrix<double, 6, 6>;

Eigen::Quaterniond expMap(const Eigen::Vector3d& theta) {
  const double angle = theta.norm();
  if (angle == 0.0) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, theta / angle));
}

// Body rate that turns q0 into q1 in dt at a constant rate: what an integrating gyro reports.
Eigen::Vector3d meanRate(const Eigen::Quaterniond& q0, const Eigen::Quaterniond& q1, double dt) {
  const Eigen::AngleAxisd aa(q0.conjugate() * q1);
  return aa.angle() * aa.axis() / dt;
}

Eigen::Isometry3d pose(const Eigen::Vector3d& p_WB, const Eigen::Quaterniond& q_WB) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = q_WB.toRotationMatrix();
  X.translation() = p_WB;
  return X;
}

VehicleState stateAt(const Eigen::Vector3d& p, const Eigen::Vector3d& v, const Eigen::Quaterniond& q) {
  VehicleState s;
  s.p_WB = p;
  s.v_WB = v;
  s.q_WB = q;
  return s;
}

double positionTrace(const Matrix6d& P) { return P.topLeftCorner<3, 3>().trace(); }
double velocityTrace(const Matrix6d& P) { return P.bottomRightCorner<3, 3>().trace(); }

double minEigenvalue(const Matrix6d& P) {
  return Eigen::SelfAdjointEigenSolver<Matrix6d>(P, Eigen::EigenvaluesOnly).eigenvalues()(0);
}

// A flight with an analytic position (circle with a vertical wave) and a quadrotor's attitude:
// body z along the specific force, yaw turning and oscillating.
struct Flight {
  static constexpr double kRadius = 2.0, kOmega = 0.8, kHeight = 1.5, kWave = 0.3, kWaveOmega = 1.6;

  static Eigen::Vector3d p(double t) {
    return {kRadius * std::cos(kOmega * t), kRadius * std::sin(kOmega * t), kHeight + kWave * std::sin(kWaveOmega * t)};
  }
  static Eigen::Vector3d v(double t) {
    return {-kRadius * kOmega * std::sin(kOmega * t), kRadius * kOmega * std::cos(kOmega * t),
            kWave * kWaveOmega * std::cos(kWaveOmega * t)};
  }
  static Eigen::Vector3d a(double t) {
    return {-kRadius * kOmega * kOmega * std::cos(kOmega * t), -kRadius * kOmega * kOmega * std::sin(kOmega * t),
            -kWave * kWaveOmega * kWaveOmega * std::sin(kWaveOmega * t)};
  }
  static Eigen::Quaterniond q(double t) {
    const Eigen::Vector3d z_B = (a(t) + Eigen::Vector3d(0, 0, kG)).normalized();
    const double yaw = 0.5 * t + 0.4 * std::sin(0.7 * t);
    const Eigen::Vector3d x_C(std::cos(yaw), std::sin(yaw), 0.0);
    const Eigen::Vector3d y_B = z_B.cross(x_C).normalized();
    Eigen::Matrix3d R;
    R << y_B.cross(z_B), y_B, z_B;
    return Eigen::Quaterniond(R);
  }
  static VehicleState state(double t) { return stateAt(p(t), v(t), q(t)); }
  // The exact IMU over [t - dt, t]: mean body rate and the specific force at the midpoint.
  static ImuSample imu(double t, double dt) {
    const double t_mid = t - 0.5 * dt;
    ImuSample s;
    s.t_s = t;
    s.w_B = meanRate(q(t - dt), q(t), dt);
    s.f_B = q(t_mid).conjugate() * (a(t_mid) + Eigen::Vector3d(0, 0, kG));
    return s;
  }
};

// Noise and biases of the simulated IMU and VO (the harness's defaults, VO at 1.5 cm and 0.2 deg).
struct Sensors {
  double accel_noise = 0.05, accel_bias = 0.02, gyro_noise = 0.005, gyro_bias = 0.001;
  double vo_position_sigma = 0.015, vo_rotation_sigma = 0.2 * kDeg;
};

struct Errors {
  double position_rmse = 0.0, velocity_rmse = 0.0, max_position = 0.0, max_attitude_rad = 0.0;
};

// Flies `Flight` for duration_s, fusing each VO pose one camera period late when `with_vo`.
Errors flyCircle(bool with_vo, std::uint64_t seed, double duration_s, const EstimatorConfig& config = {},
                 const Sensors& sensors = {}) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  auto gaussian = [&](double sigma) -> Eigen::Vector3d {
    return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)) * sigma;
  };
  const Eigen::Vector3d accel_bias = gaussian(sensors.accel_bias);
  const Eigen::Vector3d gyro_bias = gaussian(sensors.gyro_bias);

  StateEstimator est(config, kG);
  est.reset(Flight::state(0.0), 0.0);
  std::vector<Eigen::Isometry3d> vo_poses{pose(Flight::p(0.0), Flight::q(0.0))};
  double sum_p2 = 0.0, sum_v2 = 0.0;
  Errors e;
  const int steps = static_cast<int>(std::lround(duration_s / kDt));
  for (int k = 1; k <= steps; ++k) {
    const double t = k * kDt;
    ImuSample imu = Flight::imu(t, kDt);
    imu.f_B += accel_bias + gaussian(sensors.accel_noise);
    imu.w_B += gyro_bias + gaussian(sensors.gyro_noise);
    est.propagate(imu);
    if (with_vo && k % kStepsPerFrame == 0) {
      // The pose of the image taken one period ago arrives now; this image's pose is computed.
      EXPECT_TRUE(est.fusePose(t - kLatency, vo_poses.back()));
      vo_poses.push_back(pose(Flight::p(t) + gaussian(sensors.vo_position_sigma),
                              Flight::q(t) * expMap(gaussian(sensors.vo_rotation_sigma))));
    }
    const VehicleState s = est.state();
    const double ep = (s.p_WB - Flight::p(t)).norm();
    sum_p2 += ep * ep;
    sum_v2 += (s.v_WB - Flight::v(t)).squaredNorm();
    e.max_position = std::max(e.max_position, ep);
    e.max_attitude_rad = std::max(e.max_attitude_rad, s.q_WB.angularDistance(Flight::q(t)));
  }
  e.position_rmse = std::sqrt(sum_p2 / steps);
  e.velocity_rmse = std::sqrt(sum_v2 / steps);
  return e;
}

TEST(StateEstimator, AtRestWithExactImuStaysAtTheStart) {
  const std::vector<Eigen::Quaterniond> attitudes = {
      Eigen::Quaterniond::Identity(), Eigen::Quaterniond(Eigen::AngleAxisd(30 * kDeg, Eigen::Vector3d::UnitZ())),
      Eigen::Quaterniond(Eigen::AngleAxisd(20 * kDeg, Eigen::Vector3d(1, -1, 0.5).normalized()))};
  for (const Eigen::Quaterniond& q : attitudes) {
    const Eigen::Vector3d p0(1.0, -2.0, 0.3);
    StateEstimator est(EstimatorConfig{}, kG);
    est.reset(stateAt(p0, Eigen::Vector3d::Zero(), q), 0.0);
    ImuSample imu;
    imu.f_B = q.conjugate() * Eigen::Vector3d(0, 0, kG);  // the ground holds the vehicle up
    for (int k = 1; k <= 5000; ++k) {
      imu.t_s = k * kDt;
      est.propagate(imu);
    }
    const VehicleState s = est.state();
    EXPECT_NEAR(est.time(), 10.0, 1e-12);
    EXPECT_LE((s.p_WB - p0).norm(), 1e-9);
    EXPECT_LE(s.v_WB.norm(), 1e-9);
    EXPECT_LE(s.q_WB.angularDistance(q), 1e-9);
    EXPECT_LE(s.w_B.norm(), 0.0);
  }
}

TEST(StateEstimator, AccelerometerBiasDriftsAsHalfBiasTimesTimeSquared) {
  // VO lost: a constant accelerometer bias b integrates to b T and b T^2 / 2.
  const Eigen::Vector3d bias(0.05, -0.03, 0.02);
  const double T = 10.0;
  StateEstimator est(EstimatorConfig{}, kG);
  est.reset(VehicleState{}, 0.0);
  ImuSample imu;
  imu.f_B = Eigen::Vector3d(0, 0, kG) + bias;
  for (int k = 1; k <= static_cast<int>(std::lround(T / kDt)); ++k) {
    imu.t_s = k * kDt;
    est.propagate(imu);
  }
  const VehicleState s = est.state();
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(s.p_WB[i], 0.5 * bias[i] * T * T, 0.01 * std::abs(0.5 * bias[i] * T * T)) << "axis " << i;
    EXPECT_NEAR(s.v_WB[i], bias[i] * T, 0.01 * std::abs(bias[i] * T)) << "axis " << i;
  }
}

TEST(StateEstimator, GyroBiasTiltsTheEstimateAndDriftsAsCubeOfTime) {
  // A roll-rate bias w_b tilts the estimated body z towards -y by w_b t, so gravity leaks into
  // the horizontal: y drifts by -g w_b T^3 / 6.
  const double gyro_bias = 0.002;
  const double T = 10.0;
  StateEstimator est(EstimatorConfig{}, kG);
  est.reset(VehicleState{}, 0.0);
  ImuSample imu;
  imu.f_B = Eigen::Vector3d(0, 0, kG);
  imu.w_B = Eigen::Vector3d(gyro_bias, 0, 0);
  for (int k = 1; k <= static_cast<int>(std::lround(T / kDt)); ++k) {
    imu.t_s = k * kDt;
    est.propagate(imu);
  }
  const double expected_y = -kG * gyro_bias * T * T * T / 6.0;
  EXPECT_NEAR(est.state().p_WB.y(), expected_y, 0.01 * std::abs(expected_y));
  EXPECT_NEAR(est.state().p_WB.x(), 0.0, 1e-9);
  EXPECT_NEAR(est.state().q_WB.angularDistance(Eigen::Quaterniond::Identity()), gyro_bias * T, 1e-9);
}

TEST(StateEstimator, DeadReckonsTheFlightOnAnExactImu) {
  // Frames, gravity and rotation order checked against the analytic flight: 20 s of exact IMU
  // keep the estimate within 0.1 mm (rotating the specific force by the interval's start
  // attitude instead of its midpoint would be 2.6 cm off).
  Sensors exact;
  exact.accel_noise = exact.accel_bias = exact.gyro_noise = exact.gyro_bias = 0.0;
  const Errors e = flyCircle(false, 1, 20.0, EstimatorConfig{}, exact);
  EXPECT_LT(e.max_position, 1e-4);
  EXPECT_LT(e.velocity_rmse, 1e-5);
  EXPECT_LT(e.max_attitude_rad, 1e-9);
}

TEST(StateEstimator, TracksAKnownFlightWithLateVoPosesAndDriftsWithout) {
  const double duration_s = 20.0;
  EstimatorConfig with_bias;  // the acceleration bias estimated: tracks as well
  with_bias.accel_bias_walk_m_s2_sqrt_s = 0.02;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const Errors vio_b = flyCircle(true, seed, duration_s, with_bias);
    std::printf("seed %d, bias estimated: VIO position RMSE %.4f m (max %.4f), velocity RMSE %.4f m/s\n",
                static_cast<int>(seed), vio_b.position_rmse, vio_b.max_position, vio_b.velocity_rmse);
    EXPECT_LT(vio_b.position_rmse, 0.03) << "seed " << seed;
    EXPECT_LT(vio_b.velocity_rmse, 0.1) << "seed " << seed;
    const Errors vio = flyCircle(true, seed, duration_s);
    const Errors dead_reckoning = flyCircle(false, seed, duration_s);
    RecordProperty("position_rmse_m_seed" + std::to_string(seed), std::to_string(vio.position_rmse));
    std::printf(
        "seed %d: VIO position RMSE %.4f m (max %.4f), velocity RMSE %.4f m/s, max attitude %.3f deg; "
        "IMU only: position RMSE %.3f m, velocity RMSE %.3f m/s, max attitude %.3f deg\n",
        static_cast<int>(seed), vio.position_rmse, vio.max_position, vio.velocity_rmse, vio.max_attitude_rad / kDeg,
        dead_reckoning.position_rmse, dead_reckoning.velocity_rmse, dead_reckoning.max_attitude_rad / kDeg);
    EXPECT_LT(vio.position_rmse, 0.03) << "seed " << seed;
    EXPECT_LT(vio.velocity_rmse, 0.1) << "seed " << seed;
    EXPECT_LT(vio.max_attitude_rad, 1.0 * kDeg) << "seed " << seed;
    EXPECT_GT(dead_reckoning.position_rmse, 10.0 * vio.position_rmse) << "seed " << seed;
  }
}

TEST(StateEstimator, LateFusionEqualsFusionInTime) {
  // Constant velocity, exact IMU, the estimate started 0.2 m off. Fusing exact poses taken at
  // 0.95 s and 0.976 s when they arrive at 1.0 s gives the state that fusing each at its own time
  // would have given; each correction moves the estimate part of the way towards the truth.
  EstimatorConfig config;
  config.accel_noise_m_s2 = 1.0;  // enough uncertainty after 1 s for a visible correction
  const Eigen::Vector3d v(1.0, 0.5, -0.2), p0(0.0, 0.0, 1.0), offset(0.2, -0.1, 0.05);
  auto truth = [&](double t) { return p0 + v * t; };
  const Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  ImuSample imu;
  imu.f_B = Eigen::Vector3d(0, 0, kG);

  StateEstimator late(config, kG), in_time(config, kG);
  late.reset(stateAt(p0 + offset, v, q), 0.0);
  in_time.reset(stateAt(p0 + offset, v, q), 0.0);
  const int k_first = 475, k_second = 488, k_now = 500;  // 0.95 s, 0.976 s, 1.0 s
  for (int k = 1; k <= k_now; ++k) {
    imu.t_s = k * kDt;
    late.propagate(imu);
    in_time.propagate(imu);
    if (k == k_first || k == k_second) {
      EXPECT_TRUE(in_time.fusePose(imu.t_s, pose(truth(imu.t_s), q)));
    }
  }
  const double t_now = k_now * kDt;
  const Eigen::Vector3d error_before = late.state().p_WB - truth(t_now);
  EXPECT_LE((error_before - offset).norm(), 1e-12);

  ASSERT_TRUE(late.fusePose(k_first * kDt, pose(truth(k_first * kDt), q)));
  const Eigen::Vector3d error_after_first = late.state().p_WB - truth(t_now);
  for (int i = 0; i < 3; ++i) {
    const double ratio = error_after_first[i] / error_before[i];
    EXPECT_GT(ratio, 0.05) << "axis " << i;  // towards the truth without overshoot ...
    EXPECT_LT(ratio, 0.95) << "axis " << i;  // ... and by a real step
  }
  ASSERT_TRUE(late.fusePose(k_second * kDt, pose(truth(k_second * kDt), q)));
  EXPECT_LT((late.state().p_WB - truth(t_now)).norm(), error_after_first.norm());

  EXPECT_LE((late.state().p_WB - in_time.state().p_WB).norm(), 1e-12);
  EXPECT_LE((late.state().v_WB - in_time.state().v_WB).norm(), 1e-12);
  EXPECT_LE((late.covariance() - in_time.covariance()).norm(), 1e-12 * in_time.covariance().norm());
  EXPECT_EQ(late.fused(), 2);
}

TEST(StateEstimator, LateAttitudeCorrectionEqualsCorrectionInTime) {
  // Rolling and yawing with an exact gyro: the attitude correction from a late pose is the one
  // re-integrating the gyro from the corrected past attitude gives.
  const Eigen::Vector3d w_B(1.5, -0.4, 0.5);
  const Eigen::Quaterniond q_error = expMap(Eigen::Vector3d(0.05, -0.1, 0.15));
  auto truth = [&](double t) { return expMap(w_B * t); };
  ImuSample imu;
  imu.w_B = w_B;
  StateEstimator late(EstimatorConfig{}, kG), in_time(EstimatorConfig{}, kG);
  late.reset(stateAt(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), q_error), 0.0);
  in_time.reset(stateAt(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), q_error), 0.0);
  for (int k = 1; k <= 100; ++k) {
    imu.t_s = k * kDt;
    imu.f_B = truth(imu.t_s).conjugate() * Eigen::Vector3d(0, 0, kG);
    late.propagate(imu);
    in_time.propagate(imu);
    if (k == 75) {
      EXPECT_TRUE(in_time.fusePose(imu.t_s, pose(Eigen::Vector3d::Zero(), truth(imu.t_s))));
    }
  }
  ASSERT_TRUE(late.fusePose(75 * kDt, pose(Eigen::Vector3d::Zero(), truth(75 * kDt))));
  EXPECT_LE(late.state().q_WB.angularDistance(in_time.state().q_WB), 1e-12);
  EXPECT_LT(late.state().q_WB.angularDistance(truth(late.time())),
            q_error.angularDistance(Eigen::Quaterniond::Identity()));
}

TEST(StateEstimator, GateAndTimeWindowRejectWithoutChangingAnything) {
  EstimatorConfig config;
  StateEstimator est(config, kG);
  est.reset(Flight::state(0.0), 0.0);
  for (int k = 1; k <= 600; ++k) est.propagate(Flight::imu(k * kDt, kDt));
  const double t = est.time();

  auto expectRejectedAndUnchanged = [&](double t_meas, const Eigen::Isometry3d& X, const std::string& what) {
    const VehicleState before = est.state();
    const Matrix6d P_before = est.covariance();
    const int rejected_before = est.rejected(), fused_before = est.fused();
    EXPECT_FALSE(est.fusePose(t_meas, X)) << what;
    const VehicleState after = est.state();
    EXPECT_TRUE(after.p_WB == before.p_WB) << what;
    EXPECT_TRUE(after.v_WB == before.v_WB) << what;
    EXPECT_TRUE(after.q_WB.coeffs() == before.q_WB.coeffs()) << what;
    EXPECT_TRUE(after.w_B == before.w_B) << what;
    EXPECT_TRUE(est.covariance() == P_before) << what;
    EXPECT_EQ(est.rejected(), rejected_before + 1) << what;
    EXPECT_EQ(est.fused(), fused_before) << what;
    EXPECT_EQ(est.time(), t) << what;
  };
  const double t_meas = t - kLatency;
  const Eigen::Vector3d away(3.0, -4.0, 0.0);  // 5 m
  expectRejectedAndUnchanged(t_meas, pose(Flight::p(t_meas) + away, Flight::q(t_meas)), "5 m away");
  expectRejectedAndUnchanged(t - config.history_s - 0.1, pose(Flight::p(t - 1.1), Flight::q(t - 1.1)), "too old");
  expectRejectedAndUnchanged(t + 0.01, pose(Flight::p(t), Flight::q(t)), "in the future");
  Eigen::Isometry3d nan_pose = pose(Flight::p(t_meas), Flight::q(t_meas));
  nan_pose.translation().x() = std::nan("");
  expectRejectedAndUnchanged(t_meas, nan_pose, "not finite");

  // Inside the gate and the window it is fused; an older pose after it is out of order.
  const Eigen::Vector3d near(0.6, -0.7, 0.0);  // 0.92 m
  EXPECT_TRUE(est.fusePose(t_meas, pose(Flight::p(t_meas) + near, Flight::q(t_meas))));
  EXPECT_EQ(est.fused(), 1);
  expectRejectedAndUnchanged(t_meas - 0.01, pose(Flight::p(t_meas - 0.01), Flight::q(t_meas - 0.01)), "out of order");
  EXPECT_EQ(est.rejected(), 5);
}

TEST(StateEstimator, PosesUpToHistoryOldAreFused) {
  EstimatorConfig config;
  StateEstimator est(config, kG);
  est.reset(Flight::state(0.0), 0.0);
  for (int k = 1; k <= 1000; ++k) est.propagate(Flight::imu(k * kDt, kDt));
  const double t_meas = est.time() - config.history_s;
  EXPECT_TRUE(est.fusePose(t_meas, pose(Flight::p(t_meas), Flight::q(t_meas))));
  const double too_old = est.time() - config.history_s - 2.0 * kDt;
  StateEstimator est2(config, kG);
  est2.reset(Flight::state(0.0), 0.0);
  for (int k = 1; k <= 1000; ++k) est2.propagate(Flight::imu(k * kDt, kDt));
  EXPECT_FALSE(est2.fusePose(too_old, pose(Flight::p(too_old), Flight::q(too_old))));
}

TEST(StateEstimator, CovarianceStaysSymmetricPositiveDefiniteGrowsAloneShrinksWithPoses) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  auto gaussian = [&](double sigma) -> Eigen::Vector3d {
    return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)) * sigma;
  };
  StateEstimator est(EstimatorConfig{}, kG);
  est.reset(Flight::state(0.0), 0.0);
  const int lost_from = 10000, lost_until = 12500;  // VO lost from 20 s to 25 s
  double trace_at_loss = 0.0;
  int fusions = 0;
  std::vector<Eigen::Isometry3d> vo_poses{pose(Flight::p(0.0), Flight::q(0.0))};
  for (int k = 1; k <= 30000; ++k) {  // 60 s
    const double t = k * kDt;
    ImuSample imu = Flight::imu(t, kDt);
    imu.f_B += gaussian(0.05);
    imu.w_B += gaussian(0.005);
    const Matrix6d P_prev = est.covariance();
    est.propagate(imu);
    const Matrix6d P_propagated = est.covariance();
    // Uncertainty only grows between poses.
    ASSERT_GT(positionTrace(P_propagated), positionTrace(P_prev)) << "t " << t;
    ASSERT_GT(velocityTrace(P_propagated), velocityTrace(P_prev)) << "t " << t;
    const bool lost = k > lost_from && k < lost_until;
    if (k % kStepsPerFrame == 0) {
      if (!lost) {
        ASSERT_TRUE(est.fusePose(t - kLatency, vo_poses.back()));
        ++fusions;
        const Matrix6d reduction = P_propagated - est.covariance();
        ASSERT_GE(minEigenvalue(reduction), -1e-15) << "t " << t;
        // The first pose is of the start, which is known exactly: nothing to reduce.
        if (fusions > 1) {
          ASSERT_LT(est.covariance().trace(), P_propagated.trace()) << "t " << t;
        }
      }
      vo_poses.push_back(pose(Flight::p(t) + gaussian(0.015), Flight::q(t)));
    }
    const Matrix6d P = est.covariance();
    ASSERT_TRUE(P == P.transpose()) << "t " << t;
    if (k >= 2) {  // after one step only the direction [dt^2/2; dt] is uncertain
      ASSERT_GT(minEigenvalue(P), 0.0) << "t " << t;
    }
    if (k == lost_from) trace_at_loss = positionTrace(P);
    if (k == lost_until - 1) {
      std::printf("position variance trace: %.3g m^2 when VO is lost, %.3g m^2 5 s later\n", trace_at_loss,
                  positionTrace(P));
      EXPECT_GT(positionTrace(P), 10.0 * trace_at_loss);
    }
  }
  EXPECT_EQ(est.fused(), fusions);
  // With poses, the position uncertainty settles below the VO's own.
  EXPECT_LT(std::sqrt(positionTrace(est.covariance()) / 3.0), EstimatorConfig{}.position_sigma_m);
}

TEST(StateEstimator, AttitudeErrorDecaysByOneMinusGainPerPose) {
  // A 10 deg yaw error while rolling, pitching and yawing, exact gyro, exact poses fused late:
  // each pose removes attitude_gain of the error and the gyro keeps the rest unchanged.
  for (double gain : {0.2, 0.5}) {
    EstimatorConfig config;
    config.attitude_gain = gain;
    config.max_position_innovation_m = 1e3;  // the tilted gravity runs the position off; not tested here
    const Eigen::Vector3d w_B(1.5, -0.4, 0.5);
    const Eigen::Quaterniond q0(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()));
    auto truth = [&](double t) { return q0 * expMap(w_B * t); };
    StateEstimator est(config, kG);
    est.reset(stateAt(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                      q0 * Eigen::Quaterniond(Eigen::AngleAxisd(10 * kDeg, Eigen::Vector3d::UnitZ()))),
              0.0);
    ImuSample imu;
    imu.w_B = w_B;
    int poses = 0;
    for (int k = 1; k <= 20 * kStepsPerFrame; ++k) {
      const double t = k * kDt;
      imu.t_s = t;
      imu.f_B = truth(t - 0.5 * kDt).conjugate() * Eigen::Vector3d(0, 0, kG);
      est.propagate(imu);
      if (k % kStepsPerFrame == 0) {
        ASSERT_TRUE(est.fusePose(t - kLatency, pose(Eigen::Vector3d::Zero(), truth(t - kLatency))));
        ++poses;
      }
      const double expected = 10 * kDeg * std::pow(1.0 - gain, poses);
      ASSERT_NEAR(est.state().q_WB.angularDistance(truth(t)), expected, 1e-9) << "gain " << gain << " t " << t;
    }
  }
}

TEST(StateEstimator, GyroBiasIsLearntWhenItsGainIsPositive) {
  const Eigen::Vector3d gyro_bias(0.01, -0.02, 0.015);
  auto run = [&](double bias_gain, Eigen::Vector3d* rate_error) {
    EstimatorConfig config;
    config.gyro_bias_gain = bias_gain;
    StateEstimator est(config, kG);
    est.reset(Flight::state(0.0), 0.0);
    double max_late_attitude_error = 0.0;
    for (int k = 1; k <= 15000; ++k) {  // 30 s
      const double t = k * kDt;
      ImuSample imu = Flight::imu(t, kDt);
      imu.w_B += gyro_bias;
      est.propagate(imu);
      if (k % kStepsPerFrame == 0) {
        EXPECT_TRUE(est.fusePose(t - kLatency, pose(Flight::p(t - kLatency), Flight::q(t - kLatency))));
      }
      if (t > 20.0) {
        max_late_attitude_error = std::max(max_late_attitude_error, est.state().q_WB.angularDistance(Flight::q(t)));
      }
    }
    *rate_error = est.state().w_B - Flight::imu(est.time(), kDt).w_B;
    return max_late_attitude_error;
  };
  Eigen::Vector3d rate_error_learnt, rate_error_fixed;
  const double error_learnt = run(0.1, &rate_error_learnt);
  const double error_fixed = run(0.0, &rate_error_fixed);
  std::printf(
      "attitude error after 20 s: %.4f deg with bias learning, %.4f deg without; rate error %.2e vs %.2e rad/s\n",
      error_learnt / kDeg, error_fixed / kDeg, rate_error_learnt.norm(), rate_error_fixed.norm());
  EXPECT_LT(rate_error_learnt.norm(), 0.05 * gyro_bias.norm());
  EXPECT_NEAR((rate_error_fixed - gyro_bias).norm(), 0.0, 1e-9);
  EXPECT_LT(error_learnt, 0.1 * error_fixed);
}

TEST(StateEstimator, ATiltedVoAttitudeBiasesTheVelocityUnlessTheAccelerationBiasIsEstimated) {
  // A hover with an exact IMU, exact VO positions and VO attitudes rolled by a constant 1 deg (the
  // VO's roll and pitch drift): the attitude follows the VO's, so g sin(1 deg) = 0.17 m/s^2 of
  // gravity leaks into y. Without the bias state the filter settles with its velocity off the
  // truth (the controller would then hold off its setpoint); with it the leak is learnt and the
  // velocity returns to zero.
  const Eigen::Quaterniond tilt(Eigen::AngleAxisd(1.0 * kDeg, Eigen::Vector3d::UnitX()));
  const Eigen::Vector3d p0(0.5, -1.0, 1.2);
  auto run = [&](double walk, Eigen::Vector3d* bias) {
    EstimatorConfig config;
    config.accel_bias_walk_m_s2_sqrt_s = walk;
    StateEstimator est(config, kG);
    est.reset(stateAt(p0, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity()), 0.0);
    ImuSample imu;
    imu.f_B = Eigen::Vector3d(0, 0, kG);
    double max_late_speed = 0.0;
    for (int k = 1; k <= 15000; ++k) {  // 30 s
      const double t = k * kDt;
      imu.t_s = t;
      est.propagate(imu);
      if (k % kStepsPerFrame == 0) {
        EXPECT_TRUE(est.fusePose(t - kLatency, pose(p0, tilt)));
      }
      if (t > 20.0) max_late_speed = std::max(max_late_speed, est.state().v_WB.norm());
    }
    *bias = est.accelBias();
    return max_late_speed;
  };
  Eigen::Vector3d bias_fixed, bias_learnt;
  const double speed_fixed = run(0.0, &bias_fixed);
  const double speed_learnt = run(0.02, &bias_learnt);
  const Eigen::Vector3d leak = tilt * Eigen::Vector3d(0, 0, kG) - Eigen::Vector3d(0, 0, kG);
  std::printf("velocity error after 20 s: %.4f m/s with the bias state, %.4f m/s without; bias %.4f %.4f %.4f\n",
              speed_learnt, speed_fixed, bias_learnt.x(), bias_learnt.y(), bias_learnt.z());
  EXPECT_EQ(bias_fixed, Eigen::Vector3d::Zero());
  EXPECT_GT(speed_fixed, 0.02);
  EXPECT_LT(speed_learnt, 0.1 * speed_fixed);
  EXPECT_LT((bias_learnt - leak).norm(), 0.05 * leak.norm());
}

// The circle flown with a noisy IMU and VO poses of `vo_sigma` white noise plus `vo_error(frame)`
// (frame 1 is the first pose fused), each fused one camera period late. Returns the largest
// position error over the last `tail_s` seconds.
struct JumpFlight {
  double max_tail_error_m = 0.0;
  int jumps = 0;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
};
JumpFlight flyWithVoError(const EstimatorConfig& config, std::uint64_t seed, double vo_sigma,
                          const std::function<Eigen::Vector3d(int)>& vo_error, double duration_s = 12.0,
                          double tail_s = 4.0) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  auto gaussian = [&](double sigma) -> Eigen::Vector3d {
    return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)) * sigma;
  };
  const Sensors sensors;
  const Eigen::Vector3d accel_bias = gaussian(sensors.accel_bias);
  StateEstimator est(config, kG);
  est.reset(Flight::state(0.0), 0.0);
  Eigen::Isometry3d pending = pose(Flight::p(0.0), Flight::q(0.0));
  JumpFlight out;
  int frame = 0;
  const int steps = static_cast<int>(std::lround(duration_s / kDt));
  for (int k = 1; k <= steps; ++k) {
    const double t = k * kDt;
    ImuSample imu = Flight::imu(t, kDt);
    imu.f_B += accel_bias + gaussian(sensors.accel_noise);
    imu.w_B += gaussian(sensors.gyro_noise);
    est.propagate(imu);
    if (k % kStepsPerFrame == 0) {
      est.fusePose(t - kLatency, pending);
      ++frame;
      pending = pose(Flight::p(t) + gaussian(vo_sigma) + vo_error(frame), Flight::q(t));
    }
    if (t > duration_s - tail_s) {
      out.max_tail_error_m = std::max(out.max_tail_error_m, (est.state().p_WB - Flight::p(t)).norm());
    }
  }
  out.jumps = est.jumps();
  out.offset = est.voOffset();
  return out;
}

TEST(StateEstimator, AVoJumpIsTakenOffAndTheEstimateGoesOnFromTheImu) {
  // From frame 100 (5 s) on, every VO pose is 0.25 m off: the VO jumped and tracked on from there.
  // Off, the estimate follows the VO there; with the step check, the jump is found in its one
  // step, taken off every later pose, and the estimate stays on the true flight.
  const Eigen::Vector3d jump(0.15, -0.1, 0.17);  // 0.25 m
  auto jumped = [&](int frame) -> Eigen::Vector3d { return frame >= 100 ? jump : Eigen::Vector3d::Zero(); };
  EstimatorConfig off;
  EstimatorConfig on;
  on.max_vo_step_error_m = 0.08;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const JumpFlight a = flyWithVoError(off, seed, 0.01, jumped);
    const JumpFlight b = flyWithVoError(on, seed, 0.01, jumped);
    std::printf("seed %d: after a 0.25 m VO jump, largest error over the last 4 s: %.3f m off, %.3f m on\n",
                static_cast<int>(seed), a.max_tail_error_m, b.max_tail_error_m);
    EXPECT_GT(a.max_tail_error_m, 0.2) << "seed " << seed;
    EXPECT_EQ(a.jumps, 0);
    EXPECT_LT(b.max_tail_error_m, 0.05) << "seed " << seed;
    EXPECT_EQ(b.jumps, 1) << "seed " << seed;
    EXPECT_LT((b.offset - jump).norm(), 0.04) << "seed " << seed;
  }
}

TEST(StateEstimator, AVoJumpAndItsReturnLeaveNoOffsetAndNoiseAloneIsNoJump) {
  EstimatorConfig on;
  on.max_vo_step_error_m = 0.08;
  // One pose 0.3 m off, the next back on the flight: two jumps that cancel.
  auto spike = [](int frame) -> Eigen::Vector3d {
    return frame == 100 ? Eigen::Vector3d(0.0, 0.3, 0.0) : Eigen::Vector3d::Zero();
  };
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const JumpFlight f = flyWithVoError(on, seed, 0.01, spike);
    EXPECT_EQ(f.jumps, 2) << "seed " << seed;
    EXPECT_LT(f.offset.norm(), 0.04) << "seed " << seed;
    EXPECT_LT(f.max_tail_error_m, 0.05) << "seed " << seed;
  }
  // Noise alone, 1 cm per pose (a step's error has 1.4 cm per axis): no step is a jump, and the
  // flight is tracked as with the check off, to the bit.
  auto none = [](int) { return Eigen::Vector3d::Zero(); };
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const JumpFlight f = flyWithVoError(on, seed, 0.01, none, 20.0, 20.0);
    const JumpFlight g = flyWithVoError(EstimatorConfig{}, seed, 0.01, none, 20.0, 20.0);
    EXPECT_EQ(f.jumps, 0) << "seed " << seed;
    EXPECT_EQ(f.max_tail_error_m, g.max_tail_error_m) << "seed " << seed;
  }
}

TEST(EstimatorConfig, ValidateNamesTheBadField) {
  EXPECT_NO_THROW(EstimatorConfig{}.validate());
  const double nan = std::nan("");
  const std::vector<std::pair<std::string, std::function<void(EstimatorConfig&, double)>>> fields = {
      {"accel_noise_m_s2", [](EstimatorConfig& c, double v) { c.accel_noise_m_s2 = v; }},
      {"position_sigma_m", [](EstimatorConfig& c, double v) { c.position_sigma_m = v; }},
      {"attitude_gain", [](EstimatorConfig& c, double v) { c.attitude_gain = v; }},
      {"gyro_bias_gain", [](EstimatorConfig& c, double v) { c.gyro_bias_gain = v; }},
      {"max_position_innovation_m", [](EstimatorConfig& c, double v) { c.max_position_innovation_m = v; }},
      {"history_s", [](EstimatorConfig& c, double v) { c.history_s = v; }},
      {"accel_bias_walk_m_s2_sqrt_s", [](EstimatorConfig& c, double v) { c.accel_bias_walk_m_s2_sqrt_s = v; }},
      {"max_vo_step_error_m", [](EstimatorConfig& c, double v) { c.max_vo_step_error_m = v; }},
  };
  const std::vector<std::vector<double>> bad = {{0.0, -1.0, nan},
                                                {0.0, -0.01, nan},
                                                {0.0, -0.2, 1.01, nan},
                                                {-0.1, 1.0, nan},
                                                {0.0, -1.0, nan},
                                                {0.0, -1.0, nan},
                                                {-0.01, nan, std::numeric_limits<double>::infinity()},
                                                {-0.01, nan, std::numeric_limits<double>::infinity()}};
  for (std::size_t i = 0; i < fields.size(); ++i) {
    for (double value : bad[i]) {
      EstimatorConfig c;
      fields[i].second(c, value);
      try {
        c.validate();
        ADD_FAILURE() << fields[i].first << " = " << value << " accepted";
      } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()).rfind(fields[i].first + " = ", 0), 0u) << e.what();
      }
      EXPECT_THROW(StateEstimator(c, kG), std::invalid_argument);
    }
  }
  // The edges of the ranges are allowed.
  EstimatorConfig edges;
  edges.attitude_gain = 1.0;
  edges.gyro_bias_gain = 0.0;
  EXPECT_NO_THROW(edges.validate());
}

TEST(StateEstimator, RejectsBadGravityAndTimeGoingBackwards) {
  EXPECT_THROW(StateEstimator(EstimatorConfig{}, 0.0), std::invalid_argument);
  EXPECT_THROW(StateEstimator(EstimatorConfig{}, -kG), std::invalid_argument);
  StateEstimator est(EstimatorConfig{}, kG);
  est.reset(VehicleState{}, 1.0);
  ImuSample imu;
  imu.t_s = 1.0;
  EXPECT_THROW(est.propagate(imu), std::invalid_argument);
  imu.t_s = 0.5;
  EXPECT_THROW(est.propagate(imu), std::invalid_argument);
  imu.t_s = 1.002;
  EXPECT_NO_THROW(est.propagate(imu));
}

}  // namespace
}  // namespace tgnav::control
