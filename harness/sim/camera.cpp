#include "harness/sim/camera.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <opencv2/core.hpp>
#include <stdexcept>

#include "harness/base/errors.h"
#include "vo/stage_clock.h"

namespace tgnav::harness {

Intrinsics intrinsicsFromFovy(double fovy_deg, int width_px, int height_px) {
  Intrinsics k;
  k.width_px = width_px;
  k.height_px = height_px;
  k.fy = 0.5 * height_px / std::tan(0.5 * fovy_deg * M_PI / 180.0);
  k.fx = k.fy;
  // OpenGL's image centre lies between pixels; OpenCV puts pixel centres on integers.
  k.cx = 0.5 * (width_px - 1);
  k.cy = 0.5 * (height_px - 1);
  return k;
}

Camera::Camera(mjModel* m, const EglContext& gl, const CameraConfig& config, std::uint64_t seed)
    : model_(m), gl_(gl), config_(config), noise_(config, seed) {
  if (config_.name == kVehicleCamera) {
    throw std::logic_error("Camera: the camera name 'vehicle' must be resolved (CameraConfig::on)");
  }
  cam_id_ = mj_name2id(m, mjOBJ_CAMERA, config_.name.c_str());
  if (cam_id_ < 0) throw InputError("camera '" + config_.name + "' is not in the model");

  m->vis.global.offwidth = std::max(m->vis.global.offwidth, config_.width_px);
  m->vis.global.offheight = std::max(m->vis.global.offheight, config_.height_px);
  m->vis.quality.offsamples = config_.offscreen_samples;
  m->vis.map.znear = static_cast<float>(config_.near_clip_m / m->stat.extent);
  m->vis.map.zfar = static_cast<float>(config_.far_clip_m / m->stat.extent);
  // What OpenGL will actually use (float precision of vis.map included).
  near_m_ = m->vis.map.znear * m->stat.extent;
  far_m_ = m->vis.map.zfar * m->stat.extent;
  intrinsics_ = intrinsicsFromFovy(m->cam_fovy[cam_id_], config_.width_px, config_.height_px);

  gl_.makeCurrent();
  mjv_defaultCamera(&view_);
  view_.type = mjCAMERA_FIXED;
  view_.fixedcamid = cam_id_;
  mjv_defaultOption(&option_);
  // The onboard camera must not see its own vehicle (arms, propellers): every geom and site of
  // the body tree it is mounted on is left out of the scene it draws (a camera of the world sees all).
  vehicle_root_ = m->cam_bodyid[cam_id_] == 0 ? -1 : m->body_rootid[m->cam_bodyid[cam_id_]];
  mjv_defaultScene(&scene_);
  mjv_makeScene(m, &scene_, 2000);
  scene_.flags[mjRND_SHADOW] = 0;
  scene_.flags[mjRND_REFLECTION] = 0;
  scene_.flags[mjRND_SKYBOX] = 0;
  mjr_defaultContext(&context_);
  mjr_makeContext(m, &context_, mjFONTSCALE_100);
  mjr_setBuffer(mjFB_OFFSCREEN, &context_);
  if (context_.currentBuffer != mjFB_OFFSCREEN) {
    throw std::runtime_error("MuJoCo: offscreen framebuffer unavailable in this GL context");
  }
  rgb_buffer_.resize(3 * static_cast<std::size_t>(config_.width_px) * config_.height_px);
  depth_buffer_.resize(static_cast<std::size_t>(config_.width_px) * config_.height_px);
}

Camera::~Camera() {
  // A destructor must not throw: where the context cannot be made current (it could when the
  // camera was made), its GL objects are left to the context's own destruction.
  if (gl_.tryMakeCurrent()) mjr_freeContext(&context_);
  mjv_freeScene(&scene_);
}

namespace {
// MuJoCo camera (x right, y up, z backward) -> vision camera (x right, y down, z forward).
Eigen::Matrix3d mujocoToVision() { return Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal(); }
}  // namespace

Eigen::Isometry3d cameraInBody(const mjModel* m, int cam_id) {
  const mjtNum* q = m->cam_quat + 4 * static_cast<std::ptrdiff_t>(cam_id);
  Eigen::Isometry3d X_BC = Eigen::Isometry3d::Identity();
  X_BC.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).toRotationMatrix() * mujocoToVision();
  X_BC.translation() = Eigen::Vector3d(m->cam_pos + 3 * static_cast<std::ptrdiff_t>(cam_id));
  return X_BC;
}

