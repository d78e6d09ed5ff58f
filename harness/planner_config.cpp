#include "harness/planner_config.h"

#include <stdexcept>

#include "harness/errors.h"

namespace tgnav::harness {

void PlannerSettings::validate() const {
  perception.validate();
  rrt_star.validate();
  trajectory.validate();
}

void readPlannerSettings(FieldReader r, PlannerSettings* s) {
  planner::PerceptionPlannerConfig& p = s->perception;
  r.read("robot_radius_m", p.robot_radius_m)
      .read("slice_half_height_m", p.slice_half_height_m)
      .read("keep_start_yaw", p.keep_start_yaw)
      .read("threads", p.threads)
      .section("topology",
               [&](FieldReader t) {
                 t.read("max_classes", p.topo.max_classes)
                     .read("max_expansions", p.topo.max_expansions)
                     .read("max_length_ratio", p.topo.max_length_ratio)
                     .read("min_spur_length_m", p.topo.min_spur_length_m)
                     .finish();
               })
      .section("visibility",
               [&](FieldReader v) {
                 v.read("hfov_rad", p.visibility.hfov_rad)
                     .read("vfov_rad", p.visibility.vfov_rad)
                     .read("min_range_m", p.visibility.min_range_m)
                     .read("max_range_m", p.visibility.max_range_m)
                     .finish();
               })
      .section("information",
               [&](FieldReader i) {
                 i.read("bearing_noise_rad", p.information.bearing_noise_rad)
                     .read("epsilon", p.information.epsilon)
                     .finish();
               })
      .section("segments",
               [&](FieldReader g) {
                 g.read("min_length_m", p.segments.min_length_m)
                     .read("covisibility_ratio", p.segments.covisibility_ratio)
                     .finish();
               })
      .section("pose_graph",
               [&](FieldReader g) {
                 g.read("nominal_speed_mps", p.graph.nominal_speed_mps)
                     .read("time_step_s", p.graph.time_step_s)
                     .read("position_samples", p.graph.position_samples)
                     .read("sample_radius_m", p.graph.sample_radius_m)
                     .read("yaw_samples", p.graph.yaw_samples)
                     .read("yaw_rate_limit_rad_s", p.graph.yaw_rate_limit_rad_s)
                     .read("distance_weight", p.graph.distance_weight)
                     .read("perception_weight", p.graph.perception_weight)
                     .finish();
               })
      .section("selection",
               [&](FieldReader g) {
                 g.read("c_p_threshold", p.selection.c_p_threshold)
                     .read("distance_weight", p.selection.distance_weight)
                     .read("perception_weight", p.selection.perception_weight)
                     .finish();
               })
      .section("rrt_star",
               [&](FieldReader g) {
                 planner::RrtStarConfig& q = s->rrt_star;
                 g.read("samples", q.samples)
                     .read("range_m", q.range_m)
                     .read("goal_bias", q.goal_bias)
                     .read("goal_tolerance_m", q.goal_tolerance_m)
                     .read("distance_weight", q.distance_weight)
                     .read("perception_weight", q.perception_weight)
                     .read("c_p_threshold", q.c_p_threshold)
                     .finish();
               })
      .section("trajectory",
               [&](FieldReader g) {
                 planner::TrajectoryConfig& t = s->trajectory;
                 g.read("nominal_speed_mps", t.nominal_speed_mps)
                     .read("nominal_accel_mps2", t.nominal_accel_mps2)
                     .read("nominal_yaw_rate_rad_s", t.nominal_yaw_rate_rad_s)
                     .read("max_speed_mps", t.max_speed_mps)
                     .read("max_accel_mps2", t.max_accel_mps2)
                     .read("max_yaw_rate_rad_s", t.max_yaw_rate_rad_s)
                     .read("safety_margin_m", t.safety_margin_m)
                     .read("knot_spacing_m", t.knot_spacing_m)
                     .read("smoothing_length_m", t.smoothing_length_m)
                     .read("clearance_weight", t.clearance_weight)
                     .read("feasibility_weight", t.feasibility_weight)
                     .read("max_iterations", t.max_iterations)
                     .read("sample_rate_hz", t.sample_rate_hz)
                     .finish();
               })
      .finish();
  s->rrt_star.robot_radius_m = p.robot_radius_m;
  s->rrt_star.visibility = p.visibility;
  s->rrt_star.information = p.information;
  s->trajectory.robot_radius_m = p.robot_radius_m;
}

YAML::Node toYaml(const PlannerSettings& s) {
  PlannerSettings copy = s;
  YAML::Node out(YAML::NodeType::Map);
  readPlannerSettings(FieldReader::writer(out), &copy);
  return out;
}

void validatePlannerSettings(const PlannerSettings& s, const std::string& source) {
  try {
    s.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(source + ": " + e.what());
  }
}

PlannerSettings loadPlannerSettings(const std::filesystem::path& yaml, PlannerSettings base) {
  const YamlDoc doc = YamlDoc::load(yaml);
  readPlannerSettings(FieldReader(doc, doc.root(), ""), &base);
  validatePlannerSettings(base, yaml.string());
  return base;
}

}  // namespace tgnav::harness
