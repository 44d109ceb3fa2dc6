#pragma once
// The grid drawing of perf/frame, also drawn by perf/render: cells of 2 cm on a wavy sheet, nx across and
// ny up (20 x 10: 200 faces); a border, the long curves across, then the short ones cell by cell. Strokes
// at 100 Hz, 5 mm apart, half a second between strokes, with a fixed +-0.2 mm jitter inside every stroke.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "engine/input_log.hpp"

namespace fire::perf {

inline constexpr double kGridCell = 0.02;

// The sheet's height at (x, y): every stroke of the drawing lies on it.
inline double sheet(double x, double y) { return 0.015 * std::sin(12 * x) * std::cos(9 * y); }

inline std::vector<InputEvent> grid_drawing(int nx, int ny) {
  const double cell = kGridCell, W = nx * cell, H = ny * cell;
  std::vector<InputEvent> out;
  int64_t t = 1'000'000;
  uint64_t state = 12345;
  auto jitter = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return (double(state >> 11) / 9007199254740992.0 - 0.5) * 0.0004;
  };
  auto event = [&](EventKind kind, const Vec3& p = Vec3::Zero()) {
    InputEvent e;
    e.t_us = t;
    e.kind = kind;
    e.p = p;
    out.push_back(e);
    t += 10'000;
  };
  auto stroke = [&](double ax, double ay, double bx, double by) {
    const int n = std::max(2, int(std::hypot(bx - ax, by - ay) / 0.005) + 1);
    event(EventKind::Down);
    for (int i = 0; i < n; ++i) {
      const double s = double(i) / (n - 1), x = ax + s * (bx - ax), y = ay + s * (by - ay);
      const bool end = i == 0 || i == n - 1;
      event(EventKind::Pen, Vec3(x + (end ? 0 : jitter()), y + (end ? 0 : jitter()), sheet(x, y)));
    }
    event(EventKind::Up);
    t += 500'000;
  };
  stroke(0, 0, W, 0);
  stroke(W, 0, W, H);
  stroke(W, H, 0, H);
  stroke(0, H, 0.0005, 0.0005);
  for (int i = 1; i < nx; ++i) stroke(i * cell, 0, i * cell, H);
  for (int i = 0; i < nx; ++i)
    for (int j = 1; j < ny; ++j) stroke(i * cell, j * cell, (i + 1) * cell, j * cell);
  return out;
}

}  // namespace fire::perf
