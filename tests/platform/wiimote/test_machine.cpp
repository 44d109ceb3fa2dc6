// A remote's start-up and upkeep (RemoteMachine) against one fake remote, stepped by hand on a
// manual clock: lost acknowledgements, a remote that never answers, a camera that comes up wrong,
// status reports mid-drawing, garbage.
#include <catch2/catch.hpp>

#include <functional>

#include "platform/wiimote/fake_remote.hpp"
#include "platform/wiimote/remote_machine.hpp"
#include "tests/platform/wiimote/helpers.hpp"

using namespace fire;
using namespace fire::wiimote;
using namespace fire::wiimote::test;

namespace {

struct Harness {
  explicit Harness(Role role = Role::Camera0, StartupOptions options = {})
      : bus(clock.clock()), remote(bus.add_remote({})), machine(role, options) {
    auto found = bus.enumerate();
    REQUIRE(found.ok());
    auto d = bus.open(found->front());
    REQUIRE(d.ok());
    device = std::move(*d);
    remote->set_blob_source([this](int64_t) { return pen; });
  }
  void send(std::vector<Bytes>& out) {
    for (const Bytes& r : out) REQUIRE(device->write(r).ok());
    out.clear();
  }
  void begin() {
    std::vector<Bytes> out;
    machine.begin(clock.now(), player_led(1), out);
    send(out);
  }
  // Steps of 1 ms: every report that arrived goes to the machine, then its timeouts.
  void run_ms(int ms) {
    for (int i = 0; i < ms; ++i) {
      clock.advance(kMs);
      std::vector<Bytes> out;
      for (;;) {
        ReadResult r = device->read(0);
        if (r.status != ReadStatus::Report) break;
        ++reports;
        machine.on_report(r.report, clock.now(), out);
      }
      machine.tick(clock.now(), out);
      send(out);
    }
  }
  // Runs until the machine is no longer starting; returns the milliseconds it took.
  int run_until_started(int limit_ms) {
    int ms = 0;
    while (machine.state() == MachineState::Starting && ms < limit_ms) {
      run_ms(1);
      ++ms;
    }
    return ms;
  }
  void light(uint16_t x, uint16_t y) { pen[0] = {.seen = true, .x = x, .y = y, .size = 2}; }

  ManualClock clock;
  FakeBus bus;
  std::shared_ptr<FakeRemote> remote;
  std::unique_ptr<Device> device;
  RemoteMachine machine;
  IrSlots pen{};
  size_t reports = 0;
};

// Output reports whose acknowledgement the machine waits for must ask for it.
void check_every_waited_report_asks(const std::vector<Bytes>& writes) {
  for (const Bytes& w : writes) {
    if (w[0] == kOutWriteMemory || w[0] == kOutStatusRequest) continue;
    if (w[0] == kOutLeds && !(w[1] & kAckRequestBit)) continue;  // feedback, never waited for
    INFO("report " << int(w[0]));
    CHECK((w[1] & kAckRequestBit) != 0);
  }
}

}  // namespace

TEST_CASE("start-up sends the notes' sequence in order, each report asking for its acknowledgement") {
  Harness h;
  h.light(400, 200);
  h.begin();
  CHECK(h.run_until_started(1000) < 60);  // ten answers, each 2 to 4 ms on the radio
  REQUIRE(h.machine.state() == MachineState::Running);
  const auto w = h.remote->writes();
  REQUIRE(w.size() == 10);
  CHECK(w[0][0] == kOutStatusRequest);
  CHECK(w[1] == Bytes{kOutLeds, 0x12});
  CHECK(w[2] == Bytes{kOutIrPixelClock, 0x06});
  CHECK(w[3] == Bytes{kOutIrLogic, 0x06});
  const uint32_t addresses[] = {kRegIrControl, kRegIrBlock1, kRegIrBlock2, kRegIrMode, kRegIrControl};
  for (int k = 0; k < 5; ++k) {
    const Bytes& r = w[4 + k];
    CHECK(r[0] == kOutWriteMemory);
    CHECK((uint32_t{r[2]} << 16 | uint32_t{r[3]} << 8 | r[4]) == addresses[k]);
  }
  CHECK(w[9] == Bytes{kOutReportingMode, 0x06, 0x33});
  check_every_waited_report_asks(w);
  CHECK(h.remote->camera_working());
  CHECK(h.machine.status());
  CHECK(h.machine.status()->battery == 0xA0);
  h.run_ms(100);
  CHECK(h.machine.warning().empty());
}

