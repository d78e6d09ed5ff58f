// One libFuzzer executable per target (tests/fuzz/CMakeLists.txt sets TGNAV_FUZZ_TARGET): an
// exception other than the parser's documented error is a finding, reported as a crash.
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "tests/fuzz/fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    tgnav::fuzz::run(TGNAV_FUZZ_TARGET, data, size);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz target %s: an exception escaped the parser: %s\n", TGNAV_FUZZ_TARGET, e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz target %s: a non-standard exception escaped the parser\n", TGNAV_FUZZ_TARGET);
    std::abort();
  }
  return 0;
}
