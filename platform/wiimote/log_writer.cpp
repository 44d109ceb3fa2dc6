#include "platform/wiimote/log_writer.hpp"

#include <algorithm>

namespace fire::wiimote {

LogWriter::LogWriter(std::ostream& out, Clock clock) : out_(&out), clock_(std::move(clock)), origin_ns_(clock_()) {
  out << kInputLogHeader << '\n';
  out.flush();
}

LogWriter::LogWriter(Clock clock) : clock_(std::move(clock)), origin_ns_(clock_()) {}

int64_t LogWriter::now_us() const { return (clock_() - origin_ns_) / 1000; }

int64_t LogWriter::add_locked(InputEvent e, std::optional<int64_t> arrival_ns) {
  // Stamped inside the lock: a stream's line is written now, so it may not go below the line above it;
  // a live event may land among the held ones, but not in time already taken.
  const int64_t arrival_us = arrival_ns ? (*arrival_ns - origin_ns_) / 1000 : now_us();
  e.t_us = std::max(floor_us_, arrival_us);
  restamped_ += e.t_us != arrival_us;
  ++lines_;
  if (out_) {
    floor_us_ = e.t_us;
    *out_ << format_event(e);
    // One flush a line: a crash leaves at most the last line cut off, which the reader reports.
    out_->flush();
    return e.t_us;
  }
  // After every held event of the same stamp: equal stamps keep their arrival order.
  const auto at = std::upper_bound(held_.begin(), held_.end(), e.t_us,
                                   [](int64_t t, const InputEvent& h) { return t < h.t_us; });
  const int64_t t_us = e.t_us;
  held_.insert(at, std::move(e));
  return t_us;
}

int64_t LogWriter::hid(int device, std::span<const uint8_t> report, std::optional<int64_t> arrival_ns) {
  InputEvent e;
  e.kind = EventKind::Hid;
  e.device = device;
  e.bytes.assign(report.begin(), report.end());
  std::lock_guard lock(mutex_);
  return add_locked(std::move(e), arrival_ns);
}

int64_t LogWriter::meta(const std::string& key, const std::string& text) {
  InputEvent e;
  e.kind = EventKind::Meta;
  e.name = key;
  e.text = text;
  std::replace(e.text.begin(), e.text.end(), '\n', ' ');  // one event, one line
  std::lock_guard lock(mutex_);
  return add_locked(std::move(e), std::nullopt);
}

int64_t LogWriter::command(InputEvent command) {
  command.kind = EventKind::Command;
  std::lock_guard lock(mutex_);
  return add_locked(std::move(command), std::nullopt);
}

void LogWriter::take_before(int64_t until_us, std::vector<InputEvent>& out) {
  std::lock_guard lock(mutex_);
  // Closed up to now at most: an event that has not arrived yet keeps its own stamp.
  floor_us_ = std::max(floor_us_, std::min(until_us, now_us()));
  while (!held_.empty() && held_.front().t_us < until_us) {
    // An event taken past the floor (taking everything at the end) raises it: nothing goes before it.
    floor_us_ = std::max(floor_us_, held_.front().t_us);
    out.push_back(std::move(held_.front()));
    held_.pop_front();
  }
}

size_t LogWriter::lines() const {
  std::lock_guard lock(mutex_);
  return lines_;
}

size_t LogWriter::restamped() const {
  std::lock_guard lock(mutex_);
  return restamped_;
}

bool LogWriter::good() const {
  std::lock_guard lock(mutex_);
  return !out_ || out_->good();
}

}  // namespace fire::wiimote
