#include "tools/fire/session.hpp"

#include "systems/split/split_system.hpp"

namespace fire {

Scheduler make_scheduler(World& w, Scheduler::Clock clock) {
  Scheduler s(clock);
  s.add("input", [&w] { input_system(w.log, w.frame, w.cursor, w.frame_events); });
  s.add("sketch", [&w] { sketch_system(w.frame_events, w.mesh, w.snap, w.sketch_settings, w.sketch, w.requests, w.rejections); });
  s.add("split", [&w] { split_system(w.requests, w.mesh, w.history, w.rejections); });
  s.add("snap", [&w] { sync_snap_index(w); });
  return s;
}

void sync_snap_index(World& w) {
  // The index is the only reader of the dirty tags in a session, so it clears them; change stamps will
  // replace the tags here.
  w.snap.update(w.mesh, changed_slots(w.mesh.edges.dirty));
  w.mesh.clear_dirty();
}

void replay_headless(World& w, Scheduler& scheduler) {
  if (w.log.events.empty()) return;
  int64_t t = w.log.events.front().t_us;
  w.frame = {0, t, t + kFrameStepUs};
  while (w.cursor.next < w.log.events.size() || !w.sketch.pending.empty()) {
    // Skip stretches with nothing to do: the frames still count, so frame numbers match a live session.
    if (w.sketch.pending.empty() && w.log.events[w.cursor.next].t_us >= w.frame.end_us) {
      int64_t steps = (w.log.events[w.cursor.next].t_us - w.frame.begin_us) / kFrameStepUs;
      w.frame = {w.frame.index + uint64_t(steps), w.frame.begin_us + steps * kFrameStepUs,
                 w.frame.begin_us + (steps + 1) * kFrameStepUs};
    }
    scheduler.run_frame();
    w.frame = {w.frame.index + 1, w.frame.end_us, w.frame.end_us + kFrameStepUs};
  }
}

}  // namespace fire
