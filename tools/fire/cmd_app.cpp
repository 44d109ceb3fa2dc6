// fire app: the interactive window. The session's systems run at the scheduler's fixed step on the input
// log's clock; the display is paced by vsync. Edits made with keys become commands in the session's input
// log, so `fire replay` of the recorded log (--record) gives the same pools and surface, bit for bit.
#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "engine/input_log.hpp"
#include "platform/clock.hpp"
#include "platform/files.hpp"
#include "platform/network_file.hpp"
#include "platform/obj.hpp"
#include "platform/surface_io.hpp"
#include "systems/evaluate/evaluate.hpp"
#include "tools/fire/app_live.hpp"
#include "tools/fire/app_window.hpp"
#include "tools/fire/commands.hpp"
#include "tools/fire/session.hpp"
#include "tools/fire/surface_args.hpp"

namespace fire::cli {

namespace {

struct AppArgs {
  std::string input_path, reference_path, out_path, export_path, record_path, script_path, screenshot_path,
      session_dir, size = "1280x720";
  uint64_t snapshot_every = 3000;
  SurfaceArgs surface_args;
  reconstruct::Options surface;  // from surface_args
  bool surface_given = false;    // a surface option on the command line
  int reference_levels = 3;
  double snap_pixels = 12;
  bool live = false;
  AppLiveOptions live_options;
};

int fail(const std::string& message) {
  std::cerr << "fire app: " << message << "\n";
  return 1;
}

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// The help overlay and `fire app --help` list the same keys.
const std::vector<std::string> kKeys = {
    "left drag       draw a stroke (logged): on --reference, else on the surface or the view plane",
    "right drag      orbit",
    "Shift + drag    pan",
    "scroll          zoom",
    "Ctrl+Z          undo (logged)",
    "Ctrl+Shift+Z    redo (logged; also Ctrl+Y)",
    "C               close the border to its first vertex (logged)",
    "Delete          delete the curve under the cursor (logged)",
    "K               the curve under the cursor sharp / smooth (logged)",
    "1 / 2 / 3       surface / curves / wireframe on or off",
    "F               frame everything",
    "Ctrl+S / E      save the network (-o) / export the surface (--export)",
    "H or F1         this help",
    "Esc             quit",
};
// With --live, besides the pad's buttons.
const std::vector<std::string> kLiveKeys = {
    "M               the pen rests on the mark shown: touched (logged)",
    "R               register the object on the marks touched (logged)",
    "N / P           show the next / previous mark",
};

// A new session folder's default name: the time it began, so a second session never meets the first's.
std::string default_live_session() {
  const std::time_t now = std::time(nullptr);
  char name[64];
  std::strftime(name, sizeof name, "fire-live-%Y%m%d-%H%M%S", std::localtime(&now));
  return name;
}

// A scripted event of --script: at display frame `frame`, `event` goes through the window's callbacks, or,
// with a resize size, the window asks the window system for that size (as a person dragging its border).
struct ScriptEvent {
  uint64_t frame = 0;
  window::WindowEvent event;
  uint32_t resize_width = 0, resize_height = 0;
};

Result<int> parse_key(const std::string& name) {
  if (name.size() == 1 && name[0] >= 'a' && name[0] <= 'z') return GLFW_KEY_A + (name[0] - 'a');
  if (name.size() == 1 && name[0] >= '0' && name[0] <= '9') return GLFW_KEY_0 + (name[0] - '0');
  if (name == "delete") return GLFW_KEY_DELETE;
  if (name == "escape") return GLFW_KEY_ESCAPE;
  if (name == "f1") return GLFW_KEY_F1;
  return Result<int>::failure("unknown key '" + name + "' (a-z, 0-9, delete, escape, f1)");
}

// The --script format, one event a line ('#' starts a comment):
//   FRAME move X Y | press left|right|middle | release left|right|middle | scroll DY | key [ctrl+][shift+]KEY |
//   resize WIDTH HEIGHT | close
// FRAME is the display frame (from 0) before which the event is delivered; frames never decrease.
Result<std::vector<ScriptEvent>> read_script(const std::string& path) {
  using R = Result<std::vector<ScriptEvent>>;
  auto text = read_text_file(path);
  if (!text) return R::failure(text.error());
  std::vector<ScriptEvent> events;
  std::istringstream lines(*text);
  std::string line;
  for (uint32_t number = 1; std::getline(lines, line); ++number) {
    if (const size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream in(line);
    ScriptEvent s;
    std::string kind;
    if (!(in >> s.frame)) {
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      return R::failure(path + ":" + std::to_string(number) + ": expected a frame number");
    }
    auto bad = [&](const std::string& why) { return R::failure(path + ":" + std::to_string(number) + ": " + why); };
    if (!events.empty() && s.frame < events.back().frame) return bad("frames must not decrease");
    if (!(in >> kind)) return bad("expected an event after the frame");
    window::WindowEvent& e = s.event;
    if (kind == "move") {
      e.kind = window::EventKind::CursorMove;
      if (!(in >> e.x >> e.y)) return bad("move needs X Y");
    } else if (kind == "press" || kind == "release") {
      e.kind = kind == "press" ? window::EventKind::ButtonPress : window::EventKind::ButtonRelease;
      std::string b;
      in >> b;
      if (b == "left") e.button = window::Button::Left;
      else if (b == "right") e.button = window::Button::Right;
      else if (b == "middle") e.button = window::Button::Middle;
      else return bad(kind + " needs left, right or middle");
    } else if (kind == "scroll") {
      e.kind = window::EventKind::Scroll;
      if (!(in >> e.y)) return bad("scroll needs DY");
    } else if (kind == "key") {
      e.kind = window::EventKind::KeyPress;
      std::string name;
      in >> name;
      for (const auto& [prefix, flag] : {std::pair{"ctrl+", window::kCtrl}, std::pair{"shift+", window::kShift}})
        while (name.rfind(prefix, 0) == 0) {
          e.mods |= flag;
          name = name.substr(std::string(prefix).size());
        }
      auto key = parse_key(name);
      if (!key) return bad(key.error());
      e.key = *key;
    } else if (kind == "resize") {
      if (!(in >> s.resize_width >> s.resize_height) || s.resize_width < 64 || s.resize_height < 64)
        return bad("resize needs WIDTH HEIGHT, at least 64 each");
    } else if (kind == "close") {
      e.kind = window::EventKind::Close;
    } else {
      return bad("unknown event '" + kind + "' (move, press, release, scroll, key, resize, close)");
    }
    std::string extra;
    if (in >> extra) return bad("unexpected '" + extra + "'");
    events.push_back(s);
  }
  return events;
}

// The polyline point nearest to the cursor on screen, within `radius` pixels, and its edge (kNone: none):
// what Delete and K pick.
uint32_t curve_point_under(const Mesh& mesh, const render::Camera& camera, uint32_t width, uint32_t height,
                           glm::vec2 cursor, float radius, Vec3& out) {
  float best = radius * radius;
  uint32_t found = kNone;
  for (uint32_t e = 0; e < mesh.edge_slots(); ++e) {
    if (!mesh.edge_alive(e)) continue;
    for (const Vec3& p : mesh.polyline(e)) {
      const glm::vec4 clip = camera.view_projection() * glm::vec4(float(p.x()), float(p.y()), float(p.z()), 1.0f);
      if (clip.w <= 0.0f) continue;  // behind the eye
      const glm::vec2 d = render::project_to_pixels(camera, p, width, height) - cursor;
      if (glm::dot(d, d) < best) {
        best = glm::dot(d, d);
        out = p;
        found = e;
      }
    }
  }
  return found;
}

std::string default_output(const std::string& input) {
  if (input.empty()) return "fire-app.fnet";
  std::filesystem::path p(input);
  return (p.parent_path() / (p.stem().string() + "-app.fnet")).string();
}

// Beside the network Ctrl+S saves: its name with .obj.
std::string default_export(const std::string& network_path) {
  return std::filesystem::path(network_path).replace_extension(".obj").string();
}

int run_app(const AppArgs& a) {
  uint32_t width = 0, height = 0;
  char tail = 0;
  if (std::sscanf(a.size.c_str(), "%ux%u%c", &width, &height, &tail) != 2 || width < 64 || height < 64 ||
      width > 8192 || height > 8192)
    return fail("--size must be WIDTHxHEIGHT, 64 to 8192 pixels a side, not '" + a.size + "'");
  if (!a.screenshot_path.empty() && !ends_with(a.screenshot_path, ".png"))
    return fail(a.screenshot_path + ": --screenshot must be a .png file");
  if (a.live) {
    if (!a.input_path.empty())
      return fail("--live starts a new session from the remotes; " + a.input_path +
                  " cannot be continued live (open it without --live to go on drawing with the mouse)");
    if (!a.record_path.empty()) return fail("--record: with --live the session folder's input.log is the record");
    if (!a.live_options.fake_rig_seed && a.live_options.rig_path.empty())
      return fail("--live needs the rig file from fire calibrate: give --rig RIG.json (or --fake-rig SEED to try it "
                  "without remotes)");
    if (a.live_options.fake_rig_seed && !a.live_options.rig_path.empty())
      return fail("--fake-rig brings its own rig and marks; --rig is for real remotes");
    if (!(a.live_options.fake_speed > 0 && a.live_options.fake_speed <= 100))
      return fail("--fake-speed must be above 0 and at most 100");
    if (a.live_options.fake_strokes < 0) return fail("--fake-strokes must be 0 (all) or more");
    if (a.live_options.ir_sensitivity < 1 || a.live_options.ir_sensitivity > 6)
      return fail("--ir-sensitivity must be 1 to 5, or 6 for the high-sensitivity block");
  } else if (a.live_options.fake_rig_seed || !a.live_options.rig_path.empty() || !a.live_options.marks_path.empty()) {
    return fail("--rig, --marks and --fake-rig are for --live");
  }
  const bool from_network = ends_with(a.input_path, ".fnet");
  const bool session_in = !a.input_path.empty() && is_directory(a.input_path);
  const bool recording = session_in || !a.session_dir.empty();
  if (from_network && !a.record_path.empty())
    return fail("--record: a session that starts from a network file cannot be replayed from its log alone; "
                "start from an input log or from nothing");
  if (from_network && !a.session_dir.empty())
    return fail("--session: a session that starts from a network file cannot be replayed from its log alone; "
                "start from an input log or from nothing");
  if (session_in && !a.session_dir.empty())
    return fail("--session writes a new session folder; " + a.input_path +
                " is a session already, and it goes on being written");
  if (session_in && a.surface_given)
    return fail(a.input_path + " is a session folder: its settings.json sets the surface options (--method, "
                "--coons-steps, --levels, --fairness, --planarity)");
  if (recording && !a.record_path.empty())
    return fail("--record: the session folder's input.log is the record already");
  if (a.snapshot_every == 0) return fail("--snapshot-every must be at least 1 frame");
  std::vector<ScriptEvent> script;
  if (!a.script_path.empty()) {
    auto s = read_script(a.script_path);
    if (!s) return fail("--script: " + s.error());
    script = std::move(*s);
  }
  if (!a.export_path.empty())
    if (auto format = surface_format_of(a.export_path); !format) return fail("--export: " + format.error());
  if (a.reference_levels < 0 || a.reference_levels > 5) return fail("--reference-levels must be 0 to 5");
  if (!(a.snap_pixels > 0) || a.snap_pixels > 200) return fail("--snap-pixels must be above 0 and at most 200");
  // The reference as drawn on: its Catmull-Clark limit surface (a control mesh), or its faces as fans (level 0).
  evaluate::TriangleMesh reference;
  if (!a.reference_path.empty()) {
    auto mesh = read_obj(a.reference_path);
    if (!mesh) return fail("--reference: " + mesh.error());
    auto triangles = a.reference_levels > 0
                         ? evaluate::reference_limit_surface(mesh->positions, mesh->face_offsets, mesh->face_vertices,
                                                             a.reference_levels)
                         : evaluate::triangulate(mesh->positions, mesh->face_offsets, mesh->face_vertices);
    if (!triangles) return fail("--reference: " + a.reference_path + ": " + triangles.error());
    reference = std::move(*triangles);
  }
  const evaluate::TriangleBvh reference_bvh(reference);
  const std::vector<Vec3>& reference_positions = reference.positions;

  // The session: a session folder to go on with, a network to continue from, or an input log replayed
  // first, or nothing; written to a session folder as it goes, when it has one.
  std::unique_ptr<World> world;
  std::unique_ptr<Scheduler> scheduler_owner;
  std::optional<SessionWriter> writer;
  SessionWriteOptions write_options;
  write_options.snapshot_every = a.snapshot_every;
  std::unique_ptr<AppLive> live;
  const std::string live_dir = a.session_dir.empty() ? default_live_session() : a.session_dir;
  if (a.live) {
    AppLiveOptions options = a.live_options;
    options.session_dir = live_dir;
    options.surface = a.surface;
    options.write = write_options;
    auto opened = AppLive::open(options);
    if (!opened) return fail(opened.error());
    live = std::move(*opened);
    std::cerr << "fire app: live session in " << live_dir << "\n";
  } else if (session_in) {
    auto reopened = reopen_session(a.input_path, monotonic_ns);
    if (!reopened) return fail(reopened.error());
    for (const std::string& note : reopened->notes) std::cerr << "fire app: " << note << "\n";
    auto contents = read_session(a.input_path);
    if (!contents) return fail(contents.error());
    auto resumed = SessionWriter::resume(*contents);
    if (!resumed) return fail(resumed.error());
    writer.emplace(std::move(*resumed));
    world = std::move(reopened->world);
    scheduler_owner = std::move(reopened->scheduler);
    std::cerr << "fire app: " << a.input_path << ": reopened ("
              << (reopened->snapshot ? "snapshot after frame " + std::to_string(*reopened->snapshot) : std::string("no snapshot"))
              << ", then " << reopened->events_replayed << " event(s) of its log); new strokes are added to it\n";
  } else {
    world = std::make_unique<World>();
    world->surface_options = a.surface;
    if (from_network) {
      auto network = load_network(a.input_path);
      if (!network) return fail(network.error());
      world->mesh = std::move(*network);
    } else if (!a.input_path.empty()) {
      auto log = read_input_log(a.input_path);
      if (!log) return fail(log.error());
      world->log = std::move(*log);
    }
  }
  World& w = live ? live->world() : *world;
  if (!live && w.log.events.empty()) {
    // Frame 0 starts at the first event, in a replay as here: a first event at 0 fixes the clock's origin.
    InputEvent start;
    start.kind = EventKind::Meta;
    start.name = "session";
    start.text = "fire app";
    w.log.events.push_back(start);
  }
  if (!live && !a.session_dir.empty()) {
    auto created = SessionWriter::create(a.session_dir, settings_json(w));
    if (!created) return fail(created.error());
    writer.emplace(std::move(*created));
  }
  if (!live && !scheduler_owner) scheduler_owner = std::make_unique<Scheduler>(make_scheduler(w, monotonic_ns));
  Scheduler& scheduler = live ? live->scheduler() : *scheduler_owner;
  std::optional<SessionRecorder> recorder;
  if (writer) {
    recorder.emplace(w, *writer, write_options);
    if (!session_in) {  // the input log, replayed first, is the new session's beginning
      ReplayHooks hooks;
      hooks.before_frame = [&](World& world) { recorder->before_frame(world); };
      hooks.after_frame = [&](const World& world) { recorder->after_frame(world, false); };
      replay_headless(w, scheduler, hooks);
    }
    if (Status s = recorder->finish(); !s) return fail(s.error);
  } else if (!live) {
    replay_headless(w, scheduler);
  }

  auto opened = AppWindow::open(w, scheduler, width, height, reference.positions, reference.triangles);
  if (!opened && live && live->frames_run() == 0) {
    // Nothing was recorded yet: the new folder would only be an empty session.
    live.reset();
    std::error_code ignored;
    std::filesystem::remove_all(live_dir, ignored);
  }
  if (!opened) return fail(opened.error());
  AppWindow& app = **opened;
  if (recorder) app.record_into(&*recorder);
  window::Window& window = app.window();

  render::Orbit orbit = frame_orbit(scene_box(w.mesh, w.surface, reference_positions), app.width(), app.height());
  window::HudData& hud_data = app.hud_data;
  hud_data.keys = kKeys;
  if (live) {
    hud_data.keys.insert(hud_data.keys.end(), kLiveKeys.begin(), kLiveKeys.end());
    for (const std::string& line : pad_help_lines()) hud_data.keys.push_back(line);
  }
  const std::string out_path = a.out_path.empty() ? default_output(a.input_path) : a.out_path;
  const std::string export_path = a.export_path.empty() ? default_export(out_path) : a.export_path;
  auto report = [&](std::string message) {
    hud_data.status = std::move(message);
    std::cerr << "fire app: " << hud_data.status << "\n";
  };
  // The view frames the drawing as it grows, until the person moves it.
  bool view_moved = false;
  size_t framed_edges = w.mesh.edge_count();
  if (live)
    app.drive_frames_with([&] {
      for (std::string& message : live->step()) report(std::move(message));
      live->fill_hud(hud_data);
      app.show_marks(live->marks_in_view(), live->shown_mark());
      if (!view_moved && w.mesh.edge_count() != framed_edges) {
        framed_edges = w.mesh.edge_count();
        render::Box box = scene_box(w.mesh, w.surface, reference_positions);
        for (const Vec3& mark : live->marks_in_view()) box.add(mark);
        orbit = frame_orbit(box, app.width(), app.height());
      }
    });
  auto log_command = [&](CommandKind command, const Vec3& p) {
    if (live) return live->command(command, p);
    InputEvent e;
    e.kind = EventKind::Command;
    e.command = command;
    e.p = p;
    app.log_event(std::move(e));
  };
  auto log_pen = [&](EventKind kind) {
    InputEvent e;
    e.kind = kind;
    app.log_event(std::move(e));
  };
  // The mouse pen draws on the reference; without one, on the surface where the stroke starts on it, or
  // else on the plane through the view's centre facing the view, kept for the whole stroke.
  std::optional<evaluate::TriangleBvh> surface_bvh;  // the surface as the stroke began
  const evaluate::TriangleBvh* stroke_mesh = nullptr;
  Vec3 plane_point = Vec3::Zero(), plane_normal = Vec3::UnitZ();
  auto cursor_ray = [&](glm::vec2 pixel) {
    const render::Camera& camera = app.camera();
    const glm::vec3 d = render::ray_through_pixel(camera, pixel, app.width(), app.height());
    return std::pair{Vec3(camera.eye.x, camera.eye.y, camera.eye.z), Vec3(d.x, d.y, d.z)};
  };
  auto hit_mesh = [&](const evaluate::TriangleBvh& bvh, glm::vec2 pixel) -> std::optional<Vec3> {
    const auto [origin, direction] = cursor_ray(pixel);
    const evaluate::TriangleBvh::Hit hit = bvh.ray_cast(origin, direction);
    if (hit.triangle == evaluate::kNoTriangle) return std::nullopt;
    return hit.point;
  };
  auto hit_plane = [&](glm::vec2 pixel) -> std::optional<Vec3> {
    const auto [origin, direction] = cursor_ray(pixel);
    const double facing = direction.dot(plane_normal);
    if (std::abs(facing) < 1e-9) return std::nullopt;
    const double t = (plane_point - origin).dot(plane_normal) / facing;
    if (!(t > 0)) return std::nullopt;
    return Vec3(origin + t * direction);
  };
  // Chooses what the stroke starting at `pixel` draws on; false when the pen would draw on nothing.
  auto begin_stroke_target = [&](glm::vec2 pixel) {
    if (!reference.triangles.empty()) {
      stroke_mesh = &reference_bvh;
      return hit_mesh(reference_bvh, pixel).has_value();
    }
    stroke_mesh = nullptr;
    if (!w.surface.empty()) {
      evaluate::TriangleMesh mesh{w.surface.positions, {}};
      mesh.triangles.reserve(w.surface.quads.size() / 4 * 6);
      for (size_t q = 0; q + 3 < w.surface.quads.size(); q += 4) {
        const uint32_t* v = &w.surface.quads[q];
        mesh.triangles.insert(mesh.triangles.end(), {v[0], v[1], v[2], v[0], v[2], v[3]});
      }
      surface_bvh.emplace(mesh);
      if (hit_mesh(*surface_bvh, pixel)) {
        stroke_mesh = &*surface_bvh;
        return true;
      }
    }
    const render::Camera& camera = app.camera();
    plane_point = Vec3(orbit.target.x, orbit.target.y, orbit.target.z);
    plane_normal = (plane_point - Vec3(camera.eye.x, camera.eye.y, camera.eye.z)).normalized();
    return hit_plane(pixel).has_value();
  };
  // A hit is a pen sample with the snap radius of --snap-pixels at its depth, both logged, so the drawing
  // replays without the view.
  auto pen_sample = [&](glm::vec2 pixel) {
    const std::optional<Vec3> hit = stroke_mesh ? hit_mesh(*stroke_mesh, pixel) : hit_plane(pixel);
    if (!hit) return false;
    InputEvent e;
    e.kind = EventKind::Pen;
    e.p = *hit;
    const glm::vec3 p(float(hit->x()), float(hit->y()), float(hit->z()));
    e.snap = a.snap_pixels * double(render::pixel_size_at(app.camera(), p, app.height()));
    app.log_event(std::move(e));
    return true;
  };
  bool dragging = false, panning = false, drawing = false;
  glm::vec2 cursor(0.0f);
  uint64_t display_frame = 0;
  size_t next_script = 0;

  auto handle = [&](const window::WindowEvent& e) {
    using window::EventKind;
    const bool ctrl = e.mods & window::kCtrl, shift = e.mods & window::kShift;
    switch (e.kind) {
      case EventKind::CursorMove: {
        const glm::vec2 now(float(e.x), float(e.y)), d = now - cursor;
        if (dragging) orbit.rotate(d.x, d.y);
        if (panning) orbit.pan(d.x, d.y, std::max(app.height(), 1u));
        view_moved = view_moved || dragging || panning;
        if (drawing) {  // samples every 2 pixels along the move, so a fast drag still makes a dense stroke
          const int steps = std::max(1, int(std::ceil(glm::length(d) / 2.0f)));
          for (int k = 1; k <= steps; ++k) pen_sample(cursor + d * (float(k) / float(steps)));
        }
        cursor = now;
        break;
      }
      case EventKind::ButtonPress:
        cursor = glm::vec2(float(e.x), float(e.y));
        if (app.hud().wants_mouse() || dragging || panning || drawing) break;
        if (shift || e.button == window::Button::Middle) panning = true;
        else if (e.button == window::Button::Left && live) {
          hud_data.status = "--live: the IR pen draws; right drag orbits, Shift + drag pans";
        } else if (e.button == window::Button::Left) {
          // The pen goes down with its first sample, on what the stroke will draw on.
          if (!begin_stroke_target(cursor)) {
            hud_data.status = "press on the reference mesh to draw";
            break;
          }
          log_pen(fire::EventKind::Down);
          drawing = pen_sample(cursor);
        } else if (e.button == window::Button::Right) dragging = true;
        else panning = true;
        break;
      case EventKind::ButtonRelease:
        if (drawing) log_pen(fire::EventKind::Up);
        dragging = panning = drawing = false;
        break;
      case EventKind::Scroll:
        if (!app.hud().wants_mouse()) {
          orbit.zoom(float(e.y));
          view_moved = true;
        }
        break;
      case EventKind::KeyPress:
        if (ctrl && e.key == GLFW_KEY_Z) log_command(shift ? CommandKind::Redo : CommandKind::Undo, Vec3::Zero());
        else if (ctrl && e.key == GLFW_KEY_Y) log_command(CommandKind::Redo, Vec3::Zero());
        else if (ctrl && e.key == GLFW_KEY_S) {
          const Status saved = save_network(w.mesh, out_path);
          report(saved ? "saved " + std::to_string(w.mesh.edge_count()) + " curves to " + out_path : saved.error);
        } else if (ctrl) break;
        else if (e.key == GLFW_KEY_C) log_command(CommandKind::Close, Vec3::Zero());
        else if (e.key == GLFW_KEY_DELETE) {
          Vec3 p;
          if (curve_point_under(w.mesh, app.camera(), app.width(), app.height(), cursor, 12.0f, p) != kNone)
            log_command(CommandKind::Delete, p);
          else hud_data.status = "no curve under the cursor to delete";
        } else if (e.key == GLFW_KEY_K) {
          Vec3 p;
          const uint32_t edge = curve_point_under(w.mesh, app.camera(), app.width(), app.height(), cursor, 12.0f, p);
          if (edge == kNone) hud_data.status = "no curve under the cursor to mark sharp";
          else {
            log_command(CommandKind::Sharp, p);
            hud_data.status = w.mesh.edges.flags[edge] & kSharpEdge ? "making the curve smooth" : "marking the curve sharp";
          }
        } else if (e.key == GLFW_KEY_E) {
          // The surface as the frames have built it so far; a failed write leaves the session untouched.
          if (w.surface.empty()) report("export: no surface yet (it needs a closed border)");
          else if (const Status s = write_surface(to_surface_mesh(w.surface), export_path); !s) report("export failed: " + s.error);
          else
            report("exported " + std::to_string(w.surface.quad_count()) + " surface quads to " + export_path +
                   (w.surface.settled ? "" : " (provisional: the fit was still converging)"));
        } else if (live && e.key == GLFW_KEY_M) report(live->act(PadAction::TouchMark));
        else if (live && e.key == GLFW_KEY_R) report(live->act(PadAction::Register));
        else if (live && e.key == GLFW_KEY_N) report(live->act(PadAction::NextMark));
        else if (live && e.key == GLFW_KEY_P) report(live->act(PadAction::PreviousMark));
        else if (e.key == GLFW_KEY_1) hud_data.view.surface = !hud_data.view.surface;
        else if (e.key == GLFW_KEY_2) hud_data.view.curves = !hud_data.view.curves;
        else if (e.key == GLFW_KEY_3) hud_data.view.wireframe = !hud_data.view.wireframe;
        else if (e.key == GLFW_KEY_F) orbit = frame_orbit(scene_box(w.mesh, w.surface, reference_positions), app.width(), app.height());
        else if (e.key == GLFW_KEY_H || e.key == GLFW_KEY_F1) hud_data.help = !hud_data.help;
        else if (e.key == GLFW_KEY_ESCAPE) glfwSetWindowShouldClose(window.handle(), GLFW_TRUE);
        break;
      case EventKind::Close:
        break;
    }
  };

  while (app.status() && !window.should_close()) {
    for (; next_script < script.size() && script[next_script].frame <= display_frame; ++next_script) {
      const ScriptEvent& s = script[next_script];
      if (s.resize_width) window.request_size(s.resize_width, s.resize_height);
      else window.inject(s.event);
    }
    window.poll();
    for (const window::WindowEvent& e : window.events()) handle(e);
    window.events().clear();
    if (!app.display(orbit) && app.status() && app.width() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(16));
    ++display_frame;
  }
  if (!app.status()) return fail("Vulkan: " + app.status().error);

  // Every logged event handled, as `fire replay` ends, and the session's last snapshot; then the last
  // picture, which --screenshot keeps.
  if (live) {
    if (Status s = live->finish(); !s) return fail(s.error);
    app.drive_frames_with([] {});
  }
  while (!live && !replay_done(w)) app.run_frame();
  if (recorder) {
    app.run_frame(true);
    if (Status s = recorder->finish(); !s) return fail(s.error);
  }
  render::Image shot;
  if (!a.screenshot_path.empty()) {
    bool shown = false;
    for (int attempt = 0; attempt < 3 && app.status() && !shown; ++attempt) shown = app.display(orbit, &shot);
    if (!app.status()) return fail("Vulkan: " + app.status().error);
    if (!shown) return fail("--screenshot: the window could not be drawn (minimised?)");
  }
  const uint64_t hash = world_hash(w);
  const std::string device = app.context().device_name();
  const bool validation = app.context().validation();
  const size_t messages = app.close();
  if (messages) return fail(std::to_string(messages) + " Vulkan validation message(s), see above");
  if (!a.screenshot_path.empty())
    if (Status s = render::write_png(shot, a.screenshot_path); !s) return fail(s.error);
  if (!a.record_path.empty())
    if (Status s = write_file_atomic(a.record_path, format_input_log(w.log.events)); !s) return fail(s.error);

  char hex[17];
  std::snprintf(hex, sizeof hex, "%016" PRIx64, hash);
  nlohmann::ordered_json out;
  out["display_frames"] = display_frame;
  out["system_frames"] = scheduler.frames();
  out["events"] = w.log.forgotten + w.log.events.size();
  out["edges"] = w.mesh.edge_count();
  out["faces"] = w.mesh.face_count();
  out["surface_quads"] = w.surface.quad_count();
  out["hash"] = hex;
  if (live) {
    out["session"] = live_dir;
    out["strokes"] = w.triangulate.counts.strokes;
    out["registrations"] = w.registration.done.size();
  }
  out["device"] = device;
  out["validation"] = validation;
  std::cout << out.dump() << "\n";
  return 0;
}

}  // namespace

void add_app_commands(CLI::App& app, Registry& registry) {
  auto a = std::make_shared<AppArgs>();
  CLI::App* cmd = app.add_subcommand("app", "The interactive window: the sketch, its surface and a HUD");
  std::string keys;
  for (const std::string& k : kKeys) keys += "  " + k + "\n";
  std::string live_keys;
  for (const std::string& k : kLiveKeys) live_keys += "  " + k + "\n";
  for (const std::string& k : pad_help_lines()) live_keys += "  " + k + "\n";
  cmd->footer(
      "Opens a window (GLFW) drawn with Vulkan (lavapipe without a GPU) and a HUD: frame time, per-system "
      "timings, counts, the sketch mode, the last rejected edit. INPUT is a session folder to go on with, a "
      "network (.fnet) to continue from, or an input log, replayed first. The systems run at the scheduler's fixed step "
      "(10 ms of log time) as the wall clock advances; vsync paces the display. Edits made with keys are "
      "commands appended to the session's input log, so `fire replay` of the --session folder or of the "
      "--record log reproduces the session bit for bit. Needs a display (DISPLAY or WAYLAND_DISPLAY); without one it exits 1 and points "
      "to `fire render`. On exit prints one JSON line: display_frames, system_frames, events, edges, faces, "
      "surface_quads, hash (as `fire replay --hash`), device, validation. FIRE_VK_VALIDATION=1 turns the "
      "validation layer on; any message then fails the command. While a stroke is drawn, the face it would split "
      "is tinted magenta and the point its end would snap to is marked cyan; on an open border, its first vertex "
      "is marked green when the stroke would close it there. Ctrl+S and E report in the HUD and on stderr. With "
      "--live the Wii Remotes draw: the HUD adds the remotes' states and batteries, each IR camera's view and "
      "the mark to touch next, and the JSON line adds session, strokes and registrations."
      "\n\nKeys:\n" + keys + "\nWith --live:\n" + live_keys);
  cmd->add_option("INPUT", a->input_path,
                  "a session folder to go on with (engine/SESSION.md: its last good snapshot, then its log's tail; "
                  "new strokes are written to it; its settings.json fixes the surface options), a curve network (.fnet) to "
                  "continue from, or an input log replayed first");
  cmd->add_option("--session", a->session_dir,
                  "write the session to this new folder as it goes (engine/SESSION.md): every event on disk as it is "
                  "delivered, fsynced at every pen-up and command, snapshots on the way, so a crash or a kill loses "
                  "no committed stroke; reopen it with `fire app DIR` or `fire replay DIR`");
  cmd->add_option("--snapshot-every", a->snapshot_every,
                  "frames (10 ms each) between a session's snapshots, which bound the replay on reopening")
      ->capture_default_str();
  cmd->add_option("--reference", a->reference_path,
                  "OBJ mesh drawn see-through; a left drag draws on it (ray casts through a BVH): a pen sample at "
                  "every hit, logged with its snap radius. Without one, a stroke draws on the surface where it starts "
                  "on it, or else on the plane through the view's centre facing the view");
  cmd->add_option("--reference-levels", a->reference_levels,
                  "the reference as its Catmull-Clark limit surface at this level (so strokes lie on the surface "
                  "fire eval measures against); 0: its faces as they are")
      ->capture_default_str();
  cmd->add_option("--snap-pixels", a->snap_pixels,
                  "snap radius of the mouse pen in screen pixels, converted to model units at each sample")
      ->capture_default_str();
  cmd->add_option("-o,--output", a->out_path, "where Ctrl+S saves the network (default: INPUT-app.fnet beside the "
                                              "input, or fire-app.fnet)");
  cmd->add_option("--export", a->export_path,
                  "where E exports the surface; the extension chooses the format: .obj, .ply, .stl or .glb "
                  "(default: the -o network's path with .obj)");
  cmd->add_option("--record", a->record_path, "write the session's input log here on exit (not with a .fnet input, nor with a session folder, whose "
                  "input.log is the record)");
  cmd->add_option("--size", a->size, "window size WIDTHxHEIGHT in pixels")->capture_default_str();
  add_surface_options(*cmd, a->surface_args);
  cmd->add_option("--script", a->script_path,
                  "test hook: input events delivered through the window's GLFW callbacks, one a line: "
                  "'FRAME move X Y', 'FRAME press|release left|right|middle', 'FRAME scroll DY', "
                  "'FRAME key [ctrl+][shift+]KEY', 'FRAME resize W H' (asks the window system), 'FRAME close'; FRAME is "
                  "the display frame");
  cmd->add_option("--screenshot", a->screenshot_path, "on exit, write the last presented frame (HUD included) as PNG");
  cmd->add_flag("--live", a->live,
                "draw with the IR pen: the rig's Wii Remotes (platform/wiimote, docs/wiimote.md) feed a new session "
                "folder (--session, default fire-live-DATE-TIME) frame by frame, 20 ms behind the clock; keys and the "
                "command pad's buttons are logged commands; `fire replay DIR` gives the same pools and surface");
  cmd->add_option("--rig", a->live_options.rig_path,
                  "--live: the rig file from fire calibrate (the cameras, and the remotes' roles by address)");
  cmd->add_option("--marks", a->live_options.marks_path,
                  "--live: the object's marks (fire-marks JSON, object frame, metres), to register it: the HUD shows "
                  "the mark to touch next");
  cmd->add_option("--ir-sensitivity", a->live_options.ir_sensitivity,
                  "--live: the cameras' IR sensitivity, 1 to 5 (the Wii's levels), 6 the high-sensitivity block")
      ->capture_default_str();
  cmd->add_option("--fake-rig", a->live_options.fake_rig_seed,
                  "--live without hardware: three fake remotes (two cameras and the pad) show `fire simulate drawing` "
                  "with this seed, the person pressing the pad for each command; its rig and marks are the simulation's");
  cmd->add_option("--fake-strokes", a->live_options.fake_strokes,
                  "--fake-rig: the simulated person stops after this many strokes (0: the whole network)")
      ->capture_default_str();
  cmd->add_option("--fake-speed", a->live_options.fake_speed,
                  "--fake-rig: seconds of the drawing per 60 displayed frames, whatever they cost (the fake clock is "
                  "the frames', not the wall's)")
      ->capture_default_str();
  cmd->callback([a, cmd, &registry] {
    auto surface = surface_options(a->surface_args, *cmd);
    if (!surface) {
      registry.exit_code = fail(surface.error());
      return;
    }
    a->surface = *surface;
    a->surface_given = surface_options_given(*cmd);
    registry.exit_code = run_app(*a);
  });
}

}  // namespace fire::cli
