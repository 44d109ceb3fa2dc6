#pragma once
// The frame scheduler: runs the systems in their declared order once per fixed time step and records
// how long each took. Timing uses a clock handed in by platform/; systems themselves never see it.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace fire {

struct SystemTiming {
  std::string name;
  int64_t total_ns = 0;
  int64_t max_ns = 0;
  uint64_t runs = 0;
};

class Scheduler {
 public:
  using Clock = int64_t (*)();  // nanoseconds, monotonic
  explicit Scheduler(Clock clock) : clock_(clock) {}
  // Systems run in the order they are added.
  void add(std::string name, std::function<void()> system);
  void run_frame();
  const std::vector<SystemTiming>& timings() const { return timings_; }
  uint64_t frames() const { return frames_; }

 private:
  Clock clock_;
  std::vector<std::function<void()>> systems_;
  std::vector<SystemTiming> timings_;
  uint64_t frames_ = 0;
};

}  // namespace fire
