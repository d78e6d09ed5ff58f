// TrialProfile's critical path (a replay of the simulation / features / tracking pipeline from
// measured stage times) on hand-made ticks whose answer is known, and what metrics.json's
// `timing.profile` holds. The helpers' VO time is the features stage's; `ba_s` adds tracking.
#include "harness/run/trial_profile.h"

#include <gtest/gtest.h>
#include <pthread.h>

#include <thread>

#include "harness/base/process.h"
#include "vo/stage_clock.h"

namespace tgnav::harness {
namespace {

TickProfile tick(double sim_s, double vo_s, bool rendered = true) {
  TickProfile t;
  t.sim_busy_s = sim_s;
  t.rendered = rendered;
  t.vo.features_s = vo_s;
  return t;
}

TrialProfile profile(bool pipelined, int ticks, double sim_s, double vo_s) {
  TrialProfile p;
  p.pipelined = pipelined;
  p.queue_capacity = 3;
  for (int k = 0; k < ticks; ++k) p.ticks.push_back(tick(k == 0 ? 0.0 : sim_s, vo_s));
  return p;
}

TEST(TrialProfile, SequentialIsTheSumOfBothStages) {
  EXPECT_NEAR(profile(false, 10, 0.01, 0.02).criticalPathSeconds(), 9 * 0.01 + 10 * 0.02, 1e-12);
}

// Pipelined, the slower stage sets the pace: n frames of VO after the first tick's, or the
// simulation's ticks and the last frame's VO.
TEST(TrialProfile, PipelinedRunsAtTheSlowerStage) {
  EXPECT_NEAR(profile(true, 100, 0.01, 0.02).criticalPathSeconds(), 100 * 0.02, 1e-12);
  EXPECT_NEAR(profile(true, 100, 0.02, 0.01).criticalPathSeconds(), 99 * 0.02 + 0.01, 1e-12);
}

// One slow VO frame is absorbed by the queue when the simulation has slack; with a queue of one
// frame the simulation must wait for it.
TEST(TrialProfile, TheQueueAbsorbsASlowFrame) {
  TrialProfile p = profile(true, 20, 0.02, 0.01);
  p.ticks[5].vo.ba_s = 0.1;  // frame 5 (submitted at 100 ms) tracks from 110 to 210 ms
  const double unhurried = 19 * 0.02 + 0.01;
  EXPECT_NEAR(p.criticalPathSeconds(), unhurried, 1e-12);
  // Queues of one frame: frame 6 waits in the tracking queue, frame 7 in the features stage
  // (done at 150 ms, handed on at 210 ms), frame 8 in the features queue, and tick 9 (done at
  // 180 ms) waits for room there until 210 ms: every later tick slips by 30 ms.
  p.queue_capacity = 1;
  EXPECT_NEAR(p.criticalPathSeconds(), unhurried + 0.03, 1e-12);
}

// Flying on the VO, tick k waits for frame k-1's pose: a slow frame the queue would absorb
// holds the simulation up instead. Frame 5 tracks in 30 ms and ends at 80 ms; tick 6 (done at
// 60 ms) waits for it, and every later tick slips by those 20 ms.
TEST(TrialProfile, WaitingForThePoseSerialisesTheStages) {
  TrialProfile p = profile(true, 50, 0.01, 0.005);
  p.ticks[5].vo.ba_s = 0.025;
  EXPECT_NEAR(p.criticalPathSeconds(), 49 * 0.01 + 0.005, 1e-12);
  p.waits_for_pose = true;
  EXPECT_NEAR(p.criticalPathSeconds(), 49 * 0.01 + 0.005 + 0.02, 1e-12);
}

// Ticks without a frame (tracking lost for good) cost the simulation only.
TEST(TrialProfile, TicksWithoutAFrameCostTheSimulationOnly) {
  TrialProfile p = profile(true, 10, 0.01, 0.005);
  for (int k = 0; k < 5; ++k) p.ticks.push_back(tick(0.01, 0.0, false));
  EXPECT_NEAR(p.criticalPathSeconds(), 14 * 0.01, 1e-12);
}

TEST(TrialProfile, JsonHasPerStageAndPerThreadTotals) {
  TrialProfile p = profile(true, 4, 0.02, 0.01);
  p.flight_wall_s = 0.07;
  p.sim_time_s = 0.2;
  p.physics_s = 0.004;
  p.control_s = 0.001;
  p.process_cpu_s = 0.15;
  p.renderer_cpu_s = 0.02;
  for (TickProfile& t : p.ticks) {
    t.frame.render_s = 0.002;
    t.frame.readback_s = 0.006;
    t.sim_wait_s = 0.0005;
    t.sim_busy_cpu_s = 0.015;
    t.frame_cpu.render_s = 0.001;
    t.frame_cpu.readback_s = 0.002;
    t.frame_cpu.noise_s = 0.001;
    t.vo_cpu.features_s = 0.008;
    t.vo_cpu.ba_s = 0.004;
  }
  const nlohmann::ordered_json j = p.toJson();
  EXPECT_EQ(j["camera_ticks"], 4);
  EXPECT_EQ(j["frames_processed"], 4);
  EXPECT_NEAR(j["per_frame_ms"]["readback"].get<double>(), 6.0, 1e-9);
  EXPECT_NEAR(j["per_frame_ms"]["vo_total"].get<double>(), 10.0, 1e-9);
  EXPECT_NEAR(j["per_sim_second_ms"]["physics"].get<double>(), 20.0, 1e-9);
  const auto& sim = j["threads"]["simulation"];
  EXPECT_NEAR(sim["busy_s"].get<double>(), 0.06, 1e-12);
  EXPECT_NEAR(sim["wait_vo_s"].get<double>(), 0.002, 1e-12);
  EXPECT_NEAR(sim["render_s"].get<double>(), 4 * 0.008, 1e-12);
  EXPECT_NEAR(sim["other_s"].get<double>(), 0.06 - 0.004 - 0.001 - 4 * 0.008, 1e-12);
  EXPECT_NEAR(sim["cpu_s"].get<double>(), 4 * 0.015, 1e-12);
  // CPU seconds per simulated second (0.2 s): per stage, per thread, llvmpipe's and the rest.
  const auto& cpu = j["cpu_per_sim_second_s"];
  EXPECT_NEAR(cpu["readback"].get<double>(), 4 * 0.002 / 0.2, 1e-9);
  EXPECT_NEAR(cpu["simulation_thread"].get<double>(), 4 * 0.015 / 0.2, 1e-9);
  EXPECT_NEAR(cpu["physics_control_other"].get<double>(), 4 * (0.015 - 0.003) / 0.2, 1e-9);
  EXPECT_NEAR(cpu["features_thread"].get<double>(), 4 * 0.009 / 0.2, 1e-9);
  EXPECT_NEAR(cpu["tracking_thread"].get<double>(), 4 * 0.004 / 0.2, 1e-9);
  EXPECT_NEAR(cpu["renderer_threads"].get<double>(), 0.02 / 0.2, 1e-9);
  EXPECT_NEAR(cpu["other_threads"].get<double>(), (0.15 - 4 * 0.028 - 0.02) / 0.2, 1e-9);
  EXPECT_NEAR(cpu["process"].get<double>(), 0.15 / 0.2, 1e-9);
  EXPECT_NEAR(j["per_frame_cpu_ms"]["vo_ba"].get<double>(), 4.0, 1e-9);
  // Unknown renderer threads (no /proc): null, not a number that looks measured.
  p.renderer_cpu_s = -1.0;
  EXPECT_TRUE(p.toJson()["cpu_per_sim_second_s"]["renderer_threads"].is_null());
  EXPECT_NEAR(j["threads"]["features"]["busy_s"].get<double>(), 0.04, 1e-12);
  EXPECT_NEAR(j["threads"]["features"]["idle_s"].get<double>(), 0.03, 1e-12);
  EXPECT_NEAR(j["threads"]["features"]["cpu_s"].get<double>(), 4 * 0.009, 1e-12);
  EXPECT_NEAR(j["threads"]["tracking"]["busy_s"].get<double>(), 0.0, 1e-12);
  EXPECT_EQ(j["bottleneck"], "simulation");
  EXPECT_NEAR(j["critical_path"]["total_s"].get<double>(), 3 * 0.02 + 0.01, 1e-12);
  EXPECT_NEAR(j["critical_path"]["ratio_to_wall"].get<double>(), 1.0, 1e-9);
  // Sequential: the VO's stages are listed as such, on the simulation thread.
  p.pipelined = false;
  const nlohmann::ordered_json s = p.toJson();
  EXPECT_TRUE(s["threads"].contains("features_on_simulation_thread"));
  EXPECT_TRUE(s["threads"].contains("tracking_on_simulation_thread"));
  EXPECT_EQ(s["bottleneck"], "sequential");
}

// The CPU clocks behind the profile: a thread busy for 0.2 s of CPU is counted under its name
// prefix and in the process's total; a stage that only waits costs its thread no CPU.
TEST(TrialProfile, CpuClocksCountBusyThreadsNotWaiting) {
  ASSERT_GE(threadsCpuSeconds("tgnav-busy"), 0.0) << "no /proc/self/task";
  const double process0 = vo::processCpuSeconds();
  double named_cpu = -1.0;
  vo::StageClock waiting;
  std::thread busy([&] {
    pthread_setname_np(pthread_self(), "tgnav-busy-1");
    const double cpu0 = vo::threadCpuSeconds();
    volatile double x = 0.0;
    while (vo::threadCpuSeconds() - cpu0 < 0.2) {
      for (int i = 0; i < 10000; ++i) x = x + 1.0;
    }
    named_cpu = threadsCpuSeconds("tgnav-busy");  // while it still runs
  });
  busy.join();
  const vo::StageClock::Lap wait = waiting.lap();
  EXPECT_GE(wait.wall_s, 0.2);
  EXPECT_LT(wait.cpu_s, 0.05);  // joining costs this thread (almost) nothing
  EXPECT_GE(named_cpu, 0.19);
  EXPECT_GE(vo::processCpuSeconds() - process0, 0.2);
  EXPECT_EQ(threadsCpuSeconds("no-thread-has-this-name"), 0.0);
}

}  // namespace
}  // namespace tgnav::harness