TEST_CASE("start-up survives lost acknowledgements by sending the report again") {
  Harness h;
  h.light(400, 200);
  h.remote->drop_acks(kOutIrPixelClock, 2);
  h.remote->drop_acks(kOutWriteMemory, 1);
  h.remote->drop_acks(kOutReportingMode, 3);
  h.begin();
  h.run_until_started(10000);  // six lost acks, each waited for the kernel's 1 s
  REQUIRE(h.machine.state() == MachineState::Running);
  CHECK(h.machine.resends() == 6);
  CHECK(h.machine.sequences() == 1);
  CHECK(writes_of(h.remote->writes(), kOutIrPixelClock).size() == 3);
  check_every_waited_report_asks(h.remote->writes());
  CHECK(h.remote->camera_working());
}

TEST_CASE("too many lost acknowledgements of one report restart the whole sequence") {
  Harness h;
  h.light(400, 200);
  h.remote->drop_acks(kOutIrLogic, 4);
  h.begin();
  h.run_until_started(10000);
  REQUIRE(h.machine.state() == MachineState::Running);
  CHECK(h.machine.sequences() == 2);
  CHECK(writes_of(h.remote->writes(), kOutIrPixelClock).size() == 2);
}

TEST_CASE("a remote that never acknowledges is given up in bounded time with a clear error") {
  StartupOptions o;
  Harness h(Role::Camera0, o);
  h.remote->set_never_ack(true);
  h.begin();
  const int ms = h.run_until_started(60000);
  REQUIRE(h.machine.state() == MachineState::Failed);
  // Every try of every sequence waited one timeout, no more.
  CHECK(ms <= o.max_sequences * o.max_tries * (o.ack_timeout_ns / kMs + 1) + 10);
  CHECK_THAT(h.machine.error(), Catch::Contains("no acknowledgement of report 0x11"));
  CHECK_THAT(h.machine.error(), Catch::Contains("hid-wiimote"));
  const size_t writes = h.remote->writes().size();
  h.run_ms(2000);
  CHECK(h.remote->writes().size() == writes);  // a failed remote is left alone
}

TEST_CASE("a camera that comes up dark or in another mode is set up again") {
  SECTION("no IR objects") {
    Harness h;
    h.light(600, 500);
    h.remote->start_in_bad_state(BadState::NoIr);
    h.begin();
    h.run_until_started(1000);
    REQUIRE(h.machine.state() == MachineState::Running);
    h.run_ms(2900);
    CHECK(h.machine.restarts() == 0);
    h.run_ms(200);
    CHECK(h.machine.restarts() == 1);
    h.run_until_started(1000);
    h.run_ms(4000);
    CHECK(h.machine.restarts() == 1);
    CHECK(h.machine.state() == MachineState::Running);
    CHECK(h.remote->camera_working());
    CHECK(h.machine.warning().empty());
  }
  SECTION("another mode, state drawn from a seed") {
    Harness h;
    h.light(600, 500);
    h.remote->start_in_bad_state(BadState::Random, 3);
    h.begin();
    h.run_until_started(1000);
    h.run_ms(5000);
    CHECK(h.machine.restarts() == 1);
    CHECK(h.machine.state() == MachineState::Running);
    CHECK(h.remote->camera_working());
    CHECK(h.remote->initialisations() == 2);
  }
  SECTION("reports in another mode") {
    Harness h;
    h.light(600, 500);
    h.remote->start_in_bad_state(BadState::WrongMode);
    h.begin();
    h.run_until_started(1000);
    for (int ms = 0; ms < 300 && h.machine.restarts() == 0; ++ms) h.run_ms(1);
    CHECK(h.machine.restarts() == 1);
    CHECK_THAT(h.machine.warning(), Catch::Contains("mode 0x31"));
    h.run_until_started(1000);
    h.run_ms(1000);
    CHECK(h.machine.restarts() == 1);
    CHECK(h.remote->camera_working());
  }
  SECTION("dark for good: a bounded number of restarts, then a warning") {
    Harness h;  // the pen is never lit
    h.begin();
    h.run_ms(20000);
    CHECK(h.machine.restarts() == StartupOptions{}.max_dark_restarts);
    CHECK(h.machine.state() == MachineState::Running);
    CHECK_THAT(h.machine.warning(), Catch::Contains("no IR object"));
  }
}

