// The fake remote behaves as strictly as shared/wiimote-protocol.md, the kernel and Dolphin say a
// remote does; the driver's tests are only as good as this. Most cases here take a prompt remote
// (no radio latency) to read its answers at once; the strict timing has cases of its own.
#include <catch2/catch.hpp>

#include <algorithm>

#include "platform/wiimote/fake_remote.hpp"
#include "engine/ir_report.hpp"
#include "tests/platform/wiimote/helpers.hpp"

using namespace fire;
using namespace fire::wiimote;
using fire::wiimote::test::kMs;

namespace {

// Everything the remote has queued for the host right now.
std::vector<Bytes> drain(Device& d) {
  std::vector<Bytes> out;
  for (;;) {
    ReadResult r = d.read(0);
    if (r.status != ReadStatus::Report) return out;
    out.push_back(std::move(r.report));
  }
}

std::unique_ptr<Device> open_only(FakeBus& bus) {
  auto found = bus.enumerate();
  REQUIRE(found.ok());
  REQUIRE(found->size() == 1);
  auto d = bus.open(found->front());
  REQUIRE(d.ok());
  return std::move(*d);
}

void write(Device& d, Bytes r) { REQUIRE(d.write(r).ok()); }

// The notes' initialisation, every report asking for its acknowledgement.
void initialise(Device& d) {
  const uint8_t enable[] = {kIrControlEnable};
  const uint8_t mode[] = {kIrModeExtended};
  const SensitivityBlocks s = sensitivity_blocks(3);
  write(d, ir_pixel_clock_report(true));
  write(d, ir_logic_report(true));
  write(d, write_register_report(kRegIrControl, enable));
  write(d, write_register_report(kRegIrBlock1, s.block1));
  write(d, write_register_report(kRegIrBlock2, s.block2));
  write(d, write_register_report(kRegIrMode, mode));
  write(d, write_register_report(kRegIrControl, enable));
  write(d, reporting_mode_report(kInIrExtended, true, true));
}

// A remote whose answers are on the host's side at the instant of the write.
FakeRemoteOptions prompt(FakeRemoteOptions o = {}) {
  o.schedule.latency_ns = o.schedule.jitter_ns = 0;
  return o;
}

IrSlots one_blob(uint16_t x, uint16_t y) {
  IrSlots o{};
  o[0] = {.seen = true, .x = x, .y = y, .size = 3};
  return o;
}

}  // namespace

TEST_CASE("fake remote acknowledges only what asks for it, and every memory write") {
  ManualClock clock;
  FakeBus bus(clock.clock());
  bus.add_remote(prompt());
  auto d = open_only(bus);
  for (uint8_t id : {kOutLeds, kOutReportingMode, kOutIrPixelClock, uint8_t{0x14}, uint8_t{0x19}, kOutIrLogic}) {
    write(*d, Bytes{id, 0x00, 0x30});
    CHECK(drain(*d).empty());
    write(*d, Bytes{id, kAckRequestBit, 0x30});
    const auto acks = drain(*d);
    REQUIRE(acks.size() == 1);
    const auto ack = parse_ack(acks[0]);
    REQUIRE(ack);
    CHECK(ack->report_id == id);
    CHECK(ack->error == 0);
  }
  const uint8_t one[] = {0x08};
  write(*d, write_register_report(kRegIrControl, one));
  CHECK(drain(*d).size() == 1);
  // Rumble-only and status requests are never acknowledged; the status request is answered.
  write(*d, Bytes{0x10, 0x02});
  CHECK(drain(*d).empty());
  write(*d, status_request_report());
  const auto status = drain(*d);
  REQUIRE(status.size() == 1);
  CHECK(parse_status(status[0]));
}

TEST_CASE("fake remote drops chosen acknowledgements, or all of them") {
  ManualClock clock;
  FakeBus bus(clock.clock());
  auto remote = bus.add_remote(prompt());
  auto d = open_only(bus);
  remote->drop_acks(kOutIrLogic, 1);
  write(*d, ir_logic_report(true));
  CHECK(drain(*d).empty());
  write(*d, ir_logic_report(true));
  CHECK(drain(*d).size() == 1);
  remote->set_never_ack(true);
  const uint8_t one[] = {0x08};
  write(*d, write_register_report(kRegIrControl, one));
  write(*d, leds_report(0x10, true));
  CHECK(drain(*d).empty());
}

