// The simulated rig end to end on short sessions: bytes that match the truth, a wand session that calibrates,
// a sketch session that tracks, and a damaged log that still does (the rig alone: tests/platform/simulated_rig/).
#include <catch2/catch.hpp>
#include <algorithm>
#include <sstream>
#include <string>

#include "engine/input_log.hpp"
#include "tests/platform/simulated_rig/sessions.hpp"
#include "tools/simulation/simulate.hpp"
#include "systems/tracking/track.hpp"
#include "systems/triangulate/triangulate.hpp"

using namespace fire;
using namespace fire::tracking;
using namespace fire::simulation;
using namespace fire::simulation::test;

namespace {

// The log as text and read back, as `fire track` sees it.
InputLog through_text(const std::vector<InputEvent>& events) {
  Result<InputLog> log = parse_input_log(format_input_log(events), "simulated");
  REQUIRE(log.ok());
  return *log;
}

// A short wand session calibrated once, shared by the tests that need a rig.
struct Calibrated {
  RigOptions rig;
  WandCalibration cal;
  SessionTruth truth;
};
const Calibrated& calibrated() {
  static const Calibrated c = [] {
    Calibrated out;
    out.rig.seed = 7;
    out.rig.rig_seed = 7;
    out.rig.clock_offset_ms = 5;
    out.rig.focal_error = 0.02;
    Result<SimulatedSession> wand = simulate_wand(out.rig, WandOptions{.duration_s = 12, .length_m = 0.3});
    REQUIRE(wand.ok());
    const InputLog log = through_text(wand->events);
    out.truth = read_session_truth(log.events);
    REQUIRE(out.truth.has_nominal[0]);
    REQUIRE(out.truth.has_wand_length);
    CalibrationOptions options{.nominal0 = out.truth.nominal[0], .nominal1 = out.truth.nominal[1],
                               .wand_length_m = out.truth.wand_length_m, .max_iterations = 100};
    Result<WandCalibration> cal = calibrate_wand_streams(decode_device_streams(log.events), options);
    REQUIRE(cal.ok());
    out.cal = *cal;
    return out;
  }();
  return c;
}

}  // namespace

TEST_CASE("every report holds exactly the rounded images of the true LEDs") {
  RigOptions rig;
  rig.noise_px = 0;
  rig.stray = 0;
  rig.dropout = 0;
  Result<SimulatedSession> s = simulate_wand(rig, WandOptions{.duration_s = 1, .length_m = 0.3});
  REQUIRE(s.ok());
  const InputLog log = through_text(s->events);
  const SessionTruth truth = read_session_truth(log.events);
  REQUIRE(truth.has_cameras);
  size_t checked = 0;
  for (size_t i = 0; i + 1 < log.events.size(); ++i) {
    const InputEvent& e = log.events[i];
    if (e.kind != EventKind::Hid) continue;
    const InputEvent& t = log.events[i + 1];
    REQUIRE(t.kind == EventKind::Truth);
    REQUIRE(t.name == "wand");
    REQUIRE(t.values[0] == e.device);
    REQUIRE(e.bytes.size() == kReport33Size);
    const DecodedReport d = decode_ir_report(e.bytes);
    REQUIRE(d.status == ReportStatus::Ok);
    std::vector<std::pair<int, int>> expected, got;
    for (int led = 0; led < 2; ++led) {
      const Vec3 X(t.values[2 + 3 * led], t.values[3 + 3 * led], t.values[4 + 3 * led]);
      const Vec2 p = truth.cameras[e.device].project(X);
      const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
      if (x >= 0 && x <= 1023 && y >= 0 && y <= 767) expected.emplace_back(x, y);
    }
    for (const IrSlot& slot : d.report.slots)
      if (slot.seen) got.emplace_back(slot.x, slot.y);
    std::sort(expected.begin(), expected.end());
    std::sort(got.begin(), got.end());
    CHECK(got == expected);
    ++checked;
  }
  CHECK(checked > 190);
}

