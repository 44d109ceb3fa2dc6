// The app frame as `fire app` shows it (tools/app/app_window.hpp: systems, uploads, draw, HUD, present
// with vsync) in a real GLFW window, 1280 x 720, on the surface and curves of perf/frame's grid drawing.
// Run under an X server (perf/render/run.sh starts Xvfb). Per network and subdivision level:
//   - idle: the frame sustained for --seconds with nothing drawn: mean fps, p50 and p99 frame time (wall
//     time between presents), the process's CPU time per frame, and where the time goes: per stage, and
//     the fps with the surface or the curves hidden;
//   - orbiting: the camera turned a little every frame, as a drag turns it, for --seconds: mean fps, p50 and p99;
//   - drawing: strokes across grid cells, one pen sample (0.5 mm on) per displayed frame, as the mouse pen
//     logs them: bytes uploaded on the frames of a stroke in progress, and on the frames from its pen-up
//     (split, refine, subdivide) until nothing more is uploaded.
//
//   bench_render [--seconds S] [NXxNY:L ...]   (default: 20x10:2 20x10:3 10x5:2; 20 x 10 cells: 200 faces)
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "perf/frame/grid_drawing.hpp"
#include "platform/clock.hpp"
#include "tools/app/app_window.hpp"

using namespace fire;

namespace {

struct Config {
  int nx = 20, ny = 10;
  uint32_t levels = 2;
};

struct Stat {
  std::vector<double> v;
  void add(double x) { v.push_back(x); }
  double percentile(double p) const {
    if (v.empty()) return 0;
    std::vector<double> s = v;
    std::sort(s.begin(), s.end());
    const size_t rank = std::clamp<size_t>(size_t(std::ceil(p / 100.0 * double(s.size()))), 1, s.size());
    return s[rank - 1];
  }
  double mean() const {
    double sum = 0;
    for (double x : v) sum += x;
    return v.empty() ? 0 : sum / double(v.size());
  }
  double max() const { return v.empty() ? 0 : *std::max_element(v.begin(), v.end()); }
};

struct Stages {
  Stat systems, wait, upload, hud, present;
  void add(const app::FrameStages& s) {
    systems.add(s.systems);
    wait.add(s.wait);
    upload.add(s.upload);
    hud.add(s.hud);
    present.add(s.present);
  }
};

struct Measurement {
  std::string name, device;
  uint32_t samples = 1;  // per pixel, as the renderer chose them
  Config config;
  size_t faces_before = 0, faces_after = 0, quads = 0;
  double scene_bytes = 0;  // the first frame's upload: everything
  // idle
  size_t frames = 0;
  double seconds = 0, cpu_ms_per_frame = 0;
  Stat frame_ms;
  Stages stages;
  std::vector<double> toggle_fps;  // surface hidden, curves hidden, both
  // orbiting
  size_t orbit_frames = 0;
  double orbit_seconds = 0;
  uint32_t orbit_level = 0;  // the level the last orbiting frame drew the surface at
  Stat orbit_frame_ms;
  // drawing
  Stat stroke_bytes, stroke_bytes_per_point, stroke_scene_bytes, stroke_frame_ms;
  Stat commit_bytes, commit_frames, commit_frame_ms, commit_surface_bytes;
  Stages commit_stages;
  std::string problem;
};

// Strokes drawn after the idle run, and pen samples per stroke: 0.5 mm apart across a 2 cm cell.
constexpr int kStrokes = 6, kSamples = 41;
// Seconds of each idle run with parts of the scene hidden.
constexpr int kToggleS = 3;
// How far the camera turns per orbiting frame: a drag of 2 pixels a frame (render::kOrbitRadiansPerPixel).
constexpr float kOrbitStepPx = 2;

// CPU time of the whole process (the app thread and lavapipe's), which waiting for a core on a shared
// machine does not inflate as it does the wall time.
double process_cpu_ms() {
  rusage u;
  getrusage(RUSAGE_SELF, &u);
  return (double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) * 1e6 + double(u.ru_utime.tv_usec + u.ru_stime.tv_usec)) / 1e3;
}

