#pragma once
// Perception score of a 4-DoF pose from a set of candidate landmarks (paper Sec. V-D): the
// landmarks inside the camera's field of view at that pose (range, vertical and horizontal FoV;
// occlusion was settled when the candidate set was built) add their bearing Fisher information,
// and the score is the regularised log det (fisher.h). The camera is level and looks along the
// body's yaw (the MAV's forward camera).
//
// Landmarks sharing a map voxel are summed as one point with a weight (their mean position and
// count): they lie within one voxel (0.1 m) of each other, metres from the camera, so their
// bearings and information agree to a fraction of a percent, and the sums get 10-20x cheaper.
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "planner/feature_map.h"
#include "planner/fisher.h"
#include "planner/track_model.h"
#include "planner/voxel_map.h"

namespace tgnav::planner {

struct InformationConfig {
  double bearing_noise_rad = 1.0;  // sigma of eq. 5; 1 puts c_p on the scale of Table I's c_p,thr = 6
  double epsilon = 1e-2;           // log det regulariser: a blind pose scores 6 ln(1e-2) = -27.6
  // Trackability (ours; the paper counts every landmark in the FoV and range). A landmark counts
  // only when the camera sees its surface within max_incidence_rad of the surface's normal (where
  // the map knows the normal: LandmarkVoxel::normal_W): feature descriptors do not match across
  // grazing views. A pose with fewer than min_landmarks landmarks that count scores as blind
  // (6 ln epsilon): the VO is lost below its minimum of inliers, however informative a handful
  // of landmarks would be in theory. Calibrated against the VO (README: the perception model).
  double max_incidence_rad = M_PI / 2.0;  // pi/2: no limit
  double min_landmarks = 0.0;
  // Image coverage (ours): the share of the image, cut into kImageCols x kImageRows cells, whose
  // cells hold at least one landmark that counts. A pose below min_image_coverage scores as blind.
  // The VO detects a fixed budget of features spread over the image, so what it can track follows
  // how much of the image is textured, not how many landmarks the map holds there: a 0.5 m strip
  // of textured wall at the edge of a view filled by a plain wall held 600 map landmarks while the
  // VO found 80 features on it and was lost (generated room-1002). Calibrated against the VO.
  double min_image_coverage = 0.2;
  // Expected detections (ours): a pose whose landmarks that count would give the VO fewer than
  // this many detections scores as blind. A landmark is expected to be detected as often as the
  // survey detected it when it had it in view (Landmark::detectability()). The map gathers every
  // landmark any survey view detected, and the views detect each one from only some of the
  // places that see it, so the landmark count overstates what one frame finds by an order of
  // magnitude: where a view of a faint surface holds a few hundred landmarks, which looks ample, it
  // promises a few dozen detections, fewer than the VO needs. Calibrated against the VO
  // (README: the perception model). The information itself stays the paper's: every landmark
  // in view adds its bearing information (c_p keeps the scale of Table I's c_p,thr).
  double min_detections = 50.0;
  // A learned perception model (track_model.h) in place of the three gates above: a pose scores
  // blind where the model gives the VO less than min_track_probability of tracking it. The file
  // (JSON, scripts/fit_track_model.py) is read by the harness, which sets `model`; "none": the gates;
  // "default": configs/track_model.json of the build's source tree ($TGNAV_CONFIGS_DIR's, when set).
  // The planner library itself only reads `model`: a caller that sets none gets the gates.
  std::string track_model = "default";
  double min_track_probability = 0.35;      // the default model's (its threshold rule's choice)
  std::shared_ptr<const TrackModel> model;  // read from track_model; not a key

  // True when a pose's score needs the image cells its landmarks fall in: the coverage gate, or
  // a model with a term on coverage, column span or row span (with a model the gates are not used).
  bool usesImageCells() const {
    if (model == nullptr) return min_image_coverage > 0.0;
    return model->uses(TrackFeature::kCoverage) || model->uses(TrackFeature::kColumnSpan) ||
           model->uses(TrackFeature::kRowSpan);
  }
  // True when a pose's score needs ViewSupport::inner_detections (a model that reads them).
  bool usesInnerDetections() const {
    return model != nullptr &&
           (model->uses(TrackFeature::kLogInnerDetections) || model->uses(TrackFeature::kLogInnerNearDetections));
  }

  // Names every field once, for the harness's config files (a(key, field); harness/config/yaml_util.h).
  template <typename Archive>
  void visit(Archive& a) {
    a("bearing_noise_rad", bearing_noise_rad);
    a("epsilon", epsilon);
    a("max_incidence_rad", max_incidence_rad);
    a("min_landmarks", min_landmarks);
    a("min_image_coverage", min_image_coverage);
    a("min_detections", min_detections);
    a("track_model", track_model);
    a("min_track_probability", min_track_probability);
  }

