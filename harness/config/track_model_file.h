#pragma once
// The learned perception model's file (planner/track_model.h), written by
// scripts/fit_track_model.py:
//   {"format": "tgnav-track-model", "version": 1, "kind": "logistic",
//    "features": [NAME, ...], "mean": [...], "scale": [...], "weights": [...], "intercept": B, ...}
// (version 2 may add "ramps": [null or [lo, hi], ...], one per feature: that term is a ramp of its
// feature, planner/track_model.h), and optionally "view_settings": {"hfov_rad", "vfov_rad", "min_range_m",
// "max_range_m", "max_incidence_rad"} and, optional (0 when absent), "sight_to_face" (0 or 1) (what its features were
// computed with; the scenario must plan with the same,
// harness/config/scenario.cpp). Other keys (what it was fitted on, its scores) are the script's record and are not
// read. Every feature name must be one of planner::trackFeatureNames(); the arrays match it in length; every number is
// finite and every scale > 0. Anything else is an InputError naming the file and key.
#include <filesystem>

#include "planner/track_model.h"

namespace tgnav::harness {

planner::TrackModel loadTrackModel(const std::filesystem::path& file);

}  // namespace tgnav::harness