TEST_CASE("the reporting mode is sent again after every status report, mid-drawing") {
  Harness h;
  h.light(300, 300);
  h.begin();
  h.run_until_started(1000);
  h.run_ms(100);
  const size_t modes = writes_of(h.remote->writes(), kOutReportingMode).size();
  for (int k = 0; k < 3; ++k) {
    h.remote->send_status();
    h.run_ms(50);
    CHECK(h.remote->continuous());
  }
  CHECK(writes_of(h.remote->writes(), kOutReportingMode).size() == modes + 3);
  // And the periodic battery request is one too.
  h.run_ms(61000);
  CHECK(writes_of(h.remote->writes(), kOutStatusRequest).size() == 2);
  CHECK(h.remote->continuous());
  CHECK(h.machine.state() == MachineState::Running);
  CHECK(h.machine.restarts() == 0);
}

TEST_CASE("garbage and truncated reports change nothing") {
  Harness h;
  h.light(300, 300);
  h.begin();
  h.remote->inject({});
  h.remote->inject({0x22});
  h.remote->inject({0x22, 0x00, 0x00, 0x13});  // a truncated acknowledgement of the next step
  h.remote->inject({0x20, 0x00});
  h.remote->inject({0x33, 0x01, 0x02});
  h.remote->inject({0xFF, 0xFF, 0xFF, 0xFF});
  h.remote->inject({0x22, 0x00, 0x00, 0x1A, 0x00, 0x00});  // longer, and asked for by nothing yet
  h.run_until_started(1000);
  REQUIRE(h.machine.state() == MachineState::Running);
  CHECK(h.machine.sequences() == 1);
  CHECK(h.remote->camera_working());
  h.remote->inject({0x33, 0x00});
  h.run_ms(500);
  CHECK(h.machine.restarts() == 0);
}

TEST_CASE("an acknowledgement with an error code counts as a failed try") {
  Harness h;
  h.light(300, 300);
  h.remote->drop_acks(kOutLeds, 1);
  h.begin();
  // The status report answers the first step; then the LED report is in flight.
  while (writes_of(h.remote->writes(), kOutLeds).empty()) h.run_ms(1);
  h.remote->inject({kInAck, 0x00, 0x00, kOutLeds, 0x03});
  h.run_until_started(1000);
  REQUIRE(h.machine.state() == MachineState::Running);
  CHECK(h.machine.resends() == 1);
}

TEST_CASE("sensitivity levels write their blocks, the pad skips the camera") {
  SECTION("high sensitivity") {
    Harness h(Role::Camera1, StartupOptions{.sensitivity = kHighSensitivity});
    h.light(1, 1);
    h.begin();
    h.run_until_started(1000);
    CHECK(h.remote->register_at(kRegIrBlock1 + 6) == 0x90);
    CHECK(h.remote->register_at(kRegIrBlock2) == 0x40);
  }
  SECTION("level 5") {
    Harness h(Role::Camera1, StartupOptions{.sensitivity = 5});
    h.begin();
    h.run_until_started(1000);
    CHECK(h.remote->register_at(kRegIrBlock1) == 0x07);
    CHECK(h.remote->register_at(kRegIrBlock2) == 0x1F);
  }
  SECTION("command pad") {
    Harness h(Role::CommandPad);
    h.begin();
    h.run_until_started(1000);
    REQUIRE(h.machine.state() == MachineState::Running);
    CHECK(writes_of(h.remote->writes(), kOutIrPixelClock).empty());
    CHECK(h.remote->reporting_mode() == kInButtons);
    h.run_ms(5000);
    CHECK(h.machine.restarts() == 0);
    CHECK(h.machine.warning().empty());
  }
}

namespace {

// A remote played by the test: each report that is answered gets its answer `latency_ms` later, or
// as `delay_ms(n)` says for the n-th memory write; the machine is fed on a 1 ms step.
struct ScriptedRemote {
  struct Sent {
    Bytes report;
    int64_t sent_at = 0;
    int64_t answer_at = 0;
    bool answered = false;
  };
  explicit ScriptedRemote(std::function<int(int)> delay_ms) : delay_ms(std::move(delay_ms)) {}

  void take(std::vector<Bytes>& out) {
    for (Bytes& r : out) {
      // Every output report the machine sends comes after the answer to the one before it.
      if (!sent.empty() && !sent.back().answered) out_of_turn.push_back(r);
      const bool answered = r[0] == kOutStatusRequest || r[0] == kOutWriteMemory || (r[1] & kAckRequestBit);
      int delay = latency_ms;
      if (r[0] == kOutWriteMemory) delay = delay_ms(writes++);
      sent.push_back({r, now, answered ? now + delay * kMs : -1, !answered});
    }
    out.clear();
  }
  void run(RemoteMachine& m, int ms) {
    for (int i = 0; i < ms; ++i) {
      now += kMs;
      std::vector<Bytes> out;
      for (Sent& s : sent) {
        if (s.answered || s.answer_at < 0 || s.answer_at > now) continue;
        s.answered = true;
        const Bytes answer = s.report[0] == kOutStatusRequest ? Bytes{kInStatus, 0, 0, 0x10, 0, 0, 0xA0}
                                                               : Bytes{kInAck, 0, 0, s.report[0], 0};
        m.on_report(answer, now, out);
      }
      m.tick(now, out);
      take(out);
    }
  }
  std::function<int(int)> delay_ms;
  int latency_ms = 100;
  int writes = 0;
  int64_t now = 0;
  std::vector<Sent> sent;
  std::vector<Bytes> out_of_turn;
};

}  // namespace

