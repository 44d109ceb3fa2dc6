#pragma once
// The input system: hands each frame the logged events that arrived before the frame ended.
#include <cstdint>
#include <vector>

#include "engine/input_log.hpp"

namespace fire {

struct FrameTime {
  uint64_t index = 0;
  int64_t begin_us = 0;  // frame covers [begin_us, end_us)
  int64_t end_us = 0;
};

struct InputCursor {
  size_t next = 0;  // first event not yet delivered
};

// Appends to `frame_events` (cleared first) every event with t_us < frame.end_us not delivered yet.
void input_system(const InputLog& log, const FrameTime& frame, InputCursor& cursor, std::vector<InputEvent>& frame_events);

}  // namespace fire
