#pragma once
// The process's memory, as the soak and the simulated hour report it: both figures from /proc/self/status,
// so the peak is never below a resident figure read before it.
#include <fstream>
#include <string>

namespace fire::soak {

// A "kB" line of /proc/self/status, in MiB (0 when it is missing).
inline double status_mib(const std::string& key) {
  std::ifstream status("/proc/self/status");
  std::string name;
  double kib = 0;
  while (status >> name) {
    if (name == key) {
      status >> kib;
      return kib / 1024.0;
    }
    status.ignore(1 << 16, '\n');
  }
  return 0;
}

// Resident now.
inline double resident_mib() { return status_mib("VmRSS:"); }
// The most resident so far.
inline double peak_mib() { return status_mib("VmHWM:"); }

}  // namespace fire::soak
