#include "harness/config_io.h"

#include <stdexcept>

#include "harness/errors.h"
#include "harness/yaml_util.h"

namespace tgnav::harness {

namespace {
template <typename Config>
void validateFrom(const YamlDoc& doc, const Config& config) {
  try {
    config.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(doc.file().string() + ": " + e.what());
  }
}
}  // namespace

CameraConfig loadCameraConfig(const std::filesystem::path& yaml, CameraConfig c) {
  const YamlDoc doc = YamlDoc::load(yaml);
  FieldReader(doc, doc.root(), "")
      .read("name", c.name)
      .read("width_px", c.width_px)
      .read("height_px", c.height_px)
      .read("near_clip_m", c.near_clip_m)
      .read("far_clip_m", c.far_clip_m)
      .read("min_depth_m", c.min_depth_m)
      .read("max_depth_m", c.max_depth_m)
      .read("rgb_noise_sigma", c.rgb_noise_sigma)
      .read("depth_noise_sigma_per_m2", c.depth_noise_sigma_per_m2)
      .finish();
  validateFrom(doc, c);
  return c;
}

control::CascadeConfig loadCascadeConfig(const std::filesystem::path& yaml, control::CascadeConfig c) {
  const YamlDoc doc = YamlDoc::load(yaml);
  FieldReader(doc, doc.root(), "")
      .section("rates_hz",
               [&](FieldReader r) {
                 r.read("position", c.position_rate_hz)
                     .read("attitude", c.attitude_rate_hz)
                     .read("rate", c.rate_rate_hz)
                     .finish();
               })
      .section("position",
               [&](FieldReader r) {
                 auto& p = c.position;
                 r.read("pos_p_xy", p.pos_p_xy)
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
               [&](FieldReader r) {
                 auto& a = c.attitude;
                 r.read("roll_p", a.roll_p)
                     .read("pitch_p", a.pitch_p)
                     .read("yaw_p", a.yaw_p)
                     .read("yaw_weight", a.yaw_weight)
                     .read("max_roll_rate_rad_s", a.max_roll_rate_rad_s)
                     .read("max_pitch_rate_rad_s", a.max_pitch_rate_rad_s)
                     .read("max_yaw_rate_rad_s", a.max_yaw_rate_rad_s)
                     .finish();
               })
      .section("rate",
               [&](FieldReader r) {
                 auto& g = c.rate;
                 r.read("p", g.p)
                     .read("i", g.i)
                     .read("d", g.d)
                     .read("ff", g.ff)
                     .read("integrator_limit", g.integrator_limit)
                     .read("dterm_cutoff_hz", g.dterm_cutoff_hz)
                     .finish();
               })
      .finish();
  validateFrom(doc, c);
  return c;
}

vo::OdometryConfig loadOdometryConfig(const std::filesystem::path& yaml, vo::OdometryConfig c) {
  const YamlDoc doc = YamlDoc::load(yaml);
  FieldReader(doc, doc.root(), "")
      .section("features",
               [&](FieldReader r) {
                 vo::FeatureConfig& f = c.features;
                 r.read("max_features", f.max_features)
                     .read("grid_cols", f.grid_cols)
                     .read("grid_rows", f.grid_rows)
                     .read("fast_threshold", f.fast_threshold)
                     .read("scale_factor", f.scale_factor)
                     .read("pyramid_levels", f.pyramid_levels)
                     .read("edge_threshold_px", f.edge_threshold_px)
                     .finish();
               })
      .read("min_depth_m", c.min_depth_m)
      .read("max_depth_m", c.max_depth_m)
      .read("depth_edge_m", c.depth_edge_m)
      .read("init_min_features", c.init_min_features)
      .read("min_inliers", c.min_inliers)
      .read("weak_inliers", c.weak_inliers)
      .read("search_radius_px", c.search_radius_px)
      .read("max_descriptor_distance", c.max_descriptor_distance)
      .read("ratio_test", c.ratio_test)
      .read("ransac_reprojection_px", c.ransac_reprojection_px)
      .read("ransac_iterations", c.ransac_iterations)
      .read("ransac_confidence", c.ransac_confidence)
      .read("local_map_keyframes", c.local_map_keyframes)
      .read("keyframe_inlier_ratio", c.keyframe_inlier_ratio)
      .read("keyframe_translation_m", c.keyframe_translation_m)
      .read("keyframe_rotation_rad", c.keyframe_rotation_rad)
      .read("landmark_max_misses", c.landmark_max_misses)
      .read("reinitialise_after_lost", c.reinitialise_after_lost)
      .finish();
  validateFrom(doc, c);
  return c;
}

}  // namespace tgnav::harness
