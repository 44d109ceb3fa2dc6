#pragma once
// A live session: the Wii Remote driver's log writer (platform/wiimote/log_writer.hpp) feeding a World
// frame by frame, recorded as a session folder (engine/SESSION.md) as it goes.
//
// The frame loop takes from the log writer the events stamped before `now - kLiveLagUs` and runs every
// frame that ends by then. From then on the writer stamps nothing before that instant: a report read
// earlier but handed in later is stamped at it (LogWriter::take_before), so each frame's events are
// final when it runs. What the frames
// do depends only on those events, and the session folder's input.log holds them in the same order with
// the same stamps: replaying the folder (reopen_session, `fire replay DIR`) gives the live world's hash.
#include <cstdint>
#include <functional>
#include <span>

#include "platform/session_files.hpp"
#include "platform/wiimote/log_writer.hpp"
#include "tools/app/session.hpp"
#include "tools/app/session_store.hpp"

namespace fire {

// How far behind the clock the frames run: a reader thread may take this long between its read
// returning (the report's stamp) and handing the report to the log writer without the report being
// restamped into a later frame. A Wii Remote frame is 10 ms; 20 ms is two of them.
inline constexpr int64_t kLiveLagUs = 20'000;

class LiveSession {
 public:
  // `world` is new (settings and rig set, no event yet) and `out` its new session folder's writer; the
  // log writer is the one the driver writes to, in its live mode.
  LiveSession(World& world, Scheduler& scheduler, wiimote::LogWriter& log, SessionWriter& out,
              SessionWriteOptions options = {});
  // Takes the events stamped before now - kLiveLagUs and runs every frame they complete; returns how
  // many frames ran. Call it as often as the display wants; the systems run on the calling thread.
  uint64_t step();
  // Once the driver has stopped: takes every event left, runs frames until all are consumed (the last
  // one snapshotted when the options ask for snapshots) and commits the log. The first failed write.
  Status finish();
  // Called with the events each step takes, in log order, before any frame delivers them (the live
  // commands' progress on stderr, the calibration's reports).
  void on_taken(std::function<void(std::span<const InputEvent>)> observer) { on_taken_ = std::move(observer); }
  uint64_t frames_run() const { return frames_run_; }
  const Status& status() const { return recorder_.status(); }

 private:
  void take(int64_t until_us);
  ReplayHooks hooks(bool at_end);

  World& world_;
  Scheduler& scheduler_;
  wiimote::LogWriter& log_;
  SessionRecorder recorder_;
  std::function<void(std::span<const InputEvent>)> on_taken_;
  bool begun_ = false;  // frame 0 begins at the first event's stamp, as replay_headless begins it
  uint64_t frames_run_ = 0;
};

}  // namespace fire
