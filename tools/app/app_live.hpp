#pragma once
// `fire app --live`: the Wii Remotes (or the fake rig) through the driver into a live session
// (live_session.hpp), shown by the app's window. The driver's reports are the session's input log, recorded
// in its folder as the frames take them; keys and the command pad's buttons (pad.hpp) become logged
// commands; the HUD shows each camera's IR view, the remotes' states and the mark to touch next.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "platform/clock.hpp"
#include "platform/window/hud.hpp"
#include "platform/wiimote/driver.hpp"
#include "tools/app/fake_rig.hpp"
#include "tools/app/live_session.hpp"
#include "tools/app/pad.hpp"

namespace fire::app {

struct AppLiveOptions {
  std::string rig_path;     // the rig file (fire calibrate): cameras and the remotes' roles
  std::string marks_path;   // the object's marks (fire-marks JSON), for registering it; optional
  std::string session_dir;  // a new session folder, written as the frames run
  reconstruct::Options surface;  // the surface options (fire app's, as fire reconstruct's)
  int ir_sensitivity = 3;
  SessionWriteOptions write;  // snapshots
  // Test and simulation hook: no hardware; three fake remotes show `fire simulate drawing` with this
  // seed (fake_rig.hpp), the rig and the marks being the simulation's; `fake_speed` seconds of the
  // drawing go by each displayed second of 60 frames, whatever the frames cost.
  std::optional<uint64_t> fake_rig_seed;
  int fake_strokes = 0;
  double fake_speed = 1;
  bool fake_measure_marks = false;  // the fake rig's person measures the marks by touch: no marks file
};

class AppLive {
 public:
  // Opens the remotes and creates the session folder (with the rig and the marks); fails, leaving no
  // folder, without two cameras or on a bad rig or marks file.
  static Result<std::unique_ptr<AppLive>> open(const AppLiveOptions& options);
  ~AppLive();

  World& world() { return world_; }
  Scheduler& scheduler() { return scheduler_; }
  // Once a displayed frame: the fake rig moves on, the frames the log has completed run, the pad's
  // presses become commands. Messages for the person (the remotes' news, what a press did) are returned.
  std::vector<std::string> step();
  // A command given now (a key), logged as the pad's are.
  void command(CommandKind kind, const Vec3& p = Vec3::Zero());
  // What the pad's buttons and the app's keys M, R, N, P do: returns what it did, in words.
  std::string act(PadAction action);
  // The HUD's live part: the remotes, the mark to touch next, each camera's IR view.
  void fill_hud(window::HudData& hud) const;
  // The marks to draw, in the network's frame, and the one to touch next: none before the object is
  // registered, when the network's frame is still the rig's.
  const std::vector<Vec3>& marks_in_view() const;
  size_t shown_mark() const;
  // Whether the fake rig has shown its whole drawing (never with real remotes).
  bool fake_finished() const { return fake_ && fake_->finished(); }
  // Stops the driver, runs every frame left and closes the session's log; the first failed write.
  Status finish();
  uint64_t frames_run() const { return live_->frames_run(); }

 private:
  explicit AppLive(const AppLiveOptions& options) : options_(options) {}
  void observe(std::span<const InputEvent> taken);

  AppLiveOptions options_;
  World world_;
  Scheduler scheduler_ = make_scheduler(world_, monotonic_ns);
  std::unique_ptr<FakeDrawingRig> fake_;
  std::unique_ptr<wiimote::Backend> hardware_;
  std::unique_ptr<wiimote::LogWriter> log_;
  std::unique_ptr<wiimote::Driver> driver_;
  std::optional<SessionWriter> out_;
  std::optional<LiveSession> live_;
  std::vector<Vec3> marks_;  // from the marks file; empty: the marks are measured by touch
  size_t shown_mark_ = 0;
  std::vector<Vec3> measured_in_view_;  // the marks measured, once the object has a frame
  PadPresses pad_;
  std::vector<PadAction> pad_actions_;  // taken from the log, acted on after the frames ran
  std::array<window::CameraView, 2> cameras_{};
  bool stopped_ = false;
};

}  // namespace fire::app