using WallClock = std::chrono::steady_clock;
double ms_between(WallClock::time_point a, WallClock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

Measurement run(const Config& c, double seconds) {
  Measurement r;
  r.config = c;
  r.name = "grid " + std::to_string(c.nx * c.ny);
  World w;
  w.log.events = perf::grid_drawing(c.nx, c.ny);
  w.sketch_settings.snap_distance = 0.005;  // as perf/frame replays it
  w.surface_options.levels = c.levels;
  Scheduler scheduler = make_scheduler(w, monotonic_ns);
  replay_headless(w, scheduler);
  r.faces_before = w.mesh.face_count();
  if (!w.surface_build.problem.empty()) {
    r.problem = "surface: " + w.surface_build.problem;
    return r;
  }

  auto opened = app::AppWindow::open(w, scheduler, 1280, 720, {}, {});
  if (!opened) {
    r.problem = opened.error();
    return r;
  }
  app::AppWindow& app = **opened;
  if (app.width() != 1280 || app.height() != 720) {
    r.problem = "the window is " + std::to_string(app.width()) + "x" + std::to_string(app.height()) + ", not 1280x720";
    return r;
  }
  r.device = app.context().device_name();
  r.samples = uint32_t(app.renderer().samples());
  const render::Orbit orbit = frame_orbit(app::scene_box(w.mesh, w.surface, {}), app.width(), app.height());
  // The app's loop without its input handling: events are drained, none is made.
  auto frame_from = [&](const render::Orbit& camera) {
    app.window().poll();
    app.window().events().clear();
    return app.display(camera) && app.status();
  };
  auto frame = [&] { return frame_from(orbit); };

  // Warm-up: the first frame uploads the whole scene; the next second settles caches and the swapchain.
  if (!frame()) {
    r.problem = "the first frame was not shown: " + app.status().error;
    return r;
  }
  r.scene_bytes = double(app.renderer().last_upload().bytes);
  for (auto until = WallClock::now() + std::chrono::seconds(1); WallClock::now() < until;) frame();

  const double cpu_start = process_cpu_ms();
  const auto start = WallClock::now();
  auto last = start;
  while (last - start < std::chrono::duration<double>(seconds)) {
    if (!frame()) {
      r.problem = "a frame was not shown: " + app.status().error;
      return r;
    }
    const auto now = WallClock::now();
    r.frame_ms.add(ms_between(last, now));
    r.stages.add(app.stages());
    last = now;
  }
  r.cpu_ms_per_frame = (process_cpu_ms() - cpu_start) / double(r.frame_ms.v.size());
  r.frames = r.frame_ms.v.size();
  r.seconds = ms_between(start, last) / 1000.0;

  // Where the device's time goes: the same idle frame with the app's view toggles (keys 1, 2) off.
  for (const auto& [surface, curves] : {std::pair{false, true}, std::pair{true, false}, std::pair{false, false}}) {
    app.hud_data.view.surface = surface;
    app.hud_data.view.curves = curves;
    frame();  // the first frame recorded without them
    const auto from = WallClock::now();
    size_t frames = 0;
    for (; WallClock::now() - from < std::chrono::seconds(kToggleS); ++frames)
      if (!frame()) {
        r.problem = "a frame was not shown: " + app.status().error;
        return r;
      }
    r.toggle_fps.push_back(double(frames) / (ms_between(from, WallClock::now()) / 1000.0));
  }
  app.hud_data.view = {};

  // Orbiting: every frame a new camera, as while a drag turns the view; then back where it was.
  {
    render::Orbit moving = orbit;
    const auto from = WallClock::now();
    auto previous = from;
    while (previous - from < std::chrono::duration<double>(seconds)) {
      moving.rotate(kOrbitStepPx, 0);
      if (!frame_from(moving)) {
        r.problem = "an orbiting frame was not shown: " + app.status().error;
        return r;
      }
      const auto now = WallClock::now();
      r.orbit_frame_ms.add(ms_between(previous, now));
      previous = now;
    }
    r.orbit_frames = r.orbit_frame_ms.v.size();
    r.orbit_level = c.levels - app.renderer().coarser_levels();
    r.orbit_seconds = ms_between(from, previous) / 1000.0;
    frame();
  }

  // Strokes across cells away from each other, bottom to top through the cell's middle: each splits it.
  auto log = [&](EventKind kind, const Vec3& p = Vec3::Zero()) {
    InputEvent e;
    e.kind = kind;
    e.p = p;
    app.log_event(std::move(e));
  };
  for (int k = 0; k < kStrokes; ++k) {
    const int i = (3 * k + 1) % c.nx, j = (2 * k + 1) % c.ny;
    const double x = (i + 0.5) * perf::kGridCell, y0 = j * perf::kGridCell;
    const size_t edits = w.history.undo_depth();
    log(EventKind::Down);
    for (int s = 0; s < kSamples; ++s) {
      const double y = y0 + perf::kGridCell * s / (kSamples - 1);
      log(EventKind::Pen, Vec3(x, y, perf::sheet(x, y)));
      auto before = WallClock::now();
      if (!frame()) {
        r.problem = "a stroke frame was not shown: " + app.status().error;
        return r;
      }
      const render::UploadStats& u = app.renderer().last_upload();
      if (!w.sketch.pen_down || w.sketch.stroke.size() < 2) continue;  // nothing of the stroke drawn yet
      const double stroke_bytes = double(w.sketch.stroke.size() * sizeof(glm::vec3));
      r.stroke_bytes.add(double(u.bytes));
      r.stroke_bytes_per_point.add(double(u.bytes) / double(w.sketch.stroke.size()));
      r.stroke_scene_bytes.add(double(u.bytes) - stroke_bytes);
      r.stroke_frame_ms.add(ms_between(before, WallClock::now()));
    }
    log(EventKind::Up);
    // From the pen-up to the frame after which nothing more is uploaded (the surface updated and settled).
    double bytes = 0, surface_bytes = 0;
    int frames = 0;
    for (bool committed = false; frames < 600; ++frames) {
      auto before = WallClock::now();
      if (!frame()) {
        r.problem = "a commit frame was not shown: " + app.status().error;
        return r;
      }
      const render::UploadStats& u = app.renderer().last_upload();
      committed = committed || w.history.undo_depth() > edits;
      if (committed && u.bytes == 0 && w.surface.settled) break;
      bytes += double(u.bytes);
      surface_bytes += double(u.surface_vertices) * 24 + double(u.surface_quads) * 24;
      if (u.bytes) {
        r.commit_frame_ms.add(ms_between(before, WallClock::now()));
        r.commit_stages.add(app.stages());
      }
    }
    r.commit_bytes.add(bytes);
    r.commit_surface_bytes.add(surface_bytes);
    r.commit_frames.add(frames);
  }
  r.faces_after = w.mesh.face_count();
  r.quads = w.surface.quad_count();
  if (r.faces_after != r.faces_before + kStrokes)
    r.problem = std::to_string(r.faces_after - r.faces_before) + " of " + std::to_string(kStrokes) +
                " strokes split a face" + (w.rejections.empty() ? "" : "; last rejection: " + w.rejections.back().reason);
  if (const size_t messages = app.close(); messages && r.problem.empty())
    r.problem = std::to_string(messages) + " Vulkan validation message(s)";
  return r;
}

double kib(double bytes) { return bytes / 1024.0; }

}  // namespace

