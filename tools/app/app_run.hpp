#pragma once
// `fire app`: the window loop. It opens the session (a session folder to go on with, a network, an input
// log replayed first, or the live remotes), runs the session's systems at the scheduler's fixed step as
// the wall clock advances (vsync paces the display), turns the mouse pen, the keys and the pad into events
// of the session's input log, and on exit prints one JSON line (display frames, system frames, events,
// edges, faces, surface quads, the world hash, the device).
#include <cstdint>
#include <string>
#include <vector>

#include "systems/reconstruct/reconstruct.hpp"
#include "tools/app/app_live.hpp"

namespace fire::app {

struct AppOptions {
  std::string input_path, reference_path, out_path, export_path, record_path, script_path, screenshot_path,
      session_dir, size = "1280x720";
  uint64_t snapshot_every = 3000;
  reconstruct::Options surface;
  bool surface_given = false;  // a surface option given on the command line
  int reference_levels = 3;
  double snap_px = 12;
  bool live = false;
  AppLiveOptions live_options;
};

// The help overlay and `fire app --help` list the same keys; with --live, besides the pad's buttons.
extern const std::vector<std::string> kAppKeys;
extern const std::vector<std::string> kAppLiveKeys;

// Runs the app until its window closes; errors go to stderr as "fire app: ...". The exit code.
int run_app(const AppOptions& options);

}  // namespace fire::app
