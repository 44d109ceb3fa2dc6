#include "tools/app/live_session.hpp"

#include <limits>

namespace fire {

LiveSession::LiveSession(World& world, Scheduler& scheduler, wiimote::LogWriter& log, SessionWriter& out,
                         SessionWriteOptions options)
    : world_(world), scheduler_(scheduler), log_(log), recorder_(world, out, std::move(options)) {}

void LiveSession::take(int64_t until_us) {
  const size_t before = world_.log.events.size();
  log_.take_before(until_us, world_.log.events);
  if (on_taken_ && world_.log.events.size() > before)
    on_taken_(std::span<const InputEvent>(world_.log.events).subspan(before));
  if (!begun_ && world_.log.events.size() > before) {
    begin_frame(world_, 0, world_.log.events.front().t_us);
    begun_ = true;
  }
}

ReplayHooks LiveSession::hooks(bool at_end) {
  ReplayHooks h;
  h.before_frame = [this](World& w) { recorder_.before_frame(w); };
  h.after_frame = [this, at_end](const World& w) {
    recorder_.after_frame(w, at_end && replay_done(w));
    ++frames_run_;
  };
  return h;
}

uint64_t LiveSession::step() {
  const uint64_t before = frames_run_;
  const int64_t until_us = log_.now_us() - kLiveLagUs;
  take(until_us);
  if (!begun_) return 0;
  run_frames_until(world_, scheduler_, until_us, hooks(false));
  // The delivered events are in the session's log on disk: memory does not grow with the session.
  forget_delivered_events(world_);
  return frames_run_ - before;
}

Status LiveSession::finish() {
  take(std::numeric_limits<int64_t>::max());
  if (begun_) continue_replay(world_, scheduler_, hooks(true));
  return recorder_.finish();
}

}  // namespace fire
