// fire replay, fire export-network: the engine foundation's commands.
#include <cinttypes>
#include <cstdio>
#include <iostream>
#include <memory>

#include "platform/clock.hpp"
#include "platform/network_file.hpp"
#include "tools/fire/commands.hpp"
#include "tools/fire/session.hpp"

namespace fire::cli {

namespace {

struct ReplayOptions {
  std::string log_path, out_path, obj_path;
  bool hash = false, timings = false;
  double snap = SketchSettings{}.snap_distance;
};

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
  auto world = std::make_unique<World>();
  world->log = std::move(*log);
  world->sketch_settings.snap_distance = o.snap;
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
  if (o.timings) {
    std::printf("frames %" PRIu64 "\n", scheduler.frames());
    for (const SystemTiming& t : scheduler.timings())
      std::printf("system %-8s total %9.3f ms  mean %8.4f ms  max %8.4f ms\n", t.name.c_str(), t.total_ns / 1e6,
                  t.runs ? t.total_ns / 1e6 / double(t.runs) : 0.0, t.max_ns / 1e6);
    std::printf("vertices %zu edges %zu faces %zu points %zu; edits %zu applied, %zu rejected\n", m.vertex_count(),
                m.edge_count(), m.face_count(), m.live_point_count(), world->history.undo_depth(),
                world->rejections.size());
  }
  if (o.hash) std::printf("%016" PRIx64 "\n", m.hash());
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
  CLI::App* replay = app.add_subcommand("replay", "Replay an input log headless through the frame systems (input, sketch, split)");
  replay->add_option("LOG", o->log_path, "input log (format: engine/INPUT_LOG.md)")->required();
  replay->add_option("-o,--output", o->out_path, "write the final curve network here (format: engine/NETWORK_FORMAT.md)");
  replay->add_option("--export-obj", o->obj_path, "also write the network's polylines as OBJ lines");
  replay->add_flag("--hash", o->hash, "print a 64-bit hash of the final pools (identical on every run and machine)");
  replay->add_flag("--timings", o->timings, "print per-system timings and final counts");
  replay->add_option("--snap", o->snap, "snap distance for stroke ends, in model units")->capture_default_str();
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
