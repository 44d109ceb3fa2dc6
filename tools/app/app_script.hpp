#pragma once
// `fire app --script`: input events delivered through the window's callbacks at given display frames, so
// tests drive the real window as a person would.
#include <cstdint>
#include <string>
#include <vector>

#include "engine/common.hpp"
#include "platform/window/window.hpp"

namespace fire::app {

// A scripted event of --script: at display frame `frame`, `event` goes through the window's callbacks, or,
// with a resize size, the window asks the window system for that size (as a person dragging its border).
struct ScriptEvent {
  uint64_t frame = 0;
  window::WindowEvent event;
  uint32_t resize_width = 0, resize_height = 0;
};

// The --script format, one event a line ('#' starts a comment):
//   FRAME move X Y | press left|right|middle | release left|right|middle | scroll DY | key [ctrl+][shift+]KEY |
//   resize WIDTH HEIGHT | close
// FRAME is the display frame (from 0) before which the event is delivered; frames never decrease.
Result<std::vector<ScriptEvent>> read_script(const std::string& path);
// Delivers `script`'s events from index `next` on that are due by display frame `frame` to `window`; returns the
// index of the first one not yet due.
size_t deliver_script(const std::vector<ScriptEvent>& script, size_t next, uint64_t frame, window::Window& window);

}  // namespace fire::app
