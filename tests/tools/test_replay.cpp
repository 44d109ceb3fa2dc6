// Replaying a log through the frame systems: deterministic, and bad strokes rejected without loss.
#include <catch2/catch.hpp>

#include <functional>
#include <map>

#include "systems/split/split_system.hpp"
#include "tools/app/session.hpp"

using namespace fire;

namespace {

int64_t fake_clock() {
  static int64_t t = 0;
  return t += 1000;
}

std::unique_ptr<World> replay_text(const std::string& text) {
  auto log = parse_input_log(text, "mem.log");
  REQUIRE(log.ok());
  auto w = std::make_unique<World>();
  w->log = std::move(*log);
  Scheduler s = make_scheduler(*w, fake_clock);
  replay_headless(*w, s);
  return w;
}

std::string stroke(int64_t& t, std::initializer_list<Vec3> pts) {
  std::string s = std::to_string(t) + " down\n";
  for (const Vec3& p : pts) {
    t += 10000;
    s += std::to_string(t) + " pen " + format_double(p.x()) + " " + format_double(p.y()) + " " + format_double(p.z()) + "\n";
  }
  t += 10000;
  s += std::to_string(t) + " up\n";
  t += 100000;
  return s;
}

// A 10 cm square border in four strokes; the last closes it, ending within 1 cm of the start.
std::string square_log(int64_t& t) {
  std::string text = "FIRE-LOG 1\n";
  text += stroke(t, {{0, 0, 0}, {0.05, 0, 0}, {0.1, 0, 0}});
  text += stroke(t, {{0.1, 0, 0}, {0.1, 0.05, 0}, {0.1, 0.1, 0}});
  text += stroke(t, {{0.1, 0.1, 0}, {0.05, 0.1, 0}, {0, 0.1, 0}});
  text += stroke(t, {{0, 0.1, 0}, {0, 0.05, 0}, {0.002, 0.001, 0}});
  return text;
}

}  // namespace

TEST_CASE("the demo log replays to the same pools every time", "[replay]") {
  auto log = read_input_log(FIRE_SOURCE_DIR "/tools/demo/sketch.log");
  REQUIRE(log.ok());
  uint64_t hashes[2];
  for (uint64_t& hash : hashes) {
    auto w = std::make_unique<World>();
    w->log = *log;
    Scheduler s = make_scheduler(*w, fake_clock);
    replay_headless(*w, s);
    REQUIRE(w->mesh.validate() == "");
    CHECK(w->mesh.face_count() == 14);
    CHECK(w->rejections.size() == 1);
    CHECK(s.timings().size() == 8);  // input, triangulate, register, sketch, split, refine, subdivide, snap
    CHECK(w->surface.quad_count() > 0);
    CHECK(w->surface_build.problem == "");
    hash = world_hash(*w);
  }
  CHECK(hashes[0] == hashes[1]);
}

TEST_CASE("strokes become a border, a split, and an undo", "[replay]") {
  int64_t t = 0;
  std::string text = square_log(t);
  auto w = replay_text(text);
  CHECK(w->mesh.face_count() == 1);
  CHECK(w->mesh.edge_count() == 4);
  text += stroke(t, {{0.051, 0.001, 0}, {0.05, 0.05, 0.01}, {0.049, 0.099, 0}});  // middle of bottom to middle of top
  w = replay_text(text);
  CHECK(w->mesh.face_count() == 2);
  CHECK(w->mesh.vertex_count() == 6);
  CHECK(w->rejections.empty());
  std::string undone = text + std::to_string(t) + " cmd undo\n";
  w = replay_text(undone);
  CHECK(w->mesh.face_count() == 1);
  std::string deleted = text + std::to_string(t) + " cmd delete 0.05 0.05 0.01\n";
  w = replay_text(deleted);
  CHECK(w->mesh.face_count() == 1);
  CHECK(w->mesh.vertex_count() == 4);
}