TEST_CASE("fake remote streams on its own clock, stops after a status report, and needs the full set-up for IR") {
  ManualClock clock;
  FakeBus bus(clock.clock());
  auto remote = bus.add_remote(prompt());
  remote->set_blob_source([](int64_t) { return one_blob(512, 300); });
  auto d = open_only(bus);

  // Asked for mode 0x33 without the camera set up: reports come, with no object, and fresh zero slots.
  write(*d, reporting_mode_report(kInIrExtended, true, false));
  clock.advance(100 * kMs);
  auto reports = drain(*d);
  CHECK(reports.size() == 11);  // at 0, 10, ..., 100 ms
  REQUIRE(!reports.empty());
  CHECK(reports.back().size() == 18);
  CHECK(reports.back()[6] == 0x00);  // a fresh remote's empty slot reads 0,0,0 ...
  CHECK(ir_blob_count(reports.back()) == 0);  // ... which is not an object
  CHECK(!remote->camera_working());

  initialise(*d);
  drain(*d);
  CHECK(remote->camera_working());
  CHECK(remote->register_at(kRegIrMode) == kIrModeExtended);
  clock.advance(50 * kMs);
  reports = drain(*d);
  REQUIRE(reports.size() == 5);
  CHECK(ir_blob_count(reports[0]) == 1);
  // The codec the tracker uses reads the same blob back.
  const auto decoded = decode_ir_report(reports[0]);
  REQUIRE(decoded.status == ReportStatus::Ok);
  CHECK(decoded.report.slots[0].seen);
  CHECK(decoded.report.slots[0].x == 512);
  CHECK(decoded.report.slots[0].y == 300);
  CHECK_FALSE(decoded.report.slots[1].seen);

  // After a status report nothing comes until the mode is sent again.
  remote->send_status();
  clock.advance(50 * kMs);
  reports = drain(*d);
  REQUIRE(reports.size() == 1);
  CHECK(reports[0][0] == kInStatus);
  write(*d, reporting_mode_report(kInIrExtended, true, false));
  clock.advance(30 * kMs);
  CHECK(drain(*d).size() == 4);  // the first one at once
}

TEST_CASE("fake remote in a bad state works after a second set-up") {
  ManualClock clock;
  FakeBus bus(clock.clock());
  auto remote = bus.add_remote(prompt());
  remote->set_blob_source([](int64_t) { return one_blob(100, 100); });
  auto d = open_only(bus);
  remote->start_in_bad_state(BadState::WrongMode);
  initialise(*d);
  drain(*d);
  clock.advance(20 * kMs);
  auto reports = drain(*d);
  REQUIRE(!reports.empty());
  CHECK(reports[0][0] == 0x31);
  initialise(*d);
  drain(*d);
  clock.advance(20 * kMs);
  reports = drain(*d);
  REQUIRE(!reports.empty());
  CHECK(reports[0][0] == kInIrExtended);
  CHECK(ir_blob_count(reports[0]) == 1);

  remote->start_in_bad_state(BadState::NoIr);
  initialise(*d);
  drain(*d);
  clock.advance(20 * kMs);
  reports = drain(*d);
  REQUIRE(!reports.empty());
  CHECK(ir_blob_count(reports.back()) == 0);
  CHECK(remote->initialisations() == 3);
}

TEST_CASE("fake remote disappears and comes back as after a power-on") {
  ManualClock clock;
  FakeBus bus(clock.clock());
  auto remote = bus.add_remote(prompt({.address = "00:1F:32:00:00:07"}));
  auto d = open_only(bus);
  bus.add_other_device({.vendor = 0x046D, .product = 0xC52B, .serial = "", .path = "fake:mouse"});
  write(*d, leds_report(0x30, false));
  remote->unplug();
  CHECK(d->read(0).status == ReadStatus::Gone);
  CHECK_FALSE(d->write(leds_report(0x10, false)).ok());
  auto found = bus.enumerate();
  REQUIRE(found.ok());
  CHECK(found->size() == 1);  // the mouse
  remote->plug_in();
  CHECK(d->read(0).status == ReadStatus::Gone);  // an old handle stays dead
  CHECK(remote->leds() == 0);
  found = bus.enumerate();
  REQUIRE(found->size() == 2);
  for (const DeviceInfo& info : *found)
    if (is_wii_remote(info)) CHECK(bus.open(info).ok());
  CHECK(bus.opens("00:1F:32:00:00:07") == 2);
}

