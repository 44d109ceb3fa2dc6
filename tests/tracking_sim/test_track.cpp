// From device reports to pen samples: frame clocks, stray blobs, time offset, interpolation,
// triangulation, pen down/up, and the counting of bad reports.
#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "systems/tracking/track.hpp"

using namespace fire;
using namespace fire::tracking;

namespace {

Camera look_at(const Vec3& centre, const Vec3& target, double k1) {
  const Vec3 z = (target - centre).normalized();
  const Vec3 y = (Vec3::UnitY() - Vec3::UnitY().dot(z) * z).normalized();
  Eigen::Matrix3d R;
  R.row(0) = y.cross(z);
  R.row(1) = y;
  R.row(2) = z;
  Intrinsics K = wiimote_nominal_intrinsics();
  K.k1 = k1;
  return Camera{K, R, -R * centre};
}

struct Rig {
  Camera c0 = look_at(Vec3(-0.25, 0, 0), Vec3(0, 0, 0.8), 0.03);
  Camera c1 = look_at(Vec3(0.25, 0, 0), Vec3(0, 0, 0.8), 0.02);
};

// A pen tip moving on a smooth closed path in front of the rig (t in seconds).
Vec3 pen_path(double t) {
  return Vec3(0.08 * std::sin(2.1 * t), 0.06 * std::sin(3.3 * t + 0.4), 0.8 + 0.05 * std::cos(1.7 * t));
}

void push_frame(CameraFrames& f, double t_us, std::initializer_list<Vec2> blobs) {
  f.t_us.push_back(std::llround(t_us));
  f.t_frame_us.push_back(t_us);
  std::array<Vec2, kIrSlots> b;
  b.fill(Vec2::Zero());
  uint8_t n = 0;
  for (const Vec2& p : blobs) b[n++] = p;
  f.blob_count.push_back(n);
  f.blobs.push_back(b);
}

// Exact (unrounded, noise-free) blobs: camera 0 exposes at 10 ms steps, camera 1 at 10.001 ms
// steps from a 3.7 ms phase; camera 1 stamps every instant `offset_us` late. From `stray_from_s`
// on, camera 1 also sees a stray blob exactly on the pen's epipolar line: the image of a point
// 25 % farther along camera 0's ray through the pen.
DeviceStreams exact_streams(const Rig& rig, double seconds, double offset_us, double stray_from_s) {
  DeviceStreams s;
  for (double t = 0.0; t < seconds; t += 0.010) push_frame(s.cameras[0], t * 1e6, {rig.c0.project(pen_path(t))});
  for (double t = 0.0037; t < seconds; t += 0.010001) {
    const Vec2 pen = rig.c1.project(pen_path(t));
    const Vec3 ghost = rig.c0.centre() + 1.25 * (pen_path(t) - rig.c0.centre());
    if (t >= stray_from_s)
      push_frame(s.cameras[1], t * 1e6 + offset_us, {rig.c1.project(ghost), pen});
    else
      push_frame(s.cameras[1], t * 1e6 + offset_us, {pen});
  }
  return s;
}

}  // namespace

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

TEST_CASE("time offset, interpolation and triangulation recover an exactly observed pen") {
  const Rig rig;
  const DeviceStreams s = exact_streams(rig, 6.0, 5000.0, 1e9);
  const TimeOffsetEstimate offset = estimate_time_offset(s, rig.c0, rig.c1);
  REQUIRE(offset.observable);
  CHECK(std::abs(offset.offset_us - 5000.0) < 20.0);
  CHECK(offset.cost_px < 0.05);
  CHECK(offset.cost_at_zero_px > 10 * offset.cost_px);

  const PenTrack track = track_pen(s, rig.c0, rig.c1, 5000.0, PenTrackOptions{});
  CHECK(track.strokes == 1);
  CHECK(track.rejected_reprojection == 0);
  REQUIRE(track.samples.size() > 550);
  double worst = 0;
  for (const PenSample& p : track.samples) {
    const double t = static_cast<double>(p.t_us) * 1e-6;
    worst = std::max(worst, (p.raw - pen_path(t)).norm());
  }
  // What remains is the linear interpolation of camera 1 over 10 ms of a curved path.
  CHECK(worst < 1e-4);
}

TEST_CASE("a stray blob on the pen's epipolar line in one camera is never taken for the pen") {
  const Rig rig;
  SECTION("it appears while the pen is down: the pair nearest the last position wins") {
    const DeviceStreams s = exact_streams(rig, 3.0, 0.0, 0.5);
    const PenTrack track = track_pen(s, rig.c0, rig.c1, 0.0, PenTrackOptions{});
    CHECK(track.strokes == 1);
    REQUIRE(track.samples.size() > 290);
    for (const PenSample& p : track.samples)
      CHECK((p.raw - pen_path(static_cast<double>(p.t_us) * 1e-6)).norm() < 1e-4);
  }
  SECTION("it is there from the start: no stroke starts while two points fit") {
    const DeviceStreams s = exact_streams(rig, 1.0, 0.0, 0.0);
    const PenTrack track = track_pen(s, rig.c0, rig.c1, 0.0, PenTrackOptions{});
    CHECK(track.samples.empty());
    CHECK(track.ambiguous > 90);
  }
}

