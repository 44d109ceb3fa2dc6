#pragma once
#include <cstdint>

namespace fire {

// Monotonic nanoseconds, for timing systems (never for anything a replay depends on).
int64_t monotonic_ns();

}  // namespace fire
