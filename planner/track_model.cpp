#include "planner/track_model.h"

#include <algorithm>
#include <cmath>

#include "planner/perception.h"

namespace tgnav::planner {

const std::vector<std::string>& trackFeatureNames() {
  static const std::vector<std::string> names = {"log_detections",
                                                 "log_landmarks",
                                                 "coverage",
                                                 "column_span",
                                                 "row_span",
                                                 "log_near_detections",
                                                 "mean_range_m",
                                                 "log_inner_detections",
                                                 "log_inner_near_detections"};
  return names;
}

bool parseTrackFeature(const std::string& name, TrackFeature* feature) {
  const std::vector<std::string>& names = trackFeatureNames();
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) {
      *feature = static_cast<TrackFeature>(i);
      return true;
    }
  }
  return false;
}

double trackFeatureValue(TrackFeature feature, const ViewSupport& support) {
  switch (feature) {
    case TrackFeature::kLogDetections:
      return std::log1p(support.detections);
    case TrackFeature::kLogLandmarks:
      return std::log1p(support.landmarks);
    case TrackFeature::kCoverage:
      return support.coverage();
    case TrackFeature::kColumnSpan:
      return support.columnSpan();
    case TrackFeature::kRowSpan:
      return support.rowSpan();
    case TrackFeature::kLogNearDetections:
      return std::log1p(support.near_detections);
    case TrackFeature::kMeanRange:
      return support.meanRangeM();
    case TrackFeature::kLogInnerDetections:
      return std::log1p(support.inner_detections);
    case TrackFeature::kLogInnerNearDetections:
      return std::log1p(support.inner_near_detections);
  }
  return 0.0;
}

double TrackModel::Term::value(const ViewSupport& support) const {
  const double f = trackFeatureValue(feature, support);
  return ramp ? std::clamp((f - ramp_lo) / (ramp_hi - ramp_lo), 0.0, 1.0) : f;
}

bool TrackModel::uses(TrackFeature feature) const {
  for (const Term& t : terms) {
    if (t.feature == feature) return true;
  }
  return false;
}

double TrackModel::probability(const ViewSupport& support) const {
  double z = intercept;
  for (const Term& t : terms) z += t.weight * (t.value(support) - t.mean) / t.scale;
  return 1.0 / (1.0 + std::exp(-z));
}

}  // namespace tgnav::planner
