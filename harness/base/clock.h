#pragma once
// The steady clock for the wall-clock timings a run reports (plan time, stage times, a sweep's
// progress); nothing a result depends on reads it.
#include <chrono>

namespace tgnav::harness {

// Seconds from t0 to now on the steady clock.
inline double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace tgnav::harness