TEST_CASE("a 12 s wand session with a 2 % focal error and a 5 ms clock offset calibrates") {
  const Calibrated& c = calibrated();
  CHECK(c.cal.rig.reprojection_rms_px < 0.35);
  CHECK(std::abs(c.cal.time_offset_used_us - 5000.0) < 300.0);
  CHECK(c.cal.rig.observations_used > 800);
  CHECK(c.cal.static_blobs_removed > 0);  // the stray reflection
  const Result<RigErrors> e = compare_rig(c.cal.rig, c.truth);
  REQUIRE(e.ok());
  CHECK(std::abs(e->baseline_error_mm) < 1.0);
  CHECK(e->rotation_error_deg < 0.1);
  CHECK(std::abs(e->focal_error_px[0]) < 3.0);  // from 26 px wrong
  CHECK(std::abs(e->focal_error_px[1]) < 3.0);
}

TEST_CASE("a wand session with Bluetooth bursts calibrates as well as one without") {
  // 10 % of the reports held back and delivered with the next one: numbering them as the frames after a
  // lost report put camera 0's and camera 1's instants a period apart (0.80 px at 0.3 ms of jitter);
  // using a held report's arrival as a measurement of its frame still gave 0.93 px at 4 ms.
  // Bounds: 0.3 ms gives 0.23 px and 22 us; 4 ms, 0.35 px and 0.44 ms here (a 20 s wand; the 60 s one of
  // perf/tracking_jitter.sh gives 0.24 px).
  struct Case {
    double jitter_ms, max_px, max_offset_error_us;
  };
  for (const auto [jitter_ms, max_px, max_offset_error_us] : {Case{0.3, 0.3, 100}, Case{4.0, 0.45, 1000}}) {
    CAPTURE(jitter_ms);
    RigOptions rig;
    rig.seed = 3;
    rig.rig_seed = 3;
    rig.burst = 0.1;
    rig.jitter_ms = jitter_ms;
    Result<SimulatedSession> wand = simulate_wand(rig, WandOptions{.duration_s = 20, .length_m = 0.3});
    REQUIRE(wand.ok());
    const InputLog log = through_text(wand->events);
    const SessionTruth truth = read_session_truth(log.events);
    CalibrationOptions options{.nominal0 = truth.nominal[0], .nominal1 = truth.nominal[1],
                               .wand_length_m = truth.wand_length_m, .max_iterations = 100};
    Result<WandCalibration> cal = calibrate_wand_streams(decode_device_streams(log.events), options);
    REQUIRE(cal.ok());
    CHECK(cal->rig.reprojection_rms_px < max_px);
    CHECK(std::abs(cal->time_offset_used_us - rig.clock_offset_ms * 1e3) < max_offset_error_us);
  }
}

TEST_CASE("a short sketch session tracks within a millimetre or two") {
  const Calibrated& c = calibrated();
  Result<SimulatedSession> sketch = simulate_sketch(c.rig, short_sketch(), pawn().view());
  REQUIRE(sketch.ok());
  CHECK(sketch->stats.strokes == 3);
  const InputLog log = through_text(sketch->events);
  DeviceStreams streams = decode_device_streams(log.events);
  for (CameraFrames& f : streams.cameras) fit_frame_clock(f);
  const TimeOffsetEstimate offset = estimate_time_offset(streams, c.cal.rig.cam0, c.cal.rig.cam1);
  REQUIRE(offset.observable);
  CHECK(std::abs(offset.offset_us - 5000.0) < 300.0);
  // The triangulation system, started from no offset at all, finds it from the pen's motion as it goes.
  TrackingRig rig{c.cal.rig.cam0, c.cal.rig.cam1, 0.0, true, PenTrackOptions{}};
  PenTrack track;
  TriangulateState state;
  track_log(log.events, rig, track, &state);
  CHECK(state.offset_estimates > 0);
  CHECK(std::abs(state.time_offset_us - 5000.0) < 300.0);
  CHECK(track.strokes == 3);
  const Result<PenAccuracy> acc = evaluate_pen_accuracy(track, read_session_truth(log.events), 0.25);
  REQUIRE(acc.ok());
  CHECK(acc->static_filtered.samples > 100);
  CHECK(acc->dynamic_filtered.samples > 50);
  CHECK(acc->static_filtered.rms_mm < 1.0);
  CHECK(acc->dynamic_filtered.rms_mm < 2.0);
  CHECK(acc->phantom == 0);
  CHECK(acc->unmatched == 0);
}

