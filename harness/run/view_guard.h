#pragma once
// The tracking guard of an online trial (trial.guard_tracking): the VO's own inlier count, not a
// prediction, stops a turn of the camera that is losing the texture it tracks.
//
// Online, a surface is rated only once seen, so the first look into unknown space whose walls are
// bare is blind, and the VO was lost there on every planner (docs/results/online10). A real VO knows
// how many points it still tracks. When a frame tracks fewer than `min_inliers` while the camera
// turns (by at least `min_turn_rad` over the last kTurnWindowS), the guard trips: the vehicle stops where it is, turns
// back to the good yaw, and the space it was turning toward (the new part of the view, from the good view's edge to the
// bad view's far edge and kBeyondRad on) becomes a blind wedge. Unknown space inside a wedge, within its range of the
// place it was seen from, is planned as occupied: the vehicle does not fly into space it cannot
// look at while the VO tracks. Observed space inside it is planned as it is.
//
// With `still` (trial.guard_still) it trips as well where the camera does not turn: the texture
// leaves the image as the vehicle moves (it slides along a wall whose texture ends). The vehicle
// stops while the VO still tracks, and the wedge is the view it lost: its field of view.
#include <octomap/OcTree.h>

#include <Eigen/Core>
#include <array>
#include <deque>
#include <optional>
#include <utility>
#include <vector>

#include "harness/run/plan_run.h"
#include "vo/camera_intrinsics.h"
#include "vo/odometry.h"

namespace tgnav::harness {

// Horizontal bearings from `from_rad` counter-clockwise over `width_rad` (at most pi), seen from
// `apex`, out to `range_m`.
struct BlindWedge {
  Eigen::Vector3d apex = Eigen::Vector3d::Zero();
  double from_rad = 0.0;
  double width_rad = 0.0;
  double range_m = 0.0;
};

// Whether `p` lies inside the wedge (horizontally; its height is not compared).
bool inWedge(const BlindWedge& wedge, const Eigen::Vector3d& p);

// When the guard tripped, for online.json.
struct GuardEvent {
  double t_s = 0.0;
  double yaw_rad = 0.0;       // the camera's (estimated) at the frame that tripped it
  double good_yaw_rad = 0.0;  // the last yaw that tracked enough
  int inliers = 0;
  bool turning = true;  // false: tripped without a turn (trial.guard_still); its wedge is the view lost
  BlindWedge wedge;     // its apex: where the camera was (estimated)
  // The commanded turn the lead foresaw and tripped on (trial.guard_planned_turn), else 0: the turn
  // toward the bad view is then yaw_rad - good_yaw_rad plus this.
  double planned_rad = 0.0;
  // >= 0 where trial.look_guard tripped it, not the inliers: the detections the view the look would
  // fly guard_lead_s ahead expects on the latest plan's map, below the look's floor. Its wedge's apex
  // is then the body's place there, yaw_rad that view's yaw, good_yaw_rad the yaw held; turning is false.
  double predicted_detections = -1.0;
  bool predicted() const { return predicted_detections >= 0.0; }
};

// Whether the guard's trip `event` rules out the view from p along yaw: within within_m of where it
// tripped, from halfway through its turn (with the commanded turn it foresaw, event.planned_rad) to
// beyond_rad past its end; for a trip without a turn, within half of beyond_rad of its yaw either
// way.
bool trippedView(const GuardEvent& event, const Eigen::Vector2d& p, double yaw_rad, double within_m, double beyond_rad);

// How many of a frame's inliers (vo::FrameResult::inlier_columns, binned across `camera`'s image)
// stay in the image after the camera turns by turn_rad about its vertical axis (counter-clockwise,
// as yaw, positive: the points move right), its edges moved in by edge_px (where the detector
// finds no keypoints). Each bin counts at its centre's bearing.
int inliersAfterTurn(const std::array<int, vo::FrameResult::kColumnBins>& columns, const vo::CameraIntrinsics& camera,
                     double turn_rad, double edge_px);

// The guard's lead (trial.guard_lead_s > 0): it judges a frame by the inliers that would stay in
// view were the turn to go on at its rate (over the last ViewGuard::kRateWindowS) for lead_s, not by the
// inliers alone. The reactive guard tripped 0.15 s before the loss, too late to stop the turn
// (docs/results/guard): a turn toward bare space takes the texture out at the image's trailing
// edge, and the inliers' columns show it coming.
struct GuardLead {
  double lead_s = 0.0;  // 0: the inliers alone
  vo::CameraIntrinsics camera;
  double edge_px = 0.0;
};

class ViewGuard {
 public:
  // How far past the bad view's far edge the wedge reaches: the turn was heading that way.
  static constexpr double kBeyondRad = M_PI / 4.0;
  // The camera turns when its yaw changed by min_turn_rad over this long.
  static constexpr double kTurnWindowS = 0.5;
  // The lead's turn rate: over this long (three frames at 20 Hz).
  static constexpr double kRateWindowS = 0.15;

