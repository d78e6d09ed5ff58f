#pragma once
// Pictures of one closed-loop trial (drawn with OpenCV, no display needed):
//   topdown.png  the feature map from above with the planned path, the trajectory, the flown
//                (true) path, the VO's estimated path, where VO was lost and where it crashed;
//   ate.png      position error of the VO against distance travelled (the paper's Fig. 4);
//   frames.png   a strip of onboard camera frames with captions.
#include <Eigen/Core>
#include <optional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "harness/scene_config.h"
#include "planner/feature_map.h"

namespace tgnav::harness {

struct TrialPaths {
  std::vector<Eigen::Vector2d> planned;     // the chosen planner path (waypoints), x-y in W
  std::vector<Eigen::Vector2d> trajectory;  // the generated trajectory, sampled
  std::vector<Eigen::Vector2d> flown;       // the true body path
  std::vector<Eigen::Vector2d> estimated;   // the VO's camera path (tracked frames only)
  std::optional<Eigen::Vector2d> vo_lost_at;     // true position when VO was first lost
  std::optional<Eigen::Vector2d> collision_at;   // true position of the first collision
  std::string caption;                           // one line at the top, e.g. "storage proposed seed 1: success"
};

// Map as Topdown draws it (occupancy band around the flight height, landmark density), start
// and goal, then the paths: planned (thin blue), trajectory (thin grey dashes), flown (green,
// thick), estimated (magenta), VO-lost (black X with ring), collision (red X); a legend and
// the caption. `metres_per_px` sets the scale (0.02 gives 600 px for a 12 m scene).
cv::Mat drawTrialTopdown(const SceneConfig& scene, const planner::FeatureMap& map, const TrialPaths& paths,
                         double metres_per_px = 0.02);

struct ErrorCurve {
  std::vector<double> distance_m;  // distance travelled (ground truth), non-decreasing
  std::vector<double> error_m;     // position error at that distance, same size
  std::string label;
  std::optional<double> lost_at_distance_m;  // draw a marker where tracking was lost
};

// Line plot of error against distance with axes, ticks, gridlines, axis labels, a title and a
// legend; several curves get distinct colours. Empty curves are listed in the legend only.
// Size `width` x `height` pixels.
cv::Mat drawErrorVsDistance(const std::vector<ErrorCurve>& curves, const std::string& title, int width = 800,
                            int height = 500);

// Frames (CV_8UC3, any sizes) scaled to `thumb_width` and laid out in rows of `per_row`, each
// with its caption underneath. Empty input gives an empty Mat.
cv::Mat drawFrameStrip(const std::vector<cv::Mat>& frames, const std::vector<std::string>& captions,
                       int thumb_width = 240, int per_row = 4);

}  // namespace tgnav::harness
