#pragma once
// The input system: hands each frame the logged events that arrived before the frame ended.
#include <cstdint>
#include <vector>

#include "engine/input_log.hpp"
#include "engine/scheduler.hpp"

namespace fire {

struct InputCursor {
  size_t next = 0;  // first event not yet delivered
};

// Appends to `frame_events` (cleared first) every event with t_us < frame.end_us not delivered yet.
void input_system(const InputLog& log, const FrameTime& frame, InputCursor& cursor, std::vector<InputEvent>& frame_events);

}  // namespace fire
