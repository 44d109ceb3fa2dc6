#pragma once
// The frame scheduler: runs the systems in their declared order once per fixed time step and records
// how long each took. Timing uses a clock handed in by platform/; systems themselves never see it.
//
// A system is declared with the members of the world it takes, by member pointer (declare_system):
// Read<&World::m> hands it `const T&`, Write<&World::m> `T&`, and ReadPrevious<&World::m> `const T&` to
// what a later system writes in the frame, as the previous frame left it (sketch snaps against the mesh
// that split left last frame). Its function captures nothing, so it reaches only what it declared; a
// function whose parameters do not match the declaration does not compile. The order is checked when the
// schedule is built: a system may not read what a later system writes in the same frame unless it declares
// the read as the previous frame's. Reads of members no system writes are inputs from outside the frame.
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "engine/common.hpp"
#include "engine/ir_report.hpp"

namespace fire {

// The frame step: one frame per report of a Wii Remote.
inline constexpr int64_t kFrameStepUs = kReportPeriodUs;

// The fixed step a frame covers on the input log's clock.
struct FrameTime {
  uint64_t index = 0;
  int64_t begin_us = 0;  // frame covers [begin_us, end_us)
  int64_t end_us = 0;
};

// What a system takes from the world, by member pointer.
template <auto Member> struct Read {};
template <auto Member> struct Write {};
template <auto Member> struct ReadPrevious {};

// The name a member pointer's member has in its class ("mesh" for &World::mesh), as the compiler spells it.
template <auto Member>
std::string member_name() {
  const std::string_view signature = __PRETTY_FUNCTION__;  // "... [with auto Member = &fire::World::mesh; ...]"
  const size_t at = signature.find("Member = ");
  std::string_view name = signature.substr(at == std::string_view::npos ? 0 : at);
  name = name.substr(0, name.find_first_of(";]"));
  return std::string(name.substr(name.rfind("::") + 2));
}

class SystemSpec {
 public:
  const std::string& name() const { return name_; }
  const std::vector<std::string>& reads() const { return reads_; }
  const std::vector<std::string>& writes() const { return writes_; }
  // Written later in the frame: this system sees the previous frame's value.
  const std::vector<std::string>& reads_previous_frame() const { return reads_previous_frame_; }
  void run() const { run_(); }

 private:
  template <class... Access>
  friend SystemSpec declared(std::string name, std::function<void()> run);
  SystemSpec(std::string name, std::function<void()> run) : name_(std::move(name)), run_(std::move(run)) {}
  std::string name_;
  std::vector<std::string> reads_, writes_, reads_previous_frame_;
  std::function<void()> run_;
};

namespace scheduling {

template <class Access> struct Take;
template <auto M> struct Take<Read<M>> {
  template <class World> static const auto& from(World& w) { return w.*M; }
  static void declare(std::vector<std::string>& reads, std::vector<std::string>&, std::vector<std::string>&) {
    reads.push_back(member_name<M>());
  }
};
template <auto M> struct Take<Write<M>> {
  template <class World> static auto& from(World& w) { return w.*M; }
  static void declare(std::vector<std::string>&, std::vector<std::string>& writes, std::vector<std::string>&) {
    writes.push_back(member_name<M>());
  }
};
template <auto M> struct Take<ReadPrevious<M>> {
  template <class World> static const auto& from(World& w) { return w.*M; }
  static void declare(std::vector<std::string>&, std::vector<std::string>&, std::vector<std::string>& previous) {
    previous.push_back(member_name<M>());
  }
};

}  // namespace scheduling

// A system's function as a plain function pointer, which a lambda converts to only when it captures
// nothing and takes exactly the parameters given.
template <class Function, class Fn>
Function system_function(Fn fn) {
  static_assert(std::is_convertible_v<Fn, Function>,
                "a system's function captures nothing and takes exactly its declared members: const T& for Read and "
                "ReadPrevious, T& for Write, in declaration order");
  return fn;
}

// The spec of a system whose function `run` reaches the members `Access` names.
template <class... Access>
SystemSpec declared(std::string name, std::function<void()> run) {
  SystemSpec spec(std::move(name), std::move(run));
  (scheduling::Take<Access>::declare(spec.reads_, spec.writes_, spec.reads_previous_frame_), ...);
  return spec;
}

// Declares system `name` over `world`: `fn` is called every frame with each declared member in
// declaration order (const T& for Read and ReadPrevious, T& for Write).
template <class... Access, class World, class Fn>
SystemSpec declare_system(World& world, std::string name, Fn fn) {
  const auto call = system_function<void (*)(decltype(scheduling::Take<Access>::from(world))...)>(fn);
  return declared<Access...>(std::move(name), [&world, call] { call(scheduling::Take<Access>::from(world)...); });
}

// The same for an observer that keeps state outside the world (a test's probe, the pictures of `fire render
// --every`): `fn` takes `context` first.
template <class... Access, class World, class Context, class Fn>
SystemSpec declare_system(World& world, std::string name, Context& context, Fn fn) {
  const auto call = system_function<void (*)(Context&, decltype(scheduling::Take<Access>::from(world))...)>(fn);
  return declared<Access...>(std::move(name),
                             [&world, &context, call] { call(context, scheduling::Take<Access>::from(world)...); });
}

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
  // later system writes. `clock` times them by the wall; `cpu_clock`, when given, by the thread's CPU time
  // too, which a busy machine's other work does not inflate.
  static Result<Scheduler> build(std::vector<SystemSpec> systems, Clock clock, Clock cpu_clock = nullptr);

  void run_frame();
  const std::vector<SystemTiming>& timings() const { return timings_; }
  // Timings of the whole frame (all systems together), one sample per frame.
  const SystemTiming& frame_timing() const { return frame_timing_; }
  // The same by the thread's CPU time; empty (no samples) without a cpu_clock.
  const std::vector<SystemTiming>& cpu_timings() const { return cpu_timings_; }
  const SystemTiming& frame_cpu_timing() const { return frame_cpu_timing_; }
  uint64_t frames() const { return frames_; }
  const std::vector<SystemSpec>& systems() const { return systems_; }
  // The frame: one line per system, in order, with what it reads (this frame's and the previous frame's)
  // and writes.
  std::string describe() const;

 private:
  Scheduler(std::vector<SystemSpec> systems, Clock clock, Clock cpu_clock);
  std::vector<SystemSpec> systems_;
  Clock clock_, cpu_clock_;
  std::vector<SystemTiming> timings_, cpu_timings_;
  SystemTiming frame_timing_{"frame", {}, 0, 0}, frame_cpu_timing_{"frame", {}, 0, 0};
  uint64_t frames_ = 0;
};

}  // namespace fire