TEST_CASE("a curve marked sharp creases the surface, undo, redo and a replay of the log reproduce it bit for bit",
          "[replay][sharp]") {
  int64_t t = 0;
  std::string text = square_log(t);
  text += stroke(t, {{0.051, 0.001, 0}, {0.05, 0.05, 0.01}, {0.049, 0.099, 0}});
  const auto smooth = replay_text(text);
  const std::string marked = text + std::to_string(t) + " cmd sharp 0.05 0.05 0.01\n";
  const auto sharp = replay_text(marked);
  CHECK(sharp->rejections.empty());
  uint32_t middle = kNone;
  for (EdgeIndex e{0}; e < sharp->mesh.edge_slots(); ++e)
    if (sharp->mesh.edge_alive(e) && !sharp->mesh.is_border_edge(e)) middle = e;
  REQUIRE(middle != kNone);
  CHECK((sharp->mesh.edges.flags[middle] & kSharpEdge) != 0);
  // The live surface creased along it, as a reconstruction from scratch of the marked network does.
  REQUIRE(sharp->surface.quad_count() == smooth->surface.quad_count());
  CHECK(surface_hash(sharp->surface) != surface_hash(smooth->surface));
  auto fresh = reconstruct::reconstruct_surface(sharp->mesh, sharp->surface_options);
  REQUIRE(fresh);
  CHECK(fresh->positions == sharp->surface.positions);

  const std::string undone = marked + std::to_string(t + 10000) + " cmd undo\n";
  CHECK(world_hash(*replay_text(undone)) == world_hash(*smooth));
  CHECK(world_hash(*replay_text(undone + std::to_string(t + 20000) + " cmd redo\n")) == world_hash(*sharp));
  // The log as the app records it (format_input_log) replays to the same pools and surface.
  CHECK(world_hash(*replay_text(format_input_log(sharp->log.events))) == world_hash(*sharp));
  const auto missed = replay_text(text + std::to_string(t) + " cmd sharp 0.05 0.5 0\n");
  REQUIRE(missed->rejections.size() == 1);
  CHECK_THAT(missed->rejections[0].reason, Catch::Matchers::Contains("sharp: no curve within"));
}

TEST_CASE("a stroke with NaN or ends on two faces is rejected and nothing drawn is lost", "[replay][reject]") {
  int64_t t = 0;
  std::string text = "FIRE-LOG 1\n";
  text += stroke(t, {{0, 0, 0}, {0.1, 0, 0}});
  text += stroke(t, {{0.1, 0, 0}, {0.1, 0.1, 0}});
  text += stroke(t, {{0.1, 0.1, 0}, {0, 0.1, 0}});
  text += stroke(t, {{0, 0.1, 0}, {0, 0, 0}});
  auto clean = replay_text(text);
  std::string bad = text + stroke(t, {{0.05, 0, 0}, {std::nan(""), 0.05, 0}, {0.05, 0.1, 0}});
  bad += stroke(t, {{0.05, 0.3, 0}, {0.05, 0.5, 0}});  // nowhere near the network
  auto w = replay_text(bad);
  REQUIRE(w->rejections.size() == 2);
  CHECK_THAT(w->rejections[0].reason, Catch::Matchers::Contains("not finite"));
  CHECK_THAT(w->rejections[1].reason, Catch::Matchers::Contains("does not start and end"));
  CHECK(w->rejections[0].line > 0);
  CHECK(w->mesh.same_pools(clean->mesh));
}

TEST_CASE("a snap radius logged with the end samples replaces the session's setting", "[replay]") {
  int64_t t = 0;
  std::string square = "FIRE-LOG 1\n";
  square += stroke(t, {{0, 0, 0}, {0.05, 0, 0}, {0.1, 0, 0}});
  square += stroke(t, {{0.1, 0, 0}, {0.1, 0.1, 0}});
  square += stroke(t, {{0.1, 0.1, 0}, {0.05, 0.1, 0}, {0, 0.1, 0}});
  square += stroke(t, {{0, 0.1, 0}, {0, 0, 0}});
  // Ends 3 cm off the bottom and top edges' middle points: beyond the default 1 cm, within a logged 4 cm.
  auto split = [&](const char* radius) {
    int64_t u = t;
    std::string s = std::to_string(u) + " down\n";
    s += std::to_string(u += 10000) + " pen 0.05 -0.03 0" + radius + "\n";
    s += std::to_string(u += 10000) + " pen 0.05 0.05 0\n";
    s += std::to_string(u += 10000) + " pen 0.05 0.13 0" + radius + "\n";
    s += std::to_string(u += 10000) + " up\n";
    return s;
  };
  auto w = replay_text(square + split(""));
  CHECK(w->mesh.face_count() == 1);
  REQUIRE(w->rejections.size() == 1);
  // It says which end missed and by how much: here both, by 3 cm.
  CHECK_THAT(w->rejections[0].reason,
             Catch::Matchers::Contains("within 10.00 mm (the start is 30.00 mm from the nearest curve, the end 30.00 mm)"));
  w = replay_text(square + split(" 0.04"));
  CHECK(w->rejections.empty());
  CHECK(w->mesh.face_count() == 2);
}

