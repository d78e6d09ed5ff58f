#include "harness/config_io.h"

namespace tgnav::harness {

void readCameraConfig(FieldReader r, CameraConfig* c) {
  r.read("name", c->name)
      .read("width_px", c->width_px)
      .read("height_px", c->height_px)
      .read("near_clip_m", c->near_clip_m)
      .read("far_clip_m", c->far_clip_m)
      .read("min_depth_m", c->min_depth_m)
      .read("max_depth_m", c->max_depth_m)
      .read("rgb_noise_sigma", c->rgb_noise_sigma)
      .read("depth_noise_sigma_per_m2", c->depth_noise_sigma_per_m2)
      .finish();
}

void readCascadeConfig(FieldReader r, control::CascadeConfig* c) {
  r.section("rates_hz",
            [&](FieldReader s) {
              s.read("position", c->position_rate_hz)
                  .read("attitude", c->attitude_rate_hz)
                  .read("rate", c->rate_rate_hz)
                  .finish();
            })
      .section("position",
               [&](FieldReader s) {
                 control::PositionControlConfig& p = c->position;
                 s.read("pos_p_xy", p.pos_p_xy)
                     .read("pos_p_z", p.pos_p_z)
                     .read("vel_p_xy", p.vel_p_xy)
                     .read("vel_i_xy", p.vel_i_xy)
                     .read("vel_d_xy", p.vel_d_xy)
                     .read("vel_p_z", p.vel_p_z)
                     .read("vel_i_z", p.vel_i_z)
                     .read("vel_d_z", p.vel_d_z)
                     .read("max_vel_xy_m_s", p.max_vel_xy_m_s)
                     .read("max_vel_up_m_s", p.max_vel_up_m_s)
                     .read("max_vel_down_m_s", p.max_vel_down_m_s)
                     .read("tilt_max_rad", p.tilt_max_rad)
                     .read("thrust_min", p.thrust_min)
                     .read("thrust_max", p.thrust_max)
                     .read("thrust_xy_margin", p.thrust_xy_margin)
                     .read("vel_deriv_cutoff_hz", p.vel_deriv_cutoff_hz)
                     .finish();
               })
      .section("attitude",
               [&](FieldReader s) {
                 control::AttitudeControlConfig& a = c->attitude;
                 s.read("roll_p", a.roll_p)
                     .read("pitch_p", a.pitch_p)
                     .read("yaw_p", a.yaw_p)
                     .read("yaw_weight", a.yaw_weight)
                     .read("max_roll_rate_rad_s", a.max_roll_rate_rad_s)
                     .read("max_pitch_rate_rad_s", a.max_pitch_rate_rad_s)
                     .read("max_yaw_rate_rad_s", a.max_yaw_rate_rad_s)
                     .finish();
               })
      .section("rate",
               [&](FieldReader s) {
                 control::RateControlConfig& g = c->rate;
                 s.read("p", g.p)
                     .read("i", g.i)
                     .read("d", g.d)
                     .read("ff", g.ff)
                     .read("integrator_limit", g.integrator_limit)
                     .read("dterm_cutoff_hz", g.dterm_cutoff_hz)
                     .finish();
               })
      .finish();
}

void readOdometryConfig(FieldReader r, vo::OdometryConfig* c) {
  r.section("features",
            [&](FieldReader s) {
              vo::FeatureConfig& f = c->features;
              s.read("max_features", f.max_features)
                  .read("grid_cols", f.grid_cols)
                  .read("grid_rows", f.grid_rows)
                  .read("fast_threshold", f.fast_threshold)
                  .read("scale_factor", f.scale_factor)
                  .read("pyramid_levels", f.pyramid_levels)
                  .read("edge_threshold_px", f.edge_threshold_px)
                  .finish();
            })
      .read("min_depth_m", c->min_depth_m)
      .read("max_depth_m", c->max_depth_m)
      .read("depth_edge_m", c->depth_edge_m)
      .read("init_min_features", c->init_min_features)
      .read("min_inliers", c->min_inliers)
      .read("weak_inliers", c->weak_inliers)
      .read("search_radius_px", c->search_radius_px)
      .read("max_descriptor_distance", c->max_descriptor_distance)
      .read("ratio_test", c->ratio_test)
      .read("ransac_reprojection_px", c->ransac_reprojection_px)
      .read("ransac_iterations", c->ransac_iterations)
      .read("ransac_confidence", c->ransac_confidence)
      .read("local_map_keyframes", c->local_map_keyframes)
      .read("keyframe_inlier_ratio", c->keyframe_inlier_ratio)
      .read("keyframe_translation_m", c->keyframe_translation_m)
      .read("keyframe_rotation_rad", c->keyframe_rotation_rad)
      .read("landmark_max_misses", c->landmark_max_misses)
      .read("reinitialise_after_lost", c->reinitialise_after_lost)
      .finish();
}

void readTrialConfig(FieldReader r, TrialConfig* c) {
  std::string source = toString(c->state_source);
  r.read("state_source", source, {toString(StateSource::kGroundTruth), toString(StateSource::kVo)})
      .read("camera_rate_hz", c->camera_rate_hz)
      .read("goal_radius_m", c->goal_radius_m)
      .read("pipeline", c->pipeline)
      .section("flight",
               [&](FieldReader s) {
                 FlightConfig& f = c->flight;
                 s.read("takeoff_speed_m_s", f.takeoff_speed_m_s)
                     .read("settle_s", f.settle_s)
                     .read("hold_s", f.hold_s)
                     .read("max_start_offset_m", f.max_start_offset_m)
                     .read("diverged_tilt_rad", f.diverged_tilt_rad)
                     .read("diverged_speed_m_s", f.diverged_speed_m_s)
                     .finish();
               })
      .section("imu",
               [&](FieldReader s) {
                 ImuConfig& i = c->imu;
                 s.read("accel_noise_m_s2", i.accel_noise_m_s2)
                     .read("accel_bias_m_s2", i.accel_bias_m_s2)
                     .read("gyro_noise_rad_s", i.gyro_noise_rad_s)
                     .read("gyro_bias_rad_s", i.gyro_bias_rad_s)
                     .finish();
               })
      .section("estimator",
               [&](FieldReader s) {
                 control::EstimatorConfig& e = c->estimator;
                 s.read("accel_noise_m_s2", e.accel_noise_m_s2)
                     .read("position_sigma_m", e.position_sigma_m)
                     .read("attitude_gain", e.attitude_gain)
                     .read("gyro_bias_gain", e.gyro_bias_gain)
                     .read("max_position_innovation_m", e.max_position_innovation_m)
                     .read("history_s", e.history_s)
                     .finish();
               })
      .finish();
  // The reader checked the text against the names.
  parseStateSource(source, &c->state_source);
}

namespace {
template <typename Config, typename Read>
Config loadFile(const std::filesystem::path& yaml, Config c, Read read) {
  const YamlDoc doc = YamlDoc::load(yaml);
  read(FieldReader(doc, doc.root(), ""), &c);
  validateConfig(c, yaml.string());
  return c;
}

template <typename Config, typename Read>
YAML::Node writeYaml(Config c, Read read) {
  YAML::Node out(YAML::NodeType::Map);
  read(FieldReader::writer(out), &c);
  return out;
}
}  // namespace

CameraConfig loadCameraConfig(const std::filesystem::path& yaml, CameraConfig base) {
  return loadFile(yaml, std::move(base), readCameraConfig);
}

control::CascadeConfig loadCascadeConfig(const std::filesystem::path& yaml, control::CascadeConfig base) {
  return loadFile(yaml, base, readCascadeConfig);
}

vo::OdometryConfig loadOdometryConfig(const std::filesystem::path& yaml, vo::OdometryConfig base) {
  return loadFile(yaml, base, readOdometryConfig);
}

TrialConfig loadTrialConfig(const std::filesystem::path& yaml, TrialConfig base) {
  return loadFile(yaml, base, readTrialConfig);
}

YAML::Node toYaml(const CameraConfig& c) { return writeYaml(c, readCameraConfig); }
YAML::Node toYaml(const control::CascadeConfig& c) { return writeYaml(c, readCascadeConfig); }
YAML::Node toYaml(const vo::OdometryConfig& c) { return writeYaml(c, readOdometryConfig); }
YAML::Node toYaml(const TrialConfig& c) { return writeYaml(c, readTrialConfig); }

}  // namespace tgnav::harness