TEST_CASE("fake remote holds reports back and releases them late") {
  ManualClock clock;
  FakeBus bus(clock.clock());
  auto remote = bus.add_remote(prompt());
  auto d = open_only(bus);
  write(*d, reporting_mode_report(kInIrExtended, true, false));
  remote->hold_reports(true);
  clock.advance(40 * kMs);
  CHECK(drain(*d).empty());
  remote->hold_reports(false);
  CHECK(drain(*d).size() == 5);  // at 0, 10, ..., 40 ms
}

TEST_CASE("fake remote reports its buttons: at once when it does not stream, in every report when it does") {
  ManualClock clock;
  FakeBus bus(clock.clock());
  auto remote = bus.add_remote(prompt());
  auto d = open_only(bus);
  // A pad: buttons only, reported when they change.
  write(*d, reporting_mode_report(kInButtons, false, false));
  CHECK(drain(*d).empty());
  remote->set_buttons(kButtonA | kButtonLeft);
  std::vector<Bytes> got = drain(*d);
  REQUIRE(got.size() == 1);
  CHECK(got[0] == Bytes{kInButtons, 0x01, 0x08});
  CHECK(core_buttons(got[0]) == uint16_t(kButtonA | kButtonLeft));
  remote->set_buttons(kButtonA | kButtonLeft);  // no change, no report
  CHECK(drain(*d).empty());
  remote->set_buttons(0);
  got = drain(*d);
  REQUIRE(got.size() == 1);
  CHECK(core_buttons(got[0]) == uint16_t{0});
  // Acknowledgements and status reports carry them too.
  remote->set_buttons(kButtonHome);
  drain(*d);
  write(*d, leds_report(player_led(3), true));
  write(*d, status_request_report());
  got = drain(*d);
  REQUIRE(got.size() == 2);
  CHECK(got[0][0] == kInAck);
  CHECK(core_buttons(got[0]) == kButtonHome);
  CHECK(got[1][0] == kInStatus);
  CHECK(core_buttons(got[1]) == kButtonHome);
  // Streaming: a change waits for the next report, which shows it.
  write(*d, reporting_mode_report(kInIrExtended, true, false));
  clock.advance(10 * kMs);
  drain(*d);
  remote->set_buttons(kButtonTwo);
  CHECK(drain(*d).empty());
  clock.advance(10 * kMs);
  got = drain(*d);
  REQUIRE(got.size() == 1);
  CHECK(core_buttons(got[0]) == kButtonTwo);
}

TEST_CASE("core buttons are read only from reports that carry them, whole") {
  CHECK(core_buttons(Bytes{kInButtons, 0xFF, 0xFF}) == kAllButtons);  // the unused bits are not buttons
  CHECK(core_buttons(Bytes{0x3D, 0x01, 0x08}) == std::nullopt);       // 0x3D is all extension bytes
  CHECK(core_buttons(Bytes{kInButtons, 0x01}) == std::nullopt);
  CHECK(core_buttons(Bytes{kInIrExtended, 0x00, 0x04}) == std::nullopt);  // a 0x33 is 18 bytes
  Bytes ir(18, 0);
  ir[0] = kInIrExtended;
  ir[2] = 0x04;
  CHECK(core_buttons(ir) == kButtonB);
  CHECK(core_buttons(Bytes{}) == std::nullopt);
}

TEST_CASE("fake remote answers after its radio latency, never inside the write") {
  ManualClock clock;
  FakeBus bus(clock.clock());
  auto remote = bus.add_remote({});
  const FakeSchedule f = remote->options().schedule;
  REQUIRE(f.latency_ns > 0);
  auto d = open_only(bus);
  write(*d, leds_report(player_led(1), true));
  write(*d, status_request_report());
  CHECK(drain(*d).empty());
  clock.advance(f.latency_ns - kMs);
  CHECK(drain(*d).empty());
  clock.advance(f.jitter_ns + 2 * kMs);
  const auto got = drain(*d);
  REQUIRE(got.size() == 2);  // in the order of the writes
  CHECK(got[0][0] == kInAck);
  CHECK(got[1][0] == kInStatus);
}

