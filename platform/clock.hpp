#pragma once
#include <cstdint>

namespace fire {

// Monotonic nanoseconds, for timing systems (never for anything a replay depends on).
int64_t monotonic_ns();
// CPU time the calling thread has used, in nanoseconds: what a system costs, whatever else the machine runs.
int64_t thread_cpu_ns();

}  // namespace fire
