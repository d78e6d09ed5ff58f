#pragma once
// Wall-clock and CPU seconds of a stage of work, for profiles only: neither is deterministic, and
// neither may feed a result that must repeat. CPU time compares across machines and loads better
// than wall time: a stage that waits for a core it shares with other threads takes longer on the
// wall clock, not on its thread's CPU clock.
#include <chrono>
#include <ctime>

namespace tgnav::vo {

// CPU seconds used so far by the calling thread (0 where the platform cannot tell).
inline double threadCpuSeconds() {
  timespec ts{};
  if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0) return 0.0;
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// CPU seconds used so far by the whole process, all its threads (0 where the platform cannot tell).
inline double processCpuSeconds() {
  timespec ts{};
  if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0) return 0.0;
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Seconds since construction or the previous lap: wall clock, and the calling thread's CPU (a
// clock is read on the thread that made it).
class StageClock {
 public:
  struct Lap {
    double wall_s = 0.0;
    double cpu_s = 0.0;
  };
  Lap lap() {
    const auto now = std::chrono::steady_clock::now();
    const double cpu = threadCpuSeconds();
    const Lap l{std::chrono::duration<double>(now - wall_).count(), cpu - cpu_};
    wall_ = now;
    cpu_ = cpu;
    return l;
  }

 private:
  std::chrono::steady_clock::time_point wall_ = std::chrono::steady_clock::now();
  double cpu_ = threadCpuSeconds();
};

}  // namespace tgnav::vo
