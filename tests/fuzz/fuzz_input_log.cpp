// Input log reader: a failed parse names the input and the problem; a parsed log has non-decreasing
// timestamps and reads back to the same events after format_input_log (garbled hid lines aside: their
// hex is not kept, so they cannot be written back). Non-finite pen samples are read as written: the
// sketch system rejects their stroke (tests/tools/test_replay.cpp), so they must survive the round trip.
#include <cmath>
#include <cstdint>
#include <string_view>

#include "engine/input_log.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace fire;

namespace {

bool same_double(double a, double b) { return a == b ? std::signbit(a) == std::signbit(b) : std::isnan(a) && std::isnan(b); }

bool same_point(const Vec3& a, const Vec3& b) {
  return same_double(a.x(), b.x()) && same_double(a.y(), b.y()) && same_double(a.z(), b.z());
}

bool same_event(const InputEvent& a, const InputEvent& b) {
  if (a.t_us != b.t_us || a.kind != b.kind) return false;
  switch (a.kind) {
    case EventKind::Pen:
      return same_point(a.p, b.p);
    case EventKind::Down:
    case EventKind::Up:
      return true;
    case EventKind::Command:
      if (a.command == CommandKind::Mark) return b.command == CommandKind::Mark && a.mark == b.mark && same_point(a.p, b.p);
      return a.command == b.command && ((a.command != CommandKind::Delete && a.command != CommandKind::Sharp) || same_point(a.p, b.p));
    case EventKind::Hid:
      return a.device == b.device && a.hid_ok == b.hid_ok && a.bytes == b.bytes;
    case EventKind::Truth:
      if (a.name != b.name || a.values.size() != b.values.size()) return false;
      for (size_t k = 0; k < a.values.size(); ++k)
        if (!same_double(a.values[k], b.values[k])) return false;
      return true;
    case EventKind::Meta:
      return a.name == b.name && a.text == b.text;
  }
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const Result<InputLog> log = parse_input_log(text, fuzz::kSource);
  if (!log) {
    FUZZ_CHECK(fuzz::names_input_and_problem(log.error()), "an error names the input and the problem");
    return 0;
  }
  std::vector<InputEvent> writable;
  int64_t last = INT64_MIN;
  size_t hid_back_in_time = 0;
  for (const InputEvent& e : log->events) {
    // Only a device report may be stamped before the line above it; it is counted, and the order goes on.
    if (e.t_us < last) {
      FUZZ_CHECK(e.kind == EventKind::Hid, "timestamps go back only on hid lines");
      ++hid_back_in_time;
    } else {
      last = e.t_us;
    }
    if (e.kind == EventKind::Hid) FUZZ_CHECK(e.hid_ok || e.bytes.empty(), "a garbled hid line keeps no bytes");
    if (e.kind != EventKind::Hid || e.hid_ok) writable.push_back(e);
  }
  FUZZ_CHECK(hid_back_in_time == log->hid_back_in_time, "hid lines back in time are counted");
  const std::string written = format_input_log(writable);
  const Result<InputLog> again = parse_input_log(written, fuzz::kSource);
  FUZZ_CHECK(again.ok(), "a formatted log parses");
  FUZZ_CHECK(again->events.size() == writable.size(), "a formatted log keeps every event");
  for (size_t i = 0; i < writable.size(); ++i)
    FUZZ_CHECK(same_event(writable[i], again->events[i]), "parse -> format -> parse keeps every event");
  return 0;
}