TEST_CASE("snapping bends the whole stroke instead of kinking its end", "[replay]") {
  int64_t t = 0;
  std::string text = "FIRE-LOG 1\n";
  text += stroke(t, {{0, 0, 0}, {0.05, 0, 0}, {0.1, 0, 0}});
  text += stroke(t, {{0.1, 0, 0}, {0.1, 0.05, 0}, {0.1, 0.1, 0}});
  text += stroke(t, {{0.1, 0.1, 0}, {0.05, 0.1, 0}, {0, 0.1, 0}});
  text += stroke(t, {{0, 0.1, 0}, {0, 0.05, 0}, {0, 0, 0}});
  // Starts exactly on the bottom edge's middle point, ends 4 mm right of the top edge's middle point.
  text += stroke(t, {{0.05, 0, 0}, {0.05, 0.05, 0.01}, {0.054, 0.1, 0}});
  auto w = replay_text(text);
  REQUIRE(w->mesh.face_count() == 2);
  EdgeIndex curve;
  for (EdgeIndex e{0}; e < w->mesh.edge_slots(); ++e)
    if (w->mesh.edge_alive(e) && !w->mesh.is_border_edge(e)) curve = e;
  REQUIRE(curve != kNone);
  auto line = w->mesh.polyline(curve);
  REQUIRE(line.size() == 3);
  CHECK(line[2] == Vec3(0.05, 0.1, 0));
  // The middle sample took the share of the end's correction that its arc length gives it.
  const double a = Vec3(0, 0.05, 0.01).norm(), b = Vec3(0.004, 0.05, -0.01).norm();
  CHECK(line[1].x() == Approx(0.05 - 0.004 * a / (a + b)).margin(1e-12));
  CHECK(line[1].y() == Approx(0.05).margin(1e-9));
}

TEST_CASE("the demo log exercises every split case, an undo, a redo and a delete", "[replay]") {
  auto log = read_input_log(FIRE_SOURCE_DIR "/tools/demo/sketch.log");
  REQUIRE(log.ok());
  auto w = std::make_unique<World>();
  w->log = std::move(*log);
  // The session's systems, with a probe between sketch and split that classifies each applied split's ends
  // on the mesh as the split finds it.
  std::map<std::string, int> seen;
  auto end_kind = [&](const CurveEnd& end) {
    const uint32_t count = w->mesh.edges.point_count[end.edge];
    return end.point == 0 || end.point + 1 == count ? std::string("vertex") : std::string("edge");
  };
  std::vector<SystemSpec> systems = session_systems(*w);
  REQUIRE(systems[3].name() == "sketch");
  struct Probe {
    std::map<std::string, int>& seen;
    std::function<std::string(const CurveEnd&)> end_kind;
  } probe{seen, end_kind};
  systems.insert(systems.begin() + 4,
                 declare_system<Read<&World::requests>, ReadPrevious<&World::mesh>>(
                     *w, "probe", probe, [](Probe& p, const std::vector<EditRequest>& requests, const Mesh&) {
                       for (const EditRequest& r : requests) {
                         if (r.kind == RequestKind::Undo) ++p.seen["undo"];
                         else if (r.kind == RequestKind::Redo) ++p.seen["redo"];
                         else if (r.command.kind == EditKind::DeleteCurve) ++p.seen["delete"];
                         else if (r.command.kind == EditKind::SplitFace)
                           ++p.seen[p.end_kind(r.command.start) + "-" + p.end_kind(r.command.end)];
                       }
                     }));
  auto s = Scheduler::build(std::move(systems), fake_clock);
  REQUIRE(s.ok());
  w->build_surface = false;
  replay_headless(*w, *s);
  REQUIRE(w->rejections.size() == 1);  // the one stroke meant to be rejected
  for (const char* kind : {"edge-edge", "edge-vertex", "vertex-edge", "vertex-vertex", "undo", "redo", "delete"}) {
    INFO(kind);
    CHECK(seen[kind] >= 1);
  }
}

