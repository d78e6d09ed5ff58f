#pragma once
// Forward RGB-D camera rendered offscreen by MuJoCo through an EGL context.
//
// Camera frame C follows the computer-vision convention (x right, y down, z forward along the
// optical axis); MuJoCo's own camera frame (x right, y up, looking along -z) is converted here
// and nowhere else. Pixel (u, v) = (column, row) with the origin at the centre of the top-left
// pixel, as in OpenCV.
#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "harness/config/camera_config.h"
#include "harness/sim/egl_context.h"
#include "vo/camera_intrinsics.h"

namespace tgnav::harness {

// The camera's intrinsics, in the form the VO takes them.
using Intrinsics = vo::CameraIntrinsics;

struct RgbdFrame {
  double t_s = 0.0;
  cv::Mat bgr;      // CV_8UC3, OpenCV channel order
  cv::Mat depth_m;  // CV_32FC1, z along the optical axis in metres; 0 = invalid
  Eigen::Isometry3d X_WC = Eigen::Isometry3d::Identity();
  // Seconds of making it (not deterministic): the scene update and the draw call, the
  // framebuffer readback (RGB and depth in one call), the flip to top-down rows with depth
  // linearisation; and the noise, added by whoever applies it. On the wall clock (`timing`) and
  // on the CPU clock of the thread that did each (`cpu`; llvmpipe rasterises on threads of its
  // own, which the readback waits for: their CPU is not in it).
  struct Timing {
    double render_s = 0.0;
    double readback_s = 0.0;
    double convert_s = 0.0;
    double noise_s = 0.0;
  };
  Timing timing;
  Timing cpu;
};

// The sensor noise of CameraConfig, seeded: Gaussian noise on every colour channel (rounded to
// the nearest 8-bit level, saturated) and depth noise of sigma k z^2 on valid depths (a noisy
// depth outside [min, max] becomes invalid). Frames must be noised in order for a seed to give
// the same noise.
//
// The samples are drawn by inversion: 16 random bits pick one of the 65536 equiprobable
// quantiles of N(0, 1) (normalQuantiles()), four samples per 64-bit draw of splitmix64. That is a
// Gaussian to within 1/65536 in probability, its tails cut at 4.32 sigma, at a fraction of the
// cost of drawing each sample (about 1.2 M samples per 640x480 frame).
class CameraNoise {
 public:
  CameraNoise(const CameraConfig& config, std::uint64_t seed);
  void apply(RgbdFrame* frame);

 private:
  std::uint64_t next();  // splitmix64

  double depth_k_;
  double min_depth_m_;
  double max_depth_m_;
  std::uint64_t state_;
  std::vector<std::int16_t> rgb_levels_;  // per quantile: sigma z rounded to 8-bit levels; empty: no noise
};

// The 65536 quantiles of the standard normal distribution at probabilities (i + 0.5) / 65536,
// in increasing order.
const std::vector<float>& normalQuantiles();

class Camera {
 public:
  // Makes `gl` current and allocates MuJoCo's render context. Writes the offscreen buffer
  // size and clipping planes this camera needs into m->vis (MuJoCo reads them from there).
  Camera(mjModel* m, const EglContext& gl, const CameraConfig& config, std::uint64_t seed);
  ~Camera();
  Camera(const Camera&) = delete;
  Camera& operator=(const Camera&) = delete;
  Camera(Camera&&) = delete;
  Camera& operator=(Camera&&) = delete;

  // Renders the current state of `d` (kinematics must be up to date, e.g. after mj_step), with
  // the configured noise.
  RgbdFrame render(mjData* d);
  // The same without noise: what a pipeline renders on one thread and noises on another.
  RgbdFrame renderNoiseless(mjData* d);
  // Pose of C in W for the current state of `d`.
  Eigen::Isometry3d pose(const mjData* d) const;
  const Intrinsics& intrinsics() const { return intrinsics_; }
  int id() const { return cam_id_; }  // the MJCF camera's id

 private:
  void hideVehicle();

  const mjModel* model_;
  const EglContext& gl_;
  CameraConfig config_;
  int vehicle_root_ = -1;  // root body of the vehicle the camera is mounted on; -1: none
  Intrinsics intrinsics_;
  int cam_id_ = -1;
  double near_m_ = 0.0;
  double far_m_ = 0.0;
  mjvScene scene_{};
  mjvCamera view_{};
  mjvOption option_{};
  mjrContext context_{};
  std::vector<unsigned char> rgb_buffer_;
  std::vector<float> depth_buffer_;
  CameraNoise noise_;
};

// Pose of camera `cam_id` in its parent body's frame (vision convention), fixed by the model.
Eigen::Isometry3d cameraInBody(const mjModel* m, int cam_id);

// Intrinsics of a pinhole camera with vertical field of view `fovy_deg` and square pixels,
// which is what MuJoCo renders.
Intrinsics intrinsicsFromFovy(double fovy_deg, int width_px, int height_px);

// Converts an OpenGL depth-buffer value in [0, 1] to metric z for the given clip planes.
inline double linearizeDepth(double buffer, double near_m, double far_m) {
  return near_m / (1.0 - buffer * (1.0 - near_m / far_m));
}

}  // namespace tgnav::harness