  void validate() const;
};

struct WeightedPoint {
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();
  double weight = 1.0;                                 // number of landmarks at this point
  Eigen::Vector3d normal_W = Eigen::Vector3d::Zero();  // their surface's outward normal; zero: unknown
  double detections = 1.0;  // their summed Landmark::detectability(): what a view of them is expected to find
};

// True when a camera at p_W sees `point`'s surface within config.max_incidence_rad of its normal
// (always, where the normal is unknown).
bool withinIncidence(const Eigen::Vector3d& p_W, const WeightedPoint& point, const InformationConfig& config);

// The image cells of InformationConfig::min_image_coverage.
constexpr int kImageCols = 8;
constexpr int kImageRows = 6;

// The range within which a landmark's detections also count as near ones (ViewSupport).
constexpr double kNearRangeM = 3.0;

// The image's inner part (ViewSupport::inner_detections): points whose projection lies at least
// this share of the half-width (half-height) inside the image's edge. The VO's ORB detector finds
// no corner within edge_threshold_px x scale_factor^level of the border of each pyramid level
// (19 px at level 0, 68 px at level 7 at the defaults; about 35 px averaged over the levels by
// the share of features each keeps), so a landmark in that band is seldom detected whatever the
// survey measured of it elsewhere: 0.1 is 32 px of 640 and 24 px of 480.
constexpr double kImageBorderShare = 0.1;

// What backs a pose's information: the landmarks that count and the image cells they fall in.
struct ViewSupport {
  double landmarks = 0.0;              // their summed weight
  double detections = 0.0;             // their summed detections
  double near_detections = 0.0;        // the detections of those within kNearRangeM of the camera
  double inner_detections = 0.0;       // the detections of those in the image's inner part (kImageBorderShare)
  double inner_near_detections = 0.0;  // the detections of those both inner and near
  double range_detections = 0.0;       // sum of detections x range, m
  std::uint64_t cells = 0;             // bit row * kImageCols + col: a landmark falls in that cell
  // `inner`: the point projects into the image's inner part (ImageCells::inner); callers whose
  // model does not use inner_detections may pass false.
  void count(const WeightedPoint& point, double range_m, bool inner) {
    landmarks += point.weight;
    detections += point.detections;
    range_detections += point.detections * range_m;
    if (range_m < kNearRangeM) near_detections += point.detections;
    if (inner) inner_detections += point.detections;
    if (inner && range_m < kNearRangeM) inner_near_detections += point.detections;
  }
  void cover(int cell) {
    if (cell >= 0) cells |= std::uint64_t{1} << cell;
  }
  void add(const WeightedPoint& point, double range_m, int cell, bool inner) {
    count(point, range_m, inner);
    cover(cell);
  }
  double coverage() const;    // share of the kImageCols x kImageRows cells marked
  double columnSpan() const;  // share of the kImageCols columns with a marked cell
  double rowSpan() const;     // share of the kImageRows rows with a marked cell
  double meanRangeM() const;  // detection-weighted mean range; 0 without detections
};

// The cell of a level pinhole camera's image at p_W looking along yaw_rad that l_W projects into
// (the image spans the horizontal and vertical FoV; points outside are clamped to the border).
int imageCell(const Eigen::Vector3d& p_W, double yaw_rad, const Eigen::Vector3d& l_W,
              const VisibilityConfig& visibility);

// imageCell() for many points seen along one yaw: the trigonometry once (the same cells).
class ImageCells {
 public:
  ImageCells(double yaw_rad, const VisibilityConfig& visibility);
  int operator()(const Eigen::Vector3d& p_W, const Eigen::Vector3d& l_W) const;
  // True when l_W projects into the image's inner part: in front of the camera and at least
  // kImageBorderShare of the half-width and half-height inside the edges.
  bool inner(const Eigen::Vector3d& p_W, const Eigen::Vector3d& l_W) const;

