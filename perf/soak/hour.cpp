// The simulated hour (issue 14): an hour of seeded pen input drawn through the whole frame (input, sketch,
// split, refine, subdivide, snap) while the session folder is written, as `fire app --session DIR` writes
// it (SessionRecorder: each event appended as its frame delivers it, the log fsynced at every pen-up and
// command, snapshots every --snapshot-every frames, delivered events dropped from memory). The events
// arrive as the frames reach their time, as the app's do. Prints resident memory at the start, every five
// simulated minutes and at the end, the peak, and the log's and snapshots' size on disk.
//
// The drawing: a square border on a 20 cm dome, then splits, each across one rectangle of the drawing from
// one side to the opposite side (so both ends lie on the same face); now and then an undo and a redo, or a
// delete and its undo. When the drawing has a face count drawn from [--min-faces, --max-faces], every
// stroke is undone and a new drawing starts: the network stays in that band, so the run measures a steady
// state, not a growing drawing. The pen reports at 100 Hz, 5 mm apart, with up to 0.3 mm of jitter.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "perf/soak/memory.hpp"
#include "platform/clock.hpp"
#include "platform/session_files.hpp"
#include "tools/app/session_store.hpp"

using namespace fire;
using soak::peak_mib;
using soak::resident_mib;

namespace {

constexpr double kSide = 0.2;                   // the drawing's square, on the dome of tools/demo/sketch.log
constexpr int64_t kSampleUs = 10'000;           // 100 Hz pen reports
constexpr double kSpacing = 0.005;              // 5 mm between samples
constexpr double kMinRect = 0.025;              // rectangles narrower than this are not split again
constexpr int64_t kReportEveryUs = 300'000'000; // a row every five simulated minutes

double dome(double x, double y) {
  const double r2 = (x - kSide / 2) * (x - kSide / 2) + (y - kSide / 2) * (y - kSide / 2);
  return 0.04 * std::exp(-r2 / 0.01);
}

struct Rect {
  double x0, y0, x1, y1;
};

// Writes the hour's events, in time order, as a person at the pen would make them.
class Drawing {
 public:
  Drawing(uint64_t seed, int64_t end_us) : rng_(seed), end_us_(end_us) {}

  bool more_time() const { return t_ < end_us_; }
  InputLog take() { return std::exchange(log_, {}); }
  uint64_t strokes = 0, drawings = 0;

  void draw(uint32_t min_faces, uint32_t max_faces) {
    ++drawings;
    uint32_t edits = 0;
    const double S = kSide;
    // The border as tools/demo/sketch.log draws it: the last side ends 2 mm from the first corner and snaps.
    stroke(0, 0, S, 0);
    stroke(S, 0, S, S);
    stroke(S, S, 0, S);
    stroke(0, S, 0.001, 0.002);
    edits += 4;
    std::vector<Rect> rects{{0, 0, S, S}};
    const uint32_t faces = std::uniform_int_distribution<uint32_t>(min_faces, max_faces)(rng_);
    while (rects.size() < faces && more_time()) {
      std::vector<size_t> open;
      for (size_t k = 0; k < rects.size(); ++k)
        if (std::max(rects[k].x1 - rects[k].x0, rects[k].y1 - rects[k].y0) >= 2 * kMinRect) open.push_back(k);
      if (open.empty()) break;
      Rect& r = rects[open[std::uniform_int_distribution<size_t>(0, open.size() - 1)(rng_)]];
      const double u = std::uniform_real_distribution<double>(0.35, 0.65)(rng_);
      Rect other = r;
      double mid_x, mid_y;
      if (r.x1 - r.x0 >= r.y1 - r.y0) {  // split the longer side, so rectangles stay squat
        const double x = r.x0 + u * (r.x1 - r.x0);
        stroke(x, r.y0, x, r.y1);
        mid_x = x, mid_y = (r.y0 + r.y1) / 2;
        other.x0 = r.x1 = x;
      } else {
        const double y = r.y0 + u * (r.y1 - r.y0);
        stroke(r.x0, y, r.x1, y);
        mid_x = (r.x0 + r.x1) / 2, mid_y = y;
        other.y0 = r.y1 = y;
      }
      rects.push_back(other);
      ++edits;
      const double p = std::uniform_real_distribution<double>(0, 1)(rng_);
      if (p < 0.08) {
        command(CommandKind::Undo);
        command(CommandKind::Redo);
      } else if (p < 0.12) {
        command(CommandKind::Delete, Vec3(mid_x, mid_y, dome(mid_x, mid_y)));
        command(CommandKind::Undo);
      }
    }
    // Start over: every edit undone (a spare undo, with nothing left to undo, is refused and harmless).
    for (uint32_t k = 0; k < edits + 1; ++k) command(CommandKind::Undo);
  }

