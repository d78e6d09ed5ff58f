#include "harness/run/trial_profile.h"

#include <algorithm>

namespace tgnav::harness {

double TrialProfile::criticalPathSeconds() const {
  double sequential = 0.0;
  for (const TickProfile& t : ticks) sequential += t.sim_busy_s + t.featuresBusy() + t.trackingBusy();
  if (!pipelined || ticks.empty()) return sequential;
  const std::size_t n = ticks.size();
  const std::size_t capacity = static_cast<std::size_t>(std::max(1, queue_capacity));
  std::vector<double> features_start(n, 0.0), tracking_start(n, 0.0), tracking_end(n, 0.0);
  double sim = 0.0;            // the simulation thread's clock
  double features_free = 0.0;  // when the features stage handed its previous frame on
  double tracking_free = 0.0;  // when the tracking stage finished its previous frame
  for (std::size_t k = 0; k < n; ++k) {
    const TickProfile& t = ticks[k];
    sim += t.sim_busy_s;
    if (t.rendered) {
      if (k >= capacity) sim = std::max(sim, features_start[k - capacity]);  // a full queue blocks the submit
      features_start[k] = std::max(sim, features_free);
      double handed_on = features_start[k] + t.featuresBusy();
      if (k >= capacity) handed_on = std::max(handed_on, tracking_start[k - capacity]);
      features_free = handed_on;
      tracking_start[k] = std::max(handed_on, tracking_free);
      tracking_end[k] = tracking_start[k] + t.trackingBusy();
      tracking_free = tracking_end[k];
    }
    if (waits_for_pose && k >= 1 && ticks[k - 1].rendered) sim = std::max(sim, tracking_end[k - 1]);
  }
  return std::max(sim, tracking_free);
}

namespace {

// Per-stage totals over the ticks that rendered a frame.
struct StageTotals {
  RgbdFrame::Timing frame;
  vo::FrameResult::Timing vo;
  void add(const RgbdFrame::Timing& f, const vo::FrameResult::Timing& v) {
    frame.render_s += f.render_s;
    frame.readback_s += f.readback_s;
    frame.convert_s += f.convert_s;
    frame.noise_s += f.noise_s;
    vo.features_s += v.features_s;
    vo.matching_s += v.matching_s;
    vo.pnp_s += v.pnp_s;
    vo.map_s += v.map_s;
    vo.ba_s += v.ba_s;
  }
  double rendering() const { return frame.render_s + frame.readback_s + frame.convert_s; }
  double features() const { return frame.noise_s + vo.features_s; }  // the features stage
  double tracking() const { return vo.total() - vo.features_s; }     // the tracking stage
  // Each stage's seconds times `scale`, under the names of metrics.json.
  nlohmann::ordered_json stages(double scale) const {
    return {{"render", frame.render_s * scale},
            {"readback", frame.readback_s * scale},
            {"convert", frame.convert_s * scale},
            {"noise", frame.noise_s * scale},
            {"vo_features", vo.features_s * scale},
            {"vo_matching", vo.matching_s * scale},
            {"vo_pnp", vo.pnp_s * scale},
            {"vo_map", vo.map_s * scale},
            {"vo_ba", vo.ba_s * scale},
            {"vo_total", vo.total() * scale}};
  }
};

// CPU seconds per simulated second: what a stage costs whatever else shares the cores (the
// figure that compares across machines). The simulation thread's physics, control, IMU,
// estimator and checks are one figure (timing each physics step's CPU would cost more than the
// step); llvmpipe draws on threads of its own; "other_threads" is the rest of the process
// (OpenCV's pool, the progress display).
nlohmann::ordered_json cpuPerSimSecond(const StageTotals& cpu, double sim_cpu_s, double process_cpu_s,
                                       double renderer_cpu_s, double per_sim_s) {
  nlohmann::ordered_json j = cpu.stages(per_sim_s);
  j["simulation_thread"] = sim_cpu_s * per_sim_s;
  j["physics_control_other"] = std::max(0.0, sim_cpu_s - cpu.rendering()) * per_sim_s;
  j["features_thread"] = cpu.features() * per_sim_s;
  j["tracking_thread"] = cpu.tracking() * per_sim_s;
  const double threads = sim_cpu_s + cpu.features() + cpu.tracking();
  if (renderer_cpu_s >= 0.0) {
    j["renderer_threads"] = renderer_cpu_s * per_sim_s;
    j["other_threads"] = std::max(0.0, process_cpu_s - threads - renderer_cpu_s) * per_sim_s;
  } else {
    j["renderer_threads"] = nullptr;
    j["other_threads"] = nullptr;
  }
  j["process"] = process_cpu_s * per_sim_s;
  return j;
}

}  // namespace

nlohmann::ordered_json TrialProfile::toJson() const {
  using nlohmann::ordered_json;
  StageTotals wall, cpu;
  double sim_busy = 0.0, sim_wait = 0.0, sim_cpu = 0.0;
  int rendered = 0;
  for (const TickProfile& t : ticks) {
    sim_busy += t.sim_busy_s;
    sim_wait += t.sim_wait_s;
    sim_cpu += t.sim_busy_cpu_s;
    if (!t.rendered) continue;
    ++rendered;
    wall.add(t.frame, t.vo);
    cpu.add(t.frame_cpu, t.vo_cpu);
  }
  const double per_frame = rendered > 0 ? 1e3 / rendered : 0.0;
  const double per_sim_s = sim_time_s > 0.0 ? 1.0 / sim_time_s : 0.0;
  const double critical = criticalPathSeconds();
  ordered_json j;
  j["pipelined"] = pipelined;
  j["queue_capacity"] = queue_capacity;
  j["waits_for_pose"] = waits_for_pose;
  j["gl_renderer"] = gl_renderer;
  j["llvmpipe_threads"] = llvmpipe_threads;
  j["opencv_threads"] = opencv_threads;
  j["camera_ticks"] = ticks.size();
  j["frames_processed"] = rendered;
  j["per_frame_ms"] = wall.stages(per_frame);
  j["per_sim_second_ms"] = {{"physics", physics_s * 1e3 * per_sim_s}, {"control", control_s * 1e3 * per_sim_s}};
  j["cpu_per_sim_second_s"] = cpuPerSimSecond(cpu, sim_cpu, process_cpu_s, renderer_cpu_s, per_sim_s);
  j["per_frame_cpu_ms"] = cpu.stages(per_frame);
  // The simulation thread's "other": IMU, estimator, contact checks, copying the state to render.
  // Sequential, the noise, the features and the tracking run on it too (listed as their own stages).
  ordered_json sim = {{"busy_s", sim_busy},
                      {"wait_vo_s", sim_wait},
                      {"cpu_s", sim_cpu},
                      {"physics_s", physics_s},
                      {"control_s", control_s},
                      {"render_s", wall.rendering()},
                      {"other_s", std::max(0.0, sim_busy - physics_s - control_s - wall.rendering())}};
  const double features = wall.features();
  const double tracking = wall.tracking();
  auto idle = [&](double busy) { return pipelined ? std::max(0.0, flight_wall_s - busy) : 0.0; };
  ordered_json features_stage = {{"busy_s", features},
                                 {"idle_s", idle(features)},
                                 {"cpu_s", cpu.features()},
                                 {"noise_s", wall.frame.noise_s},
                                 {"orb_s", wall.vo.features_s}};
  ordered_json tracking_stage = {{"busy_s", tracking},      {"idle_s", idle(tracking)},
                                 {"cpu_s", cpu.tracking()}, {"matching_s", wall.vo.matching_s},
                                 {"pnp_s", wall.vo.pnp_s},  {"map_s", wall.vo.map_s},
                                 {"ba_s", wall.vo.ba_s}};
  if (pipelined) {
    j["threads"] = {{"simulation", sim}, {"features", features_stage}, {"tracking", tracking_stage}};
  } else {
    j["threads"] = {{"simulation", sim},
                    {"features_on_simulation_thread", features_stage},
                    {"tracking_on_simulation_thread", tracking_stage}};
  }
  j["process_cpu_s"] = process_cpu_s;
  j["renderer_threads_cpu_s"] = renderer_cpu_s >= 0.0 ? ordered_json(renderer_cpu_s) : ordered_json(nullptr);
  // The stage the flight waits on: the one busy for the longest.
  const char* bottleneck = "simulation";
  if (features > sim_busy && features > tracking) bottleneck = "features";
  if (tracking > sim_busy && tracking >= features) bottleneck = "tracking";
  j["bottleneck"] = pipelined ? bottleneck : "sequential";
  j["critical_path"] = {{"ms_per_tick", ticks.empty() ? 0.0 : 1e3 * critical / static_cast<double>(ticks.size())},
                        {"total_s", critical},
                        {"flight_wall_s", flight_wall_s},
                        {"ratio_to_wall", flight_wall_s > 0.0 ? critical / flight_wall_s : 0.0}};
  return j;
}

}  // namespace tgnav::harness
