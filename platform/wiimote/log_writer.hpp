#pragma once
// The single writer of a live session's input log (engine/INPUT_LOG.md). Every reader thread
// hands it what arrived; it stamps the line with the clock and writes it under one lock, so the
// order of the lines is the order of their stamps and the log never goes back in time.
#include <cstdint>
#include <mutex>
#include <ostream>
#include <span>
#include <string>

#include "platform/wiimote/device.hpp"

namespace fire::wiimote {

class LogWriter {
 public:
  // Writes the header. Times are microseconds since this moment on `clock`.
  LogWriter(std::ostream& out, Clock clock);

  // `hid <device> <hex>`, the report as it arrived; returns its stamp.
  int64_t hid(int device, std::span<const uint8_t> report);
  // `meta <key> <text>`; returns its stamp.
  int64_t meta(const std::string& key, const std::string& text);
  size_t lines() const;
  // Whether every write so far reached the stream.
  bool good() const;

 private:
  int64_t write_locked(const std::string& line_after_stamp);

  std::ostream& out_;
  Clock clock_;
  int64_t origin_ns_;
  mutable std::mutex mutex_;
  int64_t last_us_ = 0;
  size_t lines_ = 0;
};

}  // namespace fire::wiimote
