// The triangulation system: pen samples from exactly observed reports, fed frame by frame as they would
// arrive; strokes through occlusions; the pen's events as the system emits them.
#include <catch2/catch.hpp>
#include <cmath>

#include "systems/triangulate/triangulate.hpp"
#include "tests/systems/triangulate/exact_pen.hpp"

using namespace fire;
using namespace fire::tracking;
using namespace fire::tracking::test;

namespace {

// The system over two cameras' reports, fed per 10 ms frame in arrival order, until it is no longer busy.
// The reports' instants are exact, so the frame clock the system fits has nothing to correct.
struct SystemRun {
  PenTrack track;
  std::vector<InputEvent> events;
  TriangulateState state;
};

SystemRun run_system_full(const DeviceStreams& s, const Rig& rig, double offset_us, bool estimate = false) {
  const TrackingRig live{rig.c0, rig.c1, offset_us, estimate, PenTrackOptions{}};
  SystemRun run;
  std::array<size_t, 2> next{0, 0};
  int64_t end = 10'000;
  auto pending = [&] { return next[0] < s.cameras[0].size() || next[1] < s.cameras[1].size(); };
  while (pending() || run.state.busy()) {
    for (int c = 0; c < 2; ++c) {
      const CameraFrames& f = s.cameras[c];
      for (; next[c] < f.size() && f.t_us[next[c]] < end; ++next[c]) {
        CameraReport r;
        r.camera = c;
        r.t_us = f.t_us[next[c]];
        r.blob_count = f.blob_count[next[c]];
        r.blobs = f.blobs[next[c]];
        triangulate_report(live, run.state, r);
      }
    }
    triangulate_advance(end, live, run.state, run.events, &run.track.samples);
    end += 10'000;
    REQUIRE(end < 1'000'000'000);
  }
  static_cast<PenCounts&>(run.track) = run.state.counts;
  return run;
}

PenTrack run_system(const DeviceStreams& s, const Rig& rig, double offset_us) {
  return run_system_full(s, rig, offset_us).track;
}

// Every sample within 0.1 mm of where the pen was at its instant (`where`: seconds -> position).
template <class Where>
void check_on_path(const std::vector<PenSample>& samples, Where where) {
  for (const PenSample& p : samples) CHECK((p.raw - where(static_cast<double>(p.t_us) * 1e-6)).norm() < 1e-4);
}

}  // namespace

TEST_CASE("time offset, interpolation and triangulation recover an exactly observed pen") {
  const Rig rig;
  const DeviceStreams s = exact_streams(rig, 6.0, 5000.0, 1e9);
  const TimeOffsetEstimate offset = estimate_time_offset(s, rig.c0, rig.c1);
  REQUIRE(offset.observable);
  CHECK(std::abs(offset.offset_us - 5000.0) < 20.0);
  CHECK(offset.cost_px < 0.05);
  CHECK(offset.cost_at_zero_px > 10 * offset.cost_px);

  const PenTrack track = run_system(s, rig, 5000.0);
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
    const PenTrack track = run_system(s, rig, 0.0);
    CHECK(track.strokes == 1);
    REQUIRE(track.samples.size() > 290);
    check_on_path(track.samples, pen_path);
  }
  SECTION("it is there from the start: no stroke starts while two points fit") {
    const DeviceStreams s = exact_streams(rig, 1.0, 0.0, 0.0);
    const PenTrack track = run_system(s, rig, 0.0);
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
  const PenTrack track = run_system(s, rig, 0.0);
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
    const PenTrack track = run_system(s, rig, 0.0);
    CHECK(track.strokes == (jump_m > 0 ? 2u : 1u));
    CHECK(track.rejected_jump == 0);
  }
}


