#pragma once
// The frame scheduler: runs the systems in their declared order once per fixed time step and records
// how long each took. Timing uses a clock handed in by platform/; systems themselves never see it.
//
// Each system is declared with what it reads and writes, by the name of a piece of world data. The
// order is checked when the schedule is built: a system may not read what a later system writes in the
// same frame, unless it declares that it reads the previous frame's value (sketch snaps against the mesh
// that split left last frame). Reads of data no system writes are inputs from outside the frame.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "engine/common.hpp"

namespace fire {

// The fixed step a frame covers on the input log's clock.
struct FrameTime {
  uint64_t index = 0;
  int64_t begin_us = 0;  // frame covers [begin_us, end_us)
  int64_t end_us = 0;
};

struct SystemSpec {
  std::string name;
  std::vector<std::string> reads;
  std::vector<std::string> writes;
  std::vector<std::string> reads_previous_frame;  // written later in the frame; this system sees last frame's
  std::function<void()> run;
};

// Samples a timing keeps: the app runs 100 frames a second for as long as a session lasts, so keeping
// every one would grow without bound (an int64 a frame for each system and one for the whole frame: at 100
// frames a second, tens of MB an hour).
inline constexpr size_t kTimingWindow = size_t(1) << 16;  // about 11 minutes of frames at 100 Hz

struct SystemTiming {
  std::string name;
  // The most recent frames run, oldest first: all of them up to 2 * kTimingWindow, then the oldest
  // kTimingWindow are dropped, so at least kTimingWindow and at most twice that.
  std::vector<int64_t> samples_ns;
  uint64_t frames = 0;  // every frame run, as total_ns and max_ns cover
  int64_t total_ns = 0;
  int64_t max_ns = 0;
  double mean_ns() const { return frames == 0 ? 0 : double(total_ns) / double(frames); }
  int64_t percentile_ns(double p) const;  // nearest rank over samples_ns, p in [0, 100]
  void add(int64_t ns);
};

class Scheduler {
 public:
  using Clock = int64_t (*)();  // nanoseconds, monotonic

  // The systems in frame order; fails, naming the systems and the data, when a read comes after its write
  // without being declared as a read of the previous frame, or a previous-frame read names data that no
  // later system writes.
  static Result<Scheduler> build(std::vector<SystemSpec> systems, Clock clock);

  void run_frame();
  const std::vector<SystemTiming>& timings() const { return timings_; }
  // Timings of the whole frame (all systems together), one sample per frame.
  const SystemTiming& frame_timing() const { return frame_timing_; }
  uint64_t frames() const { return frames_; }
  const std::vector<SystemSpec>& systems() const { return systems_; }
  // One line per system: its name, reads and writes.
  std::string describe() const;

 private:
  Scheduler(std::vector<SystemSpec> systems, Clock clock);
  std::vector<SystemSpec> systems_;
  Clock clock_;
  std::vector<SystemTiming> timings_;
  SystemTiming frame_timing_{"frame", {}, 0, 0};
  uint64_t frames_ = 0;
};

}  // namespace fire
