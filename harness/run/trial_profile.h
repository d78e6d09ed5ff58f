#pragma once
// Where a trial's flight spends its time: per camera tick, what the simulation thread did
// (physics, control, rendering) and waited for, and what the VO's two stages did with the frame
// (features: noise, ORB and back-projection; tracking: matching, PnP, local map, BA); summed per
// stage and per thread, with the critical path. Wall-clock seconds, and CPU seconds of the thread
// that ran each stage, with the process's and llvmpipe's rasteriser threads' CPU over the flight.
// None of it is deterministic, and none of it feeds a result that must repeat (metrics.json
// `timing.profile`).
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/sim/camera.h"
#include "vo/odometry.h"

namespace tgnav::harness {

// One camera tick. Frame 0 is rendered before the flight's clock starts; tick k >= 1 covers the
// simulation thread from the end of tick k-1 to the end of tick k.
struct TickProfile {
  double sim_busy_s = 0.0;      // the simulation thread working (physics, control, IMU, checks, render)
  double sim_wait_s = 0.0;      // ... blocked on the VO stage (full queue, or the pose it flies on)
  double sim_busy_cpu_s = 0.0;  // the simulation thread's CPU seconds in the tick
  bool rendered = false;        // a frame was rendered and tracked at this tick
  RgbdFrame::Timing frame;      // render, readback, convert (simulation thread), noise (features stage)
  vo::FrameResult::Timing vo;
  RgbdFrame::Timing frame_cpu;  // the same in CPU seconds
  vo::FrameResult::Timing vo_cpu;
  double featuresBusy() const { return frame.noise_s + vo.features_s; }  // the features stage
  double trackingBusy() const { return vo.total() - vo.features_s; }     // the tracking stage
};

struct TrialProfile {
  bool pipelined = false;        // features and tracking on threads of their own (trial.pipeline)
  int queue_capacity = 0;        // frames each stage may queue for the next (pipelined)
  bool waits_for_pose = false;   // the controller flies on the VO: tick k waits for frame k-1's pose
  std::string gl_renderer;       // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)" (the machine's renderer)
  int llvmpipe_threads = 0;      // LP_NUM_THREADS as the renderer saw it (0: unset, llvmpipe's default)
  int opencv_threads = 0;        // cv::getNumThreads()
  double flight_wall_s = 0.0;    // the flight's wall time, which the ticks add up to
  double sim_time_s = 0.0;       // simulated seconds flown
  double physics_s = 0.0;        // mj_step
  double control_s = 0.0;        // the cascade's stages
  double process_cpu_s = 0.0;    // CPU seconds of the whole process over the flight
  double renderer_cpu_s = -1.0;  // ... of llvmpipe's rasteriser threads (negative: unknown)
  std::vector<TickProfile> ticks;

  // The critical path through the ticks: the flight's wall time as the measured work of each
  // tick and stage implies it. Sequential, the sum of all stages. Pipelined, a replay of the
  // pipeline: each stage takes the frames in order, a frame leaves a stage once the next
  // stage's queue has room (the frame `capacity` places ahead has started there), and flying on
  // the VO, tick k also waits for frame k-1's pose.
  double criticalPathSeconds() const;
  nlohmann::ordered_json toJson() const;
};

}  // namespace tgnav::harness
