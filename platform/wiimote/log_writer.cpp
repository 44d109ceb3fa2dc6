#include "platform/wiimote/log_writer.hpp"

#include <algorithm>

#include "engine/input_log.hpp"

namespace fire::wiimote {

LogWriter::LogWriter(std::ostream& out, Clock clock) : out_(out), clock_(std::move(clock)), origin_ns_(clock_()) {
  out_ << kInputLogHeader << '\n';
  out_.flush();
}

int64_t LogWriter::write_locked(const std::string& line_after_stamp) {
  // Stamped inside the lock: a thread that read its report earlier but took the lock later
  // gets the later stamp, so the file's order is its time order.
  const int64_t t_us = std::max(last_us_, (clock_() - origin_ns_) / 1000);
  last_us_ = t_us;
  out_ << t_us << ' ' << line_after_stamp;
  // One flush a line: a crash leaves at most the last line cut off, which the reader reports.
  out_.flush();
  ++lines_;
  return t_us;
}

int64_t LogWriter::hid(int device, std::span<const uint8_t> report) {
  InputEvent e;
  e.kind = EventKind::Hid;
  e.device = device;
  e.bytes.assign(report.begin(), report.end());
  std::string line = format_event(e);
  line.erase(0, line.find(' ') + 1);
  std::lock_guard lock(mutex_);
  return write_locked(line);
}

int64_t LogWriter::meta(const std::string& key, const std::string& text) {
  InputEvent e;
  e.kind = EventKind::Meta;
  e.name = key;
  e.text = text;
  std::replace(e.text.begin(), e.text.end(), '\n', ' ');  // one event, one line
  std::string line = format_event(e);
  line.erase(0, line.find(' ') + 1);
  std::lock_guard lock(mutex_);
  return write_locked(line);
}

size_t LogWriter::lines() const {
  std::lock_guard lock(mutex_);
  return lines_;
}

bool LogWriter::good() const {
  std::lock_guard lock(mutex_);
  return out_.good();
}

}  // namespace fire::wiimote
