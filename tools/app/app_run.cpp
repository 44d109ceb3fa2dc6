#include "tools/app/app_run.hpp"

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
#include <optional>
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
#include "tools/app/app_script.hpp"
#include "tools/app/cad_export_job.hpp"
#include "tools/app/app_window.hpp"
#include "tools/app/mouse_pen.hpp"
#include "tools/app/pad.hpp"
#include "tools/app/session.hpp"

namespace fire::app {

const std::vector<std::string> kAppKeys = {
    "left drag       draw a stroke (logged): on --reference, else on the surface or the view plane",
    "right drag      orbit",
    "Shift + drag    pan",
    "scroll          zoom",
    "Ctrl+Z          undo (logged)",
    "Ctrl+Shift+Z    redo (logged; also Ctrl+Y)",
    "C               close the border to its first vertex (logged)",
    "Delete          delete the curve under the cursor (logged)",
    "K               the curve under the cursor sharp / smooth (logged)",
    "O               the face under the cursor a hole (logged)",
    "1 / 2 / 3       surface / curves / wireframe on or off",
    "F               frame everything",
    "Ctrl+S / E      save the network (-o) / export the surface (--export)",
    "H or F1         this help",
    "Esc             quit",
};
const std::vector<std::string> kAppLiveKeys = {
    "M               the pen rests on the mark shown: touched, or without a marks file measured (logged)",
    "T               the pen rests on the table: touched, 3 times before marks are measured (logged)",
    "R               register the object on the marks touched (logged)",
    "N / P           show the next / previous mark",
};

namespace {

int fail(const std::string& message) {
  std::cerr << "fire app: " << message << "\n";
  return 1;
}

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// A new session folder's default name: the time it began, so a second session never meets the first's.
std::string default_live_session() {
  const std::time_t now = std::time(nullptr);
  char name[64];
  std::strftime(name, sizeof name, "fire-live-%Y%m%d-%H%M%S", std::localtime(&now));
  return name;
}

// The polyline point nearest to the cursor on screen, within `radius` pixels, and its edge (kNone: none):
// what Delete and K pick.
uint32_t curve_point_under(const Mesh& mesh, const render::Camera& camera, uint32_t width, uint32_t height,
                           glm::vec2 cursor, float radius, Vec3& out) {
  float best = radius * radius;
  uint32_t found = kNone;
  for (EdgeIndex e{0}; e < mesh.edge_slots(); ++e) {
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

}  // namespace

int run_app(const AppOptions& a) {
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
  if (!a.export_path.empty() && !is_cad_path(a.export_path))
    if (auto format = surface_format_of(a.export_path); !format)
      return fail("--export: " + format.error() + ", or .step, .stp, .igs or .iges for CAD");
  if (a.reference_levels < 0 || a.reference_levels > 5) return fail("--reference-levels must be 0 to 5");
  if (!(a.snap_px > 0) || a.snap_px > 200) return fail("--snap-pixels must be above 0 and at most 200");
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
    auto created = SessionWriter::create(a.session_dir, settings_json(w), {}, {}, w.log.version);
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
  hud_data.keys = kAppKeys;
  if (live) {
    hud_data.keys.insert(hud_data.keys.end(), kAppLiveKeys.begin(), kAppLiveKeys.end());
    for (const std::string& line : pad_help_lines()) hud_data.keys.push_back(line);
  }
  const std::string out_path = a.out_path.empty() ? default_output(a.input_path) : a.out_path;
  const std::string export_path = a.export_path.empty() ? default_export(out_path) : a.export_path;
  auto report = [&](std::string message) {
    hud_data.status = std::move(message);
    std::cerr << "fire app: " << hud_data.status << "\n";
  };
  CadExportJob cad_job;
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
  MousePen pen(app, reference.triangles.empty() ? nullptr : &reference_bvh, a.snap_px);
  bool dragging = false, panning = false, drawing = false;
  glm::vec2 cursor(0.0f);
  uint64_t display_frame = 0;
  size_t next_script = 0;

  auto handle = [&](const window::WindowEvent& e) {
    using window::WindowEventKind;
    const bool ctrl = e.mods & window::kCtrl, shift = e.mods & window::kShift;
    switch (e.kind) {
      case WindowEventKind::CursorMove: {
        const glm::vec2 now(float(e.x), float(e.y)), d = now - cursor;
        if (dragging) orbit.rotate(d.x, d.y);
        if (panning) orbit.pan(d.x, d.y, std::max(app.height(), 1u));
        view_moved = view_moved || dragging || panning;
        if (drawing) {  // samples every 2 pixels along the move, so a fast drag still makes a dense stroke
          const int steps = std::max(1, int(std::ceil(glm::length(d) / 2.0f)));
          for (int k = 1; k <= steps; ++k) pen.sample(cursor + d * (float(k) / float(steps)));
        }
        cursor = now;
        break;
      }
      case WindowEventKind::ButtonPress:
        cursor = glm::vec2(float(e.x), float(e.y));
        if (app.hud().covers(cursor.x, cursor.y) || dragging || panning || drawing) break;
        if (shift || e.button == window::Button::Middle) panning = true;
        else if (e.button == window::Button::Left && live) {
          hud_data.status = "--live: the IR pen draws; right drag orbits, Shift + drag pans";
        } else if (e.button == window::Button::Left) {
          // The pen goes down with its first sample, on what the stroke will draw on.
          if (!pen.begin(cursor, w.surface, orbit.target)) {
            hud_data.status = "press on the reference mesh to draw";
            break;
          }
          log_pen(fire::EventKind::Down);
          drawing = pen.sample(cursor);
        } else if (e.button == window::Button::Right) dragging = true;
        else panning = true;
        break;
      case WindowEventKind::ButtonRelease:
        if (drawing) log_pen(fire::EventKind::Up);
        dragging = panning = drawing = false;
        break;
      case WindowEventKind::Scroll:
        if (!app.hud().covers(cursor.x, cursor.y)) {
          orbit.zoom(float(e.y));
          view_moved = true;
        }
        break;
      case WindowEventKind::KeyPress:
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
        } else if (e.key == GLFW_KEY_O) {
          if (const std::optional<Vec3> p = pen.point_under(cursor, w.surface)) {
            log_command(CommandKind::Hole, *p);
            hud_data.status = "making a hole of the face under the cursor";
          } else hud_data.status = "nothing under the cursor to make a hole of";
        } else if (e.key == GLFW_KEY_E) {
          // The surface as the frames have built it so far; a failed write leaves the session untouched.
          if (w.surface.empty()) report("export: no surface yet (it needs a closed border)");
          else if (is_cad_path(export_path)) {
            // The cage of the settled surface, converted and sewn on a worker thread: the frames go on meanwhile.
            if (cad_job.running()) report("export: " + export_path + " is still being written");
            else if (!w.surface.settled) report("export: the surface is still settling; press E again in a moment");
            else {
              cad_job.start(reconstruct::cage_of(w.surface_build.state, w.surface_options, to_surface_mesh(w.surface)),
                            export_path, kDefaultExportUnit);
              report("exporting the surface to " + export_path + " in the background");
            }
          }
          else if (const Status s = write_surface(to_surface_mesh(w.surface), export_path); !s) report("export failed: " + s.error);
          else
            report("exported " + std::to_string(w.surface.quad_count()) + " surface quads to " + export_path +
                   (w.surface.settled ? "" : " (provisional: the fit was still converging)"));
        } else if (live && e.key == GLFW_KEY_M) report(live->act(PadAction::TouchMark));
        else if (live && e.key == GLFW_KEY_T) report(live->act(PadAction::TouchTable));
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
      case WindowEventKind::Close:
        break;
    }
  };

  while (app.status() && !window.should_close()) {
    next_script = deliver_script(script, next_script, display_frame, window);
    window.poll();
    if (std::optional<std::string> done = cad_job.finished()) report(std::move(*done));
    for (const window::WindowEvent& e : window.events()) handle(e);
    window.events().clear();
    if (!app.display(orbit) && app.status() && app.width() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(16));
    ++display_frame;
  }
  if (!app.status()) return fail("Vulkan: " + app.status().error);
  if (cad_job.running()) std::cerr << "fire app: waiting for the export to " << export_path << " to be written\n";
  if (std::optional<std::string> done = cad_job.wait()) report(std::move(*done));

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
    if (Status s = write_file_atomic(a.record_path, format_input_log(w.log.events, w.log.version)); !s) return fail(s.error);

  char hex[17];
  std::snprintf(hex, sizeof hex, "%016" PRIx64, hash);
  nlohmann::ordered_json out;
  out["display_frames"] = display_frame;
  out["system_frames"] = scheduler.frames();
  out["events"] = w.log.forgotten + w.log.events.size();
  out["edges"] = w.mesh.edge_count();
  out["faces"] = w.mesh.face_count();
  out["border_loops"] = w.mesh.border_loop_count();
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

}  // namespace fire::app
