#include "tools/app/session_store.hpp"

#include <algorithm>
#include <limits>
#include <nlohmann/json.hpp>

#include "platform/files.hpp"
#include "tools/app/session_rig.hpp"

namespace fire {

namespace {

using nlohmann::json;

void save_event(SnapshotWriter& out, const InputEvent& e) {
  out.put(e.t_us);
  out.put(uint8_t(e.kind));
  out.put(e.p);
  out.put(e.snap);
  out.put(uint8_t(e.command));
  out.put(e.mark);
  out.put(int32_t(e.device));
  out.put(uint8_t(e.hid_ok));
  out.put(e.bytes);
  out.put(e.name);
  out.put(e.values);
  out.put(e.text);
  out.put(e.line);
}

bool load_event(SnapshotReader& in, InputEvent& e) {
  uint8_t kind = 0, command = 0, hid_ok = 0;
  int32_t device = 0;
  in.get(e.t_us);
  in.get(kind);
  in.get(e.p);
  in.get(e.snap);
  in.get(command);
  in.get(e.mark);
  in.get(device);
  in.get(hid_ok);
  in.get(e.bytes);
  in.get(e.name);
  in.get(e.values);
  in.get(e.text);
  in.get(e.line);
  if (kind > uint8_t(EventKind::Meta) || command > uint8_t(kLastCommandKind)) in.fail();
  e.kind = EventKind(kind);
  e.command = CommandKind(command);
  e.device = device;
  e.hid_ok = hid_ok != 0;
  return in.ok();
}

bool is_durable_record(const InputEvent& e) { return e.kind == EventKind::Meta && e.name == kDurableKey; }

std::string torn_record_note(const SessionContents& c) {
  return c.paths.log() + ":" + std::to_string(c.log.torn_line) + ": torn last record dropped (" +
         std::to_string(c.log.dropped_bytes) + " bytes without an end of line): the writer stopped inside it";
}

}  // namespace

std::string settings_json(const World& w) {
  json j;
  j["version"] = 1;
  j["snap_distance"] = w.sketch_settings.snap_distance;
  j["close_samples"] = w.sketch_settings.close_samples;
  j["surface"] = w.build_surface;
  j["method"] = w.surface_options.method == reconstruct::Method::Fire ? "fire" : "thesis";
  j["coons_steps"] = w.surface_options.coons_steps;
  j["levels"] = w.surface_options.levels;
  j["planarity"] = static_cast<int>(w.surface_options.planarity);
  j["fairness"] = w.surface_options.fairness;
  j["fairness_from_noise"] = w.surface_options.fairness_from_noise;
  return j.dump(2) + "\n";
}

Status apply_settings_json(std::string_view text, const std::string& source, World& w) {
  const json j = json::parse(text, nullptr, false);
  auto fail = [&](const std::string& why) { return Status::failure(source + ": " + why); };
  if (j.is_discarded() || !j.is_object()) return fail("not valid JSON");
  // Compared as JSON, not read as an int: a version out of int's range would be undefined behaviour.
  if (!j.contains("version") || j["version"] != 1) return fail("unsupported settings version (this build reads version 1)");
  const char* keys[] = {"snap_distance", "close_samples", "surface", "method", "coons_steps", "levels", "planarity", "fairness"};
  for (const char* key : keys)
    if (!j.contains(key)) return fail(std::string("missing '") + key + "'");
  if (!j["snap_distance"].is_number() || !j["fairness"].is_number() || !j["close_samples"].is_number_unsigned() ||
      !j["surface"].is_boolean() || !j["method"].is_string() || !j["coons_steps"].is_number_unsigned() ||
      !j["levels"].is_number_unsigned() || !j["planarity"].is_number_unsigned())
    return fail("a setting has the wrong type");
  // Sessions written before the fairness followed the noise lack the key: they replay with the fixed weight.
  if (j.contains("fairness_from_noise") && !j["fairness_from_noise"].is_boolean())
    return fail("a setting has the wrong type");
  const bool from_noise = j.contains("fairness_from_noise") && j["fairness_from_noise"].get<bool>();
  const double snap = j["snap_distance"], fairness = j["fairness"];
  const uint64_t close = j["close_samples"], coons = j["coons_steps"], levels = j["levels"], planarity = j["planarity"];
  const std::string method = j["method"];
  if (!(snap > 0) || close < 2 || close > 1'000'000 || (method != "fire" && method != "thesis") ||
      coons > UINT32_MAX || levels > UINT32_MAX || planarity > static_cast<uint64_t>(reconstruct::Planarity::Hough))
    return fail("a setting is out of range");
  reconstruct::Options surface = w.surface_options;
  surface.method = method == "fire" ? reconstruct::Method::Fire : reconstruct::Method::Thesis;
  surface.coons_steps = static_cast<uint32_t>(coons);
  surface.levels = static_cast<uint32_t>(levels);
  surface.planarity = static_cast<reconstruct::Planarity>(planarity);
  surface.fairness = fairness;
  surface.fairness_from_noise = from_noise;
  if (Status s = reconstruct::check_options(surface); !s) return fail(s.error);
  w.sketch_settings.snap_distance = snap;
  w.sketch_settings.close_samples = static_cast<uint32_t>(close);
  w.build_surface = j["surface"];
  w.surface_options = surface;
  return Status::success();
}

std::string snapshot_world(const World& w, uint64_t log_bytes, uint64_t log_hash) {
  SnapshotWriter out;
  out.put(log_bytes);
  out.put(log_hash);
  out.put(w.frame.index);
  out.put(w.frame.begin_us);
  out.put(w.frame.end_us);
  w.mesh.save(out);
  w.history.save(out);
  out.put(uint8_t(w.sketch.pen_down));
  out.put(w.sketch.stroke);
  out.put(w.sketch.start_snap);
  out.put(w.sketch.end_snap);
  out.put(uint64_t(w.sketch.outside.size()));
  for (const OutsideTurn& o : w.sketch.outside) {
    out.put(o.at.index);
    out.put(o.at.generation);
    out.put(o.turn);
  }
  out.put(uint64_t(w.sketch.pending.size()));
  for (const InputEvent& e : w.sketch.pending) save_event(out, e);
  save_surface(out, w.surface);
  out.put(w.surface_build.problem);
  out.put(w.surface_build.updates);
  out.put(uint64_t(w.rejections.size()));
  for (const Rejection& r : w.rejections) {
    out.put(r.t_us);
    out.put(r.line);
    out.put(r.reason);
  }
  out.put(uint8_t(w.rig.has_value()));
  if (w.rig) {
    save_triangulate_state(out, w.triangulate);
    w.registration.save(out);
  }
  return out.finish();
}

Status load_world_snapshot(SnapshotReader& in, const SessionContents& session, World& w) {
  uint64_t log_bytes = 0, log_hash = 0, count = 0;
  in.get(log_bytes);
  in.get(log_hash);
  if (!in.ok()) return Status::failure("cut off");
  if (log_bytes > session.log.kept_bytes ||
      log_prefix_hash(std::string_view(session.log_bytes).substr(0, log_bytes)) != log_hash)
    return Status::failure("continues from the first " + std::to_string(log_bytes) + " bytes of a log that " +
                           session.paths.log() + " does not begin with");
  in.get(w.frame.index);
  in.get(w.frame.begin_us);
  in.get(w.frame.end_us);
  // A frame is one step long and its times are the log's microseconds, far from int64's ends: the next
  // frames' times are computed from them.
  constexpr int64_t kFar = std::numeric_limits<int64_t>::max() / 2;
  if (w.frame.index >= uint64_t(kFar) || w.frame.begin_us < -kFar || w.frame.begin_us > kFar ||
      w.frame.end_us != w.frame.begin_us + kFrameStepUs)
    return Status::failure("frame " + std::to_string(w.frame.index) + " has an impossible number or times (damaged)");
  if (!w.mesh.load(in)) return Status::failure("the pools do not load");
  if (!w.history.load(in, w.mesh)) return Status::failure("the undo history does not load");
  uint8_t pen_down = 0;
  in.get(pen_down);
  in.get(w.sketch.stroke);
  in.get(w.sketch.start_snap);
  in.get(w.sketch.end_snap);
  w.sketch.pen_down = pen_down != 0;
  in.get(count);
  for (uint64_t k = 0; k < count && in.ok(); ++k) {
    OutsideTurn& o = w.sketch.outside.emplace_back();
    in.get(o.at.index);
    in.get(o.at.generation);
    in.get(o.turn);
    if (in.ok() && ((o.turn != 1 && o.turn != -1) || !w.mesh.valid(o.at))) return Status::failure("the sketch's outside turns do not load");
  }
  in.get(count);
  for (uint64_t k = 0; k < count && in.ok(); ++k) load_event(in, w.sketch.pending.emplace_back());
  if (!load_surface(in, w.surface)) return Status::failure("the surface does not load");
  in.get(w.surface_build.problem);
  in.get(w.surface_build.updates);
  in.get(count);
  for (uint64_t k = 0; k < count && in.ok(); ++k) {
    Rejection& r = w.rejections.emplace_back();
    in.get(r.t_us);
    in.get(r.line);
    in.get(r.reason);
  }
  uint8_t tracked = 0;
  in.get(tracked);
  if (in.ok() && tracked > 1) in.fail();
  if (in.ok() && (tracked != 0) != w.rig.has_value())
    return Status::failure(tracked ? "holds the triangulation system's state, but the session has no " +
                                         std::string(kSessionRig)
                                   : "holds no triangulation state, but the session has a " + std::string(kSessionRig));
  if (in.ok() && tracked && !load_triangulate_state(in, w.triangulate))
    return Status::failure("the triangulation system's state does not load");
  if (in.ok() && tracked && !w.registration.load(in)) return Status::failure("the registration does not load");
  if (!in.ok() || !in.at_end()) return Status::failure("cut off or followed by bytes it does not hold (damaged)");
  if (std::string problem = w.mesh.validate(); !problem.empty())
    return Status::failure("the pools break an invariant: " + problem);
  if (w.mesh.frame() != w.frame.index) return Status::failure("the pools' frame is not the snapshot's");
  // The events of the log's prefix are in the snapshot's state: the next one is the first on a later line.
  const uint32_t prefix_lines =
      static_cast<uint32_t>(std::count(session.log_bytes.begin(), session.log_bytes.begin() + log_bytes, '\n'));
  w.log = session.log.log;
  w.cursor.next = static_cast<size_t>(
      std::partition_point(w.log.events.begin(), w.log.events.end(),
                           [&](const InputEvent& e) { return e.line <= prefix_lines; }) -
      w.log.events.begin());
  // The index as the frame's last system left it, then the next frame begun, as replay_headless does.
  w.snap.sync(w.mesh);
  begin_frame(w, w.frame.index + 1, w.frame.end_us);
  return Status::success();
}

SessionRecorder::SessionRecorder(const World& w, SessionWriter& out, SessionWriteOptions options)
    : out_(out),
      options_(std::move(options)),
      appended_(w.log.forgotten + w.cursor.next),
      last_snapshot_(w.frame.index) {}

void SessionRecorder::commit() {
  if (!status_) return;
  status_ = out_.commit();
  if (status_ && options_.on_commit) options_.on_commit(ups_, commands_);
}


// The events this frame delivers (input_system: t_us before the frame's end) go to the log first, and
// take the line they have there, so rejections name the session log's lines, as after reopening.
void SessionRecorder::before_frame(World& w) {
  bool commit_point = false;
  for (; appended_ - w.log.forgotten < w.log.events.size(); ++appended_) {
    InputEvent& e = w.log.events[appended_ - w.log.forgotten];
    if (e.t_us >= w.frame.end_us) break;
    if (is_durable_record(e)) continue;  // a replayed session's own records name offsets in its log, not this one
    e.line = out_.lines() + 1;
    if (status_) status_ = out_.append(e);
    ups_ += e.kind == EventKind::Up;
    commands_ += e.kind == EventKind::Command;
    commit_point = commit_point || e.kind == EventKind::Up || e.kind == EventKind::Command;
  }
  if (commit_point) commit();
}

void SessionRecorder::after_frame(const World& w, bool last) {
  if (options_.snapshot_every == 0 || !(last || w.frame.index >= last_snapshot_ + options_.snapshot_every)) return;
  commit();
  if (status_) status_ = out_.write_snapshot(w.frame.index, snapshot_world(w, out_.log_bytes(), out_.log_hash()));
  if (status_ && options_.on_snapshot) options_.on_snapshot(w.frame.index);
  last_snapshot_ = w.frame.index;
}

Status SessionRecorder::finish() {
  commit();
  return status_;
}

Status replay_into_session(World& w, Scheduler& scheduler, SessionWriter& out, const SessionWriteOptions& options) {
  SessionRecorder recorder(w, out, options);
  ReplayHooks hooks;
  hooks.before_frame = [&](World& world) { recorder.before_frame(world); };
  hooks.after_frame = [&](const World& world) { recorder.after_frame(world, replay_done(world)); };
  if (w.cursor.next == 0 && w.log.forgotten == 0) replay_headless(w, scheduler, hooks);
  else continue_replay(w, scheduler, hooks);
  return recorder.finish();
}

Status write_log_session(const std::string& dir, const World& w, std::span<const InputEvent> events,
                         std::string_view rig_json, std::string_view marks_json) {
  auto out = SessionWriter::create(dir, settings_json(w), rig_json, marks_json, w.log.version);
  if (!out) return Status::failure(out.error());
  constexpr size_t kCommitEvery = 1000;
  size_t since_commit = 0;
  for (const InputEvent& e : events) {
    if (Status s = out->append(e); !s) return s;
    if (e.kind == EventKind::Up || e.kind == EventKind::Command || ++since_commit == kCommitEvery) {
      if (Status s = out->commit(); !s) return s;
      since_commit = 0;
    }
  }
  return out->commit();
}

Result<InputLog> read_log_or_session(const std::string& path, std::vector<std::string>& notes) {
  if (!is_directory(path)) return read_input_log(path);
  auto session = read_session(path);
  if (!session) return Result<InputLog>::failure(session.error());
  if (session->log.dropped_bytes > 0) notes.push_back(torn_record_note(*session));
  return std::move(session->log.log);
}

Result<ReopenedSession> reopen_session(const std::string& dir, Scheduler::Clock clock) {
  auto contents = read_session(dir);
  if (!contents) return Result<ReopenedSession>::failure(contents.error());
  const SessionContents& c = *contents;
  // The rig is read and checked against the log's remotes (a decode of every report) once, not per world.
  std::optional<TrackingRig> rig;
  if (!c.rig.empty()) {
    Result<TrackingRig> read = tracking_rig_from_json(c.rig, c.paths.rig(), c.log.log, c.paths.log());
    if (!read) return Result<ReopenedSession>::failure(read.error());
    rig = *read;
  }
  auto fresh = [&] {
    auto w = std::make_unique<World>();
    Status s = apply_settings_json(c.settings, c.paths.settings(), *w);
    if (rig) set_rig(*w, *rig);
    return std::make_pair(std::move(w), s);
  };
  if (Status s = fresh().second; !s) return Result<ReopenedSession>::failure(s.error);
  if (c.rig.empty() && has_device_reports(c.log.log))
    return Result<ReopenedSession>::failure(c.paths.log() + " holds Wii Remote reports, but the session has no " +
                                            std::string(kSessionRig) + " to triangulate them with (put the rig "
                                            "they were drawn with there, from fire calibrate)");
  ReopenedSession r;
  if (c.log.dropped_bytes > 0) r.notes.push_back(torn_record_note(c));
  r.snapshot = load_last_good_snapshot(
      c,
      [&](SnapshotReader& in) {
        auto [w, settings] = fresh();
        Status s = load_world_snapshot(in, c, *w);
        if (s) r.world = std::move(w);
        return s;
      },
      r.notes);
  if (!r.world) {
    r.world = fresh().first;
    r.world->log = c.log.log;
  }
  r.scheduler = std::make_unique<Scheduler>(make_scheduler(*r.world, clock));
  const size_t from = r.world->cursor.next;
  if (r.snapshot) continue_replay(*r.world, *r.scheduler);
  else replay_headless(*r.world, *r.scheduler);
  r.events_replayed = r.world->log.events.size() - from;
  r.log_info = c.log;
  r.log_info.log = {};
  return r;
}

}  // namespace fire
