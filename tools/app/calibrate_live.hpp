#pragma once
// `fire calibrate --live`: records the camera remotes' reports of a waved wand into a new session folder,
// through the driver (platform/wiimote) and the live session (live_session.hpp), with each camera's
// progress on stderr, until both cameras have seen enough of the wand, a key is pressed or time is up.
// The rig is then calibrated from those events exactly as `fire calibrate DIR` calibrates the folder.
#include <cstdint>
#include <optional>
#include <string>

#include "engine/input_log.hpp"

namespace fire::app {

struct LiveWandOptions {
  std::string session_dir;  // a new session folder: the reports are recorded there as they arrive
  double wand_length_m = 0.3;  // logged as `meta wand_length_m`, which the offline command reads back
  double max_s = 120;    // stops after this long
  double coverage = 0.5;       // stops once each camera's wand blobs have covered this share of its image...
  size_t samples = 1500;       // ... in at least this many reports showing both LEDs
  // Test and simulation hook: no hardware; two fake remotes (platform/wiimote/fake_remote.hpp) on a fake
  // bus stream a simulated wand (`fire simulate wand`'s rig and motion with this seed) on a clock that
  // runs as fast as the machine allows.
  std::optional<uint64_t> fake_rig_seed;
};

// The session's events in log order (the header's time line; no durability records). Errors say what
// failed: no folder, fewer than two cameras, a failed write.
Result<std::vector<InputEvent>> record_live_wand(const LiveWandOptions& options);

}  // namespace fire::app
