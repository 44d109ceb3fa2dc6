#pragma once
// `fire aim`: the camera remotes, opened through the driver as `fire calibrate --live` opens them (no rig
// needed; roles by address, or by the --rig file's remotes), shown while a person aims them (aim.hpp): in a
// window, live, or headless as one PNG per camera written after a while. Stdout gets a JSON line every second
// of each camera's rate, battery, sensitivity and blobs and the problems now, and one at the end with every
// problem named and every stray light seen.
#include <cstdint>
#include <optional>
#include <string>

namespace fire::app {

struct AimOptions {
  std::string rig_path;  // optional: the rig whose working volume each view shades, and the remotes' roles
  std::string png_dir;   // headless: the pictures go here (camera0.png, camera1.png); empty: a window
  double seconds = 5;    // --png-dir: how long the remotes are watched (from when both cameras run)
  int ir_sensitivity = 3;
  // The window's size, the test hooks of `fire app` (scripted input events, the last frame as PNG).
  std::string size = "1100x620", script_path, screenshot_path;
  // Test and simulation hook: no hardware; the fake remotes of `fire app --live --fake-rig` (fake_rig.hpp)
  // show `fire simulate drawing`'s pen and stray light, one 60th of a second of it each displayed frame.
  std::optional<uint64_t> fake_rig_seed;
};

// Runs until the window closes (or, headless, for `seconds`); errors go to stderr as "fire aim: ...".
// The exit code.
int run_aim(const AimOptions& options);

}  // namespace fire::app
