#include "harness/config/trial_config.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "harness/config/check.h"

namespace tgnav::harness {

const std::vector<std::pair<std::string, StateSource>>& stateSourceNames() {
  static const std::vector<std::pair<std::string, StateSource>> names = {{"gt", StateSource::kGroundTruth},
                                                                         {"vo", StateSource::kVo}};
  return names;
}

const char* toString(StateSource source) { return nameOf(source, stateSourceNames()); }

bool parseStateSource(const std::string& text, StateSource* source) {
  for (const auto& [name, s] : stateSourceNames()) {
    if (text == name) {
      *source = s;
      return true;
    }
  }
  return false;
}

const std::vector<std::pair<std::string, TrialMode>>& trialModeNames() {
  static const std::vector<std::pair<std::string, TrialMode>> names = {{"prior", TrialMode::kPrior},
                                                                       {"online", TrialMode::kOnline}};
  return names;
}

const std::vector<std::pair<std::string, PriorMap>>& priorMapNames() {
  static const std::vector<std::pair<std::string, PriorMap>> names = {
      {"none", PriorMap::kNone}, {"survey", PriorMap::kSurvey}, {"radius", PriorMap::kRadius}};
  return names;
}

const std::vector<std::pair<std::string, MapPose>>& mapPoseNames() {
  static const std::vector<std::pair<std::string, MapPose>> names = {{"estimate", MapPose::kEstimate},
                                                                     {"truth", MapPose::kTruth}};
  return names;
}

const std::vector<std::pair<std::string, UnknownSpace>>& unknownSpaceNames() {
  static const std::vector<std::pair<std::string, UnknownSpace>> names = {{"free", UnknownSpace::kFree},
                                                                          {"blocked", UnknownSpace::kBlocked}};
  return names;
}

const std::vector<std::pair<std::string, UnseenPrior>>& unseenPriorNames() {
  static const std::vector<std::pair<std::string, UnseenPrior>> names = {
      {"blind", UnseenPrior::kBlind}, {"mean", UnseenPrior::kMean}, {"route_mean", UnseenPrior::kRouteMean}};
  return names;
}

namespace {

void nonNegative(double value, const char* field) {
  require(std::isfinite(value) && value >= 0.0, field, value, "must be >= 0");
}

// Runs a member's validate(), its field names prefixed with the member's key.
template <typename Config>
void validateMember(const Config& config, const std::string& key) {
  try {
    config.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(key + "." + e.what());
  }
}
}  // namespace

void ImuConfig::validate() const {
  nonNegative(accel_noise_m_s2, "accel_noise_m_s2");
  nonNegative(accel_bias_m_s2, "accel_bias_m_s2");
  nonNegative(gyro_noise_rad_s, "gyro_noise_rad_s");
  nonNegative(gyro_bias_rad_s, "gyro_bias_rad_s");
}

void OnlineConfig::validateLooks() const {
  if (look_ahead_best_view && look_ahead_keeps_tracking) {
    throw std::invalid_argument(
        "look_ahead_best_view = true: not with look_ahead_keeps_tracking = true (two rules for the same yaw)");
  }
  if (look_probe && !look_advance) {
    throw std::invalid_argument(
        "look_probe = true: needs look_advance = true (it probes where the vehicle cannot advance)");
  }
  if (look_fallback && !look_then_fly) {
    throw std::invalid_argument(
        "look_fallback = true: needs look_then_fly = true (it is what a plan does when no look is left)");
  }
  require(std::isfinite(look_stall_s) && look_stall_s >= 0.0 && look_stall_s <= 3600.0, "look_stall_s", look_stall_s,
          "must be in [0, 3600]");
  if (look_stall_s > 0.0 && !look_then_fly) {
    throw std::invalid_argument("look_stall_s > 0: needs look_then_fly = true (it is when the looks have stalled)");
  }
  if (look_keep_class && !look_then_fly) {
    throw std::invalid_argument(
        "look_keep_class = true: needs look_then_fly = true (it keeps the class the explorer flies)");
  }
  require(look_give_up >= 0 && look_give_up <= 1000, "look_give_up", look_give_up, "must be in [0, 1000]");
  require(std::isfinite(look_min_detections) && look_min_detections >= 0.0 && look_min_detections <= 10000.0,
          "look_min_detections", look_min_detections, "must be in [0, 10000]");
  require(std::isfinite(look_fov_margin_deg) && look_fov_margin_deg >= 0.0 && look_fov_margin_deg <= 45.0,
          "look_fov_margin_deg", look_fov_margin_deg, "must be in [0, 45]");
  if (look_fov_margin_deg > 0.0 && !look_then_fly) {
    throw std::invalid_argument(
        "look_fov_margin_deg > 0: needs look_then_fly = true (it narrows the views the explorer rates)");
  }
  require(std::isfinite(look_fallback_floor) && look_fallback_floor >= 0.0 && look_fallback_floor <= 10000.0,
          "look_fallback_floor", look_fallback_floor, "must be in [0, 10000]");
  if (look_fallback_floor > 0.0 && !look_fallback) {
    throw std::invalid_argument(
        "look_fallback_floor > 0: needs look_fallback = true (the search is made again before the fallback)");
  }
  require(look_fallback_floor < look_min_detections || look_fallback_floor <= 0.0, "look_fallback_floor",
          look_fallback_floor, "must be below look_min_detections");
  require(std::isfinite(look_hold_margin) && look_hold_margin >= 0.0 && look_hold_margin <= 10.0, "look_hold_margin",
          look_hold_margin, "must be in [0, 10]");
  if (look_hold_margin > 0.0 && !look_then_fly) {
    throw std::invalid_argument(
        "look_hold_margin > 0: needs look_then_fly = true (it is asked of the views the explorer stops at)");
  }
  if (look_along && !look_then_fly) {
    throw std::invalid_argument("look_along = true: needs look_then_fly = true (it orders the explorer's looks)");
  }
  if (look_classes && !look_then_fly) {
    throw std::invalid_argument("look_classes = true: needs look_then_fly = true (it widens the explorer's search)");
  }
}

void OnlineConfig::validate() const {
  require(std::isfinite(prior_radius_m) && prior_radius_m > 0.0, "prior_radius_m", prior_radius_m, "must be > 0");
  require(std::isfinite(plan_latency_s) && plan_latency_s >= 0.0 && plan_latency_s <= 10.0, "plan_latency_s",
          plan_latency_s, "must be in [0, 10]");
  require(std::isfinite(replan_period_s) && replan_period_s > plan_latency_s && replan_period_s <= 60.0,
          "replan_period_s", replan_period_s, "must be > plan_latency_s and <= 60");
  require(std::isfinite(blend_s) && blend_s >= 0.0 && blend_s <= 10.0, "blend_s", blend_s, "must be in [0, 10]");
  require(std::isfinite(commit_s) && commit_s >= 0.0 && commit_s <= 60.0, "commit_s", commit_s, "must be in [0, 60]");
  require(std::isfinite(route_margin) && route_margin >= 0.0 && route_margin <= 10.0, "route_margin", route_margin,
          "must be in [0, 10]");
  require(std::isfinite(look_ahead_s) && look_ahead_s >= 0.0 && look_ahead_s <= 10.0, "look_ahead_s", look_ahead_s,
          "must be in [0, 10]");
  validateLooks();
  require(guard_inliers >= 1 && guard_inliers <= 10000, "guard_inliers", guard_inliers, "must be in [1, 10000]");
  require(std::isfinite(guard_range_m) && guard_range_m > 0.0 && guard_range_m <= 100.0, "guard_range_m", guard_range_m,
          "must be in (0, 100]");
  require(std::isfinite(guard_lead_s) && guard_lead_s >= 0.0 && guard_lead_s <= 5.0, "guard_lead_s", guard_lead_s,
          "must be in [0, 5]");
  if (guard_planned_turn && !(guard_tracking && guard_lead_s > 0.0)) {
    throw std::invalid_argument(
        "guard_planned_turn = true: needs guard_tracking = true and guard_lead_s > 0 (it is what the lead foresees)");
  }
  if (look_guard && !(look_then_fly && guard_lead_s > 0.0)) {
    throw std::invalid_argument(
        "look_guard = true: needs look_then_fly = true and guard_lead_s > 0 (it rates the look's view that far ahead)");
  }
  if (look_guard_routes && !look_guard) {
    throw std::invalid_argument("look_guard_routes = true: needs look_guard = true (it widens what that guards)");
  }
  if (guard_still && !guard_tracking) {
    throw std::invalid_argument("guard_still = true: needs guard_tracking = true (it is how the guard trips)");
  }
  require(map_every_frames >= 1 && map_every_frames <= 100, "map_every_frames", map_every_frames,
          "must be in [1, 100]");
  require(std::isfinite(map_range_m) && map_range_m > 0.0 && map_range_m <= 100.0, "map_range_m", map_range_m,
          "must be in (0, 100]");
  require(map_stride_px >= 1 && map_stride_px <= 64, "map_stride_px", map_stride_px, "must be in [1, 64]");
  require(std::isfinite(max_flight_s) && max_flight_s > 0.0 && max_flight_s <= 3600.0, "max_flight_s", max_flight_s,
          "must be in (0, 3600]");
}

void TrialConfig::validate() const {
  require(std::isfinite(camera_rate_hz) && camera_rate_hz > 0.0, "camera_rate_hz", camera_rate_hz, "must be > 0");
  require(std::isfinite(goal_radius_m) && goal_radius_m > 0.0, "goal_radius_m", goal_radius_m, "must be > 0");
  require(std::isfinite(max_drift_ratio) && max_drift_ratio > 0.0, "max_drift_ratio", max_drift_ratio, "must be > 0");
  validateMember(flight, "flight");
  validateMember(imu, "imu");
  validateMember(estimator, "estimator");
  online.validate();
  if (online.online()) {
    const StateSource flies_on = online.map_pose == MapPose::kTruth ? StateSource::kGroundTruth : StateSource::kVo;
    if (state_source != flies_on) {
      throw std::invalid_argument(std::string("state_source = ") + toString(state_source) + ": must be " +
                                  toString(flies_on) + " in online mode with map_pose " +
                                  nameOf(online.map_pose, mapPoseNames()) +
                                  " (an online trial flies on the pose it maps at)");
    }
  }
}

}  // namespace tgnav::harness
