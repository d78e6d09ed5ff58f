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

nlohmann::ordered_json TrialProfile::toJson() const {
  using nlohmann::ordered_json;
  RgbdFrame::Timing frame;
  vo::FrameResult::Timing vo;
  double sim_busy = 0.0, sim_wait = 0.0;
  int rendered = 0;
  for (const TickProfile& t : ticks) {
    sim_busy += t.sim_busy_s;
    sim_wait += t.sim_wait_s;
    if (!t.rendered) continue;
    ++rendered;
    frame.render_s += t.frame.render_s;
    frame.readback_s += t.frame.readback_s;
    frame.convert_s += t.frame.convert_s;
    frame.noise_s += t.frame.noise_s;
    vo.features_s += t.vo.features_s;
    vo.matching_s += t.vo.matching_s;
    vo.pnp_s += t.vo.pnp_s;
    vo.map_s += t.vo.map_s;
    vo.ba_s += t.vo.ba_s;
  }
  const double vo_busy = vo.total();
  const double per_frame = rendered > 0 ? 1e3 / rendered : 0.0;
  const double per_sim_s = sim_time_s > 0.0 ? 1e3 / sim_time_s : 0.0;
  const double rendering = frame.render_s + frame.readback_s + frame.convert_s;
  const double camera = rendering + frame.noise_s;
  const double critical = criticalPathSeconds();
  ordered_json j;
  j["pipelined"] = pipelined;
  j["queue_capacity"] = queue_capacity;
  j["waits_for_pose"] = waits_for_pose;
  j["llvmpipe_threads"] = llvmpipe_threads;
  j["opencv_threads"] = opencv_threads;
  j["camera_ticks"] = ticks.size();
  j["frames_processed"] = rendered;
  j["per_frame_ms"] = {{"render", frame.render_s * per_frame},
                       {"readback", frame.readback_s * per_frame},
                       {"convert", frame.convert_s * per_frame},
                       {"noise", frame.noise_s * per_frame},
                       {"vo_features", vo.features_s * per_frame},
                       {"vo_matching", vo.matching_s * per_frame},
                       {"vo_pnp", vo.pnp_s * per_frame},
                       {"vo_map", vo.map_s * per_frame},
                       {"vo_ba", vo.ba_s * per_frame},
                       {"vo_total", vo_busy * per_frame}};
  j["per_sim_second_ms"] = {{"physics", physics_s * per_sim_s}, {"control", control_s * per_sim_s}};
  // The simulation thread's "other": IMU, estimator, contact checks, copying the state to render.
  // Sequential, the features and the tracking run on it too (listed as their own stages).
  ordered_json sim = {{"busy_s", sim_busy},
                      {"wait_vo_s", sim_wait},
                      {"physics_s", physics_s},
                      {"control_s", control_s},
                      {"render_s", rendering},
                      {"noise_s", frame.noise_s},
                      {"other_s", std::max(0.0, sim_busy - physics_s - control_s - camera)}};
  const double tracking = vo_busy - vo.features_s;
  auto idle = [&](double busy) { return pipelined ? std::max(0.0, flight_wall_s - busy) : 0.0; };
  ordered_json features_stage = {{"busy_s", vo.features_s}, {"idle_s", idle(vo.features_s)}};
  ordered_json tracking_stage = {{"busy_s", tracking}, {"idle_s", idle(tracking)}, {"matching_s", vo.matching_s},
                                 {"pnp_s", vo.pnp_s},  {"map_s", vo.map_s},        {"ba_s", vo.ba_s}};
  if (pipelined) {
    j["threads"] = {{"simulation", sim}, {"features", features_stage}, {"tracking", tracking_stage}};
  } else {
    j["threads"] = {{"simulation", sim},
                    {"features_on_simulation_thread", features_stage},
                    {"tracking_on_simulation_thread", tracking_stage}};
  }
  // The stage the flight waits on: the one busy for the longest.
  const char* bottleneck = "simulation";
  if (vo.features_s > sim_busy && vo.features_s > tracking) bottleneck = "features";
  if (tracking > sim_busy && tracking >= vo.features_s) bottleneck = "tracking";
  j["bottleneck"] = pipelined ? bottleneck : "sequential";
  j["critical_path"] = {{"ms_per_tick", ticks.empty() ? 0.0 : 1e3 * critical / static_cast<double>(ticks.size())},
                        {"total_s", critical},
                        {"flight_wall_s", flight_wall_s},
                        {"ratio_to_wall", flight_wall_s > 0.0 ? critical / flight_wall_s : 0.0}};
  return j;
}

}  // namespace tgnav::harness
