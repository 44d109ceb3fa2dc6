#pragma once
// Input logs written line by line for the sketch tests, and their headless replay through every system.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include <catch2/catch.hpp>

#include "tools/app/session.hpp"

namespace fire::test {

// A log built line by line, each event 10 ms after the last, so each lands in a frame of its own.
struct Log {
  std::string text = std::string(kInputLogHeader) + "\n";
  int64_t t = 0;
  Log& event(const std::string& what) {
    text += std::to_string(t += 10000) + " " + what + "\n";
    return *this;
  }
  Log& pen(double x, double y, double z = 0) {
    return event("pen " + format_double(x) + " " + format_double(y) + " " + format_double(z));
  }
  Log& stroke(std::initializer_list<Vec3> points) {
    event("down");
    for (const Vec3& p : points) pen(p.x(), p.y(), p.z());
    return event("up");
  }
};

// A straight stroke from a to b, a sample every 5 mm.
inline Log& line(Log& log, const Vec3& a, const Vec3& b) {
  const int n = std::max(2, int(std::ceil((b - a).norm() / 0.005)));
  log.event("down");
  for (int k = 0; k <= n; ++k) {
    const Vec3 p = a + (double(k) / n) * (b - a);
    log.pen(p.x(), p.y(), p.z());
  }
  return log.event("up");
}

// A flat 30 x 10 cm rectangle cut into six strips by five curves at x = 5, 10, ..., 25 cm.
inline Log strips() {
  Log log;
  line(log, {0, 0, 0}, {0.3, 0, 0});
  line(log, {0.3, 0, 0}, {0.3, 0.1, 0});
  line(log, {0.3, 0.1, 0}, {0, 0.1, 0});
  line(log, {0, 0.1, 0}, {0.0005, 0.0005, 0});
  for (double x : {0.05, 0.10, 0.15, 0.20, 0.25}) line(log, {x, 0, 0}, {x, 0.1, 0});
  return log;
}

inline int64_t step_clock() {
  static int64_t t = 0;
  return t += 1000;
}

inline std::unique_ptr<World> replay(const Log& log) {
  auto parsed = parse_input_log(log.text, "feedback.log");
  REQUIRE(parsed);
  auto w = std::make_unique<World>();
  w->log = std::move(*parsed);
  Scheduler scheduler = make_scheduler(*w, step_clock);
  replay_headless(*w, scheduler);
  return w;
}

// Every refusal's reason, one a line: what a failed check should show.
inline std::string rejections(const World& w) {
  std::string all;
  for (const Rejection& r : w.rejections) all += r.reason + "\n";
  return all;
}

}  // namespace fire::test