namespace {

// A world of three members, two of one type, for the scheduler's own cases.
struct Toy {
  int mesh = 0;
  int requests = 0;
  double surface = 0;
};

SystemSpec toy_sketch(Toy& t) {
  return declare_system<Read<&Toy::mesh>, Write<&Toy::requests>>(t, "sketch", [](const int& mesh, int& requests) {
    requests = mesh + 1;
  });
}
SystemSpec toy_split(Toy& t) {
  return declare_system<Read<&Toy::requests>, Write<&Toy::mesh>>(t, "split", [](const int& requests, int& mesh) {
    mesh = requests;
  });
}

}  // namespace

TEST_CASE("the scheduler refuses a read of what a later system writes, unless it reads the previous frame",
          "[scheduler]") {
  Toy t;
  std::vector<SystemSpec> systems;
  systems.push_back(toy_sketch(t));
  systems.push_back(toy_split(t));
  auto refused = Scheduler::build(std::move(systems), fake_clock);
  REQUIRE_FALSE(refused.ok());
  CHECK_THAT(refused.error(), Catch::Contains("'sketch' reads 'mesh'") && Catch::Contains("'split'"));

  std::vector<SystemSpec> previous;
  previous.push_back(declare_system<ReadPrevious<&Toy::mesh>, Write<&Toy::requests>>(
      t, "sketch", [](const int& mesh, int& requests) { requests = mesh + 1; }));
  previous.push_back(toy_split(t));
  auto declared = Scheduler::build(std::move(previous), fake_clock);
  REQUIRE(declared.ok());
  // The members the functions were handed are the world's: two frames carry the value on.
  declared->run_frame();
  declared->run_frame();
  CHECK(t.mesh == 2);
  CHECK_THAT(declared->describe(), Catch::Contains("sketch: reads -; reads last frame's mesh; writes requests"));

  std::vector<SystemSpec> stale;
  stale.push_back(declare_system<ReadPrevious<&Toy::surface>, Write<&Toy::requests>>(
      t, "sketch", [](const double&, int&) {}));
  stale.push_back(toy_split(t));
  auto refused_stale = Scheduler::build(std::move(stale), fake_clock);
  REQUIRE_FALSE(refused_stale.ok());
  CHECK_THAT(refused_stale.error(), Catch::Contains("'surface', but no later system writes it"));

  std::vector<SystemSpec> twice;
  twice.push_back(toy_split(t));
  twice.push_back(toy_split(t));
  CHECK_FALSE(Scheduler::build(std::move(twice), fake_clock).ok());
}

TEST_CASE("a system is declared by member pointers: two members of one type stay apart", "[scheduler]") {
  Toy t;
  const SystemSpec s = declare_system<Read<&Toy::mesh>, Write<&Toy::requests>>(t, "a", [](const int&, int&) {});
  CHECK(s.reads() == std::vector<std::string>{"mesh"});
  CHECK(s.writes() == std::vector<std::string>{"requests"});
  CHECK(s.reads_previous_frame().empty());
  CHECK(member_name<&World::object_events>() == "object_events");
  CHECK(member_name<&World::frame_events>() == "frame_events");
}

TEST_CASE("the scheduler keeps per-system samples for mean, p99 and max", "[scheduler]") {
  Toy t;
  int calls = 0;
  std::vector<SystemSpec> systems;
  systems.push_back(declare_system<Write<&Toy::requests>>(t, "count", calls, [](int& n, int&) { ++n; }));
  auto s = Scheduler::build(std::move(systems), fake_clock);
  REQUIRE(s.ok());
  for (int i = 0; i < 100; ++i) s->run_frame();
  CHECK(calls == 100);
  const SystemTiming& timing = s->timings()[0];
  REQUIRE(timing.samples_ns.size() == 100);
  CHECK(timing.percentile_ns(99) <= timing.max_ns);
  CHECK(timing.mean_ns() > 0);
  CHECK(s->frame_timing().samples_ns.size() == 100);
  CHECK(s->frame_timing().max_ns >= timing.max_ns);
  CHECK_THAT(s->describe(), Catch::Contains("count: reads -; writes requests"));
}

