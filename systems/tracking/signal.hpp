#pragma once
// The pen signal: One Euro filtering of 3D samples (Casiez, Roussel and Vogel, CHI 2012), and
// Ramer-Douglas-Peucker simplification and arc-length resampling of strokes. Time is data
// (microseconds on the log's clock), never read from a clock.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "engine/common.hpp"

namespace fire::tracking {

struct OneEuroParams {
  double min_cutoff_hz = 1.0;         // cutoff at rest: lower removes more jitter
  double beta = 0.0;                  // cutoff growth per unit of speed (per m/s for metres): higher lags less
  double derivative_cutoff_hz = 1.0;  // smoothing of the speed estimate itself
};

struct OneEuroState {
  bool primed = false;
  int64_t t_us = 0;
  Vec3 value = Vec3::Zero();       // filtered position
  Vec3 derivative = Vec3::Zero();  // filtered velocity, units per second
};

// One step. The cutoff follows the norm of the filtered velocity, so all three axes share one
// cutoff and a stroke keeps its shape. A non-finite sample, or one not later than the previous
// (t_us <= state.t_us), is rejected: nullopt, state unchanged. The first sample passes through.
std::optional<Vec3> one_euro_step(OneEuroState& state, const OneEuroParams& params, int64_t t_us, const Vec3& x);

// A stroke: samples with their instants, same length.
struct TimedPolyline {
  std::vector<int64_t> t_us;
  std::vector<Vec3> points;
};

// Indices of the points Ramer-Douglas-Peucker keeps with distance-to-segment `tolerance`
// (first and last always kept; ascending). Non-finite points are never kept and never split.
std::vector<size_t> rdp_simplify(std::span<const Vec3> points, double tolerance);

// Points every `spacing` along the polyline's arc length, the last point added at the end;
// instants interpolated along with the positions. Non-finite points are skipped. A stroke of
// zero length gives its first point only; `spacing` <= 0 or non-finite gives an empty result.
TimedPolyline resample_by_arc_length(const TimedPolyline& stroke, double spacing);

}  // namespace fire::tracking
