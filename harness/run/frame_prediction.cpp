#include "harness/run/frame_prediction.h"

#include <cmath>
#include <stdexcept>

namespace tgnav::harness {

FramePrediction predictFrame(const planner::VoxelMap& voxels, const Eigen::Isometry3d& X_WC,
                             const planner::VisibilityConfig& visibility,
                             const planner::InformationConfig& information) {
  const Eigen::Vector3d p = X_WC.translation();
  const Eigen::Vector3d forward = X_WC.linear().col(2);
  const double yaw = std::atan2(forward.y(), forward.x());
  // Only the voxels whose landmarks' mean is in this yaw's field of view count in the information
  // below (planner::inFieldOfView on the mean, which aggregateSlots makes each voxel's point):
  // the others are left out before their line of sight is traced.
  const auto in_view = [&](const planner::LandmarkVoxel& v) {
    return planner::inFieldOfView(p, yaw, v.mean_W, visibility);
  };
  const std::vector<planner::WeightedPoint> points =
      planner::aggregateSlots(voxels, voxels.visibleSlots(p, visibility, in_view));
  FramePrediction out;
  const planner::Matrix6d info = planner::poseInformation(p, yaw, points, visibility, information, &out.support);
  out.score = planner::scoreInformation(info, out.support, information);
  if (information.model) out.track_probability = information.model->probability(out.support);
  return out;
}

Eigen::Isometry3d levelCamera(const Eigen::Vector3d& p_WC, double yaw_rad) {
  // Optical frame: z forward (along yaw), y down, x right.
  const Eigen::Vector3d forward(std::cos(yaw_rad), std::sin(yaw_rad), 0.0);
  const Eigen::Vector3d down(0.0, 0.0, -1.0);
  Eigen::Matrix3d R;
  R.col(0) = down.cross(forward);
  R.col(1) = down;
  R.col(2) = forward;
  Eigen::Isometry3d X_WC = Eigen::Isometry3d::Identity();
  X_WC.linear() = R;
  X_WC.translation() = p_WC;
  return X_WC;
}

RatedView worstView(const control::SetpointTrajectory& trajectory, double tau_from, double span_s, double step_s,
                    const planner::VoxelMap& voxels, const planner::VisibilityConfig& visibility,
                    const planner::InformationConfig& information) {
  if (!(step_s > 0.0) || !(span_s >= 0.0)) throw std::invalid_argument("worstView: step_s > 0 and span_s >= 0");
  const auto worse = [](const FramePrediction& a, const FramePrediction& b) {
    return a.track_probability >= 0.0 ? a.track_probability < b.track_probability : a.score < b.score;
  };
  RatedView out;
  const int steps = static_cast<int>(std::floor(span_s / step_s + 1e-9));
  for (int i = 0; i <= steps; ++i) {
    const double tau = tau_from + i * step_s;
    const control::TrajectorySetpoint sp = trajectory.sample(tau);
    const Eigen::Vector3d p_WC = planner::cameraPosition(sp.p_WB, sp.yaw_rad, visibility);
    const FramePrediction f = predictFrame(voxels, levelCamera(p_WC, sp.yaw_rad), visibility, information);
    if (i == 0 || worse(f, out.prediction)) out = RatedView{tau, sp.yaw_rad, f};
  }
  return out;
}

std::optional<RatedView> viewAheadFallsShort(const control::SetpointTrajectory& trajectory, double tau_now,
                                             double lead_s, double floor, const planner::VoxelMap& voxels,
                                             const planner::VisibilityConfig& visibility,
                                             const planner::InformationConfig& information) {
  // worstView over no span: the one view, at the setpoints' place and yaw.
  const auto rate = [&](double tau) { return worstView(trajectory, tau, 0.0, 1.0, voxels, visibility, information); };
  const RatedView ahead = rate(tau_now + lead_s);
  if (ahead.prediction.support.detections >= floor) return std::nullopt;
  if (rate(tau_now).prediction.support.detections < floor) return std::nullopt;
  return ahead;
}

const char* const kPredictionColumns =
    "predicted_score,predicted_landmarks,predicted_coverage,predicted_detections,predicted_near_detections,"
    "predicted_mean_range_m,predicted_column_span,predicted_row_span,predicted_inner_detections,"
    "predicted_inner_near_detections,"
    "predicted_track_probability";

void writePredictionColumns(std::ostream& out, const FramePrediction& prediction) {
  const planner::ViewSupport& view = prediction.support;
  out << prediction.score << ',' << static_cast<int>(view.landmarks) << ',' << view.coverage() << ',' << view.detections
      << ',' << view.near_detections << ',' << view.meanRangeM() << ',' << view.columnSpan() << ',' << view.rowSpan()
      << ',' << view.inner_detections << ',' << view.inner_near_detections << ',';
  if (prediction.track_probability >= 0.0) out << prediction.track_probability;
}

}  // namespace tgnav::harness
