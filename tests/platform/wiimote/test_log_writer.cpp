// The one log writer: stamps in order on a stream, and for a live session events held in stamp order
// until the frame loop takes them, with time already taken closed to late hand-ins.
#include <catch2/catch.hpp>

#include <limits>
#include <sstream>

#include "platform/wiimote/fake_remote.hpp"
#include "platform/wiimote/log_writer.hpp"
#include "tests/platform/wiimote/helpers.hpp"

using namespace fire;
using namespace fire::wiimote;
using namespace fire::wiimote::test;

namespace {

const Bytes kReport = {0x33, 0x00, 0x00};

std::vector<int64_t> stamps(const std::vector<InputEvent>& events) {
  std::vector<int64_t> out;
  for (const InputEvent& e : events) out.push_back(e.t_us);
  return out;
}

}  // namespace

TEST_CASE("a stream's lines never go back: a report read before the last line is stamped at it") {
  ManualClock clock(5 * kMs);
  std::ostringstream text;
  LogWriter log(text, clock.clock());
  clock.advance(3 * kMs);
  CHECK(log.hid(0, kReport, 7 * kMs) == 2000);  // read 2 ms after the log began
  CHECK(log.meta("device", "0 00:1F:32:00:00:0A camera0 0306") == 3000);
  CHECK(log.hid(1, kReport, 6 * kMs) == 3000);  // read at 1 ms, handed in after the 3 ms line
  CHECK(log.restamped() == 1);
  CHECK(text.str() == "FIRE-LOG 3\n2000 hid 0 330000\n3000 meta device 0 00:1F:32:00:00:0A camera0 0306\n3000 hid 1 330000\n");
}

TEST_CASE("a live log holds events in stamp order until taken, and what was taken is final") {
  ManualClock clock;
  LogWriter log(clock.clock());
  clock.advance(30 * kMs);
  // Two reader threads hand in their reports out of the order they were read in.
  log.hid(1, kReport, 12 * kMs);
  log.hid(0, kReport, 4 * kMs);
  log.meta("device", "2 00:1F:32:00:00:0C pad 0306");  // now: 30 ms
  log.hid(0, kReport, 14 * kMs);
  log.hid(0, kReport, 12 * kMs);  // the same instant as an earlier one: after it
  std::vector<InputEvent> taken;
  log.take_before(13'000, taken);
  CHECK(stamps(taken) == std::vector<int64_t>{4000, 12000, 12000});
  CHECK(taken[1].device == 1);
  CHECK(taken[2].device == 0);
  CHECK(log.restamped() == 0);
  // A report read at 10 ms, handed in after 13 ms was taken: stamped 13 ms, before the ones still held.
  log.hid(0, kReport, 10 * kMs);
  CHECK(log.restamped() == 1);
  log.take_before(20'000, taken);
  CHECK(stamps(taken) == std::vector<int64_t>{4000, 12000, 12000, 13000, 14000});
  // Time is closed up to now at most: a later take of the future leaves what has not arrived its stamp.
  log.take_before(40'000, taken);
  CHECK(stamps(taken).back() == 30000);
  clock.advance(5 * kMs);
  log.hid(0, kReport, 33 * kMs);
  CHECK(log.restamped() == 1);
  log.take_before(std::numeric_limits<int64_t>::max(), taken);
  CHECK(stamps(taken).back() == 33000);
  CHECK(log.lines() == 7);
  CHECK(log.good());
}