int main(int argc, char** argv) {
  double seconds = 10;
  std::vector<Config> configs;
  for (int k = 1; k < argc; ++k) {
    Config c;
    char tail = 0;
    if (std::strcmp(argv[k], "--seconds") == 0 && k + 1 < argc) {
      seconds = std::atof(argv[++k]);
    } else if (std::sscanf(argv[k], "%dx%d:%u%c", &c.nx, &c.ny, &c.levels, &tail) == 3 && c.nx >= 2 && c.ny >= 2 &&
               c.levels >= 1 && c.levels <= reconstruct::kMaxSurfaceLevels) {
      configs.push_back(c);
    } else {
      std::fprintf(stderr, "usage: bench_render [--seconds S] [NXxNY:L ...]   (e.g. 20x10:2; levels 1 to %u)\n",
                   reconstruct::kMaxSurfaceLevels);
      return 2;
    }
  }
  if (!(seconds > 0)) {
    std::fprintf(stderr, "bench_render: --seconds must be positive\n");
    return 2;
  }
  if (configs.empty()) configs = {{20, 10, 2}, {20, 10, 3}, {10, 5, 2}};

  std::vector<Measurement> results;
  for (const Config& c : configs) {
    std::fprintf(stderr, "bench_render: grid %dx%d, level %u\n", c.nx, c.ny, c.levels);
    results.push_back(run(c, seconds));
    if (!results.back().problem.empty()) {
      std::fprintf(stderr, "bench_render: grid %dx%d level %u: %s\n", c.nx, c.ny, c.levels,
                   results.back().problem.c_str());
      return 1;
    }
  }

  std::printf("# bench_render: the app frame on %s, %u sample(s) per pixel, 1280x720, wall time between presents\n\n",
              results.front().device.c_str(), results.front().samples);
  std::printf("| network | L | surface quads | frames | s | mean fps | p50 ms | p99 ms | max ms | CPU ms per frame | "
              "target |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Measurement& r : results) {
    const double fps = double(r.frames) / r.seconds, target = r.config.levels <= 2 ? 60 : 30;
    std::printf("| %s (%zu faces) | %u | %zu | %zu | %.1f | %.1f | %.2f | %.2f | %.2f | %.1f | >= %.0f fps: %s |\n",
                r.name.c_str(), r.faces_before, r.config.levels, r.quads, r.frames, r.seconds, fps,
                r.frame_ms.percentile(50), r.frame_ms.percentile(99), r.frame_ms.max(), r.cpu_ms_per_frame, target,
                fps >= target ? "met" : "missed");
  }
  std::printf("\nOrbiting: the camera turned by a %.0f-pixel drag every frame, for the same seconds (a frame unlike the one "
              "before is drawn whole, the surface at a level by its size on screen, RenderSettings::coarser_while_moving):\n\n"
              "| network | L | level drawn | frames | mean fps | p50 ms | p99 ms | max ms | target |\n"
              "|---|---|---|---|---|---|---|---|---|\n", double(kOrbitStepPx));
  for (const Measurement& r : results) {
    const double fps = double(r.orbit_frames) / r.orbit_seconds;
    std::printf("| %s | %u | %u | %zu | %.1f | %.2f | %.2f | %.2f | >= 30 fps: %s |\n", r.name.c_str(), r.config.levels,
                r.orbit_level, r.orbit_frames, fps, r.orbit_frame_ms.percentile(50), r.orbit_frame_ms.percentile(99), r.orbit_frame_ms.max(),
                fps >= 30 ? "met" : "missed");
  }
  std::printf("\nIdle fps with parts of the scene hidden (the app's keys 1 and 2; %d s each; left: the clear, "
              "the resolve if multisampled, HUD, present):\n\n| network | L | all | surface hidden | curves hidden | both hidden |\n"
              "|---|---|---|---|---|---|\n", kToggleS);
  for (const Measurement& r : results)
    std::printf("| %s | %u | %.1f | %.1f | %.1f | %.1f |\n", r.name.c_str(), r.config.levels,
                double(r.frames) / r.seconds, r.toggle_fps[0], r.toggle_fps[1], r.toggle_fps[2]);
  std::printf("\nWhere an idle frame's time goes (mean ms per stage; wait: the previous frame's rendering on the "
              "device; present: acquire, record, submit, present):\n\n");
  std::printf("| network | L | systems | wait | upload | HUD | present | sum | commit frames: systems | wait | "
              "upload | HUD | present |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Measurement& r : results) {
    const Stages& s = r.stages;
    const Stages& c = r.commit_stages;
    std::printf("| %s | %u | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f |\n",
                r.name.c_str(), r.config.levels, s.systems.mean(), s.wait.mean(), s.upload.mean(), s.hud.mean(),
                s.present.mean(),
                s.systems.mean() + s.wait.mean() + s.upload.mean() + s.hud.mean() + s.present.mean(),
                c.systems.mean(), c.wait.mean(), c.upload.mean(), c.hud.mean(), c.present.mean());
  }
  std::printf("\nBytes uploaded: the whole scene (first frame); per frame of a stroke in progress (one pen sample "
              "a frame, %d strokes of %d samples); from each pen-up until nothing more is uploaded:\n\n",
              kStrokes, kSamples);
  std::printf("| network | L | whole scene KiB | stroke frame bytes p50 / max | bytes per stroke point (max) | "
              "scene bytes on stroke frames (max) | stroke frame ms p50 / max | commit KiB p50 / max | of which surface "
              "KiB p50 | frames to settle p50 / max | commit frame ms p50 / max |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Measurement& r : results)
    std::printf("| %s | %u | %.0f | %.0f / %.0f | %.1f | %.0f | %.1f / %.1f | %.0f / %.0f | %.0f | %.0f / %.0f | "
                "%.1f / %.1f |\n",
                r.name.c_str(), r.config.levels, kib(r.scene_bytes), r.stroke_bytes.percentile(50), r.stroke_bytes.max(),
                r.stroke_bytes_per_point.max(), r.stroke_scene_bytes.max(), r.stroke_frame_ms.percentile(50),
                r.stroke_frame_ms.max(), kib(r.commit_bytes.percentile(50)), kib(r.commit_bytes.max()),
                kib(r.commit_surface_bytes.percentile(50)), r.commit_frames.percentile(50), r.commit_frames.max(),
                r.commit_frame_ms.percentile(50), r.commit_frame_ms.max());
  return 0;
}