 private:
  void event(EventKind kind, const Vec3& p = Vec3::Zero(), CommandKind command = CommandKind::Undo) {
    InputEvent e;
    e.t_us = t_;
    e.kind = kind;
    e.p = p;
    e.command = command;
    log_.events.push_back(std::move(e));
    t_ += kSampleUs;
  }
  void pause() { t_ += std::uniform_int_distribution<int64_t>(300'000, 800'000)(rng_); }
  void command(CommandKind kind, const Vec3& p = Vec3::Zero()) {
    event(EventKind::Command, p, kind);
    pause();
  }
  void stroke(double ax, double ay, double bx, double by) {
    ++strokes;
    std::uniform_real_distribution<double> jitter(-0.0003, 0.0003);
    const int n = std::max(2, int(std::hypot(bx - ax, by - ay) / kSpacing) + 1);
    event(EventKind::Down);
    for (int i = 0; i < n; ++i) {
      const double s = double(i) / (n - 1), x = ax + s * (bx - ax), y = ay + s * (by - ay);
      const bool end = i == 0 || i == n - 1;  // the ends exactly on the curves they snap to
      event(EventKind::Pen, Vec3(x + (end ? 0 : jitter(rng_)), y + (end ? 0 : jitter(rng_)),
                                 dome(x, y) + (end ? 0 : jitter(rng_))));
    }
    event(EventKind::Up);
    pause();
  }