TEST_CASE("a lifted pen is not held down by a reflection one camera sees near where it vanished") {
  const Rig rig;
  // The pen draws for 1 s and is lifted; from 1.1 s camera 1 sees a still reflection 30 px from the pen's
  // last blob there; at 1.6 s the pen is put down again 7 cm away. Two strokes, as drawn.
  const Vec2 reflection = rig.c1.project(pen_path(1.0)) + Vec2(24, 18);
  auto where = [](double t) -> Vec3 { return pen_path(t) + Vec3(t >= 1.6 ? 0.07 : 0.0, 0, 0); };
  auto lifted = [](double t) { return t >= 1.0 && t < 1.6; };
  // From `shines` on, the reflection is in camera 1's frames: after the pen vanished (0.1 s into the lift),
  // or all along, beside the pen while it draws.
  for (const double shines : {1.1, 0.0}) {
    INFO("the reflection from " << shines << " s");
    DeviceStreams s;
    for (double t = 0.0; t < 2.2; t += 0.010) {
      if (lifted(t)) push_frame(s.cameras[0], t * 1e6, {});
      else push_frame(s.cameras[0], t * 1e6, {rig.c0.project(where(t))});
    }
    for (double t = 0.005; t < 2.2; t += 0.010) {
      const Vec2 pen = rig.c1.project(where(t));
      if (t < shines) push_frame(s.cameras[1], t * 1e6, {pen});
      else if (lifted(t)) push_frame(s.cameras[1], t * 1e6, {reflection});
      else push_frame(s.cameras[1], t * 1e6, {pen, reflection});
    }
    const SystemRun run = run_system_full(s, rig, 0.0);
    CHECK(run.track.strokes == 2);
    check_on_path(run.track.samples, where);
  }
}

TEST_CASE("a light that shone merged with the pen's blob and split from it is not taken for the pen") {
  const Rig rig;
  // The pen moves at 0.3 m/s (5 px per frame in camera 1) and passes a still light that camera 1 sees 4 px
  // off the pen's epipolar line. Within a sensor pixel (8 px) the two are one blob at their mean, and the
  // link from that blob goes on to the still light, the nearer of the two as they part. The pen stops
  // 40 ms after they part, is lifted at 0.7 s and put down again 5 cm lower at 1.3 s: two strokes, as drawn.
  constexpr double kAppears = 0.3, kStops = 0.385, kLifted = 0.7, kDownAgain = 1.3;
  auto where = [&](double t) -> Vec3 {
    const Vec3 line(-0.05 + 0.3 * std::min(t, kStops), 0.02, 0.8);
    return t < kDownAgain ? line : line + Vec3(0, 0.05, 0);
  };
  const Vec2 light = rig.c1.project(where(kAppears)) + Vec2(12, 4);
  auto lifted = [&](double t) { return t >= kLifted && t < kDownAgain; };
  DeviceStreams s;
  for (double t = 0.0; t < 2.0; t += 0.010) {
    if (lifted(t)) push_frame(s.cameras[0], t * 1e6, {});
    else push_frame(s.cameras[0], t * 1e6, {rig.c0.project(where(t))});
  }
  int merged = 0;
  for (double t = 0.005; t < 2.0; t += 0.010) {
    const Vec2 pen = rig.c1.project(where(t));
    if (t < kAppears) {
      push_frame(s.cameras[1], t * 1e6, {pen});
    } else if (lifted(t)) {
      push_frame(s.cameras[1], t * 1e6, {light});
    } else if ((pen - light).norm() < 8) {
      push_frame(s.cameras[1], t * 1e6, {0.5 * (pen + light)});
      ++merged;
    } else {
      push_frame(s.cameras[1], t * 1e6, {pen, light});
    }
  }
  REQUIRE(merged >= 1);
  const PenTrack track = run_system(s, rig, 0.0);
  CHECK(track.strokes == 2);
  // The merged blob's samples, and the one interpolated from it, lie between the pen and where the light
  // pairs; every other is the pen's.
  int off = 0;
  for (const PenSample& p : track.samples) {
    const double error = (p.raw - where(static_cast<double>(p.t_us) * 1e-6)).norm();
    CHECK(error < 0.01);
    off += error > 1e-4;
  }
  CHECK(off <= merged + 1);
}

