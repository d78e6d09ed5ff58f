#pragma once
// The `tgnav views` job: a flown trial's per-frame view features (the predicted_* columns of its
// vo.csv), computed again at the camera poses it really flew (gt.tum) with other planner settings
// (--set, e.g. the visibility range or the information gates) or another model, so that a
// perception model can be fitted and judged on settings the trials were not flown with, without
// flying them again (scripts/fit_track_model.py --views).
#include <filesystem>
#include <string>
#include <vector>

namespace tgnav::harness {

struct ViewsJob {
  std::filesystem::path trial;   // a trial folder: config.yaml, gt.tum, vo.csv
  std::vector<std::string> set;  // --set dotted.key=value overrides of its config.yaml
  std::string map;               // feature map folder; "" = the cache
  std::string map_cache;
  std::filesystem::path out;  // the CSV to write
  bool force = false;         // replace an existing --out
};

struct ViewsResult {
  int frames = 0;
  double mean_detections = 0.0;     // of the features computed here
  double mean_detections_vo = 0.0;  // of vo.csv's predicted_detections
  std::string summary;              // the line `tgnav views` prints
};

// Writes `out` (atomically): a first line "# view_settings: hfov_rad=H vfov_rad=V min_range_m=A
// max_range_m=B max_incidence_rad=I sight_to_face=F" (what the features were computed with), then the header t
// and vo.csv's predicted_* columns, one row per vo.csv row.
// InputError naming the file for a folder that is not a finished trial, a vo.csv frame without a
// gt.tum pose at its time, a bad --set, or an --out that exists without `force`.
ViewsResult runViews(const ViewsJob& job);

}  // namespace tgnav::harness
