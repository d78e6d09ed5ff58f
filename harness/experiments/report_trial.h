#pragma once
// What `tgnav report` reads from a trial folder beyond its index.csv row: metrics.json (required),
// plan.json (optional), config.yaml and the header of vo.csv (for the figures).
#include <filesystem>
#include <optional>
#include <string>

#include "harness/experiments/report.h"

namespace tgnav::harness {

// metrics.json into `row`: tracked_frames, vo_lost_position, oracle_class, chosen_class, classes
// and c_p_min (each left empty where metrics.json has no such number). InputError naming `shown`
// when the file is not a JSON object.
void readTrialMetrics(const std::filesystem::path& file, const std::string& shown, IndexRow& row);

// plan.json, when the trial folder has one, into `row`: c_p_threshold and the chosen class's c_p_min
// (classes[chosen_class].c_p_min; plan.json's chosen_class indexes its classes, which for RRT*
// hold its one path). InputError naming `shown` when the file is not a JSON object.
void readTrialPlan(const std::filesystem::path& file, const std::string& shown, IndexRow& row);

// The VO's lost threshold of the trial (vo.min_inliers of its config.yaml, the default when the
// file has no such key); none when config.yaml is missing or not YAML.
std::optional<int> trialMinInliers(const std::filesystem::path& trial_folder);

// Whether the trial's vo.csv has a column `name` in its header row (false without vo.csv).
bool voCsvHasColumn(const std::filesystem::path& trial_folder, const std::string& name);

}  // namespace tgnav::harness
