// The live frame's latency: replays drawings through every system of the session (input, sketch,
// split, refine, subdivide) on one core and reports the time of each frame with input or a fit running
// (thread CPU time: the machine is shared) as p50, p99 and max, per system and for the whole frame (and
// for the frames that commit a curve and the frames that run a fit's back-substitutions), plus how many
// frames pass from the frame that commits a curve to the first frame whose surface shows its faces
// and to the frame where the surface has settled.
//
// Drawings: the bundled demo log (a dome, 14 faces) and a grid drawing of 200 faces on a wavy sheet
// (a border, 19 long curves, then 180 short ones cell by cell), at subdivision levels 2 and 3; with
// --tracked, also a drawing of Wii Remote reports replayed with its rig through every system from
// triangulation on (perf/frame/run.sh passes `fire simulate drawing`'s, 156 faces on the pawn).
//
//   bench_frame [--whole-fit] [--tracked LOG RIG.json]
//                                          (--whole-fit: the fit runs to its end in the commit frame, as
//                                           before the frame budget; for comparisons in one session)
//   bench_frame --write-grid-log FILE      (the grid drawing as an input log, for callgrind)
#include <time.h>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "perf/frame/grid_drawing.hpp"
#include "platform/files.hpp"
#include "tools/app/session.hpp"
#include "tools/app/session_rig.hpp"

using namespace fire;

