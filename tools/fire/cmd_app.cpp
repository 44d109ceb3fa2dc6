// fire app: the interactive window (tools/app/app_run.hpp runs it). The session's systems run at the
// scheduler's fixed step on the input log's clock; the display is paced by vsync. Edits made with keys become
// commands in the session's input log, so `fire replay` of the recorded log (--record) gives the same pools
// and surface, bit for bit.
#include <iostream>
#include <memory>

#include "tools/app/app_run.hpp"
#include "tools/app/pad.hpp"
#include "tools/fire/commands.hpp"
#include "tools/fire/surface_args.hpp"

namespace fire::cli {
namespace {

struct AppArgs {
  app::AppOptions options;
  SurfaceArgs surface_args;
};

}  // namespace

void add_app_commands(CLI::App& app, Registry& registry) {
  auto a = std::make_shared<AppArgs>();
  app::AppOptions& o = a->options;
  CLI::App* cmd = app.add_subcommand("app", "The interactive window: the sketch, its surface and a HUD");
  std::string keys;
  for (const std::string& k : app::kAppKeys) keys += "  " + k + "\n";
  std::string live_keys;
  for (const std::string& k : app::kAppLiveKeys) live_keys += "  " + k + "\n";
  for (const std::string& k : app::pad_help_lines()) live_keys += "  " + k + "\n";
  cmd->footer(
      "Opens a window (GLFW) drawn with Vulkan (lavapipe without a GPU) and a HUD: frame time, per-system "
      "timings, counts, the sketch mode, the last rejected edit. INPUT is a session folder to go on with, a "
      "network (.fnet) to continue from, or an input log, replayed first. The systems run at the scheduler's fixed step "
      "(10 ms of log time) as the wall clock advances; vsync paces the display. Edits made with keys are "
      "commands appended to the session's input log, so `fire replay` of the --session folder or of the "
      "--record log reproduces the session bit for bit. Needs a display (DISPLAY or WAYLAND_DISPLAY); without one it exits 1 and points "
      "to `fire render`. On exit prints one JSON line: display_frames, system_frames, events, edges, faces, border_loops, "
      "surface_quads, hash (as `fire replay --hash`), device, validation. FIRE_VK_VALIDATION=1 turns the "
      "validation layer on; any message then fails the command. While a stroke is drawn, the face it would split "
      "is tinted magenta and the point its end would snap to is marked cyan; on an open border, its first vertex "
      "is marked green when the stroke would close it there. Ctrl+S and E report in the HUD and on stderr. With "
      "--live the Wii Remotes draw: the HUD adds the remotes' states and batteries, each IR camera's view and "
      "the mark to touch next, and the JSON line adds session, strokes and registrations."
      "\n\nKeys:\n" + keys + "\nWith --live:\n" + live_keys);
  cmd->add_option("INPUT", o.input_path,
                  "a session folder to go on with (engine/SESSION.md: its last good snapshot, then its log's tail; "
                  "new strokes are written to it; its settings.json fixes the surface options), a curve network (.fnet) to "
                  "continue from, or an input log replayed first");
  cmd->add_option("--session", o.session_dir,
                  "write the session to this new folder as it goes (engine/SESSION.md): every event on disk as it is "
                  "delivered, fsynced at every pen-up and command, snapshots on the way, so a crash or a kill loses "
                  "no committed stroke; reopen it with `fire app DIR` or `fire replay DIR`");
  cmd->add_option("--snapshot-every", o.snapshot_every,
                  "frames (10 ms each) between a session's snapshots, which bound the replay on reopening")
      ->capture_default_str();
  cmd->add_option("--reference", o.reference_path,
                  "OBJ mesh drawn see-through; a left drag draws on it (ray casts through a BVH): a pen sample at "
                  "every hit, logged with its snap radius. Without one, a stroke draws on the surface where it starts "
                  "on it, or else on the plane through the view's centre facing the view");
  cmd->add_option("--reference-levels", o.reference_levels,
                  "the reference as its Catmull-Clark limit surface at this level (so strokes lie on the surface "
                  "fire eval measures against); 0: its faces as they are")
      ->capture_default_str();
  cmd->add_option("--snap-pixels", o.snap_px,
                  "snap radius of the mouse pen in screen pixels, converted to model units at each sample")
      ->capture_default_str();
  cmd->add_option("-o,--output", o.out_path, "where Ctrl+S saves the network (default: INPUT-app.fnet beside the "
                                              "input, or fire-app.fnet)");
  cmd->add_option("--export", o.export_path,
                  "where E exports the surface; the extension chooses the format: .obj, .ply, .stl or .glb (in mm, "
                  ".glb in m), or .step, .stp, .igs or .iges for B-spline patches in mm, written in the background once the "
                  "surface has settled (default: the -o network's path with .obj)");
  cmd->add_option("--record", o.record_path, "write the session's input log here on exit (not with a .fnet input, nor with a session folder, whose "
                  "input.log is the record)");
  cmd->add_option("--size", o.size, "window size WIDTHxHEIGHT in pixels")->capture_default_str();
  add_surface_options(*cmd, a->surface_args);
  cmd->add_option("--script", o.script_path,
                  "test hook: input events delivered through the window's GLFW callbacks, one a line: "
                  "'FRAME move X Y', 'FRAME press|release left|right|middle', 'FRAME scroll DY', "
                  "'FRAME key [ctrl+][shift+]KEY', 'FRAME resize W H' (asks the window system), 'FRAME close'; FRAME is "
                  "the display frame");
  cmd->add_option("--screenshot", o.screenshot_path, "on exit, write the last presented frame (HUD included) as PNG");
  cmd->add_flag("--live", o.live,
                "draw with the IR pen: the rig's Wii Remotes (platform/wiimote, docs/wiimote.md) feed a new session "
                "folder (--session, default fire-live-DATE-TIME) frame by frame, 20 ms behind the clock; keys and the "
                "command pad's buttons are logged commands; `fire replay DIR` gives the same pools and surface");
  cmd->add_option("--rig", o.live_options.rig_path,
                  "--live: the rig file from fire calibrate (the cameras, and the remotes' roles by address)");
  cmd->add_option("--marks", o.live_options.marks_path,
                  "--live: the object's marks (fire-marks JSON, object frame, metres), to register it: the HUD shows "
                  "the mark to touch next; without it the marks are measured by touch (the table with pad up or T, "
                  "then each mark with 2 or M; Home or R makes the object's frame)");
  cmd->add_option("--ir-sensitivity", o.live_options.ir_sensitivity,
                  "--live: the cameras' IR sensitivity, 1 to 5 (the Wii's levels), 6 the high-sensitivity block")
      ->capture_default_str();
  cmd->add_option("--fake-rig", o.live_options.fake_rig_seed,
                  "--live without hardware: three fake remotes (two cameras and the pad) show `fire simulate drawing` "
                  "with this seed, the person pressing the pad for each command; its rig and marks are the simulation's");
  cmd->add_flag("--fake-measure-marks", o.live_options.fake_measure_marks,
               "--fake-rig: the simulated person measures the marks by touch (the table, then each mark), as on an object "
               "nobody modelled: no marks file");
  cmd->add_option("--fake-strokes", o.live_options.fake_strokes,
                  "--fake-rig: the simulated person stops after this many strokes (0: the whole network)")
      ->capture_default_str();
  cmd->add_option("--fake-speed", o.live_options.fake_speed,
                  "--fake-rig: seconds of the drawing per 60 displayed frames, whatever they cost (the fake clock is "
                  "the frames', not the wall's)")
      ->capture_default_str();
  cmd->callback([a, cmd, &registry] {
    auto surface = surface_options(a->surface_args, *cmd);
    if (!surface) {
      std::cerr << "fire app: " << surface.error() << "\n";
      registry.exit_code = 1;
      return;
    }
    a->options.surface = *surface;
    a->options.surface_given = surface_options_given(*cmd);
    registry.exit_code = app::run_app(a->options);
  });
}

}  // namespace fire::cli
