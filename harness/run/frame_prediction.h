#pragma once
// What the planner's perception model predicts for the camera poses a trial really flew, for
// calibrating the model against the VO (vo.csv's predicted_* columns beside the VO's own counts).
#include <Eigen/Geometry>
#include <optional>
#include <ostream>
#include <vector>

#include "control/trajectory.h"
#include "planner/perception.h"
#include "planner/voxel_map.h"

namespace tgnav::harness {

struct FramePrediction {
  double score =
      0.0;  // log det of the Fisher information of the landmarks in view (eq. 6, as the pose graph scores a node)
  // The map landmarks that count (in the field of view, range, line of sight and incidence limit):
  // their number, the detections they promise, the image cells they cover, their ranges (the
  // learned model's inputs, planner::trackFeatureValue).
  planner::ViewSupport support;
  double track_probability = -1.0;  // the model's probability that the VO tracks the frame; -1: no model
};

// The model at the true camera pose X_WC (optical frame: z forward): position and the yaw of the
// optical axis, all landmarks of the map in view (not only a segment's co-visible set, as the pose
// graph uses: the camera sees what is there).
FramePrediction predictFrame(const planner::VoxelMap& voxels, const Eigen::Isometry3d& X_WC,
                             const planner::VisibilityConfig& visibility,
                             const planner::InformationConfig& information);

// A level camera at p_WC with its optical axis along yaw_rad (the planners' view of a Pose4, the
// camera at planner::cameraPosition of the body).
Eigen::Isometry3d levelCamera(const Eigen::Vector3d& p_WC, double yaw_rad);

// The least trackable view a trajectory flies between tau_from and tau_from + span_s (its own time
// base), rated on the planners' voxel map every step_s (both ends included) at the setpoints' place
// (the camera's, planner::cameraPosition) and yaw: the view with the least track probability (with a model), else the
// least score. Online, each plan rates the views the vehicle will fly after it, which the look-ahead may have turned
// away from the plan's own (OnlinePlan::flown_*).
struct RatedView {
  double tau = 0.0;  // when, on the trajectory's time base
  double yaw_rad = 0.0;
  FramePrediction prediction;
};
RatedView worstView(const control::SetpointTrajectory& trajectory, double tau_from, double span_s, double step_s,
                    const planner::VoxelMap& voxels, const planner::VisibilityConfig& visibility,
                    const planner::InformationConfig& information);

// trial.look_guard's check: the view `trajectory` holds lead_s after tau_now, where it expects
// fewer than `floor` detections (planner::ViewSupport::detections) on `voxels` and the view at
// tau_now does not; nothing where the view ahead meets the floor or the view now is below it already.
std::optional<RatedView> viewAheadFallsShort(const control::SetpointTrajectory& trajectory, double tau_now,
                                             double lead_s, double floor, const planner::VoxelMap& voxels,
                                             const planner::VisibilityConfig& visibility,
                                             const planner::InformationConfig& information);

// vo.csv's columns of a prediction (`tgnav views` writes the same), and one frame's values in
// them: comma-separated, no leading or trailing comma; the probability is empty without a model.
extern const char* const kPredictionColumns;
void writePredictionColumns(std::ostream& out, const FramePrediction& prediction);

}  // namespace tgnav::harness
