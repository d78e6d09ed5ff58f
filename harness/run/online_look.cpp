// OnlinePlanning (online_planning.h), look then fly (trial.look_then_fly; harness/run/explore.h):
// where the plan's route runs into unknown space, the look search's flight to a trackable view of
// the way on, in place of the route, and what the flight's looks leave for the next ones.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "harness/run/explore.h"
#include "harness/run/look_ahead.h"
#include "harness/run/online_planning.h"

namespace tgnav::harness {

LookConfig OnlinePlanning::lookConfig(const Scenario& from_here, double clear_m) const {
  const planner::PerceptionPlannerConfig& perception = scenario_.planner.perception;
  LookConfig look;
  look.robot_radius_m = perception.robot_radius_m;
  look.known_m = perception.robot_radius_m;  // the body never overlaps unknown space
  look.flight_height_m = from_here.scene.flight_height_m;
  look.half_hfov_rad = 0.5 * perception.visibility.hfov_rad;
  look.observe_range_m = cfg_.map_range_m;
  look.turn_m_per_rad =
      scenario_.planner.trajectory.nominal_speed_mps / scenario_.planner.trajectory.nominal_yaw_rate_rad_s;
  look.visited_clear_m = look.way_clear_m = clear_m;
  look.advance = cfg_.look_advance;
  look.probe = cfg_.look_probe;
  look.floor_inliers = cfg_.guard_inliers;
  look.hold_margin = cfg_.look_hold_margin;
  look.along = cfg_.look_along;
  if (cfg_.look_calibrate_floor && last_inliers_ >= cfg_.guard_inliers) look.tracked_inliers = last_inliers_;
  return look;
}

bool OnlinePlanning::lookFirst(const Scenario& from_here, const planner::FeatureMap& map, double clear_m, Attempt* a) {
  const planner::PerceptionPlannerConfig& perception = scenario_.planner.perception;
  StopRule rule;
  rule.clear_m = clear_m;
  rule.half_fov_rad = lookAheadHalfFov(perception);
  const std::vector<planner::Pose4> known = stopBeforeUnknown(a->run.plan.path, map, visited_, rule);
  const bool all_observed = known.size() >= a->run.plan.path.size();
  std::vector<Eigen::Vector3d> route;
  std::vector<Eigen::Vector3d> way_on;
  for (std::size_t i = 0; i < a->run.plan.path.size(); ++i) {
    (i < known.size() ? route : way_on).push_back(a->run.plan.path[i].p_WB);
  }
  // trial.look_stall_s: the looks have stalled, the route flown as planned (as look_fallback does).
  double route_m = 0.0;
  for (std::size_t i = 1; i < a->run.plan.path.size(); ++i) {
    route_m += (a->run.plan.path[i].p_WB - a->run.plan.path[i - 1].p_WB).norm();
  }
  const double stalled_s = progress_.note(a->record.t_s, route_m);
  if (!all_observed && cfg_.look_stall_s > 0.0 && stalled_s >= cfg_.look_stall_s) {
    a->record.look_stall = true;
    return false;
  }
  const LookConfig look = lookConfig(from_here, clear_m);
  const LookMemory memory{visited_, looked_, givenUp(), result_.guards};
  const auto search = [&](double floor) {
    return searchLook(*a->run.voxels, from_here.scene.start, route, way_on, all_observed, memory, look, floor,
                      &a->record);
  };
  LookPlan found = search(cfg_.look_min_detections);
  if (cfg_.look_classes && !all_observed && !found.goal && !found.way && !found.advance && !found.probe) {
    otherClassLook(from_here, map, rule, memory, look, &found, a);
  }
  // A route all observed that the search cannot fly with trackable views: flown as planned.
  if (all_observed && !found.goal) {
    a->record.look_cells = found.cells;
    return false;
  }
  // trial.look_fallback_floor: where this failure would end the trial, the search again at the lower
  // floor before the route is flown unrated.
  if (found.path.size() < 2 && cfg_.look_fallback && last_chance_ && cfg_.look_fallback_floor > 0.0) {
    const int cells = found.cells;
    found = search(cfg_.look_fallback_floor);
    found.cells += cells;
    a->record.look_lowered = true;
  }
  a->record.look_cells = found.cells;
  // trial.look_fallback: no look left where this failure would end the trial (no_path), the route
  // flown as planned (stop_before_unknown, look-ahead). Earlier, the vehicle holds and looks: at the
  // start, with nothing mapped yet, flying the route lost the VO at once (detour-5001, -5004).
  if (found.path.size() < 2 && cfg_.look_fallback && last_chance_) {
    a->record.look_fallback = true;
    return false;
  }
  a->record.look_seen = found.seen;
  a->record.look_way = found.way;
  a->record.look_goal = found.goal;
  a->record.look_advance = found.advance;
  a->record.look_near = found.near;
  a->record.look_probe = found.probe;
  a->record.look_floor = found.floor;
  if (found.path.size() < 2) {
    a->record.ok = false;
    a->record.detail =
        "look_then_fly: the route runs into unknown space and no trackable view reached through "
        "observed space observes any";
    return true;
  }
  const planner::Pose4& end = found.path.back();
  a->record.look_pose = {end.p_WB.x(), end.p_WB.y(), end.p_WB.z(), end.yaw_rad};
  a->record.look_watched = found.watched;
  a->run.plan.path = found.path;
  if (!smoothInto(from_here, "look_then_fly: ", a)) return true;
  a->stops_short = !found.goal;
  if (!found.goal) a->look = found.path.back();
  a->watched = found.watched;
  return true;
}

LookPlan OnlinePlanning::searchLook(const planner::VoxelMap& voxels, const planner::Pose4& start,
                                    const std::vector<Eigen::Vector3d>& route,
                                    const std::vector<Eigen::Vector3d>& way_on, bool all_observed,
                                    const LookMemory& memory, const LookConfig& look, double min_detections,
                                    OnlinePlan* record) const {
  const planner::PerceptionPlannerConfig& perception = scenario_.planner.perception;
  // The views it flies must expect trial.look_min_detections detections (150 by default, what the
  // tracking guard asks of inliers: the model fitted with the paper's line of sight alone rated views
  // trackable where the VO found 50-80 features for seconds and was lost: development scene detour-5003).
  const auto search = [&](double margin_deg, std::vector<Eigen::Vector4d>* rated_path) {
    planner::VisibilityConfig rated = perception.visibility;
    rated.hfov_rad -= 2.0 * margin_deg * M_PI / 180.0;
    ViewRater rater(voxels, rated, perception.information);
    rater.setDetectionFloor(min_detections);  // 0: none
    LookPlan plan = planLook(voxels, rater, start, scenario_.scene.goal.p_WB, route, way_on, memory, look);
    rated_path->clear();
    for (const planner::Pose4& pose : plan.path) {
      rater.moveTo(pose.p_WB);
      rated_path->emplace_back(pose.p_WB.x(), pose.p_WB.y(), pose.yaw_rad, rater.detections(pose.yaw_rad));
    }
    return plan;
  };
  // trial.look_fov_margin_deg; where it leaves nothing to fly, the whole image before the route is flown
  // unrated (with the margin alone, gallery seed 1 fell back 20 times, not 2, and lost the VO).
  LookPlan found = search(cfg_.look_fov_margin_deg, &record->look_path);
  const auto nothing_to_fly = [&](const LookPlan& p) { return p.path.size() < 2 || (all_observed && !p.goal); };
  if (cfg_.look_fov_margin_deg > 0.0 && nothing_to_fly(found)) {
    const int cells = found.cells;
    found = search(0.0, &record->look_path);
    found.cells += cells;
    record->look_whole_fov = true;
  }
  return found;
}

void OnlinePlanning::otherClassLook(const Scenario& from_here, const planner::FeatureMap& map, const StopRule& rule,
                                    const LookMemory& memory, const LookConfig& look, LookPlan* found,
                                    Attempt* a) const {
  const planner::Plan& plan = a->run.plan;
  std::vector<std::size_t> order;
  for (std::size_t k = 0; k < plan.candidates.size(); ++k) {
    const planner::CandidatePath& c = plan.candidates[k];
    if (static_cast<int>(k) != plan.chosen && c.feasible && c.path.size() >= 2 && std::isfinite(c.cost)) {
      order.push_back(k);
    }
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t i, std::size_t j) { return plan.candidates[i].cost < plan.candidates[j].cost; });
  int cells = found->cells;
  for (const std::size_t k : order) {
    const std::vector<planner::Pose4>& path = plan.candidates[k].path;
    const std::size_t known = stopBeforeUnknown(path, map, visited_, rule).size();
    if (known >= path.size()) continue;  // observed all the way: no way on to look at
    std::vector<Eigen::Vector3d> route;
    std::vector<Eigen::Vector3d> way_on;
    for (std::size_t i = 0; i < path.size(); ++i) (i < known ? route : way_on).push_back(path[i].p_WB);
    OnlinePlan rated;  // its look_path and look_whole_fov
    LookPlan other = searchLook(*a->run.voxels, from_here.scene.start, route, way_on, false, memory, look,
                                cfg_.look_min_detections, &rated);
    cells += other.cells;
    if (!other.way && !other.advance) continue;
    *found = std::move(other);
    a->record.look_class = static_cast<int>(k);
    a->record.look_path = std::move(rated.look_path);
    a->record.look_whole_fov = rated.look_whole_fov;
    a->record.path.clear();
    a->record.path_unknown.clear();
    for (const planner::Pose4& p : path) {
      a->record.path.push_back(p.p_WB);
      a->record.path_unknown.push_back(!map.isKnown(p.p_WB));
    }
    break;
  }
  found->cells = cells;
}

void OnlinePlanning::noteLook(const Attempt& a) {
  if (!a.look) return;
  look_floor_ = a.record.look_floor;
  looked_.push_back(*a.look);
  if (cfg_.look_give_up > 0 && a.map) watch_.note(a.watched, a.map->resolution());
}

std::vector<Eigen::Vector2d> OnlinePlanning::givenUp() const { return watch_.givenUp(cfg_.look_give_up); }

}  // namespace tgnav::harness
