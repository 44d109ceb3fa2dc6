#include "systems/input/input.hpp"

namespace fire {

void input_system(const InputLog& log, const FrameTime& frame, InputCursor& cursor, std::vector<InputEvent>& frame_events) {
  frame_events.clear();
  while (cursor.next < log.events.size() && log.events[cursor.next].t_us < frame.end_us)
    frame_events.push_back(log.events[cursor.next++]);
}

}  // namespace fire
