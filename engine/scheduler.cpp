#include "engine/scheduler.hpp"

#include <algorithm>
#include <cmath>

namespace fire {

namespace {

bool contains(const std::vector<std::string>& names, const std::string& n) {
  return std::find(names.begin(), names.end(), n) != names.end();
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out.empty() ? "-" : out;
}

}  // namespace

int64_t SystemTiming::percentile_ns(double p) const {
  if (samples_ns.empty()) return 0;
  std::vector<int64_t> sorted = samples_ns;
  size_t rank = static_cast<size_t>(std::ceil(p / 100.0 * double(sorted.size())));
  rank = std::clamp<size_t>(rank, 1, sorted.size());
  std::nth_element(sorted.begin(), sorted.begin() + long(rank - 1), sorted.end());
  return sorted[rank - 1];
}

void SystemTiming::add(int64_t ns) {
  if (samples_ns.size() == 2 * kTimingWindow)
    samples_ns.erase(samples_ns.begin(), samples_ns.begin() + long(kTimingWindow));
  samples_ns.push_back(ns);
  ++frames;
  total_ns += ns;
  max_ns = std::max(max_ns, ns);
}

Result<Scheduler> Scheduler::build(std::vector<SystemSpec> systems, Clock clock, Clock cpu_clock) {
  for (size_t i = 0; i < systems.size(); ++i) {
    const SystemSpec& s = systems[i];
    for (size_t j = 0; j < i; ++j)
      if (systems[j].name() == s.name()) return Result<Scheduler>::failure("two systems are named '" + s.name() + "'");
    for (const std::string& data : s.reads()) {
      for (size_t j = i + 1; j < systems.size(); ++j)
        if (contains(systems[j].writes(), data))
          return Result<Scheduler>::failure("system '" + s.name() + "' reads '" + data + "', which the later system '" +
                                            systems[j].name() +
                                            "' writes; run it after, or declare it a read of the previous frame");
    }
    for (const std::string& data : s.reads_previous_frame()) {
      bool written_later = false;
      for (size_t j = i + 1; j < systems.size(); ++j) written_later = written_later || contains(systems[j].writes(), data);
      if (!written_later)
        return Result<Scheduler>::failure("system '" + s.name() + "' declares a previous-frame read of '" + data +
                                          "', but no later system writes it");
    }
  }
  return Scheduler(std::move(systems), clock, cpu_clock);
}

Scheduler::Scheduler(std::vector<SystemSpec> systems, Clock clock, Clock cpu_clock)
    : systems_(std::move(systems)), clock_(clock), cpu_clock_(cpu_clock) {
  for (const SystemSpec& s : systems_) {
    timings_.emplace_back().name = s.name();
    if (cpu_clock_) cpu_timings_.emplace_back().name = s.name();
  }
}

void Scheduler::run_frame() {
  const int64_t frame_start = clock_();
  const int64_t frame_cpu_start = cpu_clock_ ? cpu_clock_() : 0;
  for (size_t i = 0; i < systems_.size(); ++i) {
    const int64_t t0 = clock_();
    const int64_t cpu0 = cpu_clock_ ? cpu_clock_() : 0;
    systems_[i].run();
    if (cpu_clock_) cpu_timings_[i].add(cpu_clock_() - cpu0);
    timings_[i].add(clock_() - t0);
  }
  if (cpu_clock_) frame_cpu_timing_.add(cpu_clock_() - frame_cpu_start);
  frame_timing_.add(clock_() - frame_start);
  ++frames_;
}

std::string Scheduler::describe() const {
  std::string out;
  for (const SystemSpec& s : systems_) {
    out += s.name() + ": reads " + joined(s.reads());
    if (!s.reads_previous_frame().empty()) out += "; reads last frame's " + joined(s.reads_previous_frame());
    out += "; writes " + joined(s.writes()) + "\n";
  }
  return out;
}

}  // namespace fire