namespace {

int64_t thread_cpu_ns() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return int64_t(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

struct Run {
  std::vector<int64_t> frame_ns;              // every frame that ran
  std::vector<std::vector<int64_t>> system_ns;  // per system, per frame
  std::vector<std::string> names;
  std::vector<int64_t> commit_frame_ns;       // frames that committed a curve
  std::vector<int64_t> fit_frame_ns;          // the others that ran a fit's back-substitutions
  std::vector<int64_t> shown_after, settled_after;  // frames from a commit to shown / settled
  size_t faces = 0, quads = 0, rejections = 0;
  std::string problem;
};

Run replay(const std::vector<InputEvent>& events, uint32_t levels, double snap, uint32_t fit_work,
           const std::optional<TrackingRig>& rig = std::nullopt) {
  World w;
  w.log.events = events;
  w.sketch_settings.snap_distance = snap;
  if (rig) set_rig(w, *rig);
  w.surface_options.levels = levels;
  w.surface_options.fit_work_per_frame = fit_work;
  std::vector<SystemSpec> systems = session_systems(w);
  auto scheduler = Scheduler::build(std::move(systems), thread_cpu_ns);
  Run run;
  if (!scheduler) {
    run.problem = scheduler.error();
    return run;
  }
  // The replay loop of tools/app/session.cpp, watching each frame for a commit and for the surface.
  begin_frame(w, 0, w.log.events.front().t_us);
  // Frame index of the last commit whose faces are not shown yet (a border stroke's never are), and of the
  // first shown one whose surface has not settled yet (a commit while a fit runs abandons that fit: the
  // earlier commit waits for the later one's).
  int64_t pending_commit = -1, unsettled_commit = -1;
  while (!replay_done(w)) {
    if (!systems_waiting(w) && w.log.events[w.cursor.next].t_us >= w.frame.end_us) {
      const int64_t steps = (w.log.events[w.cursor.next].t_us - w.frame.begin_us) / kFrameStepUs;
      begin_frame(w, w.frame.index + uint64_t(steps), w.frame.begin_us + steps * kFrameStepUs);
    }
    const size_t edits_before = w.history.undo_depth();
    const uint64_t updates_before = w.surface_build.updates;
    const bool fitting = w.surface_build.state.fitting();
    scheduler->run_frame();
    const int64_t ns = scheduler->frame_timing().samples_ns.back();
    if (w.history.undo_depth() <= edits_before && fitting) run.fit_frame_ns.push_back(ns);
    if (w.history.undo_depth() > edits_before) {
      run.commit_frame_ns.push_back(ns);
      pending_commit = int64_t(w.frame.index);
    }
    if (pending_commit >= 0 && w.surface_build.updates > updates_before && w.surface.frame == w.frame.index) {
      run.shown_after.push_back(int64_t(w.frame.index) - pending_commit);
      if (unsettled_commit < 0) unsettled_commit = pending_commit;
      pending_commit = -1;
    }
    if (unsettled_commit >= 0 && w.surface.settled && w.surface.frame == w.frame.index) {
      run.settled_after.push_back(int64_t(w.frame.index) - unsettled_commit);
      unsettled_commit = -1;
    }
    begin_frame(w, w.frame.index + 1, w.frame.end_us);
  }
  run.frame_ns = scheduler->frame_timing().samples_ns;
  for (const SystemTiming& t : scheduler->timings()) {
    run.names.push_back(t.name);
    run.system_ns.push_back(t.samples_ns);
  }
  run.faces = w.mesh.face_count();
  run.quads = w.surface.quad_count();
  run.rejections = w.rejections.size();
  run.problem = w.surface_build.problem;
  return run;
}

double percentile_ms(std::vector<int64_t> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  size_t rank = size_t(std::ceil(p / 100.0 * double(v.size())));
  rank = std::clamp<size_t>(rank, 1, v.size());
  return double(v[rank - 1]) / 1e6;
}

void report(const char* drawing, uint32_t levels, const Run& r) {
  if (!r.problem.empty()) std::printf("%s L%u: the surface stopped following: %s\n", drawing, levels, r.problem.c_str());
  std::printf("| %s | %u | %zu faces, %zu quads | %zu | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %" PRId64
              " | %" PRId64 " |\n",
              drawing, levels, r.faces, r.quads, r.frame_ns.size(), percentile_ms(r.frame_ns, 50),
              percentile_ms(r.frame_ns, 99), percentile_ms(r.frame_ns, 100), percentile_ms(r.commit_frame_ns, 50),
              percentile_ms(r.commit_frame_ns, 100), percentile_ms(r.fit_frame_ns, 50), percentile_ms(r.fit_frame_ns, 100),
              r.shown_after.empty() ? -1 : *std::max_element(r.shown_after.begin(), r.shown_after.end()),
              r.settled_after.empty() ? -1 : *std::max_element(r.settled_after.begin(), r.settled_after.end()));
}

void report_systems(const char* drawing, uint32_t levels, const Run& r) {
  for (size_t s = 0; s < r.names.size(); ++s)
    std::printf("| %s | %u | %s | %.3f | %.3f | %.3f |\n", drawing, levels, r.names[s].c_str(),
                percentile_ms(r.system_ns[s], 50), percentile_ms(r.system_ns[s], 99), percentile_ms(r.system_ns[s], 100));
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<InputEvent> grid = perf::grid_drawing(20, 10);
  if (argc == 3 && std::strcmp(argv[1], "--write-grid-log") == 0) {
    if (Status s = write_file_atomic(argv[2], format_input_log(grid)); !s) {
      std::fprintf(stderr, "bench_frame: %s\n", s.error.c_str());
      return 1;
    }
    return 0;
  }
  bool whole_fit = false;
  std::string tracked_log, tracked_rig;
  for (int a = 1; a < argc; ++a) {
    if (std::strcmp(argv[a], "--whole-fit") == 0) {
      whole_fit = true;
    } else if (std::strcmp(argv[a], "--tracked") == 0 && a + 2 < argc) {
      tracked_log = argv[++a];
      tracked_rig = argv[++a];
    } else {
      std::fprintf(stderr, "usage: bench_frame [--whole-fit] [--tracked LOG RIG.json] | --write-grid-log FILE\n");
      return 2;
    }
  }
  std::optional<InputLog> tracked;
  std::optional<TrackingRig> rig;
  if (!tracked_log.empty()) {
    auto log = read_input_log(tracked_log);
    if (!log) {
      std::fprintf(stderr, "bench_frame: %s\n", log.error().c_str());
      return 1;
    }
    auto loaded = load_tracking_rig(tracked_rig, *log, tracked_log);
    if (!loaded) {
      std::fprintf(stderr, "bench_frame: %s\n", loaded.error().c_str());
      return 1;
    }
    tracked = std::move(*log);
    rig = std::move(*loaded);
  }
  const uint32_t fit_work = whole_fit ? reconstruct::kWholeFit : reconstruct::Options{}.fit_work_per_frame;
  auto demo = read_input_log(FIRE_SOURCE_DIR "/tools/demo/sketch.log");
  if (!demo) {
    std::fprintf(stderr, "bench_frame: %s\n", demo.error().c_str());
    return 1;
  }
  std::printf("# bench_frame: every frame with input or a fit running, thread CPU time, one core; fit: %s\n\n",
              whole_fit ? "whole in the commit frame" : (std::to_string(fit_work) + " base vertices times back-substitutions per frame").c_str());
  std::printf("| drawing | L | final | frames | p50 ms | p99 ms | max ms | commit p50 ms | commit max ms | "
              "fit frame p50 ms | fit frame max ms | shown after (frames) | settled after (frames) |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::vector<std::pair<std::string, std::pair<uint32_t, Run>>> runs;
  for (uint32_t levels : {2u, 3u}) {
    runs.push_back({"demo dome", {levels, replay(demo->events, levels, SketchSettings{}.snap_distance, fit_work)}});
    report("demo dome", levels, runs.back().second.second);
    runs.push_back({"grid 200", {levels, replay(grid, levels, 0.005, fit_work)}});
    report("grid 200", levels, runs.back().second.second);
    if (tracked) {
      runs.push_back({"tracked", {levels, replay(tracked->events, levels, SketchSettings{}.snap_distance, fit_work, rig)}});
      report("tracked", levels, runs.back().second.second);
    }
  }
  std::printf("\n| drawing | L | system | p50 ms | p99 ms | max ms |\n|---|---|---|---|---|---|\n");
  for (const auto& [name, lr] : runs) report_systems(name.c_str(), lr.first, lr.second);
  return 0;
}
