#pragma once
// Facts about this process.
namespace tgnav::harness {

// Peak resident memory of this process (VmHWM), MB; 0 where unavailable.
double peakRssMb();

}  // namespace tgnav::harness
