#pragma once
// The single writer of a live session's input log (engine/INPUT_LOG.md). Every reader thread
// hands it what arrived; it stamps the line and keeps it under one lock, so the order of the lines
// is the order of their stamps and the log never goes back in time.
//
// Two destinations. A stream (a bare log file): each line is written and flushed as it comes.
// A live session (tools/app/live_session.hpp): the stamped events are held, in stamp order, until
// the frame loop takes those before a time, which it writes to the session folder and delivers.
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include "engine/input_log.hpp"
#include "platform/wiimote/device.hpp"

namespace fire::wiimote {

class LogWriter {
 public:
  // To a stream: writes the header. Times are microseconds since this moment on `clock`.
  LogWriter(std::ostream& out, Clock clock);
  // For a live session: nothing is written; events wait for take_before().
  explicit LogWriter(Clock clock);

  // `hid <device> <hex>`, the report as it arrived; returns its stamp. `arrival_ns` is the reader's
  // clock when its read returned (the clock now when absent): the stamp is that instant, unless the
  // log has passed it already (below).
  int64_t hid(int device, std::span<const uint8_t> report, std::optional<int64_t> arrival_ns = std::nullopt);
  // `meta <key> <text>`, stamped with the clock now; returns its stamp.
  int64_t meta(const std::string& key, const std::string& text);
  // A command the person gave (a key, the command pad's button: `cmd ...`), stamped with the clock now;
  // returns its stamp.
  int64_t command(InputEvent command);
  // Microseconds since the log began, on its clock.
  int64_t now_us() const;

  // Live session only: moves the held events stamped before `until_us` to `out`, in stamp order, and
  // closes that stretch of time (up to now_us() at most): an event handed in later whose arrival was
  // before it is stamped at its end instead, so what was taken is final. To a stream, the stamp never
  // goes below the last line's instead.
  void take_before(int64_t until_us, std::vector<InputEvent>& out);

  size_t lines() const;
  // Events stamped later than their arrival because the log had passed it (a reader that handed its
  // report in late): how often the stamps are not the arrival instants.
  size_t restamped() const;
  // Whether every write so far reached the stream (always true for a live session).
  bool good() const;

 private:
  int64_t add_locked(InputEvent e, std::optional<int64_t> arrival_ns);

  std::ostream* out_ = nullptr;  // none: a live session's, events held in `held_`
  Clock clock_;
  int64_t origin_ns_;
  mutable std::mutex mutex_;
  int64_t floor_us_ = 0;  // no stamp goes below it: the last line's (stream) or the last take's (live)
  std::deque<InputEvent> held_;  // live: stamped, not taken yet, in stamp order
  size_t lines_ = 0;
  size_t restamped_ = 0;
};

}  // namespace fire::wiimote
