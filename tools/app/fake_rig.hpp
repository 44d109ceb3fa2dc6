#pragma once
// Fake Wii Remotes showing a simulated session, for the live commands' --fake-rig hooks (`fire calibrate
// --live`, `fire app --live`) and their tests: the real driver reads them through its Backend interface,
// so everything after the radio runs as with hardware, on a clock that moves as fast as the machine allows.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "engine/input_log.hpp"
#include "platform/wiimote/driver.hpp"
#include "platform/wiimote/fake_remote.hpp"

namespace fire::app {

// What each camera of a simulated rig saw: the blobs of the simulator's camera reports in arrival order.
struct SimulatedBlobs {
  std::array<std::vector<std::pair<int64_t, IrSlots>>, 2> frames;  // (arrival ns, blobs) per camera
  // What camera `camera` shows `t_ns` after the simulation began: each blob seen in the reports arrived
  // before and after, interpolated between them; the last report's blobs across a gap or at the end.
  IrSlots at(int camera, int64_t t_ns) const;
};
// The blobs of a simulated session's camera reports (devices 0 and 1, mode 0x33).
SimulatedBlobs simulated_blobs_of(const std::vector<InputEvent>& events);

// A press of the command pad's button (a wiimote::kButton* bit) by the simulated person, held kPadHoldNs.
struct PadPress {
  int64_t t_ns = 0;  // from the simulation's start
  uint16_t button = 0;
};
inline constexpr int64_t kPadHoldNs = 50'000'000;
// The presses that give the simulated person's commands (`cmd mark`, `cmd register`, `cmd undo`, ...) on
// the pad as pad.hpp maps it: a mark is chosen with left / right from the app's shown mark (mark 0 at first,
// the next one after each touch; `mark_count` marks), then touched with 2 at the command's instant. Marks
// measured by touch are chosen so among kMeasuredMarkIds ids; the table is touched with up.
std::vector<PadPress> pad_presses_for(const std::vector<InputEvent>& commands, size_t mark_count);

// Fake remotes on a fake clock: two cameras showing `blobs` from the instant both run (the simulation's
// start), and, with a pad, the command pad pressed at `presses` from then on. The real driver reads them
// through `backend()`; `advance` moves the clock and reads them on the calling thread.
class FakeRig {
 public:
  static inline const std::array<std::string, 3> kAddresses = {"00:1F:32:FA:CE:00", "00:1F:32:FA:CE:01",
                                                               "00:1F:32:FA:CE:02"};
  FakeRig(SimulatedBlobs blobs, bool with_pad, std::vector<PadPress> presses = {});
  FakeRig(const FakeRig&) = delete;  // the remotes' blob sources hold `this`
  FakeRig& operator=(const FakeRig&) = delete;

  wiimote::Backend& backend() { return bus_; }
  wiimote::Clock clock() { return clock_.clock(); }
  // Moves the fake clock on by `ns`, a millisecond at a time: the remotes stream, `driver` reads every
  // remote, the person presses the pad; then `each_ms`.
  void advance(int64_t ns, wiimote::Driver& driver, const std::function<void()>& each_ms = {});
  // Nanoseconds of the simulation shown so far; negative until both cameras run.
  int64_t elapsed_ns() const { return origin_ns_ < 0 ? -1 : clock_.now() - origin_ns_; }

 private:
  wiimote::ManualClock clock_;
  wiimote::FakeBus bus_{clock_.clock()};
  std::vector<std::shared_ptr<wiimote::FakeRemote>> remotes_;  // the cameras, then the pad if any
  SimulatedBlobs blobs_;
  std::vector<PadPress> presses_;
  size_t next_press_ = 0;
  int64_t release_at_ = -1;
  int64_t origin_ns_ = -1;  // when both cameras ran; -1 before
};

// `fire simulate drawing` (the pawn, registered on marks, its network drawn) on three fake remotes: two
// cameras showing the simulated pen, and the command pad the person presses for each of its commands. The
// drawing starts once both cameras run.
class FakeDrawingRig {
 public:
  // `max_strokes`: the drawing stops after this many strokes (0: the whole network).
  // `measure_marks`: the person measures the marks by touch (fire simulate drawing --measure-marks), and
  // there is no marks file.
  static Result<std::unique_ptr<FakeDrawingRig>> create(uint64_t seed, int max_strokes, bool measure_marks = false);

  FakeRig& remotes() { return *remotes_; }
  // The true cameras as a rig file, with the three remotes' roles; the marks file of the object.
  const std::string& rig_json() const { return rig_json_; }
  const std::string& marks_json() const { return marks_json_; }
  // Seconds of the simulated drawing.
  double duration_s() const { return duration_s_; }
  // Whether the drawing has been shown to its end.
  bool finished() const;

 private:
  FakeDrawingRig() = default;

  std::unique_ptr<FakeRig> remotes_;
  double duration_s_ = 0;
  std::string rig_json_, marks_json_;
};

}  // namespace fire::app