Eigen::Isometry3d Camera::pose(const mjData* d) const {
  Eigen::Isometry3d X_WC = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d R_W_mj;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R_W_mj(r, c) = d->cam_xmat[9 * cam_id_ + 3 * r + c];
  }
  X_WC.linear() = R_W_mj * mujocoToVision();
  const mjtNum* p = d->cam_xpos + 3 * static_cast<std::ptrdiff_t>(cam_id_);
  X_WC.translation() = Eigen::Vector3d(p[0], p[1], p[2]);
  return X_WC;
}

RgbdFrame Camera::render(mjData* d) {
  RgbdFrame frame = renderNoiseless(d);
  noise_.apply(&frame);
  return frame;
}

void Camera::hideVehicle() {
  if (vehicle_root_ < 0) return;
  int kept = 0;
  for (int i = 0; i < scene_.ngeom; ++i) {
    const mjvGeom& g = scene_.geoms[i];
    const int body = g.objtype == mjOBJ_GEOM   ? model_->geom_bodyid[g.objid]
                     : g.objtype == mjOBJ_SITE ? model_->site_bodyid[g.objid]
                                               : -1;
    const bool own = body >= 0 && model_->body_rootid[body] == vehicle_root_;
    if (!own) scene_.geoms[kept++] = g;
  }
  scene_.ngeom = kept;
}

RgbdFrame Camera::renderNoiseless(mjData* d) {
  vo::StageClock clock;
  gl_.makeCurrent();
  const int w = config_.width_px;
  const int h = config_.height_px;
  mjv_updateScene(model_, d, &option_, nullptr, &view_, mjCAT_ALL, &scene_);
  hideVehicle();
  // Several cameras may share one GL context: bind this camera's framebuffer every time.
  mjr_setBuffer(mjFB_OFFSCREEN, &context_);
  const mjrRect viewport = {0, 0, w, h};
  mjr_render(viewport, &scene_, &context_);
  const vo::StageClock::Lap render = clock.lap();
  mjr_readPixels(rgb_buffer_.data(), depth_buffer_.data(), viewport, &context_);
  const vo::StageClock::Lap readback = clock.lap();

  RgbdFrame frame;
  frame.t_s = d->time;
  frame.X_WC = pose(d);
  frame.bgr.create(h, w, CV_8UC3);
  frame.depth_m.create(h, w, CV_32FC1);
  const auto min_depth = static_cast<float>(config_.min_depth_m);
  const auto max_depth = static_cast<float>(config_.max_depth_m);
  // OpenGL rows run bottom-up; images run top-down.
  for (int row = 0; row < h; ++row) {
    const std::size_t src_row = static_cast<std::size_t>(h - 1 - row) * w;
    auto* bgr = frame.bgr.ptr<cv::Vec3b>(row);
    auto* depth = frame.depth_m.ptr<float>(row);
    for (int col = 0; col < w; ++col) {
      const unsigned char* rgb = &rgb_buffer_[3 * (src_row + col)];
      bgr[col] = cv::Vec3b(rgb[2], rgb[1], rgb[0]);
      const auto z = static_cast<float>(linearizeDepth(depth_buffer_[src_row + col], near_m_, far_m_));
      depth[col] = (z >= min_depth && z <= max_depth) ? z : 0.0f;
    }
  }
  const vo::StageClock::Lap convert = clock.lap();
  frame.timing = {render.wall_s, readback.wall_s, convert.wall_s, 0.0};
  frame.cpu = {render.cpu_s, readback.cpu_s, convert.cpu_s, 0.0};
  return frame;
}