int64_t fake_cpu_clock() {
  static int64_t t = 0;
  return t += 300;
}

TEST_CASE("the scheduler times each system by the wall and, given a second clock, by the thread's CPU time", "[scheduler]") {
  Toy t;
  std::vector<SystemSpec> systems;
  systems.push_back(declare_system<Write<&Toy::requests>>(t, "a", [](int&) {}));
  systems.push_back(declare_system<Read<&Toy::requests>>(t, "b", [](const int&) {}));
  auto wall_only = Scheduler::build(systems, fake_clock);
  REQUIRE(wall_only.ok());
  wall_only->run_frame();
  CHECK(wall_only->cpu_timings().empty());
  CHECK(wall_only->frame_cpu_timing().frames == 0);
  auto both = Scheduler::build(std::move(systems), fake_clock, fake_cpu_clock);
  REQUIRE(both.ok());
  for (int i = 0; i < 3; ++i) both->run_frame();
  REQUIRE(both->cpu_timings().size() == 2);
  for (size_t i = 0; i < 2; ++i) {
    const SystemTiming& wall = both->timings()[i];
    const SystemTiming& cpu = both->cpu_timings()[i];
    CHECK(cpu.name == wall.name);
    CHECK(cpu.frames == 3);
    // Each clock is read once before and once after a system: one step of each.
    CHECK(wall.max_ns == 1000);
    CHECK(cpu.max_ns == 300);
  }
  // The frame's own reads bracket both systems': five steps of the wall clock, five of the CPU clock.
  CHECK(both->frame_timing().max_ns == 5000);
  CHECK(both->frame_cpu_timing().max_ns == 1500);
  CHECK(both->frame_cpu_timing().frames == 3);
}

TEST_CASE("the scheduler's samples stay bounded over a long session, mean and max cover every frame", "[scheduler]") {
  Toy t;
  std::vector<SystemSpec> systems;
  systems.push_back(declare_system<Write<&Toy::requests>>(t, "a", [](int&) {}));
  auto s = Scheduler::build(std::move(systems), fake_clock);
  REQUIRE(s.ok());
  const size_t frames = 2 * kTimingWindow + 1;
  for (size_t i = 0; i < frames; ++i) s->run_frame();
  for (const SystemTiming* timing : {&s->timings()[0], &s->frame_timing()}) {
    CHECK(timing->frames == frames);
    CHECK(timing->samples_ns.size() == kTimingWindow + 1);  // the oldest window dropped when the next frame came
    CHECK(timing->mean_ns() == double(timing->total_ns) / double(frames));
    CHECK(timing->percentile_ns(100) <= timing->max_ns);
  }
}

TEST_CASE("the session's frame order is accepted and the surface follows the network", "[scheduler][surface]") {
  auto log = read_input_log(FIRE_SOURCE_DIR "/tools/demo/sketch.log");
  REQUIRE(log.ok());
  auto w = std::make_unique<World>();
  w->log = std::move(*log);
  auto s = Scheduler::build(session_systems(*w), fake_clock);
  REQUIRE(s.ok());
  CHECK_THAT(s->describe(), Catch::Contains("sketch: reads object_events, sketch_settings, log, registration; reads last frame's mesh, snap; "
                                            "writes sketch, requests, rejections, pen_feedback"));
  CHECK_THAT(s->describe(), Catch::Contains("triangulate: reads frame, rig, frame_events; writes triangulate, pen_events"));
  replay_headless(*w, *s);
  // The surface the frame's refine and subdivide left is the network's, as a reconstruction from scratch makes it.
  REQUIRE(w->mesh.face_count() > 0);
  REQUIRE(w->surface.settled);
  auto rebuilt = reconstruct::reconstruct_surface(w->mesh, w->surface_options);
  REQUIRE(rebuilt.ok());
  const SurfaceMesh framed = to_surface_mesh(w->surface);
  CHECK(framed.face_vertices == rebuilt->face_vertices);
  CHECK(framed.positions == rebuilt->positions);
}
