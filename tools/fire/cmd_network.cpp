// fire replay, fire open, fire export-network: the engine foundation's commands.
#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include <unistd.h>

#include "engine/text.hpp"
#include "platform/clock.hpp"
#include "platform/files.hpp"
#include "platform/network_file.hpp"
#include "platform/surface_io.hpp"
#include "tools/fire/commands.hpp"
#include "tools/app/session.hpp"
#include "tools/app/session_rig.hpp"
#include "tools/app/session_store.hpp"
#include "tools/fire/surface_args.hpp"

namespace fire::cli {

namespace {

// How far through its log a replay is, on stderr: every 10 % with --progress; on a terminal, once the replay has
// run a second, at most four times a second, on one line.
ReplayHooks progress_hooks(bool asked) {
  const bool terminal = ::isatty(STDERR_FILENO) != 0;
  if (!asked && !terminal) return {};
  struct State {
    int64_t start_ns = monotonic_ns(), shown_ns = 0;
    int last_tenth = -1;
    bool printed = false, finished = false;
  };
  auto state = std::make_shared<State>();
  ReplayHooks hooks;
  hooks.after_frame = [state, asked, terminal](const World& w) {
    const size_t total = w.log.events.size();
    const size_t done = std::min(w.cursor.next, total);
    const int percent = total ? int(100 * done / total) : 100;
    const int64_t now = monotonic_ns();
    if (asked && !terminal) {
      if (percent / 10 == state->last_tenth) return;
      state->last_tenth = percent / 10;
      std::fprintf(stderr, "fire replay: %d %% of the log's events (frame %" PRIu64 ")\n", percent, w.frame.index);
      return;
    }
    // The line ends once every event is read (the frames after it only settle the surface).
    const bool last = done == total && state->printed && !state->finished;
    if (!last && (state->finished || now - state->start_ns < 1'000'000'000 || now - state->shown_ns < 250'000'000)) return;
    state->shown_ns = now;
    state->printed = true;
    state->finished = done == total;
    std::fprintf(stderr, "\rfire replay: %d %% of the log's events (frame %" PRIu64 ")%s", percent, w.frame.index, done == total ? "\n" : "");
  };
  return hooks;
}

struct ReplayOptions {
  std::string log_path, out_path, obj_path, session_dir, rig_path, measured_marks_path;
  std::vector<std::string> surface_paths;
  uint64_t snapshot_every = 0;
  uint64_t until_stroke = 0;  // 0: the whole log
  bool hash = false, timings = false, no_surface = false, schedule = false, progress = false;
  bool settings_given = false;  // --snap, a surface option or --no-surface on the command line
  double snap = SketchSettings{}.snap_distance;
  SurfaceArgs surface_args;
  reconstruct::Options surface;
  std::string units = unit_name(kDefaultExportUnit);
  LengthUnit unit = kDefaultExportUnit;
};

// By the wall, then by the thread's CPU time (the same system's, when `cpu` has samples).
void print_timing(const SystemTiming& t, const SystemTiming& cpu) {
  std::printf("system %-10s mean %10.1f us  p99 %10.1f us  max %10.1f us  total %9.3f ms", t.name.c_str(), t.mean_ns() / 1e3,
              double(t.percentile_ns(99)) / 1e3, double(t.max_ns) / 1e3, double(t.total_ns) / 1e6);
  if (cpu.frames > 0)
    std::printf("  cpu mean %10.1f us  p99 %10.1f us  max %10.1f us", cpu.mean_ns() / 1e3, double(cpu.percentile_ns(99)) / 1e3,
                double(cpu.max_ns) / 1e3);
  std::printf("\n");
}

// Reopens a session folder (engine/SESSION.md), saying on stderr what recovery dropped and passed over.
Result<ReopenedSession> reopen(const std::string& command, const std::string& dir) {
  auto r = reopen_session(dir, monotonic_ns);
  if (!r) return r;
  for (const std::string& note : r->notes) std::cerr << command << ": " << note << "\n";
  std::cerr << command << ": " << dir << ": "
            << (r->snapshot ? "snapshot after frame " + std::to_string(*r->snapshot) : std::string("no snapshot"))
            << ", then " << r->events_replayed << " event(s) of the log replayed\n";
  return r;
}

// How many events of `log` the frame that commits its n-th pen stroke has read (a stroke the split system
// applied: part of a border, a split, a stroke across curves or a hole, a piece of a chain; not a command), from
// a replay without the surface, which no commit depends on. nullopt, with how many it commits, when fewer.
std::optional<size_t> events_until_stroke(const InputLog& log, const std::optional<TrackingRig>& rig, double snap,
                                          uint64_t n, uint64_t& committed) {
  auto w = std::make_unique<World>();
  w->log = log;
  if (rig) set_rig(*w, *rig);
  w->sketch_settings.snap_distance = snap;
  w->build_surface = false;
  std::vector<char> command_line;
  for (const InputEvent& e : log.events) {
    if (e.line >= command_line.size()) command_line.resize(e.line + 1, 0);
    command_line[e.line] = e.kind == EventKind::Command;
  }
  std::optional<size_t> until;
  committed = 0;
  size_t rejections_seen = 0;
  ReplayHooks hooks;
  hooks.after_frame = [&](const World& world) {
    for (const EditRequest& r : world.requests) {
      if (r.kind != RequestKind::Edit || (r.line < command_line.size() && command_line[r.line])) continue;
      const bool refused = std::any_of(world.rejections.begin() + std::ptrdiff_t(rejections_seen), world.rejections.end(),
                                       [&](const Rejection& x) { return x.line == r.line; });
      if (!refused && ++committed == n) until = world.cursor.next;
    }
    rejections_seen = world.rejections.size();
  };
  Scheduler scheduler = make_scheduler(*w, monotonic_ns);
  replay_headless(*w, scheduler, hooks);
  return until;
}

int run_replay(const ReplayOptions& o) {
  const int64_t started_ns = monotonic_ns();
  const bool session_in = is_directory(o.log_path);
  if (session_in && o.settings_given) {
    std::cerr << "fire replay: " << o.log_path << " is a session folder: its settings.json sets --snap, the surface "
              << "options (--method, --coons-steps, --levels, --fairness, --planarity) and --no-surface\n";
    return 1;
  }
  if (session_in && !o.session_dir.empty()) {
    std::cerr << "fire replay: --session writes a new session from a log; " << o.log_path << " is a session already\n";
    return 1;
  }
  if (!o.rig_path.empty() && session_in) {
    std::cerr << "fire replay: " << o.log_path << " is a session folder: it replays with the rig.json it holds, not --rig\n";
    return 1;
  }
  if (o.until_stroke > 0 && (session_in || !o.session_dir.empty())) {
    std::cerr << "fire replay: --until-stroke replays part of a log; it takes no session folder, in or out\n";
    return 1;
  }
  if (o.snapshot_every > 0 && o.session_dir.empty()) {
    std::cerr << "fire replay: --snapshot-every needs --session DIR to write the snapshots to\n";
    return 1;
  }
  if (!(o.snap > 0)) {
    std::cerr << "fire replay: --snap must be a positive distance\n";
    return 1;
  }
  if (o.no_surface && !o.surface_paths.empty()) {
    std::cerr << "fire replay: --surface needs the surface that --no-surface turns off\n";
    return 1;
  }
  for (const std::string& path : o.surface_paths)
    if (auto format = surface_format_of(path); !format) {
      std::cerr << "fire replay: " << format.error() << "\n";
      return 1;
    }
  std::unique_ptr<World> world;
  std::unique_ptr<Scheduler> scheduler_owner;
  int64_t replay_started_ns = 0, replayed_ns = 0;  // the frames of a log replayed, by the wall (not a reopened session's)
  // Where rejections' lines are: the log read, or the log of the session written or reopened.
  std::string lines_of = o.log_path;
  if (session_in) {
    auto r = reopen("fire replay", o.log_path);
    if (!r) {
      std::cerr << "fire replay: " << r.error() << "\n";
      return 1;
    }
    world = std::move(r->world);
    scheduler_owner = std::move(r->scheduler);
    lines_of = SessionPaths{o.log_path}.log();
  } else {
    auto log = read_input_log(o.log_path);
    if (!log) {
      std::cerr << "fire replay: " << log.error() << "\n";
      return 1;
    }
    world = std::make_unique<World>();
    std::string rig_text;  // a session written from this log keeps a copy of it
    if (!o.rig_path.empty()) {
      Result<std::string> text = read_text_file(o.rig_path);
      Result<TrackingRig> rig = text ? tracking_rig_from_json(*text, o.rig_path, *log, o.log_path)
                                     : Result<TrackingRig>::failure(text.error());
      if (!rig) {
        std::cerr << "fire replay: " << rig.error() << "\n";
        return 1;
      }
      set_rig(*world, *rig);
      rig_text = std::move(*text);
    } else if (has_device_reports(*log)) {
      std::cerr << "fire replay: " << o.log_path << " holds Wii Remote reports; give the rig they were drawn with: "
                << "--rig RIG.json (from fire calibrate)\n";
      return 1;
    }
    if (o.until_stroke > 0) {
      uint64_t committed = 0;
      const std::optional<size_t> until = events_until_stroke(*log, world->rig, o.snap, o.until_stroke, committed);
      if (!until) {
        std::cerr << "fire replay: " << o.log_path << " commits " << committed << " pen stroke(s), not " << o.until_stroke
                  << " (--until-stroke)\n";
        return 1;
      }
      log->events.resize(*until);
    }
    world->log = std::move(*log);
    world->sketch_settings.snap_distance = o.snap;
    world->build_surface = !o.no_surface;
    world->surface_options = o.surface;
    scheduler_owner = std::make_unique<Scheduler>(make_scheduler(*world, monotonic_ns, thread_cpu_ns));
    replay_started_ns = monotonic_ns();
    if (o.session_dir.empty()) {
      replay_headless(*world, *scheduler_owner, progress_hooks(o.progress));
    } else {
      auto writer = SessionWriter::create(o.session_dir, settings_json(*world), rig_text, {}, world->log.version);
      if (!writer) {
        std::cerr << "fire replay: " << writer.error() << "\n";
        return 1;
      }
      SessionWriteOptions options;
      options.snapshot_every = o.snapshot_every;
      if (Status s = replay_into_session(*world, *scheduler_owner, *writer, options); !s) {
        std::cerr << "fire replay: " << s.error << "\n";
        return 1;
      }
      lines_of = writer->paths().log();
    }
    replayed_ns = monotonic_ns() - replay_started_ns;
  }
  Scheduler& scheduler = *scheduler_owner;
  // A replay that showed its progress (--progress, or a terminal once it ran two seconds) ends with a summary line.
  if (o.progress || (::isatty(STDERR_FILENO) != 0 && monotonic_ns() - started_ns > 2'000'000'000))
    std::fprintf(stderr, "fire replay: %" PRIu64 " frames in %.1f s: %zu edits applied, %zu rejected, %zu curves\n",
                 scheduler.frames(), double(monotonic_ns() - started_ns) * 1e-9, world->history.undo_depth(),
                 world->rejections.size(), world->mesh.edge_count());

  for (const Rejection& r : world->rejections)
    std::cerr << lines_of << ":" << r.line << ": rejected: " << r.reason << "\n";
  if (world->log.rejected_hid_lines && !world->rig)  // with a rig, the triangulation system's words say it
    std::cerr << lines_of << ": " << world->log.rejected_hid_lines << " garbled device report line(s) skipped\n";
  if (world->log.hid_back_in_time)
    std::cerr << lines_of << ": " << world->log.hid_back_in_time
              << " device report line(s) stamped before the line above them (kept for the triangulation system)\n";
  if (world->rig)
    for (const std::string& problem : describe_device_problems(world->triangulate))
      std::cerr << lines_of << ": device input: " << problem << "\n";
  if (world->rig)
    for (const std::string& line : describe_registration(world->registration))
      std::cerr << lines_of << ": " << line << "\n";
  std::string problem = world->mesh.validate();
  if (!problem.empty()) {
    std::cerr << "fire replay: internal error, the replayed network is invalid: " << problem << "\n";
    return 2;
  }
  const Mesh& m = world->mesh;
  // Nothing pending is dropped in silence: a stroke in pieces the log never finished is in the network, not the surface.
  for (const std::vector<EdgeIndex>& chain : m.pending_chains()) {
    const Vec3& free_end = m.vertices.position[m.edges.vertex[chain.back()][1]];
    std::cerr << lines_of << ": a stroke in " << chain.size() << " piece(s) is still pending: it ends off the network at ("
              << format_double(free_end.x()) << ", " << format_double(free_end.y()) << ", " << format_double(free_end.z())
              << "); no surface follows it until a stroke from there reaches a curve\n";
  }
  const SurfaceLevels& surface = world->surface;
  if (!world->surface_build.problem.empty())
    std::cerr << o.log_path << ": the surface does not follow the last edit: " << world->surface_build.problem << "\n";
  if (o.timings) {
    std::printf("frames %" PRIu64 " run (frames with no input skipped)\n", scheduler.frames());
    for (size_t i = 0; i < scheduler.timings().size(); ++i)
      print_timing(scheduler.timings()[i], i < scheduler.cpu_timings().size() ? scheduler.cpu_timings()[i] : SystemTiming{});
    print_timing(scheduler.frame_timing(), scheduler.frame_cpu_timing());
    // How much faster than the person drew it: the log's span of time against the replay's by the wall.
    if (world->log.events.size() > 1 && replayed_ns > 0) {
      const double drawn_s = double(world->log.events.back().t_us - world->log.events.front().t_us) * 1e-6;
      std::printf("log %.1f s replayed in %.3f s: %.0f times faster\n", drawn_s, double(replayed_ns) * 1e-9,
                  drawn_s / (double(replayed_ns) * 1e-9));
    }
    std::printf("vertices %zu edges %zu faces %zu points %zu; edits %zu applied, %zu rejected\n", m.vertex_count(),
                m.edge_count(), m.face_count(), m.live_point_count(), world->history.undo_depth(),
                world->rejections.size());
    std::printf("surface: level %u, %u quads, %u vertices, %" PRIu64 " updates\n", surface.level, surface.quad_count(),
                surface.vertex_count(), world->surface_build.updates);
  }
  if (o.hash) std::printf("%016" PRIx64 "\n", world_hash(*world));
  if (!o.surface_paths.empty()) {
    if (surface.empty()) {
      std::cerr << "fire replay: " << o.log_path << " ends with no surface to write to " << o.surface_paths.front()
                << (m.face_count() == 0 ? " (the network has no faces)\n" : "\n");
      return 1;
    }
    const SurfaceMesh mesh = to_surface_mesh(surface);
    for (const std::string& path : o.surface_paths)
      if (auto s = write_surface(mesh, path, o.unit); !s) {
        std::cerr << "fire replay: " << s.error << "\n";
        return 1;
      }
  }
  if (!o.out_path.empty()) {
    if (auto s = save_network(m, o.out_path); !s) {
      std::cerr << "fire replay: " << s.error << "\n";
      return 1;
    }
  }
  if (!o.obj_path.empty()) {
    if (auto s = export_network_obj(m, o.obj_path); !s) {
      std::cerr << "fire replay: " << s.error << "\n";
      return 1;
    }
  }
  if (!o.measured_marks_path.empty()) {
    const RegistrationState& r = world->registration;
    if (r.measured.empty() || !r.transform) {
      std::cerr << "fire replay: " << o.log_path << (r.measured.empty() ? " measures no mark (cmd measure N)" : " measures marks but never registers: they have no frame")
                << ", nothing to write to " << o.measured_marks_path << "\n";
      return 1;
    }
    std::vector<IdentifiedMark> marks;
    for (const MeasuredMark& mark : r.measured) marks.push_back({mark.mark, mark.p});
    if (auto s = write_file_atomic(o.measured_marks_path, identified_marks_to_json(marks, "measured")); !s) {
      std::cerr << "fire replay: " << s.error << "\n";
      return 1;
    }
  }
  return 0;
}

}  // namespace

void add_network_commands(CLI::App& app, Registry& registry) {
  auto o = std::make_shared<ReplayOptions>();
  CLI::App* replay = app.add_subcommand(
      "replay", "Replay an input log headless through the frame systems (input, triangulate, register, sketch, split, "
                "refine, subdivide, snap)");
  replay->add_option("LOG", o->log_path,
                     "input log (format: engine/INPUT_LOG.md), or a session folder (engine/SESSION.md) to reopen: its "
                     "last good snapshot, then its log's tail, a torn last record dropped; a folder's settings.json "
                     "fixes --snap, the surface options and --no-surface");
  replay->add_flag("--schedule", o->schedule,
                   "print the frame and exit: each system in order with the world members it reads (this frame's and "
                   "the previous frame's) and writes, as the code declares them; needs no LOG");
  replay->add_option("--session", o->session_dir,
                     "write a session folder while replaying LOG: the input log, fsynced with a durability record at "
                     "every pen-up and command, and snapshots (a new or empty folder)");
  replay->add_option("--snapshot-every", o->snapshot_every,
                     "with --session: write a snapshot every N frames and one at the end (0: none)")
      ->capture_default_str();
  replay->add_option("--rig", o->rig_path,
                     "rig file from fire calibrate: the log's Wii Remote reports go through the triangulation system "
                     "(pen samples in the rig's frame, camera 0's, metres); needed when the log holds reports; a --session "
                     "written from the log keeps a copy (rig.json), so reopening it needs no --rig");
  replay->add_option("-o,--output", o->out_path, "write the final curve network here (format: engine/NETWORK_FORMAT.md)");
  replay->add_option("--export-obj", o->obj_path, "also write the network's polylines as OBJ lines");
  replay->add_option("--measured-marks-out", o->measured_marks_path,
                     "write the marks the log measured by touch (cmd measure N) with their ids and positions in the "
                     "object's frame they made (fire-marks JSON, metres), for fire eval --align");
  replay->add_option("--surface", o->surface_paths,
                     "write the final surface here (.obj, .ply, .stl or .glb), as the frame's subdivide system left it; "
                     "repeat it for more than one file")
      ->allow_extra_args(false);
  add_units_option(*replay, o->units);
  replay->add_flag("--no-surface", o->no_surface, "run only input, sketch and split (no refine and subdivide)");
  replay->add_option("--until-stroke", o->until_stroke,
                     "N: replay the log up to the frame that commits its N-th pen stroke (one the network took: part of "
                     "a border, a split, a stroke across curves or a hole, a piece of a chain; commands do not count), "
                     "then let the surface settle: -o, --surface and --hash give the drawing as it was then")
      ->check(kPositive);
  replay->add_flag("--progress", o->progress,
                   "say how far through the log it is, every 10 %, and end with a summary line (on a terminal it always does, after "
                   "a second, and sums up a replay that took over two seconds)");
  add_surface_options(*replay, o->surface_args);
  replay->add_flag("--hash", o->hash,
                   "print a 64-bit hash of the final pools and surface (identical on every run and machine)");
  replay->add_flag("--timings", o->timings, "print per-system timings (mean, p99, max per frame), by the wall and by the thread's CPU time, for each system and the whole frame; how many times faster than the log's own span it replayed; and final counts");
  replay->add_option("--snap", o->snap,
                     "snap distance for stroke ends, in model units (a stroke end whose pen sample carries its own "
                     "radius, as a mouse drawing from fire app does, uses that, and lands on a vertex within it)")
      ->capture_default_str();
  replay->footer("Pictures of the replay's frames: fire render LOG --every N --png-dir DIR.");
  replay->callback([o, replay, &registry] {
    if (o->schedule) {
      World world;
      std::cout << make_scheduler(world, monotonic_ns).describe();
      return;
    }
    if (o->log_path.empty()) {
      std::cerr << "fire replay: LOG is required: an input log or a session folder (--help)\n";
      registry.exit_code = 2;
      return;
    }
    o->settings_given =
        replay->count("--snap") + replay->count("--no-surface") > 0 || surface_options_given(*replay);
    auto surface = surface_options(o->surface_args, *replay);
    if (!surface) {
      std::cerr << "fire replay: " << surface.error() << "\n";
      registry.exit_code = 1;
      return;
    }
    o->surface = *surface;
    auto unit = export_unit(o->units, *replay, o->surface_paths);
    if (!unit) {
      std::cerr << "fire replay: " << unit.error() << "\n";
      registry.exit_code = 1;
      return;
    }
    o->unit = *unit;
    registry.exit_code = run_replay(*o);
  });

  auto dir = std::make_shared<std::string>();
  CLI::App* open = app.add_subcommand(
      "open", "Reopen a session folder (engine/SESSION.md) after a clean exit or a crash and print its world hash");
  open->add_option("DIR", *dir, "session folder, as `fire replay LOG --session DIR` writes it")->required();
  open->footer(
      "Loads the newest snapshot that is whole (a damaged one is named and the one before used), replays the log's "
      "tail, drops a torn last record (saying how many bytes) and prints the hash of the pools and surface: that of a "
      "clean replay of the log that survived (`fire replay DIR/input.log --hash` when no record was torn). Exit 1 when nothing can be recovered (no folder, no log, a log corrupt "
      "before its last line, bad settings.json).");
  open->callback([dir, &registry] {
    auto r = reopen("fire open", *dir);
    if (!r) {
      std::cerr << "fire open: " << r.error() << "\n";
      registry.exit_code = 1;
      return;
    }
    if (std::string problem = r->world->mesh.validate(); !problem.empty()) {
      std::cerr << "fire open: internal error, the reopened network is invalid: " << problem << "\n";
      registry.exit_code = 2;
      return;
    }
    std::printf("%016" PRIx64 "\n", world_hash(*r->world));
  });

  auto net = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  CLI::App* exp = app.add_subcommand("export-network", "Write a curve network's polylines as OBJ (one `l` line per edge)");
  exp->add_option("NET", *net, "curve network file")->required();
  exp->add_option("-o,--output", *out, "OBJ file to write")->required();
  exp->callback([net, out, &registry] {
    auto mesh = load_network(*net);
    if (!mesh) {
      std::cerr << "fire export-network: " << mesh.error() << "\n";
      registry.exit_code = 1;
      return;
    }
    if (auto s = export_network_obj(*mesh, *out); !s) {
      std::cerr << "fire export-network: " << s.error << "\n";
      registry.exit_code = 1;
    }
  });
}

}  // namespace fire::cli
