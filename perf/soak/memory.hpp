#pragma once
// The process's memory, as the soak and the simulated hour report it.
#include <sys/resource.h>
#include <unistd.h>

#include <fstream>

namespace fire::soak {

// Resident now (/proc/self/statm).
inline double resident_mib() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return double(resident) * double(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

// The most resident so far (getrusage's ru_maxrss).
inline double peak_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;
}

}  // namespace fire::soak
