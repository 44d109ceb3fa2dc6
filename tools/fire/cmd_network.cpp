// fire replay, fire export-network: the engine foundation's commands.
#include <cinttypes>
#include <cstdio>
#include <iostream>
#include <memory>

#include "platform/clock.hpp"
#include "platform/network_file.hpp"
#include "platform/surface_io.hpp"
#include "tools/fire/commands.hpp"
#include "tools/fire/session.hpp"

namespace fire::cli {

namespace {

struct ReplayOptions {
  std::string log_path, out_path, obj_path, surface_path;
  bool hash = false, timings = false, no_surface = false;
  double snap = SketchSettings{}.snap_distance;
  reconstruct::Options surface;
};

void print_timing(const SystemTiming& t) {
  std::printf("system %-10s mean %10.1f us  p99 %10.1f us  max %10.1f us  total %9.3f ms\n", t.name.c_str(),
              t.mean_ns() / 1e3, double(t.percentile_ns(99)) / 1e3, double(t.max_ns) / 1e3, double(t.total_ns) / 1e6);
}

int run_replay(const ReplayOptions& o) {
  auto log = read_input_log(o.log_path);
  if (!log) {
    std::cerr << "fire replay: " << log.error() << "\n";
    return 1;
  }
  if (!(o.snap > 0)) {
    std::cerr << "fire replay: --snap must be a positive distance\n";
    return 1;
  }
  if (o.no_surface && !o.surface_path.empty()) {
    std::cerr << "fire replay: --surface needs the surface that --no-surface turns off\n";
    return 1;
  }
  if (!o.surface_path.empty()) {
    if (auto format = surface_format_of(o.surface_path); !format) {
      std::cerr << "fire replay: " << format.error() << "\n";
      return 1;
    }
  }
  auto world = std::make_unique<World>();
  world->log = std::move(*log);
  world->sketch_settings.snap_distance = o.snap;
  world->build_surface = !o.no_surface;
  world->surface_options = o.surface;
  Scheduler scheduler = make_scheduler(*world, monotonic_ns);
  replay_headless(*world, scheduler);

  for (const Rejection& r : world->rejections)
    std::cerr << o.log_path << ":" << r.line << ": rejected: " << r.reason << "\n";
  if (world->log.rejected_hid_lines)
    std::cerr << o.log_path << ": " << world->log.rejected_hid_lines << " garbled device report line(s) skipped\n";
  std::string problem = world->mesh.validate();
  if (!problem.empty()) {
    std::cerr << "fire replay: internal error, the replayed network is invalid: " << problem << "\n";
    return 2;
  }
  const Mesh& m = world->mesh;
  const SurfaceLevels& surface = world->surface;
  if (!world->surface_build.problem.empty())
    std::cerr << o.log_path << ": the surface does not follow the last edit: " << world->surface_build.problem << "\n";
  if (o.timings) {
    std::printf("frames %" PRIu64 " run (frames with no input skipped)\n", scheduler.frames());
    for (const SystemTiming& t : scheduler.timings()) print_timing(t);
    print_timing(scheduler.frame_timing());
    std::printf("vertices %zu edges %zu faces %zu points %zu; edits %zu applied, %zu rejected\n", m.vertex_count(),
                m.edge_count(), m.face_count(), m.live_point_count(), world->history.undo_depth(),
                world->rejections.size());
    std::printf("surface: level %u, %u quads, %u vertices, %" PRIu64 " updates\n", surface.level, surface.quad_count(),
                surface.vertex_count(), world->surface_build.updates);
  }
  if (o.hash) std::printf("%016" PRIx64 "\n", world_hash(*world));
  if (!o.surface_path.empty()) {
    if (surface.empty()) {
      std::cerr << "fire replay: " << o.log_path << " ends with no surface to write to " << o.surface_path
                << (m.face_count() == 0 ? " (the network has no faces)\n" : "\n");
      return 1;
    }
    if (auto s = write_surface(to_surface_mesh(surface), o.surface_path); !s) {
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
  return 0;
}

}  // namespace

void add_network_commands(CLI::App& app, Registry& registry) {
  auto o = std::make_shared<ReplayOptions>();
  CLI::App* replay = app.add_subcommand(
      "replay", "Replay an input log headless through the frame systems (input, sketch, split, refine, subdivide, snap)");
  replay->add_option("LOG", o->log_path, "input log (format: engine/INPUT_LOG.md)")->required();
  replay->add_option("-o,--output", o->out_path, "write the final curve network here (format: engine/NETWORK_FORMAT.md)");
  replay->add_option("--export-obj", o->obj_path, "also write the network's polylines as OBJ lines");
  replay->add_option("--surface", o->surface_path,
                     "write the final surface here (.obj, .ply, .stl or .glb), as the frame's subdivide system left it");
  replay->add_flag("--no-surface", o->no_surface, "run only input, sketch and split (no refine and subdivide)");
  replay->add_option("--levels", o->surface.levels, "subdivision levels of the surface")
      ->capture_default_str()
      ->check(CLI::Range(1u, reconstruct::kMaxSurfaceLevels));
  replay->add_option("--fairness", o->surface.fairness, "fairness weight of the surface fit, 0 to 1")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  replay->add_flag("--hash", o->hash,
                   "print a 64-bit hash of the final pools and surface (identical on every run and machine)");
  replay->add_flag("--timings", o->timings, "print per-system timings (mean, p99, max per frame) and final counts");
  replay->add_option("--snap", o->snap,
                     "snap distance for stroke ends, in model units (a stroke end whose pen sample carries its own "
                     "radius, as a mouse drawing from fire app does, uses that)")
      ->capture_default_str();
  replay->callback([o, &registry] { registry.exit_code = run_replay(*o); });

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