  std::mt19937_64 rng_;
  int64_t end_us_, t_ = 1'000'000;
  InputLog log_;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The simulated hour: an hour of drawing through the whole frame, writing a session folder; "
               "prints resident memory at the start, every five simulated minutes, at the end, and the peak"};
  double minutes = 60;
  uint64_t seed = 20261202, snapshot_every = 6000;
  uint32_t min_faces = 10, max_faces = 40;
  std::string dir = "hour-session";
  app.add_option("--minutes", minutes, "simulated drawing time")->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "seed of the drawing");
  app.add_option("--session", dir, "session folder to write (removed first if it exists)");
  app.add_option("--snapshot-every", snapshot_every, "frames between snapshots (6000: one a simulated minute)");
  app.add_option("--min-faces", min_faces, "fewest faces a drawing reaches before it is undone");
  app.add_option("--max-faces", max_faces, "most faces a drawing reaches before it is undone");
  CLI11_PARSE(app, argc, argv);
  if (min_faces < 1 || max_faces < min_faces) {
    std::fprintf(stderr, "hour: need 1 <= --min-faces <= --max-faces\n");
    return 2;
  }

  // The events arrive as the app's do: a drawing's worth is made when the frames reach it, handed to the
  // world's log as its time comes, and dropped from memory once delivered (the session has it on disk).
  const int64_t end_us = 1'000'000 + int64_t(minutes * 60e6);
  Drawing drawing(seed, end_us);
  std::deque<InputEvent> coming;
  World w;
  auto refill = [&] {
    while (coming.empty() && drawing.more_time()) {
      drawing.draw(min_faces, max_faces);
      for (InputEvent& e : drawing.take().events) coming.push_back(std::move(e));
    }
  };
  auto arrive = [&](int64_t before_us) {
    for (refill(); !coming.empty() && coming.front().t_us < before_us; refill()) {
      w.log.events.push_back(std::move(coming.front()));
      coming.pop_front();
    }
  };
  refill();
  if (coming.empty()) {
    std::fprintf(stderr, "hour: --minutes %g draws nothing\n", minutes);
    return 2;
  }
  arrive(coming.front().t_us + 1);  // the first event fixes frame 0, as in a replay
  const double rss_start = resident_mib();

  std::filesystem::remove_all(dir);
  auto writer = SessionWriter::create(dir, settings_json(w));
  if (!writer) {
    std::fprintf(stderr, "hour: %s\n", writer.error().c_str());
    return 1;
  }
  Scheduler scheduler = make_scheduler(w, monotonic_ns);
  SessionWriteOptions options;
  options.snapshot_every = snapshot_every;
  uintmax_t snapshot_last = 0, snapshot_max = 0;
  options.on_snapshot = [&](uint64_t frame) {
    snapshot_last = std::filesystem::file_size(writer->paths().snapshot(frame));
    snapshot_max = std::max(snapshot_max, snapshot_last);
  };
  int64_t next_report = w.log.events.front().t_us;
  std::printf("%8s %12s %8s %10s %12s %8s %14s %10s\n", "minute", "resident_MiB", "faces", "undo_depth", "vertex_slots",
              "log_MiB", "snapshot_KiB", "in_memory");
  options.on_commit = [&](uint64_t, uint64_t) {
    if (w.frame.begin_us < next_report) return;
    next_report += kReportEveryUs;
    std::printf("%8.1f %12.1f %8zu %10zu %12zu %8.1f %14.1f %10zu\n", double(w.frame.begin_us) / 60e6, resident_mib(),
                w.mesh.face_count(), w.history.undo_depth(), w.mesh.vertex_slots(),
                double(writer->log_bytes()) / (1 << 20), double(snapshot_last) / 1024, w.log.events.size());
    std::fflush(stdout);
  };
  const auto started = std::chrono::steady_clock::now();
  // The app's frame loop (AppWindow::run_frame with a session): frames with no input are skipped as a
  // replay skips them, which changes nothing but the count of frames run.
  SessionRecorder recorder(w, *writer, options);
  begin_frame(w, 0, w.log.events.front().t_us);
  for (;;) {
    arrive(w.frame.end_us);
    if (replay_done(w)) {
      if (coming.empty()) break;
      const int64_t steps = (coming.front().t_us - w.frame.begin_us) / kFrameStepUs;
      begin_frame(w, w.frame.index + uint64_t(steps), w.frame.begin_us + steps * kFrameStepUs);
      arrive(w.frame.end_us);
    }
    recorder.before_frame(w);
    scheduler.run_frame();
    recorder.after_frame(w, false);
    forget_delivered_events(w);
    begin_frame(w, w.frame.index + 1, w.frame.end_us);
  }
  if (Status s = recorder.finish(); !s) {
    std::fprintf(stderr, "hour: %s\n", s.error.c_str());
    return 1;
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  uintmax_t snapshot_bytes = 0;
  size_t snapshots = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    uint64_t frame = 0;
    if (parse_snapshot_name(entry.path().filename().string(), frame)) snapshot_bytes += entry.file_size(), ++snapshots;
  }
  std::printf("%llu events (%llu strokes, %llu drawings, %.0f simulated minutes), %zu in memory at the end\n",
              static_cast<unsigned long long>(w.log.forgotten + w.log.events.size()),
              static_cast<unsigned long long>(drawing.strokes), static_cast<unsigned long long>(drawing.drawings), minutes,
              w.log.events.size());
  std::printf("frames %llu, %zu edits rejected, %llu commits, %.1f s wall\n",
              static_cast<unsigned long long>(scheduler.frames()), w.rejections.size(),
              static_cast<unsigned long long>(writer->commits()), wall);
  const double rss_end = resident_mib();
  std::printf("resident: start %.1f MiB, end %.1f MiB, peak %.1f MiB\n", rss_start, rss_end, peak_mib());
  std::printf("on disk: log %.1f MiB, %zu snapshots kept, %.1f KiB together; the largest written %.1f KiB\n",
              double(writer->log_bytes()) / (1 << 20), snapshots, double(snapshot_bytes) / 1024,
              double(snapshot_max) / 1024);
  return 0;
}
