#pragma once
// Facts about this process.
#include <string>

namespace tgnav::harness {

// Peak resident memory of this process (VmHWM), MB; 0 where unavailable.
double peakRssMb();

// CPU seconds used so far by this process's threads whose name begins with `prefix` (for
// example llvmpipe's rasteriser threads, "llvmpipe-"), from /proc/self/task; a negative value
// where the platform cannot tell.
double threadsCpuSeconds(const std::string& prefix);

}  // namespace tgnav::harness
