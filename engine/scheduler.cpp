#include "engine/scheduler.hpp"

#include <algorithm>

namespace fire {

void Scheduler::add(std::string name, std::function<void()> system) {
  systems_.push_back(std::move(system));
  timings_.push_back({std::move(name), 0, 0, 0});
}

void Scheduler::run_frame() {
  for (size_t i = 0; i < systems_.size(); ++i) {
    int64_t t0 = clock_();
    systems_[i]();
    int64_t dt = clock_() - t0;
    SystemTiming& t = timings_[i];
    t.total_ns += dt;
    t.max_ns = std::max(t.max_ns, dt);
    ++t.runs;
  }
  ++frames_;
}

}  // namespace fire
