#pragma once
// Visual-inertial state estimate for the controller (the `vo` state source of a trial): an IMU
// propagates position, velocity and attitude at its own rate; poses from the visual odometry
// correct them when they arrive, which is later than the image they were measured on.
//
//   position/velocity: a linear Kalman filter, state [p_WB; v_WB; b_W], input the accelerometer's
//     specific force rotated into W plus gravity, less b_W, measurement the VO's body position.
//     b_W is a slowly wandering acceleration bias in W (a random walk, `accel_bias_walk`; 0 keeps it
//     at zero, the filter then being the [p; v] one): what a tilt error of the attitude leaks of
//     gravity (g sin(err), 0.17 m/s^2 per degree; the attitude follows the VO's, whose roll and pitch
//     drift) and the accelerometer's own bias. Unestimated, it leaves the velocity biased while the
//     position follows the VO: the controller then holds off its setpoint by that bias / its
//     position gain;
//   attitude: gyro integration, pulled towards the VO's attitude by a fixed fraction of the
//     rotation error at each VO pose (a complementary filter);
//   body rates: the gyro, less the gyro bias estimate (zero unless `gyro_bias_gain` > 0).
//
// A VO pose taken at t_m is fused at a later time t (the caller's latency): the innovation is
// formed against the estimate stored at t_m, and the correction is carried forward to t through
// the transition, so a late measurement does not pull the estimate back in time.
// Without VO poses (tracking lost) the estimate dead-reckons on the IMU and drifts, as a real
// vehicle's would.
//
// Because the transition F(dt) = [I dt*I -dt^2/2*I; 0 I -dt*I; 0 0 I] does not depend on the state
// (and F(s) F(t) = F(s + t)), carrying the
// correction (and the covariance reduction) forward is exactly what re-running the filter from t_m
// with the measurement inserted would give, for poses fused in order of their measurement times
// (t_m rounded to the nearest IMU sample); poses older than one already fused are rejected. The
// attitude correction is carried forward exactly too (as a rotation in W); the positions between
// t_m and t are not re-integrated with the corrected attitude.
#include <Eigen/Geometry>
#include <cstddef>
#include <deque>

#include "control/types.h"

namespace tgnav::control {

struct EstimatorConfig {
  // Process noise, white acceleration with this sigma per IMU sample. Ten times the simulated
  // accelerometer's white noise because it also covers what the filter does not estimate: the
  // accelerometer bias (0.02 m/s^2 per axis) and the attitude error's share of gravity
  // (g * 0.25 deg = 0.04 m/s^2). On the test flight, 0.05 gives 6 cm position RMSE (14 cm worst
  // of 30 seeds) where 0.5 gives 1.3 cm (1.9 cm).
  double accel_noise_m_s2 = 0.5;
  double position_sigma_m = 0.02;  // VO position measurement noise, sigma per axis
  double attitude_gain = 0.2;      // fraction of the VO attitude error removed per pose, (0, 1]
  // Fraction of the attitude error rate fed to the gyro bias, [0, 1). The VO's rotation noise
  // enters divided by the camera period, so keep it at 0.01 or below with a real VO.
  double gyro_bias_gain = 0.0;
  double max_position_innovation_m = 1.0;  // VO poses further than this from the estimate are rejected
  double history_s = 1.0;                  // how old a fused measurement may be
  // Random walk of the acceleration bias b_W, sigma [m/s^2 per sqrt(s)]; 0: not estimated.
  double accel_bias_walk_m_s2_sqrt_s = 0.0;
  // The VO's jumps [m]; 0: off. Where the VO's position moved between two poses by more than this
  // away from what the estimate moved between their times (the IMU's prediction of that step, on
  // the poses fused so far), the difference is a jump: it is added to an offset that every later
  // pose is taken less of (voOffset()), so the estimate, and whatever uses the poses it corrects,
  // goes on from where the IMU put it. A jump back, as large, takes it off again.
  double max_vo_step_error_m = 0.0;

  // Names every field once, for the harness's config files (a(key, field); harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a("accel_noise_m_s2", accel_noise_m_s2);
    a("position_sigma_m", position_sigma_m);
    a("attitude_gain", attitude_gain);
    a("gyro_bias_gain", gyro_bias_gain);
    a("max_position_innovation_m", max_position_innovation_m);
    a("history_s", history_s);
    a("accel_bias_walk_m_s2_sqrt_s", accel_bias_walk_m_s2_sqrt_s);
    a("max_vo_step_error_m", max_vo_step_error_m);
  }