TEST_CASE("a late acknowledgement of one memory write is never taken for the next") {
  // Every answer takes 100 ms; the first camera register write's takes 300 ms, within the kernel's 1 s.
  ScriptedRemote remote([](int n) { return n == 0 ? 300 : 100; });
  RemoteMachine m(Role::Camera0, {});
  std::vector<Bytes> out;
  m.begin(0, player_led(1), out);
  remote.take(out);
  remote.run(m, 3000);
  CHECK(m.state() == MachineState::Running);
  CHECK(m.resends() == 0);
  CHECK(remote.out_of_turn.empty());
  CHECK(remote.writes == 5);
}

TEST_CASE("an acknowledgement longer than its layout is read") {
  ScriptedRemote remote([](int) { return 5; });
  remote.latency_ms = 5;
  RemoteMachine m(Role::CommandPad, {});
  std::vector<Bytes> out;
  m.begin(0, player_led(3), out);
  remote.take(out);
  remote.run(m, 7);  // the status report answered at 5 ms; the LED report in flight, its ack due at 10 ms
  REQUIRE(remote.sent.size() == 2);
  remote.sent[1].answered = true;  // answered here instead, with padding
  m.on_report(Bytes{kInAck, 0, 0, kOutLeds, 0, 0xEE, 0xEE}, remote.now, out);
  remote.take(out);
  remote.run(m, 20);
  CHECK(m.state() == MachineState::Running);
  CHECK(m.resends() == 0);
}

TEST_CASE("error 7, the camera off, sets the camera up again from its pixel clock") {
  Harness h;
  h.light(400, 200);
  h.begin();
  // The first camera register is written; then an extension is plugged and the camera goes off.
  while (writes_of(h.remote->writes(), kOutWriteMemory).empty()) h.run_ms(1);
  h.remote->extension_event();
  h.run_until_started(5000);
  REQUIRE(h.machine.state() == MachineState::Running);
  CHECK(h.remote->refused_camera_writes() >= 1);
  CHECK(h.machine.sequences() == 1);
  CHECK(writes_of(h.remote->writes(), kOutIrPixelClock).size() == 2);
  CHECK(h.remote->camera_working());
  h.run_ms(100);
  CHECK(h.remote->continuous());
}

TEST_CASE("a status report with the camera off sets the camera up again") {
  Harness h;
  h.light(400, 200);
  h.begin();
  h.run_until_started(1000);
  h.run_ms(100);
  REQUIRE(h.remote->camera_working());
  h.remote->extension_event();
  h.run_ms(5);
  CHECK_FALSE(h.remote->camera_working());
  h.run_ms(100);
  CHECK(h.remote->camera_working());
  CHECK(h.remote->continuous());
  CHECK(writes_of(h.remote->writes(), kOutIrPixelClock).size() == 2);
  CHECK(h.machine.state() == MachineState::Running);
  CHECK(h.machine.warning().empty());
  const size_t before = h.reports;
  h.run_ms(100);
  CHECK(h.reports >= before + 9);  // streaming at 100 Hz again
}

TEST_CASE("a busy remote gets the same report again after a pause, not at once") {
  StartupOptions o;
  Harness h(Role::Camera0, o);
  h.light(400, 200);
  h.begin();
  while (writes_of(h.remote->writes(), kOutIrLogic).empty()) h.run_ms(1);
  h.remote->inject({kInAck, 0x00, 0x00, kOutIrLogic, kAckBusy});
  h.run_ms(1);
  const int64_t refused_at = h.clock.now();
  while (writes_of(h.remote->writes(), kOutIrLogic).size() < 2) h.run_ms(1);
  CHECK(h.clock.now() - refused_at >= o.busy_wait_ns - kMs);
  h.run_until_started(2000);
  CHECK(h.machine.state() == MachineState::Running);
  CHECK(h.remote->camera_working());
}