namespace {

// The standard normal quantile function: Acklam's rational approximation (relative error below
// 1.2e-9), refined by one step of Halley's method on erfc to double precision.
double normalQuantile(double p) {
  static constexpr double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                                 1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static constexpr double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                                 6.680131188771972e+01, -1.328068155288572e+01};
  static constexpr double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                                 -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static constexpr double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                                 3.754408661907416e+00};
  constexpr double kLow = 0.02425;
  double x = 0.0;
  if (p < kLow || p > 1.0 - kLow) {
    const double q = std::sqrt(-2.0 * std::log(p < kLow ? p : 1.0 - p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
    if (p > 1.0 - kLow) x = -x;
  } else {
    const double q = p - 0.5;
    const double r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
  }
  const double e = 0.5 * std::erfc(-x / std::sqrt(2.0)) - p;
  const double u = e * std::sqrt(2.0 * M_PI) * std::exp(0.5 * x * x);
  return x - u / (1.0 + 0.5 * x * u);
}

constexpr int kQuantileBits = 16;

}  // namespace

const std::vector<float>& normalQuantiles() {
  static const std::vector<float> table = [] {
    constexpr std::size_t n = std::size_t{1} << kQuantileBits;
    std::vector<float> t(n);
    for (std::size_t i = 0; i < n / 2; ++i) {  // symmetric: the upper half mirrors the lower
      const auto z = static_cast<float>(normalQuantile((static_cast<double>(i) + 0.5) / static_cast<double>(n)));
      t[i] = z;
      t[n - 1 - i] = -z;
    }
    return t;
  }();
  return table;
}

CameraNoise::CameraNoise(const CameraConfig& config, std::uint64_t seed)
    : depth_k_(config.depth_noise_sigma_per_m2),
      min_depth_m_(config.min_depth_m),
      max_depth_m_(config.max_depth_m),
      state_(seed) {
  config.validate();
  if (config.rgb_noise_sigma > 0.0) {
    const std::vector<float>& z = normalQuantiles();
    rgb_levels_.resize(z.size());
    for (std::size_t i = 0; i < z.size(); ++i) {
      rgb_levels_[i] = static_cast<std::int16_t>(std::lround(config.rgb_noise_sigma * z[i]));
    }
  }
}

std::uint64_t CameraNoise::next() {
  std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

void CameraNoise::apply(RgbdFrame* frame) {
  vo::StageClock clock;
  constexpr std::uint64_t kMask = (std::uint64_t{1} << kQuantileBits) - 1;
  // The 8-bit value plus a rounded normal sample equals the rounded sum: the value is an integer.
  if (!rgb_levels_.empty()) {
    CV_Assert(frame->bgr.type() == CV_8UC3);
    const std::int16_t* levels = rgb_levels_.data();
    auto add = [&](std::uint8_t* p, std::uint64_t bits) {
      *p = static_cast<std::uint8_t>(std::clamp(*p + levels[bits & kMask], 0, 255));
    };
    for (int row = 0; row < frame->bgr.rows; ++row) {
      std::uint8_t* p = frame->bgr.ptr<std::uint8_t>(row);
      const int n = 3 * frame->bgr.cols;
      int i = 0;
      for (; i + 4 <= n; i += 4) {  // four samples per draw
        const std::uint64_t bits = next();
        add(p + i, bits);
        add(p + i + 1, bits >> 16);
        add(p + i + 2, bits >> 32);
        add(p + i + 3, bits >> 48);
      }
      if (i < n) {
        for (std::uint64_t bits = next(); i < n; ++i, bits >>= kQuantileBits) add(p + i, bits);
      }
    }
  }
  if (depth_k_ > 0.0) {
    const float* z_table = normalQuantiles().data();
    const auto k = static_cast<float>(depth_k_);
    const auto lo = static_cast<float>(min_depth_m_);
    const auto hi = static_cast<float>(max_depth_m_);
    for (int row = 0; row < frame->depth_m.rows; ++row) {
      auto* z = frame->depth_m.ptr<float>(row);
      std::uint64_t bits = 0;
      for (int col = 0; col < frame->depth_m.cols; ++col, bits >>= kQuantileBits) {
        if (col % 4 == 0) bits = next();  // a sample per pixel, used or not: the stream stays aligned
        if (z[col] <= 0.0f) continue;     // invalid stays invalid
        const float noisy = z[col] + k * z[col] * z[col] * z_table[bits & kMask];
        z[col] = (noisy >= lo && noisy <= hi) ? noisy : 0.0f;
      }
    }
  }
  const vo::StageClock::Lap noise = clock.lap();
  frame->timing.noise_s = noise.wall_s;
  frame->cpu.noise_s = noise.cpu_s;
}

}  // namespace tgnav::harness