  // half_fov_rad: half the camera's horizontal field of view. still: it trips without a turn too.
  ViewGuard(int min_inliers, double min_turn_rad, double half_fov_rad, double range_m, GuardLead lead = {},
            bool still = false)
      : min_inliers_(min_inliers),
        min_turn_rad_(min_turn_rad),
        half_fov_rad_(half_fov_rad),
        range_m_(range_m),
        lead_(lead),
        still_(still) {}

  // One tracked frame: the camera's position and yaw (estimated) and the VO's inliers (with a
  // lead, `columns`: where they lie across the image). Returns the blind wedge when the guard
  // trips; it then stays disarmed until rearm(). With a lead, the wedge reaches past the bad view
  // by the turn the lead foresaw as well. Without a turn (with `still`), the wedge is the bad view's
  // field of view, and lastTripTurned() is false. planned_turn_rad (trial.guard_planned_turn): the
  // turn the trajectory commands over the lead; where it is larger than the turn at the measured
  // rate the lead foresees it instead, and at min_turn_rad or more it counts as a turn
  // (lastTripPlannedRad() then returns it).
  std::optional<BlindWedge> observe(double t_s, const Eigen::Vector3d& p, double yaw_rad, int inliers,
                                    const std::array<int, vo::FrameResult::kColumnBins>* columns = nullptr,
                                    double planned_turn_rad = 0.0);
  // Arms it again from the next frame that tracks enough (a new plan is flown).
  void rearm() { rearm_ = true; }
  bool armed() const { return armed_; }
  double goodYaw() const { return good_yaw_rad_; }
  bool lastTripTurned() const { return last_trip_turned_; }
  double lastTripPlannedRad() const { return last_trip_planned_rad_; }

 private:
  int min_inliers_;
  double min_turn_rad_;
  double half_fov_rad_;
  double range_m_;
  GuardLead lead_;
  bool still_ = false;
  bool last_trip_turned_ = true;
  double last_trip_planned_rad_ = 0.0;
  bool armed_ = true;
  bool rearm_ = false;
  bool has_good_ = false;
  double good_yaw_rad_ = 0.0;
  std::deque<std::pair<double, double>> recent_;  // (time, yaw) over the last kTurnWindowS
};

// Marks occupied every voxel of `tree` never observed, over the band, inside any of `wedges`,
// except within keep_m (horizontally) of the wedge's apex or of any of `keep_free` (where the
// vehicle has been, the goal). Returns how many it marked.
int blockWedges(octomap::OcTree* tree, const std::vector<BlindWedge>& wedges, const ClearanceBand& band,
                const std::vector<Eigen::Vector3d>& keep_free, double keep_m);

// Marks free the never-observed voxels of `tree` within `radius_m` (horizontally) of each of
// `centres`, over the band: where the vehicle has been, and the goal the mission gives, are free
// whether the camera saw them or not. With unknown_space: blocked the planners see only these and
// what was observed free; without them the start's own voxels, which the forward camera never
// sees, left no route from no map (`invalid_start`, then `no_path`).
void markFree(octomap::OcTree* tree, const std::vector<Eigen::Vector3d>& centres, double radius_m,
              const ClearanceBand& band);

}  // namespace tgnav::harness
