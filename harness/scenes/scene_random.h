#pragma once
// The random numbers of a generated scene: std::mt19937_64 (its output is fixed by the C++
// standard) with uniforms computed here from the raw 64-bit output, never through
// std::uniform_*_distribution (whose output differs between standard libraries), so a seed gives
// the same scene with every compiler and library.
#include <cstdint>
#include <random>

namespace tgnav::harness::scenes {

// SplitMix64's finaliser: independent seeds for the streams of one scene seed.
inline std::uint64_t mixSeed(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ULL * (stream + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

class SceneRng {
 public:
  explicit SceneRng(std::uint64_t seed) : engine_(seed) {}

  std::uint64_t next() { return engine_(); }
  // In [0, 1): the top 53 bits of one draw.
  double uniform01() { return static_cast<double>(engine_() >> 11) * (1.0 / 9007199254740992.0); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform01(); }
  // In [lo, hi], both included (the modulo bias of a 64-bit draw is negligible here).
  int uniformInt(int lo, int hi) {
    const std::uint64_t span = static_cast<std::uint64_t>(static_cast<std::int64_t>(hi) - lo + 1);
    return lo + static_cast<int>(engine_() % span);
  }
  bool chance(double p) { return uniform01() < p; }

 private:
  std::mt19937_64 engine_;
};

}  // namespace tgnav::harness::scenes