TEST_CASE("the pen goes up when the LED is gone longer than the gap, and pen_events writes strokes") {
  const Rig rig;
  DeviceStreams s;
  // Both cameras dark for 40 ms (bridged), camera 0 alone for 300 ms (a hand passing: followed on camera
  // 1's ray), both for 500 ms (the pen lifted).
  auto dark_both = [](double t) { return (t >= 1.0 && t < 1.04) || (t >= 2.0 && t < 2.5); };
  auto dark_0 = [&](double t) { return dark_both(t) || (t >= 1.5 && t < 1.8); };
  for (double t = 0.0; t < 3.0; t += 0.010) {
    if (!dark_0(t))
      push_frame(s.cameras[0], t * 1e6, {rig.c0.project(pen_path(t))});
    else
      push_frame(s.cameras[0], t * 1e6, {});
  }
  for (double t = 0.005; t < 3.0; t += 0.010) {
    if (!dark_both(t))
      push_frame(s.cameras[1], t * 1e6, {rig.c1.project(pen_path(t))});
    else
      push_frame(s.cameras[1], t * 1e6, {});
  }
  const PenTrack track = track_pen(s, rig.c0, rig.c1, 0.0, PenTrackOptions{});
  CHECK(track.strokes == 2);
  CHECK(track.bridged_frames >= 25);
  const std::vector<InputEvent> ev = pen_events(track);
  REQUIRE(ev.size() == track.samples.size() + 4);
  CHECK(ev.front().kind == EventKind::Down);
  CHECK(ev.back().kind == EventKind::Up);
  int downs = 0, ups = 0;
  for (size_t k = 0; k < ev.size(); ++k) {
    downs += ev[k].kind == EventKind::Down;
    ups += ev[k].kind == EventKind::Up;
    if (k > 0) CHECK(ev[k].t_us >= ev[k - 1].t_us);
    if (ev[k].kind == EventKind::Pen) CHECK(ev[k].p.allFinite());
  }
  CHECK(downs == 2);
  CHECK(ups == 2);

  const std::vector<InputEvent> shaped = pen_events(track, StrokeShaping{.simplify_tolerance = 0, .resample_spacing = 0.005});
  std::vector<Vec3> stroke;
  for (const InputEvent& e : shaped) {
    if (e.kind == EventKind::Up) break;
    if (e.kind == EventKind::Pen) stroke.push_back(e.p);
  }
  REQUIRE(stroke.size() > 10);
  for (size_t k = 1; k + 1 < stroke.size(); ++k) CHECK(std::abs((stroke[k] - stroke[k - 1]).norm() - 0.005) < 1e-4);
}

TEST_CASE("after both cameras lose the pen, it continues the stroke only where a hand could have moved it") {
  const Rig rig;
  for (const double jump_m : {0.0, 0.3}) {
    INFO("jump " << jump_m);
    // Both cameras dark for 200 ms; then the pen is seen on its path again, or 30 cm away from it.
    auto where = [&](double t) -> Vec3 { return pen_path(t) + Vec3(t >= 1.2 ? jump_m : 0.0, 0, 0); };
    auto dark = [](double t) { return t >= 1.0 && t < 1.2; };
    DeviceStreams s;
    for (double t = 0.0; t < 2.0; t += 0.010) {
      if (dark(t)) push_frame(s.cameras[0], t * 1e6, {});
      else push_frame(s.cameras[0], t * 1e6, {rig.c0.project(where(t))});
    }
    for (double t = 0.005; t < 2.0; t += 0.010) {
      if (dark(t)) push_frame(s.cameras[1], t * 1e6, {});
      else push_frame(s.cameras[1], t * 1e6, {rig.c1.project(where(t))});
    }
    const PenTrack track = track_pen(s, rig.c0, rig.c1, 0.0, PenTrackOptions{});
    CHECK(track.strokes == (jump_m > 0 ? 2u : 1u));
    CHECK(track.rejected_jump == 0);
  }
}

TEST_CASE("bad device reports are counted and skipped; the good ones are kept") {
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

TEST_CASE("cameras are the remotes the log's device records name; the command pad is no camera") {
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

  // A log without device records (the simulator's): devices 0 and 1 are cameras 0 and 1.
  const DeviceStreams bare = decode_device_streams(std::vector<InputEvent>{hid(0, 10), hid(1, 20), hid(2, 30)});
  REQUIRE(bare.cameras[0].size() == 1);
  CHECK(bare.cameras[0].blobs[0][0].x() == 10);
  CHECK(bare.counts.unknown_device == 1);
  CHECK(bare.camera_address[0].empty());
}