 private:
  double cos_yaw_;
  double sin_yaw_;
  double tan_half_hfov_;
  double tan_half_vfov_;
};

// The score of a pose from its information and what backs it: log det (I + eps Id), or the blind
// score 6 ln eps when fewer than config.min_landmarks count, they promise fewer than
// config.min_detections detections or they cover less of the image than config.min_image_coverage;
// with a model (config.model), when the model's probability is below config.min_track_probability
// (the three gates are then not used).
double scoreInformation(const Matrix6d& info, const ViewSupport& support, const InformationConfig& config);

// How far a pose falls short of its gates: 0 when it passes every gate of scoreInformation() (or
// none is set), else 1 minus the smallest of landmarks / min_landmarks, detections /
// min_detections and coverage / min_image_coverage over the gates it fails, in (0, 1]; with a
// model, 1 - p / min_track_probability where p falls below it.
double gateShortfall(const ViewSupport& support, const InformationConfig& config);

// The score a search ranks a pose by (ours): scoreInformation(), lowered by gateShortfall() times
// |6 ln eps| for a pose its gates blind. Every gated pose scores the same 6 ln eps, so where every
// candidate of a layer is gated the search would have no reason left to prefer the yaw that misses
// the gates by least; this keeps that order, below every pose that passes.
double rankedScore(double score, const ViewSupport& support, const InformationConfig& config);

// The candidate landmarks `ids` grouped by their voxel in `voxels` (weight: their number;
// detections: their summed detectability); ids outside its box are left out.
std::vector<WeightedPoint> aggregateByVoxel(const VoxelMap& voxels, const std::vector<int>& ids);
// The same for whole voxels, given as ascending indices into voxels.landmarkVoxels() (e.g.
// VoxelMap::visibleSlots): equal to aggregateByVoxel() of the union of their ids.
std::vector<WeightedPoint> aggregateSlots(const VoxelMap& voxels, const std::vector<int>& slots);

// std::atan2(opposite, adjacent) <= half_angle (both sides >= 0, half_angle in (0, pi/2)), the
// arctangent skipped where comparing opposite with tan_half_angle * adjacent decides by a margin
// (1e-9 relative) far beyond both functions' rounding: the same answer, mostly without atan2.
inline bool withinHalfAngle(double opposite, double adjacent, double half_angle, double tan_half_angle) {
  const double edge = tan_half_angle * adjacent;
  if (opposite < edge * (1.0 - 1e-9)) return true;
  if (opposite > edge * (1.0 + 1e-9)) return false;
  return std::atan2(opposite, adjacent) <= half_angle;
}

// The camera's position when the body is at p_WB heading along yaw_rad (level):
// VisibilityConfig::camera_forward_m ahead and camera_up_m above.
inline Eigen::Vector3d cameraPosition(const Eigen::Vector3d& p_WB, double yaw_rad, const VisibilityConfig& visibility) {
  return {p_WB.x() + visibility.camera_forward_m * std::cos(yaw_rad),
          p_WB.y() + visibility.camera_forward_m * std::sin(yaw_rad), p_WB.z() + visibility.camera_up_m};
}
// True where the camera sits away from the body's centre.
inline bool cameraOffset(const VisibilityConfig& visibility) {
  return visibility.camera_forward_m != 0.0 || visibility.camera_up_m != 0.0;
}

// True if a level camera at p_W looking along yaw_rad sees l_W within range and both FoVs.
bool inFieldOfView(const Eigen::Vector3d& p_W, double yaw_rad, const Eigen::Vector3d& l_W,
                   const VisibilityConfig& visibility);

// inFieldOfView() for many points seen from one yaw: the same answers, its trigonometry done once
// and the arctangents skipped where a comparison decides by a margin far beyond their rounding
// (as withinHalfAngle()). `visibility` must outlive it.
class FieldOfView {
 public:
  FieldOfView(double yaw_rad, const VisibilityConfig& visibility);
  bool operator()(const Eigen::Vector3d& p_W, const Eigen::Vector3d& l_W) const;

 private:
  double yaw_rad_;
  const VisibilityConfig* visibility_;
  double cos_yaw_;
  double sin_yaw_;
  double tan_half_hfov_;
  double tan_half_vfov_;
  bool shortcuts_;  // both FoVs in (0, pi), as the comparisons assume; else inFieldOfView() answers
};

// Summed information (camera-centred frame, fisher.h) of the points in the FoV of the pose that
// are within the incidence limit; `support` (optional): their weight and image cells. p_W is the
// camera's position: cameraPosition() of a body pose.
Matrix6d poseInformation(const Eigen::Vector3d& p_W, double yaw_rad, const std::vector<WeightedPoint>& points,
                         const VisibilityConfig& visibility, const InformationConfig& config,
                         ViewSupport* support = nullptr);
// scoreInformation() of poseInformation(): log det (I + epsilon Id), the pose's term of eq. 8.
double poseScore(const Eigen::Vector3d& p_W, double yaw_rad, const std::vector<WeightedPoint>& points,
                 const VisibilityConfig& visibility, const InformationConfig& config);

}  // namespace tgnav::planner
