#pragma once
// The route a prior-map trial flies: planned on the scene's map by a built-in planner, given
// (`--trajectory`, `--path`), or asked of an external planner.
#include <atomic>

#include "harness/run/trial.h"

namespace tgnav::harness {

// The route into result->setpoints (and result->plan, result->external); false with
// result->status and result->detail set when there is none.
bool makeRoute(const Scenario& scenario, const planner::FeatureMap& map, const TrialOptions& options,
               const std::atomic<bool>* interrupt, TrialResult* result);

}  // namespace tgnav::harness
