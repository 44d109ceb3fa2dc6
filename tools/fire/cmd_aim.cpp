// fire aim: each camera remote's IR view while the cameras are aimed (tools/app/aim_run.hpp runs it).
#include <memory>

#include "tools/app/aim.hpp"
#include "tools/app/aim_run.hpp"
#include "tools/fire/commands.hpp"

namespace fire::cli {

void add_aim_commands(CLI::App& app, Registry& registry) {
  auto o = std::make_shared<app::AimOptions>();
  CLI::App* cmd = app.add_subcommand(
      "aim", "Each camera remote's IR view, live, while the cameras are aimed: blobs, report rate, battery, problems");
  cmd->footer(
      "Opens the two camera remotes through the driver as `fire calibrate --live` does: no rig needed, the remotes take "
      "their roles by the order of their addresses (camera 0, camera 1, then the pad), or by --rig's \"remotes\". A "
      "window (needs a display) shows each camera's 1024 x 768 image: the blobs of its last report as discs that grow "
      "with their size, still lights taken for strays in orange, and each camera's IR reports in the last second, "
      "battery and sensitivity. With --rig it shades where the working volume lies in each image (a box 40 x 30 x 40 "
      "cm around where the cameras' axes pass closest): teal where the other camera sees it too, dim red where only "
      "this one does; that is the rig's aim as calibrated, stale once a camera has been turned. It names problems, "
      "each naming the camera: a light one camera sees and the other does not that stays still for " +
      std::to_string(app::kAimStrayStillUs / 1000) + " ms, or one both see still for " +
      std::to_string(app::kAimLampStillUs / 1'000'000) +
      " s (a stray light); the pen seen by one camera and not the other for over a second; fewer than " +
      std::to_string(int(app::kAimMinRateHz)) +
      " IR reports in the last second; a low battery. Stdout gets a JSON line every second (t_s, each camera's "
      "remote, state, rate_hz, battery_percent, battery_low, sensitivity and blobs, the problems now) and one at the "
      "end (each camera's strays too, problems_named: every problem the first time it was named, overlap: the share "
      "of each image where both cameras see the working volume, null without --rig, pictures). With --png-dir there "
      "is no window: after --seconds from when both cameras run, camera0.png and camera1.png (512 x 384, half the "
      "sensor's size, dark) show the shaded working volume, the trail of every blob the pen made meanwhile in blue, "
      "every stray light named in orange and the last report's blobs in white. Real remotes are untested: FIRE's "
      "tests run it on fake ones (--fake-rig).");
  cmd->add_option("--rig", o->rig_path,
                  "a rig file (fire calibrate): shades where its working volume lies in each view, and gives the remotes "
                  "their roles by address");
  cmd->add_option("--png-dir", o->png_dir,
                  "no window: watch the remotes for --seconds, then write camera0.png and camera1.png into this folder "
                  "(made if missing)");
  cmd->add_option("--seconds", o->seconds, "--png-dir: how long to watch, from when both cameras run")
      ->capture_default_str();
  cmd->add_option("--ir-sensitivity", o->ir_sensitivity,
                  "the cameras' IR sensitivity, 1 to 5 (the Wii's levels), 6 the high-sensitivity block")
      ->capture_default_str();
  cmd->add_option("--size", o->size, "window size WIDTHxHEIGHT in pixels")->capture_default_str();
  cmd->add_option("--script", o->script_path,
                  "test hook: input events through the window's callbacks, as `fire app --script` (Esc or close quits)");
  cmd->add_option("--screenshot", o->screenshot_path, "test hook: on exit, write the last presented frame as PNG");
  cmd->add_option("--fake-rig", o->fake_rig_seed,
                  "test and simulation hook, not for aiming anything real: no hardware; the fake remotes of `fire app "
                  "--live --fake-rig` show `fire simulate drawing` with this seed (its pen, and a stray light camera 1 "
                  "sees in some seconds), a 60th of a second each displayed frame, as fast as it runs with --png-dir");
  cmd->callback([o, &registry] { registry.exit_code = app::run_aim(*o); });
}

}  // namespace fire::cli
