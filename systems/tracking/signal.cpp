#include "systems/tracking/signal.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

namespace fire::tracking {
namespace {

// Smoothing factor of an exponential low-pass with the given cutoff for a step of dt seconds.
double smoothing_factor(double cutoff_hz, double dt_s) {
  const double tau = 1.0 / (2.0 * std::numbers::pi * cutoff_hz);
  return 1.0 / (1.0 + tau / dt_s);
}

double distance_to_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  if (len2 == 0.0) return (p - a).norm();
  const double s = std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
  return (p - (a + s * ab)).norm();
}

}  // namespace

std::optional<Vec3> one_euro_step(OneEuroState& state, const OneEuroParams& params, int64_t t_us, const Vec3& x) {
  if (!x.allFinite()) return std::nullopt;
  if (!state.primed) {
    state = OneEuroState{.primed = true, .t_us = t_us, .value = x, .derivative = Vec3::Zero()};
    return x;
  }
  if (t_us <= state.t_us) return std::nullopt;
  const double dt = static_cast<double>(t_us - state.t_us) * 1e-6;
  const Vec3 velocity = (x - state.value) / dt;
  state.derivative += smoothing_factor(params.derivative_cutoff_hz, dt) * (velocity - state.derivative);
  const double cutoff = params.min_cutoff_hz + params.beta * state.derivative.norm();
  state.value += smoothing_factor(cutoff, dt) * (x - state.value);
  state.t_us = t_us;
  return state.value;
}

std::vector<size_t> rdp_simplify(std::span<const Vec3> points, double tolerance) {
  std::vector<size_t> finite;
  for (size_t i = 0; i < points.size(); ++i)
    if (points[i].allFinite()) finite.push_back(i);
  if (finite.size() <= 2) return finite;
  std::vector<char> keep(finite.size(), 0);
  keep.front() = keep.back() = 1;
  // An explicit stack instead of recursion: a long stroke must not exhaust the call stack.
  std::vector<std::pair<size_t, size_t>> spans{{0, finite.size() - 1}};
  while (!spans.empty()) {
    const auto [first, last] = spans.back();
    spans.pop_back();
    double worst = -1.0;
    size_t worst_at = first;
    for (size_t k = first + 1; k < last; ++k) {
      const double d = distance_to_segment(points[finite[k]], points[finite[first]], points[finite[last]]);
      if (d > worst) {
        worst = d;
        worst_at = k;
      }
    }
    if (worst > tolerance) {
      keep[worst_at] = 1;
      spans.emplace_back(first, worst_at);
      spans.emplace_back(worst_at, last);
    }
  }
  std::vector<size_t> kept;
  for (size_t k = 0; k < finite.size(); ++k)
    if (keep[k]) kept.push_back(finite[k]);
  return kept;
}

TimedPolyline resample_by_arc_length(const TimedPolyline& stroke, double spacing) {
  TimedPolyline out;
  if (!(spacing > 0.0) || !std::isfinite(spacing)) return out;
  std::vector<size_t> finite;
  for (size_t i = 0; i < stroke.points.size() && i < stroke.t_us.size(); ++i)
    if (stroke.points[i].allFinite()) finite.push_back(i);
  if (finite.empty()) return out;
  auto emit = [&](int64_t t, const Vec3& p) {
    out.t_us.push_back(t);
    out.points.push_back(p);
  };
  emit(stroke.t_us[finite.front()], stroke.points[finite.front()]);
  double next_at = spacing;  // arc length of the next point to emit
  double walked = 0.0;       // arc length at the start of the current segment
  for (size_t k = 1; k < finite.size(); ++k) {
    const Vec3& a = stroke.points[finite[k - 1]];
    const Vec3& b = stroke.points[finite[k]];
    const double ta = static_cast<double>(stroke.t_us[finite[k - 1]]);
    const double tb = static_cast<double>(stroke.t_us[finite[k]]);
    const double len = (b - a).norm();
    while (len > 0.0 && next_at <= walked + len) {
      const double s = (next_at - walked) / len;
      emit(static_cast<int64_t>(std::llround(ta + s * (tb - ta))), a + s * (b - a));
      next_at += spacing;
    }
    walked += len;
  }
  // The stroke's end is kept unless the last emitted point already sits on it.
  const Vec3& end = stroke.points[finite.back()];
  if (walked > 0.0 && (out.points.back() - end).norm() > 1e-12 * (1.0 + walked))
    emit(stroke.t_us[finite.back()], end);
  return out;
}

}  // namespace fire::tracking