TEST_CASE("a lamp merged with a resting pen's blob, shining on after the pen goes out, does not hold it down") {
  // As on the pawn's seed 2 measured by touch: the pen rests at a stroke's end where camera 1 sees it beside a
  // still lamp, one blob with it; it goes out at 1.0 s; camera 1 shows nothing for 40 ms, then the lamp alone,
  // a few pixels off, whose ray passes within millimetres of the pen. The pen is put down 5 cm away at 1.5 s,
  // 0.5 s later, within the time one camera may follow it alone: two strokes, as drawn, not one.
  const Rig rig;
  constexpr double kRests = 0.6, kOut = 1.0, kDark = 1.04, kDownAgain = 1.5;
  auto where = [&](double t) -> Vec3 {
    const Vec3 line(-0.05 + 0.2 * std::min(t, kRests), 0.02, 0.8);
    return t < kDownAgain ? line : line + Vec3(0, 0.05, 0);
  };
  const Vec2 lamp = rig.c1.project(where(kRests)) + Vec2(3, 2);
  auto lifted = [&](double t) { return t >= kOut && t < kDownAgain; };
  DeviceStreams s;
  for (double t = 0.0; t < 2.0; t += 0.010) {
    if (lifted(t)) push_frame(s.cameras[0], t * 1e6, {});
    else push_frame(s.cameras[0], t * 1e6, {rig.c0.project(where(t))});
  }
  for (double t = 0.005; t < 2.0; t += 0.010) {
    const Vec2 pen = rig.c1.project(where(t));
    if (t < kRests - 0.1) push_frame(s.cameras[1], t * 1e6, {pen});
    else if (t < kOut) push_frame(s.cameras[1], t * 1e6, {0.5 * (pen + lamp)});
    else if (t < kDark) push_frame(s.cameras[1], t * 1e6, {});
    else if (lifted(t)) push_frame(s.cameras[1], t * 1e6, {lamp});
    else push_frame(s.cameras[1], t * 1e6, {pen, lamp});
  }
  const SystemRun run = run_system_full(s, rig, 0.0);
  CHECK(run.track.strokes == 2);
  // No sample while the pen is out; those of the merged blob lie off by its share of the lamp.
  for (const PenSample& p : run.track.samples) {
    const double t = static_cast<double>(p.t_us) * 1e-6;
    CHECK(!lifted(t));
    if (t < kRests - 0.1 || t >= kDownAgain) CHECK((p.raw - where(t)).norm() < 1e-4);
  }
}

