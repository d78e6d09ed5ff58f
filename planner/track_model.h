#pragma once
// A perception model learned from the closed loop (issue 38; the paper's future work: "reducing
// the need of tuning parameters via data-driven methods"): the probability that the VO tracks a
// frame (at least vo.min_inliers PnP inliers) from what the planner computes for a pose before
// flying (ViewSupport: the landmarks in view, the detections they promise, how much of the image
// they cover, how near they are, how many fall inside the detector's image border). A logistic
// model over standardised terms,
//   p = 1 / (1 + exp(-(b + sum_i w_i (g_i - mean_i) / scale_i))),
// where a term's value g_i is its feature f_i, or a ramp of it, clamp((f_i - lo_i) / (hi_i - lo_i), 0, 1)
// (the file's "ramps", version 2): ramps between consecutive knots with weights >= 0 make p any
// monotone piecewise-linear function of the feature in the logit, which follows the VO's sharp step
// from lost to tracked that one straight line cannot.
// fitted offline by scripts/fit_track_model.py on oracle trials of calibration scenes (by default
// with the texture features' weights held >= 0, so that more texture never lowers p) and read
// from its JSON file by the harness (harness/config/track_model_file.h). With a model, a pose
// scores blind below InformationConfig::min_track_probability (perception.h) in place of the
// hand-set gates: c_p,thr becomes a probability with a meaning.
#include <string>
#include <vector>

namespace tgnav::planner {

struct ViewSupport;

// What a model may use; the names are the JSON file's and vo.csv's (predicted_<name>).
enum class TrackFeature {
  kLogDetections,           // log(1 + detections promised)
  kLogLandmarks,            // log(1 + landmarks that count)
  kCoverage,                // share of the image's cells holding a landmark
  kColumnSpan,              // share of the image's columns holding a landmark
  kRowSpan,                 // share of its rows
  kLogNearDetections,       // log(1 + detections of landmarks within kNearRangeM)
  kMeanRange,               // detection-weighted mean range of the landmarks, m (0 when none)
  kLogInnerDetections,      // log(1 + detections of landmarks in the image's inner part, kImageBorderShare)
  kLogInnerNearDetections,  // log(1 + detections of landmarks both inner and within kNearRangeM)
};

const std::vector<std::string>& trackFeatureNames();  // in TrackFeature's order
// The feature called `name`, or false when there is none of that name.
bool parseTrackFeature(const std::string& name, TrackFeature* feature);
double trackFeatureValue(TrackFeature feature, const ViewSupport& support);

struct TrackModel {
  struct Term {
    TrackFeature feature = TrackFeature::kLogDetections;
    double mean = 0.0;
    double scale = 1.0;  // > 0
    double weight = 0.0;
    bool ramp = false;  // the term is clamp((f - ramp_lo) / (ramp_hi - ramp_lo), 0, 1), ramp_hi > ramp_lo
    double ramp_lo = 0.0;
    double ramp_hi = 1.0;
    double value(const ViewSupport& support) const;
  };
  std::vector<Term> terms;
  double intercept = 0.0;
  std::string source;  // the file it came from (reports, errors)
  // The view settings its features were computed with (the file's "view_settings"): a planner
  // that counts landmarks otherwise (another range or field of view) would feed it other
  // numbers. Empty for a file that does not record them.
  struct ViewSettings {
    double hfov_rad = 0.0;
    double vfov_rad = 0.0;
    double min_range_m = 0.0;
    double max_range_m = 0.0;
    double max_incidence_rad = 0.0;
    double sight_to_face = 0.0;  // 1: VisibilityConfig::sight_to_face (absent from older files: 0)
  };
  bool has_view_settings = false;
  ViewSettings view_settings;

  // True when a term uses `feature` (callers skip counting what no term reads).
  bool uses(TrackFeature feature) const;

  // The probability that the VO tracks a frame whose view has `support`.
  double probability(const ViewSupport& support) const;
};

}  // namespace tgnav::planner
