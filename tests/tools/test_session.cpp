// Crash-safe sessions (engine/SESSION.md, issue 14): the bundled demo written as a session is killed with
// SIGKILL at random moments, cut at random bytes after its last durability record, and reopened from
// every snapshot; each time the reopened world holds every committed stroke, its pools validate, and its
// hash is a clean replay's of the log that survived. FIRE_CRASH_RUNS=N sets the kills and the cuts
// (20 each by default; the 100-run record in perf/RESULTS.md is FIRE_CRASH_RUNS=100).
#include <numbers>

#include <catch2/catch.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include "platform/obj.hpp"
#include "tools/simulation/simulate.hpp"
#include "tests/temp_dir.hpp"
#include "tools/app/session_rig.hpp"
#include "tools/app/session_store.hpp"

using namespace fire;
namespace fs = std::filesystem;

namespace {

int64_t fake_clock() {
  static int64_t t = 0;
  return t += 1000;
}

const InputLog& demo_log() {
  static const InputLog log = [] {
    auto l = read_input_log(FIRE_SOURCE_DIR "/tools/demo/sketch.log");
    REQUIRE(l.ok());
    return *l;
  }();
  return log;
}

uint64_t demo_hash() {
  std::ifstream in(FIRE_SOURCE_DIR "/tests/engine/demo.hash");
  std::string hex;
  in >> hex;
  return std::stoull(hex, nullptr, 16);
}

int crash_runs() {
  const char* n = std::getenv("FIRE_CRASH_RUNS");
  return n ? std::max(1, std::atoi(n)) : 20;
}

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void write_file(const fs::path& p, std::string_view bytes) {
  std::ofstream out(p, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

using test::TempDir;

bool is_durable(const InputEvent& e) { return e.kind == EventKind::Meta && e.name == kDurableKey; }

size_t count_ups(const std::vector<InputEvent>& events) {
  return static_cast<size_t>(std::count_if(events.begin(), events.end(), [](const InputEvent& e) { return e.kind == EventKind::Up; }));
}

std::vector<InputEvent> without_durable(const std::vector<InputEvent>& events) {
  std::vector<InputEvent> out;
  for (const InputEvent& e : events)
    if (!is_durable(e)) out.push_back(e);
  return out;
}

// The rig of a log of device reports, from rig.json's text (none: empty).
std::optional<TrackingRig> rig_of(const std::string& rig_json, const std::vector<InputEvent>& events) {
  if (rig_json.empty()) return std::nullopt;
  InputLog log;
  log.events = events;
  auto rig = tracking_rig_from_json(rig_json, "rig.json", log, "log");
  REQUIRE(rig.ok());
  return *rig;
}

// A clean replay of these events from the start, as `fire replay LOG [--rig RIG] --hash` runs it.
uint64_t clean_hash(const InputLog& log, const std::string& rig_json = "", World* out = nullptr) {
  auto w = std::make_unique<World>();
  w->log = log;  // its version too: a version-1 log replays by version 1's sketch rules
  if (auto rig = rig_of(rig_json, log.events)) set_rig(*w, *rig);
  Scheduler s = make_scheduler(*w, fake_clock);
  replay_headless(*w, s);
  REQUIRE(w->mesh.validate() == "");
  if (out) {
    out->triangulate = w->triangulate;
    out->rejections = w->rejections;
  }
  return world_hash(*w);
}

uint64_t clean_hash(const std::vector<InputEvent>& events) {
  InputLog log;
  log.events = events;
  return clean_hash(log);
}

// Clean replays of the demo's first n events, each computed once.
uint64_t demo_prefix_hash(size_t n) {
  static std::map<size_t, uint64_t> memo;
  auto it = memo.find(n);
  if (it != memo.end()) return it->second;
  const auto& all = demo_log().events;
  return memo[n] = clean_hash(std::vector<InputEvent>(all.begin(), all.begin() + std::ptrdiff_t(std::min(n, all.size()))));
}

Status write_session(const InputLog& log, const fs::path& dir, const SessionWriteOptions& options,
                     const std::string& rig_json = "") {
  auto w = std::make_unique<World>();
  w->log = log;
  if (auto rig = rig_of(rig_json, log.events)) set_rig(*w, *rig);
  Scheduler s = make_scheduler(*w, fake_clock);
  auto out = SessionWriter::create(dir.string(), settings_json(*w), rig_json, {}, log.version);
  if (!out) return Status::failure(out.error());
  return replay_into_session(*w, s, *out, options);
}

// The log prefix a snapshot continues from (its first payload field).
uint64_t snapshot_log_bytes(const std::string& file) {
  auto r = SnapshotReader::open(file, "snapshot");
  REQUIRE(r.ok());
  uint64_t bytes = 0;
  REQUIRE(r->get(bytes));
  return bytes;
}

// A log written as a session with frequent snapshots; every snapshot the writer made is copied aside as
// it appears (the writer keeps only the newest two), with the log prefix it continues from.
struct WrittenSession {
  TempDir root;
  fs::path dir;
  std::string settings, log, rig;
  std::map<uint64_t, std::string> snapshots;     // frame -> file bytes
  std::map<uint64_t, uint64_t> snapshot_prefix;  // frame -> log bytes it continues from
};

void write_with_snapshots(const InputLog& log, uint64_t every, WrittenSession& s, const std::string& rig_json = "") {
  s.dir = s.root.path / "whole";
  s.rig = rig_json;
  SessionWriteOptions options;
  options.snapshot_every = every;
  options.on_snapshot = [&](uint64_t frame) { s.snapshots[frame] = read_file(SessionPaths{s.dir.string()}.snapshot(frame)); };
  REQUIRE(write_session(log, s.dir, options, rig_json).ok());
  s.settings = read_file(s.dir / kSessionSettings);
  s.log = read_file(s.dir / kSessionLog);
  for (const auto& [frame, bytes] : s.snapshots) s.snapshot_prefix[frame] = snapshot_log_bytes(bytes);
}

constexpr uint64_t kSnapshotEvery = 23;

const WrittenSession& demo_session() {
  static WrittenSession d;
  if (d.snapshots.empty()) write_with_snapshots(demo_log(), kSnapshotEvery, d);
  return d;
}

// What the snapshots of a session held, counted over all of them.
struct SnapshotCoverage {
  size_t pen_down = 0, pending = 0, redo = 0, tails = 0, provisional = 0, chains = 0;
};

// Reopens `s` from each of its snapshots alone with the whole log: the hash must be `expected`, and with a
// rig the triangulation system must end as `tracked` (its counts and the rejections of its strokes).
SnapshotCoverage reopen_from_each_snapshot(const WrittenSession& s, uint64_t expected, const World* tracked = nullptr) {
  SnapshotCoverage c;
  TempDir scratch;
  for (const auto& [frame, bytes] : s.snapshots) {
    INFO("snapshot after frame " << frame);
    const fs::path dir = scratch.path / std::to_string(frame);
    fs::create_directory(dir);
    write_file(dir / kSessionSettings, s.settings);
    write_file(dir / kSessionLog, s.log);
    if (!s.rig.empty()) write_file(dir / kSessionRig, s.rig);
    write_file(SessionPaths{dir.string()}.snapshot(frame), bytes);
    auto contents = read_session(dir.string());
    REQUIRE(contents.ok());
    World w;
    REQUIRE(apply_settings_json(contents->settings, "settings", w).ok());
    if (auto rig = rig_of(s.rig, contents->log.log.events)) set_rig(w, *rig);
    auto reader = SnapshotReader::open(bytes, "snapshot");
    REQUIRE(reader.ok());
    REQUIRE(load_world_snapshot(*reader, *contents, w).ok());
    c.pen_down += w.sketch.pen_down;
    c.pending += !w.sketch.pending.empty();
    c.redo += w.history.redo_depth() > 0;
    c.chains += w.mesh.pending_piece_count() > 0;
    // Taken while a fit ran: the reopened session starts it over (engine/SESSION.md).
    c.provisional += !w.surface.settled;

    auto r = reopen_session(dir.string(), fake_clock);
    REQUIRE(r.ok());
    REQUIRE(r->snapshot == frame);
    CHECK(r->notes.empty());
    c.tails += r->events_replayed > 0 || !w.surface.settled;
    REQUIRE(r->world->mesh.validate() == "");
    REQUIRE(world_hash(*r->world) == expected);
    if (tracked) {
      const TriangulateState& a = r->world->triangulate;
      const TriangulateState& b = tracked->triangulate;
      CHECK(a.counts.strokes == b.counts.strokes);
      CHECK(a.counts.frames_seen_by_both == b.counts.frames_seen_by_both);
      CHECK(a.counts.bridged_frames == b.counts.bridged_frames);
      CHECK(a.time_offset_us == b.time_offset_us);
      CHECK(a.offset_estimates == b.offset_estimates);
      CHECK(describe_device_problems(a) == describe_device_problems(b));
      CHECK(r->world->rejections.size() == tracked->rejections.size());
    }
  }
  // Only the last snapshot, after the last frame, has no tail to replay and no fit to finish.
  CHECK(c.tails + 1 == s.snapshots.size());
  return c;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// What a reopened session must be: pools that validate, at least `committed_ups` pen-ups, the demo's
// first events, and the hash of a clean replay of the surviving log (as it reads, durability records
// included, and without them as the demo's own prefix). Returns the pen-ups lost.
size_t check_reopened(const ReopenedSession& r, size_t committed_ups) {
  REQUIRE(r.world->mesh.validate() == "");
  const std::vector<InputEvent> events = without_durable(r.world->log.events);
  const auto& demo = demo_log().events;
  REQUIRE(events.size() <= demo.size());
  for (size_t i = 0; i < events.size(); ++i) {
    INFO("event " << i);
    REQUIRE(events[i].t_us == demo[i].t_us);
    REQUIRE(events[i].kind == demo[i].kind);
  }
  const size_t ups = count_ups(events);
  CHECK(ups >= committed_ups);
  const uint64_t hash = world_hash(*r.world);
  CHECK(hash == clean_hash(r.world->log.events));
  CHECK(hash == demo_prefix_hash(events.size()));
  return committed_ups > ups ? committed_ups - ups : 0;
}

// One line for perf/RESULTS.md: runs, strokes lost, what the runs covered, and the time per reopen.
void report(const char* what, int runs, size_t lost, const std::string& covered, const std::vector<double>& reopen_ms) {
  double sum = 0, worst = 0;
  for (double t : reopen_ms) {
    sum += t;
    worst = std::max(worst, t);
  }
  WARN(what << ": " << runs << " runs, " << lost << " committed strokes lost; " << covered << "; reopen mean "
            << (reopen_ms.empty() ? 0 : sum / double(reopen_ms.size())) << " ms, max " << worst << " ms over "
            << reopen_ms.size() << " reopens");
}

}  // namespace

TEST_CASE("a session's settings keep every surface option, and one out of range is refused by name", "[session]") {
  World w;
  w.surface_options.method = reconstruct::Method::Thesis;
  w.surface_options.coons_steps = 3;
  w.surface_options.levels = 2;
  w.surface_options.planarity = reconstruct::Planarity::Hough;
  w.surface_options.fairness = 0.25;
  w.surface_options.fairness_from_noise = false;
  const std::string text = settings_json(w);
  World back;
  REQUIRE(apply_settings_json(text, "settings.json", back).ok());
  CHECK(back.surface_options == w.surface_options);

  auto refused = [&](const std::string& key, const std::string& value) {
    std::string bad = text;
    const size_t at = bad.find("\"" + key + "\":");
    REQUIRE(at != std::string::npos);
    const size_t from = at + key.size() + 3, to = bad.find_first_of(",}", from);
    bad.replace(from, to - from, value);
    World other;
    const Status s = apply_settings_json(bad, "settings.json", other);
    CHECK(!s.ok());
    return s.error;
  };
  CHECK(refused("coons_steps", "9") == "settings.json: the number of Coons steps must be 1 to 5, not 9");
  CHECK(refused("levels", "0") == "settings.json: the subdivision level must be 1 to 6, not 0");
  CHECK(refused("fairness", "2") == "settings.json: the fairness weight must be 0 to 1, not 2.000000");
  CHECK(refused("planarity", "3") == "settings.json: a setting is out of range");
  CHECK(refused("coons_steps", "4294967297") == "settings.json: a setting is out of range");
}

TEST_CASE("a session log's torn last record is dropped and counted, corruption before it refused", "[session]") {
  std::string log = "FIRE-LOG 1\n0 down\n";
  log += format_durable(0, log.size());
  log += "10 pen 1 2 3\n";
  const uint64_t durable_end = log.find("10 pen");
  auto whole = recover_input_log(log, "s.log");
  REQUIRE(whole.ok());
  CHECK(whole->dropped_bytes == 0);
  CHECK(whole->durable_records == 1);
  CHECK(whole->durable_bytes == durable_end);
  CHECK(whole->log.events.size() == 3);

  auto torn = recover_input_log(log + "20 pen 4 5", "s.log");
  REQUIRE(torn.ok());
  CHECK(torn->dropped_bytes == 10);
  CHECK(torn->torn_line == 5);
  CHECK(torn->kept_bytes == log.size());
  CHECK(torn->log.events.size() == 3);

  auto bad = recover_input_log("FIRE-LOG 1\n0 dwon\n10 up\n", "s.log");
  REQUIRE_FALSE(bad.ok());
  CHECK(bad.error() == "s.log:2: unknown event kind 'dwon'");
  auto spliced = recover_input_log("FIRE-LOG 1\n0 down\n" + format_durable(0, 3), "s.log");
  REQUIRE_FALSE(spliced.ok());
  CHECK(spliced.error().find("s.log:3: durability record '3' does not name its own offset 18") == 0);
  auto header = recover_input_log("FIRE-LO", "s.log");
  REQUIRE_FALSE(header.ok());
  CHECK(header.error().find("nothing recoverable") != std::string::npos);
}

TEST_CASE("a snapshot that is cut, extended or damaged is detected by name", "[session]") {
  SnapshotWriter w;
  w.put(uint64_t(7));
  w.put(std::string("seven"));
  w.put(std::vector<Vec3>{Vec3(1, 2, 3)});
  const std::string file = w.finish();
  auto r = SnapshotReader::open(file, "a.fsnap");
  REQUIRE(r.ok());
  uint64_t n = 0;
  std::string s;
  std::vector<Vec3> v;
  CHECK((r->get(n) && r->get(s) && r->get(v)));
  CHECK((n == 7 && s == "seven" && v.size() == 1 && v[0] == Vec3(1, 2, 3)));
  CHECK(r->at_end());
  CHECK_FALSE(r->get(n));  // past the end: fails, and stays failed
  CHECK_FALSE(r->ok());

  auto cut = SnapshotReader::open(std::string_view(file).substr(0, file.size() - 1), "a.fsnap");
  REQUIRE_FALSE(cut.ok());
  CHECK(cut.error().find("a.fsnap: payload is") == 0);
  std::string flipped = file;
  flipped[flipped.size() - 2] ^= 1;
  auto damaged = SnapshotReader::open(flipped, "a.fsnap");
  REQUIRE_FALSE(damaged.ok());
  CHECK(damaged.error() == "a.fsnap: checksum mismatch (the snapshot is damaged)");
  CHECK_FALSE(SnapshotReader::open("FIRE-SNAP 2\n", "a.fsnap").ok());
}

TEST_CASE("every snapshot plus the log's tail equals a full replay, hash for hash", "[session][snapshot]") {
  SECTION("the demo, a snapshot every 23 frames: every one reopens to the recorded hash") {
    const WrittenSession& d = demo_session();
    REQUIRE(d.snapshots.size() > 20);
    const uint64_t golden = demo_hash();
    CHECK(clean_hash(recover_input_log(d.log, "log")->log.events) == golden);
    const SnapshotCoverage c = reopen_from_each_snapshot(d, golden);
    CHECK(c.pen_down > 0);     // a stroke half drawn
    CHECK(c.redo > 0);         // between the demo's undo and redo
    CHECK(c.provisional > 0);  // a fit running
  }
  SECTION("commands in the frame of a pen-up, a snapshot every frame: events waiting for the next frame") {
    // A square border, then a split whose pen-up shares its frame with an undo and a redo, so the sketch
    // system holds them over (one request per frame) across the snapshots. The last stroke starts and ends 0.05 off
    // the borders it joins, and only its first sample carries a snap radius (a mouse drawing's carry one
    // each) that reaches them where the session's 0.01 would refuse it: a snapshot taken mid-stroke must
    // keep the radius of a sample already consumed.
    std::string text = "FIRE-LOG 1\n", without_radius;
    int64_t t = 0;
    auto stroke = [&](const Vec3& a, const Vec3& b, const std::string& radius = "") {
      text += std::to_string(t) + " down\n";
      for (int k = 0; k <= 4; ++k) {
        const Vec3 p = a + (b - a) * (k / 4.0);
        text += std::to_string(t += 10'000) + " pen " + format_double(p.x()) + " " + format_double(p.y()) + " " +
                format_double(p.z()) + (k == 0 ? radius : "") + "\n";
      }
      text += std::to_string(t += 10'000) + " up\n";
    };
    stroke({0, 0, 0}, {1, 0, 0});
    stroke({1, 0, 0}, {1, 1, 0});
    stroke({1, 1, 0}, {0, 1, 0});
    stroke({0, 1, 0}, {0, 0, 0});
    stroke({0.5, 0, 0}, {0.5, 1, 0.1});
    text += std::to_string(t + 1) + " cmd undo\n" + std::to_string(t + 2) + " cmd redo\n";
    t += 2;
    const std::string before_last = text;
    stroke({0, 0.5, 0.05}, {1, 0.5, 0.05});
    without_radius = text;
    text = before_last;
    stroke({0, 0.5, 0.05}, {1, 0.5, 0.05}, " 0.08");
    auto log = parse_input_log(text, "pending.log");
    REQUIRE(log.ok());
    REQUIRE(clean_hash(*log) != clean_hash(*parse_input_log(without_radius, "no-radius.log")));
    WrittenSession s;
    write_with_snapshots(*log, 1, s);
    const uint64_t expected = clean_hash(*log);
    CHECK(clean_hash(recover_input_log(s.log, "log")->log) == expected);
    const SnapshotCoverage c = reopen_from_each_snapshot(s, expected);
    CHECK(c.pending > 0);
    CHECK(c.pen_down > 0);
    CHECK(c.redo > 0);
    CHECK(c.provisional > 0);
  }
  SECTION("topology strokes (version 2): closed across the hole, a face made a hole and back, a stroke across a curve, one in pieces, two loops joined") {
    std::string text = "FIRE-LOG 2\n";
    int64_t t = 0;
    auto stroke = [&](const Vec3& a, const Vec3& b, double bulge) {
      text += std::to_string(t) + " down\n";
      for (int k = 0; k <= 8; ++k) {
        const Vec3 p = a + (b - a) * (k / 8.0) + Vec3(0, 0, bulge * std::sin(std::numbers::pi * k / 8.0));
        text += std::to_string(t += 10'000) + " pen " + format_double(p.x()) + " " + format_double(p.y()) + " " +
                format_double(p.z()) + "\n";
      }
      text += std::to_string(t += 10'000) + " up\n";
    };
    auto command = [&](const std::string& c) { text += std::to_string(t += 10'000) + " cmd " + c + "\n"; };
    stroke({0, 0, 0}, {1, 0, 0}, 0);
    stroke({1, 0, 0}, {1, 1, 0}, 0);
    stroke({1, 1, 0}, {0, 1, 0}, 0);
    stroke({0, 1, 0}, {0.001, 0.001, 0}, 0);
    stroke({0.5, 0, 0}, {0.5, 1, 0}, 0.3);     // the top split
    stroke({0.25, 0, 0}, {0.75, 1, 0}, -0.3);  // across the hole below: closed
    command("hole 0.1 0.5 -0.05");             // the face below on the left: a hole again
    command("undo");
    command("redo");
    stroke({0, 0, 2}, {1, 0, 2}, 0);           // a second part, 2 above
    stroke({1, 0, 2}, {1, 1, 2}, 0);
    stroke({1, 1, 2}, {0, 1, 2}, 0);
    stroke({0, 1, 2}, {0.001, 0.001, 2}, 0);
    stroke({0.5, 0, 2}, {0.5, 1, 2}, 0);        // split in two, and a stroke across both halves: one edit
    stroke({0.25, 0, 2}, {0.75, 1, 2}, 0);
    command("undo");
    command("redo");
    stroke({0.25, 1, 2}, {0.3, 0.8, 2}, 0);     // a stroke in two pieces: the first ends off the network
    stroke({0.3, 0.8, 2}, {0, 0.75, 2}, 0);
    command("undo");
    command("redo");
    text += std::to_string(t) + " down\n";      // a bridge from the hole's rim up to the second part
    for (int k = 0; k <= 8; ++k)
      text += std::to_string(t += 10'000) + " pen 0 " + format_double(0.5 + 0.1 * std::sin(std::numbers::pi * k / 8.0)) + " " +
              format_double(0.25 * k) + "\n";
    text += std::to_string(t += 10'000) + " up\n";
    auto log = parse_input_log(text, "topology.log");
    REQUIRE(log.ok());
    WrittenSession s;
    write_with_snapshots(*log, 2, s);
    const uint64_t expected = clean_hash(*log);
    CHECK(clean_hash(recover_input_log(s.log, "log")->log) == expected);
    const SnapshotCoverage c = reopen_from_each_snapshot(s, expected);
    CHECK(c.redo > 0);
    CHECK(c.chains > 0);  // snapshots taken while the stroke in pieces waited
    // What the log drew: 8 faces (two on top, one below, the second part's five) and a bridge waiting.
    World w;
    w.log = *log;
    Scheduler scheduler = make_scheduler(w, [] { return int64_t(0); });
    replay_headless(w, scheduler);
    INFO((w.rejections.empty() ? std::string() : w.rejections.back().reason));
    CHECK(w.rejections.empty());
    CHECK(w.mesh.face_count() == 8);
    CHECK(w.mesh.pending_chains().empty());
    CHECK(w.mesh.pending_bridge_count() == 1);
    CHECK(w.mesh.border_loop_count() == 2);
  }
}

TEST_CASE("a live session forgets the events it has written and still reopens to the same drawing", "[session][live]") {
  // The app's loop (AppWindow::run_frame with a session): events arrive as their time comes, each frame's
  // are written before it runs, and the delivered ones leave memory (kept below 8 here, 4096 in the app).
  TempDir root;
  const fs::path dir = root.path / "live";
  const auto& demo = demo_log().events;
  World w;
  auto out = SessionWriter::create(dir.string(), settings_json(w));
  REQUIRE(out.ok());
  Scheduler s = make_scheduler(w, fake_clock);
  SessionWriteOptions options;
  options.snapshot_every = 41;
  SessionRecorder recorder(w, *out, options);
  size_t arrived = 0, most_in_memory = 0;
  auto arrive = [&](int64_t before_us) {
    for (; arrived < demo.size() && demo[arrived].t_us < before_us; ++arrived) w.log.events.push_back(demo[arrived]);
  };
  arrive(demo.front().t_us + 1);
  begin_frame(w, 0, demo.front().t_us);
  while (arrived < demo.size() || !replay_done(w)) {
    arrive(w.frame.end_us);
    recorder.before_frame(w);
    s.run_frame();
    recorder.after_frame(w, false);
    forget_delivered_events(w, 8);
    most_in_memory = std::max(most_in_memory, w.log.events.size());
    begin_frame(w, w.frame.index + 1, w.frame.end_us);
  }
  REQUIRE(recorder.finish().ok());
  CHECK(w.log.forgotten + w.log.events.size() == demo.size());
  CHECK(most_in_memory < 30);
  CHECK(world_hash(w) == demo_hash());
  auto r = reopen_session(dir.string(), fake_clock);
  REQUIRE(r.ok());
  CHECK(r->snapshot.has_value());
  CHECK(world_hash(*r->world) == demo_hash());
}

TEST_CASE("a tracked drawing's snapshots hold the triangulation system's state", "[session][snapshot][tracked]") {
  // Wii Remote reports of a pen drawing on the pawn, simulated, with the true cameras as the rig: each
  // snapshot, taken while the system holds reports waiting for their frame numbers, an open stroke and
  // its filter, reopens to what a clean `fire replay --rig` gives.
  auto pawn = read_obj(FIRE_DATA_DIR "/meshes/pawn.obj");
  REQUIRE(pawn.ok());
  simulation::RigOptions rig_options;
  rig_options.occlusion_per_s = 0.5;
  simulation::SketchOptions sketch;
  sketch.duration_s = 14;
  sketch.strokes = 4;
  sketch.hold_s = 0.5;
  auto simulated = simulation::simulate_sketch(rig_options, sketch,
                                             {pawn->positions, pawn->face_offsets, pawn->face_vertices});
  REQUIRE(simulated.ok());
  auto true_rig = simulation::true_rig_json(rig_options);
  REQUIRE(true_rig.ok());
  const std::string rig_json = *true_rig;
  auto log = parse_input_log(format_input_log(simulated->events), "sketch.log");
  REQUIRE(log.ok());

  WrittenSession s;
  write_with_snapshots(*log, 53, s, rig_json);
  REQUIRE(s.snapshots.size() >= 10);
  World tracked;
  const uint64_t expected = clean_hash(*log, rig_json, &tracked);
  REQUIRE(tracked.triangulate.counts.strokes >= 3);
  CHECK(clean_hash(recover_input_log(s.log, "log")->log, rig_json) == expected);
  reopen_from_each_snapshot(s, expected, &tracked);

  // Without its rig.json the session is refused in words, not replayed without its pen.
  const fs::path bare = s.root.path / "no-rig";
  fs::create_directory(bare);
  write_file(bare / kSessionSettings, s.settings);
  write_file(bare / kSessionLog, s.log);
  const auto& [frame, bytes] = *s.snapshots.begin();
  write_file(SessionPaths{bare.string()}.snapshot(frame), bytes);
  auto r = reopen_session(bare.string(), fake_clock);
  REQUIRE_FALSE(r.ok());
  CHECK(r.error() == (bare / "input.log").string() + " holds Wii Remote reports, but the session has no rig.json to "
                     "triangulate them with (put the rig they were drawn with there, from fire calibrate)");
  // A snapshot of a tracked drawing in a session whose rig went missing is passed over by name.
  World w;
  auto contents = read_session(s.dir.string());
  REQUIRE(contents.ok());
  auto reader = SnapshotReader::open(bytes, "snapshot");
  REQUIRE(reader.ok());
  const Status loaded = load_world_snapshot(*reader, *contents, w);
  REQUIRE_FALSE(loaded.ok());
  CHECK(loaded.error == "holds the triangulation system's state, but the session has no rig.json");
}

TEST_CASE("a session writer killed with SIGKILL at random moments reopens with every committed stroke",
          "[session][crash][kill]") {
  const int kills = crash_runs();
  TempDir root;
  // The writer runs in a child process and reports each commit (pen-ups now on disk) through a pipe.
  auto start_writer = [&](const fs::path& dir, int report_fd) {
    const pid_t pid = ::fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
      SessionWriteOptions options;
      options.snapshot_every = 53;
      options.on_commit = [report_fd](uint64_t ups, uint64_t) {
        if (::write(report_fd, &ups, sizeof ups) != sizeof ups) ::_exit(4);
      };
      Status s = write_session(demo_log(), dir, options);
      ::_exit(s.ok() ? 0 : 3);
    }
    return pid;
  };
  auto run = [&](const fs::path& dir, double kill_after_ms, int& status) {
    int fds[2];
    REQUIRE(::pipe(fds) == 0);
    const pid_t pid = start_writer(dir, fds[1]);
    ::close(fds[1]);
    if (kill_after_ms >= 0) {
      ::usleep(static_cast<useconds_t>(kill_after_ms * 1000));
      ::kill(pid, SIGKILL);
    }
    REQUIRE(::waitpid(pid, &status, 0) == pid);
    uint64_t ups = 0, last = 0;
    while (::read(fds[0], &ups, sizeof ups) == sizeof ups) last = ups;
    ::close(fds[0]);
    return last;
  };
  // One whole run sets the span the kills are spread over.
  int status = 0;
  const auto t0 = std::chrono::steady_clock::now();
  const uint64_t all_ups = run(root.path / "whole", -1, status);
  const double whole_ms = ms_since(t0);
  REQUIRE((WIFEXITED(status) && WEXITSTATUS(status) == 0));
  REQUIRE(all_ups == count_ups(demo_log().events));

  std::mt19937_64 rng(20261214);
  double span = whole_ms;  // shrinks when a writer finishes before its kill (a busy machine timed the first run)
  int interrupted = 0, attempts = 0, nothing_yet = 0;
  uint64_t fewest = all_ups, most = 0;
  size_t lost = 0;
  std::vector<double> reopen_ms;
  while (interrupted < kills && attempts < 3 * kills) {
    const fs::path dir = root.path / ("kill" + std::to_string(attempts++));
    const double at = std::uniform_real_distribution<double>(0.0, span)(rng);
    const uint64_t committed = run(dir, at, status);
    if (!WIFSIGNALED(status)) {  // the writer finished first: not a kill
      span = at;
      continue;
    }
    ++interrupted;
    INFO("kill after " << at << " ms, " << committed << " pen-ups committed");
    fewest = std::min(fewest, committed);
    most = std::max(most, committed);
    const auto t = std::chrono::steady_clock::now();
    auto r = reopen_session(dir.string(), fake_clock);
    if (r) reopen_ms.push_back(ms_since(t));
    if (!r) {
      // Killed while making the folder: nothing was committed, and the message says what is missing.
      INFO(r.error());
      CHECK(committed == 0);
      ++nothing_yet;
      continue;
    }
    lost += check_reopened(*r, committed);
    fs::remove_all(dir);
  }
  REQUIRE(interrupted == kills);
  CHECK(lost == 0);
  CHECK(nothing_yet < kills / 2);
  report("kills", interrupted, lost,
         std::to_string(attempts - interrupted) + " more writers finished before their kill, " +
             std::to_string(nothing_yet) + " killed before the folder held a log, committed pen-ups at the kill " +
             std::to_string(fewest) + " to " + std::to_string(most) + " of " + std::to_string(all_ups),
         reopen_ms);
}

TEST_CASE("a session cut at random bytes after its last durability record reopens with every committed stroke",
          "[session][crash][power]") {
  const WrittenSession& d = demo_session();
  const int cuts = crash_runs();
  // Where each durability record ends: a power cut after record j keeps the log up to its end, and may
  // keep any part of what followed before the next record reached the disk.
  std::vector<uint64_t> durable_end;
  for (size_t at = d.log.find(" meta durable "); at != std::string::npos; at = d.log.find(" meta durable ", at + 1))
    durable_end.push_back(d.log.find('\n', at) + 1);
  REQUIRE(durable_end.size() > 20);
  std::mt19937_64 rng(20261215);
  TempDir root;
  size_t lost = 0, torn = 0, damaged_snapshots = 0, from_snapshot = 0;
  std::vector<double> reopen_ms;
  for (int k = 0; k < cuts; ++k) {
    const size_t j = rng() % durable_end.size();
    const uint64_t lo = durable_end[j], hi = j + 1 < durable_end.size() ? durable_end[j + 1] - 1 : d.log.size();
    const uint64_t cut = lo + rng() % (hi - lo + 1);
    INFO("cut " << k << " at byte " << cut << " after the durability record ending at " << lo);
    const fs::path dir = root.path / std::to_string(k);
    fs::create_directory(dir);
    write_file(dir / kSessionSettings, d.settings);
    write_file(dir / kSessionLog, std::string_view(d.log).substr(0, cut));
    // The snapshots on disk at that moment: the newest two of those whose log prefix was durable.
    std::vector<uint64_t> frames;
    for (const auto& [frame, prefix] : d.snapshot_prefix)
      if (prefix <= lo) frames.push_back(frame);
    if (frames.size() > kSnapshotsKept) frames.erase(frames.begin(), frames.end() - kSnapshotsKept);
    for (uint64_t f : frames) write_file(SessionPaths{dir.string()}.snapshot(f), d.snapshots.at(f));
    // A third of the time the newest snapshot is damaged too, as on a disk that broke a rename's promise.
    std::string damaged;
    if (!frames.empty() && rng() % 3 == 0) {
      damaged = SessionPaths{dir.string()}.snapshot(frames.back());
      fs::resize_file(damaged, rng() % fs::file_size(damaged));
      ++damaged_snapshots;
    }
    const size_t committed = count_ups(recover_input_log(std::string_view(d.log).substr(0, lo), "log")->log.events);
    const auto t = std::chrono::steady_clock::now();
    auto r = reopen_session(dir.string(), fake_clock);
    reopen_ms.push_back(ms_since(t));
    REQUIRE(r.ok());
    lost += check_reopened(*r, committed);
    const uint64_t tail = cut - (d.log.rfind('\n', cut - 1) + 1);
    if (tail > 0) {
      ++torn;
      REQUIRE(!r->notes.empty());
      CHECK(r->notes.front().find("torn last record dropped (" + std::to_string(tail) + " bytes") != std::string::npos);
    }
    if (!damaged.empty()) {
      bool named = false;
      for (const std::string& note : r->notes) named = named || note.find(damaged) == 0;
      CHECK(named);
      CHECK(r->snapshot != frames.back());
    }
    from_snapshot += r->snapshot.has_value();
    fs::remove_all(dir);
  }
  CHECK(lost == 0);
  CHECK(torn > 0);
  CHECK(from_snapshot > 0);
  if (cuts >= 20) CHECK(damaged_snapshots > 0);
  report("power cuts", cuts, lost,
         std::to_string(torn) + " cut inside a record, " + std::to_string(damaged_snapshots) +
             " with the newest snapshot damaged, " + std::to_string(from_snapshot) + " reopened from a snapshot",
         reopen_ms);
}

TEST_CASE("a session resumed after a crash goes on drawing and reopens to a clean replay of its log",
          "[session][crash][resume]") {
  const WrittenSession& d = demo_session();
  const auto& demo = demo_log().events;
  std::mt19937_64 rng(20261216);
  TempDir root;
  for (int k = 0; k < 5; ++k) {
    const uint64_t cut = d.log.find('\n') + 1 + rng() % (d.log.size() - d.log.find('\n') - 1);
    INFO("log cut at byte " << cut);
    const fs::path dir = root.path / std::to_string(k);
    fs::create_directory(dir);
    write_file(dir / kSessionSettings, d.settings);
    write_file(dir / kSessionLog, std::string_view(d.log).substr(0, cut));
    for (const auto& [frame, prefix] : d.snapshot_prefix)
      if (prefix <= cut) write_file(SessionPaths{dir.string()}.snapshot(frame), d.snapshots.at(frame));
    const fs::path stale = SessionPaths{dir.string()}.snapshot(999'999) + ".tmp.12345";
    write_file(stale, "a killed writer's temporary snapshot");

    auto r = reopen_session(dir.string(), fake_clock);
    REQUIRE(r.ok());
    auto contents = read_session(dir.string());
    REQUIRE(contents.ok());
    auto out = SessionWriter::resume(*contents);
    REQUIRE(out.ok());
    CHECK_FALSE(fs::exists(stale));
    // The person goes on drawing after the restart: the rest of the demo, a second after the last frame.
    World& w = *r->world;
    const size_t done = without_durable(w.log.events).size();
    REQUIRE(done < demo.size());
    const int64_t shift = std::max<int64_t>(0, w.frame.end_us - demo[done].t_us) + 1'000'000;
    for (size_t i = done; i < demo.size(); ++i) {
      InputEvent e = demo[i];
      e.t_us += shift;
      w.log.events.push_back(std::move(e));
    }
    SessionWriteOptions options;
    options.snapshot_every = 53;
    REQUIRE(replay_into_session(w, *r->scheduler, *out, options).ok());
    REQUIRE(w.mesh.validate() == "");
    CHECK(count_ups(w.log.events) == count_ups(demo));
    const uint64_t live = world_hash(w);
    // Edits depend on the order of events, not on the frames they fall in: the whole drawing is there.
    CHECK(live == demo_hash());

    // On disk: the torn record cut off, the new records after it, and a reopen gives the live state.
    auto again = reopen_session(dir.string(), fake_clock);
    REQUIRE(again.ok());
    CHECK(again->log_info.dropped_bytes == 0);
    CHECK(again->snapshot.has_value());
    CHECK(world_hash(*again->world) == live);
    CHECK(clean_hash(again->world->log.events) == live);
  }
}

TEST_CASE("a version-1 log written into a session stays version 1 and reopens by its own rules", "[session]") {
  // A square, then a square apart from it: version 2 would start a second part, version 1 refused it.
  std::string text = "FIRE-LOG 1\n";
  int64_t t = 0;
  auto stroke = [&](const Vec3& a, const Vec3& b) {
    text += std::to_string(t += 10'000) + " down\n";
    for (int k = 0; k <= 4; ++k) {
      const Vec3 p = a + (b - a) * (k / 4.0);
      text += std::to_string(t += 10'000) + " pen " + format_double(p.x()) + " " + format_double(p.y()) + " " +
              format_double(p.z()) + "\n";
    }
    text += std::to_string(t += 10'000) + " up\n";
  };
  for (double x0 : {0.0, 3.0}) {
    stroke({x0, 0, 0}, {x0 + 1, 0, 0});
    stroke({x0 + 1, 0, 0}, {x0 + 1, 1, 0});
    stroke({x0 + 1, 1, 0}, {x0, 1, 0});
    stroke({x0, 1, 0}, {x0, 0, 0});
  }
  auto log = parse_input_log(text, "v1.log");
  REQUIRE(log.ok());
  REQUIRE(log->version == 1);
  const TempDir dir;
  REQUIRE(write_session(*log, dir.path / "s", {}).ok());
  std::ifstream in(dir.path / "s" / "input.log");
  std::string header;
  std::getline(in, header);
  CHECK(header == "FIRE-LOG 1");
  auto r = reopen_session((dir.path / "s").string(), fake_clock);
  REQUIRE(r.ok());
  CHECK(r->world->log.version == 1);
  CHECK(r->world->mesh.face_count() == 1);
  auto replay_hash = [](const InputLog& l) {
    auto w = std::make_unique<World>();
    w->log = l;
    Scheduler s = make_scheduler(*w, fake_clock);
    replay_headless(*w, s);
    return std::pair{world_hash(*w), w->mesh.face_count()};
  };
  CHECK(world_hash(*r->world) == replay_hash(*log).first);
  // The same strokes as version 2 draw the second part.
  auto v2 = parse_input_log("FIRE-LOG 2" + text.substr(10), "v2.log");
  REQUIRE(v2.ok());
  CHECK(replay_hash(*v2).second == 2);
}
