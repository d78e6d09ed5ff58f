#include "harness/base/process.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace tgnav::harness {

double peakRssMb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // kB
  }
  return 0.0;
}

namespace {

// A thread's CPU seconds: schedstat's run time (nanoseconds), else stat's utime + stime (clock
// ticks); negative when neither can be read (the thread may have ended meanwhile).
double taskCpuSeconds(const std::filesystem::path& task) {
  std::ifstream schedstat(task / "schedstat");
  unsigned long long run_ns = 0;
  if (schedstat >> run_ns) return 1e-9 * static_cast<double>(run_ns);
  std::ifstream stat(task / "stat");
  std::string line;
  if (!std::getline(stat, line)) return -1.0;
  const std::size_t close = line.rfind(')');  // the name may hold spaces and parentheses
  if (close == std::string::npos) return -1.0;
  std::istringstream rest(line.substr(close + 2));
  std::string field;
  unsigned long long utime = 0, stime = 0;
  for (int i = 3; i <= 13; ++i) rest >> field;  // fields 3 (state) .. 13
  if (!(rest >> utime >> stime)) return -1.0;
  const long ticks = sysconf(_SC_CLK_TCK);
  return ticks > 0 ? static_cast<double>(utime + stime) / static_cast<double>(ticks) : -1.0;
}

}  // namespace

double threadsCpuSeconds(const std::string& prefix) {
  std::error_code ec;
  std::filesystem::directory_iterator tasks("/proc/self/task", ec);
  if (ec) return -1.0;
  double total = 0.0;
  for (const auto& task : tasks) {
    std::ifstream comm(task.path() / "comm");
    std::string name;
    if (!std::getline(comm, name) || name.rfind(prefix, 0) != 0) continue;
    const double s = taskCpuSeconds(task.path());
    if (s > 0.0) total += s;
  }
  return total;
}

}  // namespace tgnav::harness
