#include "harness/run/trial_profile.h"

#include <algorithm>

namespace tgnav::harness {

double TrialProfile::criticalPathSeconds() const {
  double sequential = 0.0;
  for (const TickProfile& t : ticks) sequential += t.sim_busy_s + t.voBusy();
  if (!pipelined || ticks.empty()) return sequential;
  const std::size_t n = ticks.size();
  const std::size_t capacity = static_cast<std::size_t>(std::max(1, queue_capacity));
  std::vector<double> started(n, 0.0);  // when the VO began tracking frame k
  double sim = 0.0;                     // the simulation thread's clock
  double vo_free = 0.0;                 // when the VO finished its previous frame
  for (std::size_t k = 0; k < n; ++k) {
    const TickProfile& t = ticks[k];
    sim += t.sim_busy_s;
    if (t.rendered) {
      if (k >= capacity) sim = std::max(sim, started[k - capacity]);  // a full queue blocks the submit
      started[k] = std::max(sim, vo_free);
      vo_free = started[k] + t.voBusy();
    } else {
      started[k] = sim;
    }
    if (waits_for_pose && k >= 1 && ticks[k - 1].rendered) {
      sim = std::max(sim, started[k - 1] + ticks[k - 1].voBusy());
    }
  }
  return std::max(sim, vo_free);
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
  j["frames_tracked"] = rendered;
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
  // Sequential, the tracking runs on it too (listed under the VO stage).
  ordered_json sim = {{"busy_s", sim_busy},
                      {"wait_vo_s", sim_wait},
                      {"physics_s", physics_s},
                      {"control_s", control_s},
                      {"render_s", rendering},
                      {"noise_s", frame.noise_s},
                      {"other_s", std::max(0.0, sim_busy - physics_s - control_s - camera)}};
  ordered_json vo_stage = {{"busy_s", vo_busy},
                           {"idle_s", pipelined ? std::max(0.0, flight_wall_s - vo_busy) : 0.0},
                           {"features_s", vo.features_s},
                           {"matching_s", vo.matching_s},
                           {"pnp_s", vo.pnp_s},
                           {"map_s", vo.map_s},
                           {"ba_s", vo.ba_s}};
  j["threads"] = {{"simulation", sim}, {pipelined ? "vo" : "vo_on_simulation_thread", vo_stage}};
  // The stage the flight waits on: the one busy for more of the wall time.
  j["bottleneck"] = !pipelined ? "sequential" : (vo_busy > sim_busy ? "vo" : "simulation");
  j["critical_path"] = {{"ms_per_tick", ticks.empty() ? 0.0 : 1e3 * critical / static_cast<double>(ticks.size())},
                        {"total_s", critical},
                        {"flight_wall_s", flight_wall_s},
                        {"ratio_to_wall", flight_wall_s > 0.0 ? critical / flight_wall_s : 0.0}};
  return j;
}

}  // namespace tgnav::harness
