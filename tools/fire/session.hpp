#pragma once
// A drawing session: the world's data and the per-frame system order of the design card, used by
// `fire replay` headless (and later by the live app).
#include <string>
#include <vector>

#include "engine/input_log.hpp"
#include "engine/mesh.hpp"
#include "engine/scheduler.hpp"
#include "engine/snap_index.hpp"
#include "systems/input/input.hpp"
#include "systems/sketch/sketch.hpp"
#include "systems/split/edit.hpp"

namespace fire {

struct World {
  InputLog log;
  InputCursor cursor;
  FrameTime frame;
  std::vector<InputEvent> frame_events;
  SketchState sketch;
  SketchSettings sketch_settings;
  std::vector<EditRequest> requests;
  Mesh mesh;
  SnapIndex snap;  // in step with `mesh` from the end of each frame
  EditHistory history;
  std::vector<Rejection> rejections;
};

inline constexpr int64_t kFrameStepUs = 10'000;  // 100 Hz, the Wii Remote's report rate

// Builds the scheduler over `world` with the systems in design-card order.
Scheduler make_scheduler(World& world, Scheduler::Clock clock);
// The end-of-frame sync of the snapping index with the edges this frame wrote.
void sync_snap_index(World& world);
// Runs fixed-step frames from the first event until every event is consumed and no request waits.
void replay_headless(World& world, Scheduler& scheduler);

}  // namespace fire