  void validate() const;  // std::invalid_argument naming the field and value
};

// One IMU sample: specific force (what an accelerometer measures: acceleration minus gravity)
// and angular rate, both in B.
struct ImuSample {
  double t_s = 0.0;
  Eigen::Vector3d f_B = Eigen::Vector3d::Zero();  // [m/s^2]
  Eigen::Vector3d w_B = Eigen::Vector3d::Zero();  // [rad/s]
};

// What the estimator did with the VO's poses (state source vo).
struct FusionTally {
  int fused = 0;          // VO poses taken
  int rejected = 0;       // ... rejected (its gate, time window, not finite)
  int jumps = 0;          // steps taken as the VO's jumps (max_vo_step_error_m)
  double offset_m = 0.0;  // the size of their sum, taken off the VO's positions
};

class StateEstimator {
 public:
  StateEstimator(const EstimatorConfig& config, double gravity_m_s2);

  // Starts from a known state (the vehicle on the ground at the start) at time t_s.
  void reset(const VehicleState& initial, double t_s);
  // Propagates to imu.t_s with the sample, held over the interval since the last time (the
  // sample is the interval's mean; the specific force is rotated by the attitude at the interval's
  // midpoint). std::invalid_argument unless imu.t_s > time().
  void propagate(const ImuSample& imu);
  // Fuses a body pose measured at t_meas_s (<= the current time, within history_s). Returns
  // false (and changes nothing but rejected()) when it is rejected: too old (or in the future),
  // older than a pose already fused, not finite, or its position innovation is beyond
  // max_position_innovation_m. With max_vo_step_error_m, the pose's position is taken less
  // voOffset(), after its step was checked (a pose rejected by the innovation gate still is).
  bool fusePose(double t_meas_s, const Eigen::Isometry3d& X_WB);
  // What is taken off the VO's positions (W): the sum of the jumps found (max_vo_step_error_m).
  Eigen::Vector3d voOffset() const { return vo_offset_; }
  int jumps() const { return jumps_; }  // VO steps taken as jumps
  FusionTally tally() const { return {fused_, rejected_, jumps_, vo_offset_.norm()}; }

  VehicleState state() const;
  double time() const { return t_s_; }
  Eigen::Matrix<double, 6, 6> covariance() const { return P_.topLeftCorner<6, 6>(); }  // of [p_WB; v_WB]
  Eigen::Vector3d accelBias() const { return x_.tail<3>(); }                           // b_W
  int fused() const { return fused_; }
  int rejected() const { return rejected_; }

 private:
  // The estimate right after the propagation (or reset) to t_s; history_.back() is the current one.
  struct Snapshot {
    double t_s;
    Eigen::Matrix<double, 9, 1> x;
    Eigen::Matrix<double, 9, 9> P;
    Eigen::Quaterniond q_WB;
  };

  EstimatorConfig config_;
  double gravity_m_s2_;
  double t_s_ = 0.0;
  Eigen::Matrix<double, 9, 1> x_ = Eigen::Matrix<double, 9, 1>::Zero();  // [p_WB; v_WB; b_W]
  Eigen::Matrix<double, 9, 9> P_ = Eigen::Matrix<double, 9, 9>::Zero();
  Eigen::Quaterniond q_WB_ = Eigen::Quaterniond::Identity();
  Eigen::Vector3d gyro_bias_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_B_ = Eigen::Vector3d::Zero();  // last gyro sample, bias not removed
  double last_fused_t_s_ = 0.0;                       // measurement time of the last fused pose
  bool has_fused_ = false;
  std::deque<Snapshot> history_;
  // The index in history_ of the snapshot nearest t_s (history_ is never empty; t_s outside it
  // gives the nearest end).
  std::size_t nearest(double t_s) const;
  // The step check of max_vo_step_error_m: the VO position before the offset, and its time.
  Eigen::Vector3d last_vo_p_ = Eigen::Vector3d::Zero();
  double last_vo_t_s_ = 0.0;
  bool has_vo_ = false;
  Eigen::Vector3d vo_offset_ = Eigen::Vector3d::Zero();
  int jumps_ = 0;
  int fused_ = 0;
  int rejected_ = 0;
};

}  // namespace tgnav::control