TEST_CASE("reports held back in bursts cost the pen's moving accuracy little at low jitter") {
  // A fifth of the reports held and delivered with the next: the frame clock's line must not take their
  // arrivals, a period late, as the remote's (they pulled it 2 ms late and doubled the raw moving error).
  const Calibrated& c = calibrated();
  auto dynamic_raw_mm = [&](double burst) {
    RigOptions rig = c.rig;
    rig.burst = burst;
    Result<SimulatedSession> sketch = simulate_sketch(rig, short_sketch(), pawn().view());
    REQUIRE(sketch.ok());
    const InputLog log = through_text(sketch->events);
    TrackingRig tracking_rig{c.cal.rig.cam0, c.cal.rig.cam1, 5000.0, false, PenTrackOptions{}};
    PenTrack track;
    track_log(log.events, tracking_rig, track, nullptr);
    const Result<PenAccuracy> acc = evaluate_pen_accuracy(track, read_session_truth(log.events), 0.25);
    REQUIRE(acc.ok());
    REQUIRE(acc->dynamic_raw.samples > 50);
    return acc->dynamic_raw.rms_mm;
  };
  const double steady = dynamic_raw_mm(0.0), bursts = dynamic_raw_mm(0.2);
  INFO("raw moving error: " << steady << " mm without bursts, " << bursts << " mm with 20 % of reports held");
  CHECK(bursts < 1.4 * steady);
}

TEST_CASE("a damaged log: bad reports and NaN lines are counted, the rest still tracks") {
  const Calibrated& c = calibrated();
  Result<SimulatedSession> sketch = simulate_sketch(c.rig, short_sketch(), pawn().view());
  REQUIRE(sketch.ok());
  // Damage the text the way a failing device or disk would: every 40th report garbled, truncated,
  // with an unknown id, with an impossible y, or from a device that does not exist.
  std::istringstream in(format_input_log(sketch->events));
  std::string text, line;
  size_t reports = 0;
  size_t garbled = 0, truncated = 0, foreign = 0, out_of_range = 0, stranger = 0;
  bool nan_written = false;
  while (std::getline(in, line)) {
    const size_t at = line.find(" hid ");
    if (at != std::string::npos) {
      const size_t hex = line.find(' ', at + 5) + 1;
      switch (reports++ % 40) {
        case 3: line += "z"; ++garbled; break;
        case 11: line.resize(hex + 20); ++truncated; break;
        case 19: line.replace(hex, 2, "99"); ++foreign; break;
        case 27: line.replace(hex + 12, 6, "0520c0"); ++out_of_range; break;  // slot 0: y = 800
        case 35: line[at + 5] = '7'; ++stranger; break;
        default: break;
      }
    }
    text += line + "\n";
    if (!nan_written && at != std::string::npos && reports > 200) {
      const std::string t = line.substr(0, line.find(' '));
      text += t + " pen nan 0 0\n" + t + " truth pen 0 nan 0 0 0 1 0 0\n";
      nan_written = true;
    }
  }
  Result<InputLog> log = parse_input_log(text, "damaged");
  REQUIRE(log.ok());
  CHECK(log->rejected_hid_lines == garbled);
  const SessionTruth truth = read_session_truth(log->events);
  CHECK(truth.rejected_lines == 1);
  DeviceStreams streams = decode_device_streams(log->events);
  CHECK(streams.counts.garbled == garbled);
  CHECK(streams.counts.bad_length == truncated);
  CHECK(streams.counts.unknown_id == foreign);
  CHECK(streams.counts.unknown_device == stranger);
  CHECK(streams.counts.out_of_range_slots == out_of_range);
  CHECK(streams.counts.rejected_reports() == garbled + truncated + foreign + stranger);
  TrackingRig rig{c.cal.rig.cam0, c.cal.rig.cam1, c.cal.time_offset_used_us, true, PenTrackOptions{}};
  PenTrack track;
  track_log(log->events, rig, track);
  CHECK(track.strokes == 3);
  for (const InputEvent& e : pen_events(track))
    if (e.kind == EventKind::Pen) REQUIRE(e.p.allFinite());
  const Result<PenAccuracy> acc = evaluate_pen_accuracy(track, truth, 0.25);
  REQUIRE(acc.ok());
  CHECK(acc->static_filtered.rms_mm < 1.0);
  CHECK(acc->dynamic_filtered.rms_mm < 2.0);
}