TEST_CASE("a reflection level with the pen in camera 1 is not paired with camera 0's pen as it lights or goes out") {
  const Rig rig;
  // A reflection on the pen's epipolar line in camera 1, 4 % farther along camera 0's ray (3 cm deeper,
  // about 33 px from the pen): camera 0's pen fits it within the distance a hand moves the pen in a frame.
  auto reflection = [&](double t) {
    return rig.c1.project(rig.c0.centre() + 1.04 * (pen_path(t) - rig.c0.centre()));
  };
  SECTION("the pen goes out between camera 1's exposure and camera 0's: the stroke ends where it was") {
    // Lit until 0.992 s: camera 0's frame at 0.990 s still sees it, camera 1's at 0.995 s only the reflection.
    auto lit = [](double t) { return t < 0.992; };
    DeviceStreams s;
    for (double t = 0.0; t < 1.6; t += 0.010)
      if (lit(t)) push_frame(s.cameras[0], t * 1e6, {rig.c0.project(pen_path(t))});
      else push_frame(s.cameras[0], t * 1e6, {});
    for (double t = 0.005; t < 1.6; t += 0.010) {
      if (t < 0.3) push_frame(s.cameras[1], t * 1e6, {rig.c1.project(pen_path(t))});
      else if (lit(t)) push_frame(s.cameras[1], t * 1e6, {rig.c1.project(pen_path(t)), reflection(t)});
      else push_frame(s.cameras[1], t * 1e6, {reflection(t)});
    }
    const PenTrack track = run_system(s, rig, 0.0);
    CHECK(track.strokes == 1);
    REQUIRE(track.samples.size() > 90);
    check_on_path(track.samples, pen_path);
  }
  SECTION("the pen lights between camera 1's exposure and camera 0's: the stroke starts on the pair lit together") {
    // Lit from 0.048 s: camera 0's frame at 0.050 s sees it, camera 1's at 0.045 s only the reflection,
    // which shines until 0.1 s. At 0.050 s the reflection is the only light camera 1 can be interpolated
    // with, so the start waits; from 0.060 s the pen's pair, lit in both cameras at once, starts it.
    DeviceStreams s;
    for (double t = 0.0; t < 1.0; t += 0.010)
      if (t >= 0.048) push_frame(s.cameras[0], t * 1e6, {rig.c0.project(pen_path(t))});
      else push_frame(s.cameras[0], t * 1e6, {});
    for (double t = 0.005; t < 1.0; t += 0.010) {
      if (t < 0.048) push_frame(s.cameras[1], t * 1e6, {reflection(t)});
      else if (t < 0.1) push_frame(s.cameras[1], t * 1e6, {reflection(t), rig.c1.project(pen_path(t))});
      else push_frame(s.cameras[1], t * 1e6, {rig.c1.project(pen_path(t))});
    }
    const PenTrack track = run_system(s, rig, 0.0);
    CHECK(track.strokes == 1);
    CHECK(track.ambiguous == 1);
    REQUIRE(track.samples.size() > 90);
    CHECK(track.samples.front().t_us == 60'000);
    check_on_path(track.samples, pen_path);
  }
  SECTION("a lamp level with a resting pen that lights as the pen goes out does not take its place") {
    // The pen rests until 0.992 s. Camera 1's last frame with it (0.985 s) also shows a lamp on its epipolar
    // line, 6 % farther along camera 0's ray (5 cm deeper), and camera 0's last frame (0.990 s) pairs only with
    // that lamp: camera 1's pen does not go on into a later frame. A resting pen does not jump 5 cm in a frame,
    // so the stroke ends where it was; the pen goes down again 4 cm away at 1.6 s, a second stroke.
    const Vec3 rest = pen_path(0.5), next = rest + Vec3(0.04, 0, 0);
    const Vec2 lamp = rig.c1.project(rig.c0.centre() + 1.06 * (rest - rig.c0.centre()));
    auto where = [&](double t) { return t < 1.0 ? rest : next; };
    auto lit = [](double t) { return t < 0.992 || t >= 1.6; };
    DeviceStreams s;
    for (double t = 0.0; t < 2.2; t += 0.010)
      if (lit(t)) push_frame(s.cameras[0], t * 1e6, {rig.c0.project(where(t))});
      else push_frame(s.cameras[0], t * 1e6, {});
    for (double t = 0.005; t < 2.2; t += 0.010) {
      if (t < 0.98) push_frame(s.cameras[1], t * 1e6, {rig.c1.project(where(t))});
      else if (lit(t)) push_frame(s.cameras[1], t * 1e6, {rig.c1.project(where(t)), lamp});
      else push_frame(s.cameras[1], t * 1e6, {lamp});
    }
    const PenTrack track = run_system(s, rig, 0.0);
    CHECK(track.strokes == 2);
    REQUIRE(track.samples.size() > 90);
    check_on_path(track.samples, where);
  }
  SECTION("a lamp level with the pen that shone before the pen lit does not hold the start back") {
    // The pen rests on a mark, lit from 0.595 s to 1.4 s; camera 1 sees the lamp from 0.3 s on. Both pairs fit
    // from the first frame: the pen's, lit in both cameras at once, starts the stroke there, and the lamp's,
    // which shone 0.3 s before camera 0 saw anything, does not hold it back.
    const Vec3 rest = pen_path(0.6);
    const Vec2 lamp = rig.c1.project(rig.c0.centre() + 1.04 * (rest - rig.c0.centre()));
    auto lit = [](double t) { return t >= 0.595 && t < 1.4; };
    DeviceStreams s;
    for (double t = 0.0; t < 2.0; t += 0.010)
      if (lit(t)) push_frame(s.cameras[0], t * 1e6, {rig.c0.project(rest)});
      else push_frame(s.cameras[0], t * 1e6, {});
    for (double t = 0.005; t < 2.0; t += 0.010) {
      if (t < 0.3) push_frame(s.cameras[1], t * 1e6, {});
      else if (lit(t)) push_frame(s.cameras[1], t * 1e6, {lamp, rig.c1.project(rest)});
      else push_frame(s.cameras[1], t * 1e6, {lamp});
    }
    const PenTrack track = run_system(s, rig, 0.0);
    CHECK(track.strokes == 1);
    CHECK(track.ambiguous == 0);
    REQUIRE(track.samples.size() > 75);
    CHECK(track.samples.front().t_us == 600'000);
    check_on_path(track.samples, [&](double) { return rest; });
  }
}

TEST_CASE("the system's own pen events are the strokes of its samples, and it is causal") {
  const Rig rig;
  DeviceStreams s;
  // Two strokes: the pen lifted (both cameras dark) for half a second in between.
  auto dark = [](double t) { return t >= 1.5 && t < 2.0; };
  for (double t = 0.0; t < 3.0; t += 0.010) push_frame(s.cameras[0], t * 1e6, dark(t) ? std::initializer_list<Vec2>{} : std::initializer_list<Vec2>{rig.c0.project(pen_path(t))});
  for (double t = 0.004; t < 3.0; t += 0.010) push_frame(s.cameras[1], t * 1e6, dark(t) ? std::initializer_list<Vec2>{} : std::initializer_list<Vec2>{rig.c1.project(pen_path(t))});
  const SystemRun run = run_system_full(s, rig, 0.0);
  CHECK(run.track.strokes == 2);
  const std::vector<InputEvent> batch = pen_events(run.track);
  REQUIRE(run.events.size() == batch.size());
  for (size_t k = 0; k < batch.size(); ++k) {
    CHECK(run.events[k].kind == batch[k].kind);
    CHECK(run.events[k].t_us == batch[k].t_us);
    CHECK(run.events[k].p == batch[k].p);
  }
  // Causality: the same reports cut at 1.2 s give the same samples up to the cut, less the last frames'
  // worth the system was still waiting on.
  DeviceStreams cut;
  for (int c = 0; c < 2; ++c)
    for (size_t k = 0; k < s.cameras[c].size() && s.cameras[c].t_us[k] < 1'200'000; ++k)
      push_frame(cut.cameras[c], static_cast<double>(s.cameras[c].t_us[k]), {});
  for (int c = 0; c < 2; ++c) {
    cut.cameras[c].blob_count.assign(s.cameras[c].blob_count.begin(), s.cameras[c].blob_count.begin() + static_cast<std::ptrdiff_t>(cut.cameras[c].size()));
    cut.cameras[c].blobs.assign(s.cameras[c].blobs.begin(), s.cameras[c].blobs.begin() + static_cast<std::ptrdiff_t>(cut.cameras[c].size()));
  }
  const PenTrack early = run_system(cut, rig, 0.0);
  REQUIRE(early.samples.size() > 100);
  for (size_t k = 0; k < early.samples.size(); ++k) {
    CHECK(early.samples[k].t_us == run.track.samples[k].t_us);
    CHECK(early.samples[k].filtered == run.track.samples[k].filtered);
  }
}

TEST_CASE("the time offset is found from the pen's motion, and reports arriving out of order are dropped") {
  const Rig rig;
  DeviceStreams s = exact_streams(rig, 6.0, 5000.0, 1e9);
  // One camera 1 report logged earlier than the one before it (a clock going backwards).
  std::swap(s.cameras[1].t_us[300], s.cameras[1].t_us[301]);
  const SystemRun run = run_system_full(s, rig, 0.0, /*estimate=*/true);
  CHECK(run.state.offset_estimates > 0);
  CHECK(std::abs(run.state.time_offset_us - 5000.0) < 20.0);
  CHECK(run.state.out_of_order == 1);
  CHECK(run.track.strokes == 1);
}