TEST_CASE("fake remote refuses camera registers with error 7 until the camera is on") {
  ManualClock clock;
  FakeBus bus(clock.clock());
  auto remote = bus.add_remote(prompt());
  auto d = open_only(bus);
  const uint8_t enable[] = {kIrControlEnable};
  write(*d, write_register_report(kRegIrControl, enable));
  auto got = drain(*d);
  REQUIRE(got.size() == 1);
  REQUIRE(parse_ack(got[0]));
  CHECK(parse_ack(got[0])->error == kAckNoCamera);
  CHECK(remote->register_at(kRegIrControl) == 0);
  write(*d, ir_pixel_clock_report(true));
  write(*d, ir_logic_report(true));
  drain(*d);
  write(*d, write_register_report(kRegIrControl, enable));
  got = drain(*d);
  REQUIRE(got.size() == 1);
  CHECK(parse_ack(got[0])->error == 0);
  CHECK(remote->register_at(kRegIrControl) == kIrControlEnable);
  CHECK(remote->refused_camera_writes() == 1);
}

TEST_CASE("fake remote ignores a reporting mode no remote has") {
  ManualClock clock;
  FakeBus bus(clock.clock());
  auto remote = bus.add_remote(prompt());
  auto d = open_only(bus);
  write(*d, reporting_mode_report(0x29, true, false));
  clock.advance(30 * kMs);
  CHECK(drain(*d).empty());
  CHECK(remote->reporting_mode() == kInButtons);
  CHECK_FALSE(remote->continuous());
}

TEST_CASE("fake remote's empty slots read zeros until each first sees light, one by one") {
  ManualClock clock;
  FakeBus bus(clock.clock());
  auto remote = bus.add_remote(prompt());
  IrSlots shown{};
  remote->set_blob_source([&](int64_t) { return shown; });
  auto d = open_only(bus);
  initialise(*d);
  drain(*d);
  clock.advance(10 * kMs);
  auto got = drain(*d);
  REQUIRE(!got.empty());
  CHECK(std::all_of(got.back().begin() + 6, got.back().end(), [](uint8_t b) { return b == 0; }));
  shown[0] = {.seen = true, .x = 100, .y = 100, .size = 2};
  clock.advance(10 * kMs);
  drain(*d);
  shown[0] = {};
  clock.advance(10 * kMs);
  got = drain(*d);
  REQUIRE(!got.empty());
  const Bytes& r = got.back();
  CHECK(Bytes(r.begin() + 6, r.begin() + 9) == Bytes{0xFF, 0xFF, 0xFF});  // slot 0 is fixed
  CHECK(Bytes(r.begin() + 9, r.begin() + 12) == Bytes{0x00, 0x00, 0x00});  // slot 1 not yet
  CHECK(ir_blob_count(r) == 0);
}

TEST_CASE("fake remote's battery drains with a status report at each step, and an extension switches the camera off") {
  ManualClock clock;
  FakeBus bus(clock.clock());
  FakeRemoteOptions o = prompt();
  o.schedule.battery_step_ns = 1000 * kMs;
  auto remote = bus.add_remote(o);
  auto d = open_only(bus);
  initialise(*d);
  drain(*d);
  REQUIRE(remote->continuous());
  clock.advance(1000 * kMs);
  auto got = drain(*d);
  const auto status = std::find_if(got.begin(), got.end(), [](const Bytes& r) { return r[0] == kInStatus; });
  REQUIRE(status != got.end());
  CHECK(parse_status(*status)->battery == 0xA0 - 1);
  CHECK(parse_status(*status)->camera_on());
  CHECK_FALSE(remote->continuous());

  write(*d, reporting_mode_report(kInIrExtended, true, false));
  remote->extension_event();
  got = drain(*d);
  REQUIRE(!got.empty());
  const auto plugged = parse_status(got.back());
  REQUIRE(plugged);
  CHECK((plugged->flags & kStatusExtension) != 0);
  CHECK_FALSE(plugged->camera_on());
  CHECK_FALSE(remote->camera_working());
}
