// From device reports to pen samples: frame clocks, stray blobs, time offset, interpolation,
// triangulation, pen down/up, and the counting of bad reports.
#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "systems/tracking/track.hpp"
#include "tests/systems/triangulate/exact_pen.hpp"

using namespace fire;
using namespace fire::tracking;

using namespace fire::tracking::test;

TEST_CASE("the frame clock is recovered from jittered arrival times with lost reports") {
  CameraFrames f;
  std::vector<double> exposure;
  uint64_t state = 12345;
  auto jitter_us = [&] {  // deterministic, uniform in [-1500, 1500]
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return (static_cast<double>(state >> 11) * 0x1.0p-53 - 0.5) * 3000.0;
  };
  for (int k = 0; k < 600; ++k) {
    const double e = 1000.0 + k * 10000.5;
    // Now and then a report comes more than half a period late or early.
    const double arrival = e + 6000 + jitter_us() + (k % 97 == 13 ? 7000 : k % 89 == 7 ? -6500 : 0);
    if (k == 5 || k == 50 || k == 51 || k == 300) continue;  // lost reports
    exposure.push_back(e);
    f.t_us.push_back(std::llround(arrival));
    f.line.push_back(0);
    f.t_frame_us.push_back(arrival);
    f.blob_count.push_back(0);
    f.blobs.emplace_back();
  }
  fit_frame_clock(f);
  double worst = 0;
  for (size_t k = 0; k < f.size(); ++k) worst = std::max(worst, std::abs(f.t_frame_us[k] - (exposure[k] + 6000)));
  CHECK(worst < 250);  // from +-1500 us of jitter and the stragglers
  for (size_t k = 1; k < f.size(); ++k) CHECK(f.t_frame_us[k] > f.t_frame_us[k - 1]);
}

TEST_CASE("static blobs are removed, a moving one is kept") {
  CameraFrames f;
  for (int k = 0; k < 120; ++k)
    push_frame(f, k * 1e4, {Vec2(300 + 3.0 * k, 200), Vec2(700 + (k % 2), 500)});
  const size_t removed = remove_static_blobs(f);
  CHECK(removed == 120);
  for (size_t k = 0; k < f.size(); ++k) {
    REQUIRE(f.blob_count[k] == 1);
    CHECK(f.blobs[k][0].x() == 300 + 3.0 * static_cast<double>(k));
  }
}

TEST_CASE("bad device reports are counted and skipped, the good ones are kept") {
  auto hid = [](int device, std::vector<uint8_t> bytes, bool ok = true) {
    InputEvent e;
    e.kind = EventKind::Hid;
    e.device = device;
    e.bytes = std::move(bytes);
    e.hid_ok = ok;
    return e;
  };
  IrReport r;
  r.slots[0] = IrSlot{true, 100, 200, 3};
  const std::vector<uint8_t> good = encode_ir_report(r);
  std::vector<uint8_t> truncated(good.begin(), good.begin() + 9);
  std::vector<uint8_t> foreign = good;
  foreign[0] = 0x99;
  std::vector<uint8_t> out_of_range = good;
  out_of_range[7] = 0x20;  // y low byte with high bits 11 from below: y = 800
  out_of_range[8] = 0xC3;
  std::vector<InputEvent> events{hid(0, good),       hid(0, {}, false), hid(1, truncated), hid(0, foreign),
                                 hid(1, {0x22, 0, 0, 0x12, 0}), hid(7, good), hid(1, out_of_range), hid(1, good)};
  InputEvent pen;
  pen.kind = EventKind::Pen;
  pen.p = Vec3(std::nan(""), 0, 0);
  events.push_back(pen);
  const DeviceStreams s = decode_device_streams(events);
  CHECK(s.counts.ir_reports == 3);
  CHECK(s.counts.garbled == 1);
  CHECK(s.counts.bad_length == 1);
  CHECK(s.counts.unknown_id == 1);
  CHECK(s.counts.not_ir == 1);
  CHECK(s.counts.unknown_device == 1);
  CHECK(s.counts.out_of_range_slots == 1);
  CHECK(s.counts.rejected_reports() == 4);
  REQUIRE(s.cameras[0].size() == 1);
  REQUIRE(s.cameras[1].size() == 2);
  CHECK(s.cameras[1].blob_count[0] == 0);  // its only blob was out of range
  CHECK(s.cameras[1].blobs[1][0] == Vec2(100, 200));
}

TEST_CASE("cameras are the remotes the log's device records name, the command pad is no camera") {
  auto hid = [](int device, uint16_t x) {
    IrReport r;
    r.slots[0] = IrSlot{true, x, 200, 3};
    InputEvent e;
    e.kind = EventKind::Hid;
    e.device = device;
    e.bytes = encode_ir_report(r);
    return e;
  };
  auto device = [](const std::string& text) {
    InputEvent e;
    e.kind = EventKind::Meta;
    e.name = "device";
    e.text = text;
    return e;
  };
  // Remotes whose device numbers do not follow their roles, a pad, a record that does not read, and a
  // device no record names.
  const std::vector<InputEvent> events{device("0 00:1F:32:AA:BB:02 camera1 0306"),
                                       device("1 00:1f:32:aa:bb:01 camera0 0330"),
                                       device("2 00:1F:32:AA:BB:03 pad 0306"),
                                       device("3 00:1F:32:AA:BB:04 left 0306"),
                                       hid(0, 10),
                                       hid(1, 20),
                                       hid(2, 30),
                                       hid(3, 40),
                                       hid(1, 21)};
  const DeviceStreams s = decode_device_streams(events);
  REQUIRE(s.cameras[0].size() == 2);
  REQUIRE(s.cameras[1].size() == 1);
  CHECK(s.cameras[0].blobs[0][0].x() == 20);
  CHECK(s.cameras[0].blobs[1][0].x() == 21);
  CHECK(s.cameras[1].blobs[0][0].x() == 10);
  CHECK(s.camera_address[0] == "00:1f:32:aa:bb:01");
  CHECK(s.camera_address[1] == "00:1F:32:AA:BB:02");
  CHECK(s.pad_address == "00:1F:32:AA:BB:03");
  CHECK(s.counts.pad_reports == 1);
  CHECK(s.counts.bad_device_records == 1);
  CHECK(s.counts.unknown_device == 1);
  CHECK(s.counts.rejected_reports() == 1);

  // A device whose record names a product that is no Wii Remote's does not take the role it claims.
  const DeviceStreams keyboard = decode_device_streams(std::vector<InputEvent>{
      device("0 00:1F:32:AA:BB:01 camera0 0306"), device("1 00:1F:32:AA:BB:02 camera1 0330"),
      device("2 00:1F:32:AA:BB:07 camera0 c31c"), hid(2, 50), hid(0, 10), hid(1, 20)});
  REQUIRE(keyboard.cameras[0].size() == 1);
  CHECK(keyboard.cameras[0].blobs[0][0].x() == 10);
  CHECK(keyboard.camera_address[0] == "00:1F:32:AA:BB:01");
  CHECK(keyboard.counts.bad_device_records == 1);
  CHECK(keyboard.counts.unknown_device == 1);

  // A log without device records (the simulator's): devices 0 and 1 are cameras 0 and 1.
  const DeviceStreams bare = decode_device_streams(std::vector<InputEvent>{hid(0, 10), hid(1, 20), hid(2, 30)});
  REQUIRE(bare.cameras[0].size() == 1);
  CHECK(bare.cameras[0].blobs[0][0].x() == 10);
  CHECK(bare.counts.unknown_device == 1);
  CHECK(bare.camera_address[0].empty());
}
