// The pen signal: One Euro filter, Ramer-Douglas-Peucker, arc-length resampling.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "systems/tracking/signal.hpp"

using namespace fire;
using namespace fire::tracking;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double smoothing(double cutoff_hz, double dt) { return 1.0 / (1.0 + 1.0 / (2.0 * std::numbers::pi * cutoff_hz * dt)); }

}  // namespace

TEST_CASE("One Euro: the first sample passes, the second follows Casiez et al.'s update") {
  const OneEuroParams p{.min_cutoff_hz = 1.5, .beta = 40.0, .derivative_cutoff_hz = 2.0};
  OneEuroState s;
  const Vec3 x0(0.1, 0.2, 0.3), x1(0.104, 0.197, 0.3);
  REQUIRE(one_euro_step(s, p, 1000, x0) == std::optional<Vec3>(x0));
  const double dt = 0.01;
  const Vec3 velocity = (x1 - x0) / dt;
  const Vec3 derivative = smoothing(p.derivative_cutoff_hz, dt) * velocity;
  const double cutoff = p.min_cutoff_hz + p.beta * derivative.norm();
  const Vec3 expected = x0 + smoothing(cutoff, dt) * (x1 - x0);
  const std::optional<Vec3> got = one_euro_step(s, p, 11000, x1);
  REQUIRE(got);
  CHECK((*got - expected).norm() < 1e-15);
  CHECK((s.derivative - derivative).norm() < 1e-12);
}

TEST_CASE("One Euro: a resting pen stays put and its jitter shrinks") {
  const OneEuroParams p{.min_cutoff_hz = 1.0, .beta = 0.0, .derivative_cutoff_hz = 1.0};
  OneEuroState s;
  const Vec3 rest(0.01, -0.02, 0.8);
  for (int k = 0; k < 50; ++k) CHECK(*one_euro_step(s, p, 10000 * k, rest) == rest);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 1e-3);
  OneEuroState t;
  double in = 0, out = 0;
  for (int k = 0; k < 2000; ++k) {
    const Vec3 x = rest + Vec3(noise(rng), noise(rng), noise(rng));
    const Vec3 y = *one_euro_step(t, p, 10000 * k, x);
    if (k < 100) continue;  // the start-up transient
    in += (x - rest).squaredNorm();
    out += (y - rest).squaredNorm();
  }
  // A 1 Hz low-pass at 100 Hz keeps alpha / (2 - alpha) = 3 % of white noise's variance.
  CHECK(out < 0.06 * in);
  CHECK(out > 0.01 * in);
}

TEST_CASE("One Euro: the speed term cuts the lag of a moving pen") {
  auto lag_error = [](double beta) {
    const OneEuroParams p{.min_cutoff_hz = 1.0, .beta = beta, .derivative_cutoff_hz = 2.0};
    OneEuroState s;
    Vec3 y;
    for (int k = 0; k <= 100; ++k) y = *one_euro_step(s, p, 10000 * k, Vec3(0.5 * 0.01 * k, 0, 0));  // 0.5 m/s
    return std::abs(y.x() - 0.5);
  };
  const double slow = lag_error(0), fast = lag_error(300);
  CHECK(slow > 0.05);    // a 1 Hz filter trails a 0.5 m/s ramp by about 8 cm
  CHECK(fast < 0.002);   // the speed term keeps it within 2 mm
}

TEST_CASE("One Euro: non-finite samples and time that does not advance are refused") {
  const OneEuroParams p;
  OneEuroState s;
  CHECK_FALSE(one_euro_step(s, p, 0, Vec3(kNaN, 0, 0)));
  CHECK_FALSE(s.primed);
  REQUIRE(one_euro_step(s, p, 0, Vec3(1, 2, 3)));
  const OneEuroState before = s;
  CHECK_FALSE(one_euro_step(s, p, 10000, Vec3(1, std::numeric_limits<double>::infinity(), 3)));
  CHECK_FALSE(one_euro_step(s, p, 0, Vec3(1, 2, 4)));
  CHECK_FALSE(one_euro_step(s, p, -5, Vec3(1, 2, 4)));
  CHECK(s.t_us == before.t_us);
  CHECK(s.value == before.value);
  CHECK(one_euro_step(s, p, 10000, Vec3(1, 2, 3)));
}

TEST_CASE("Ramer-Douglas-Peucker keeps the corners and drops what lies within the tolerance") {
  std::vector<Vec3> line;
  for (int k = 0; k <= 10; ++k) line.emplace_back(0.01 * k, (k % 2 ? 1e-4 : -1e-4), 0);
  CHECK(rdp_simplify(line, 5e-4) == std::vector<size_t>{0, 10});
  CHECK(rdp_simplify(line, 1e-4).size() == 11);

  // An L: along x, then along y; the corner is point 5.
  std::vector<Vec3> ell;
  for (int k = 0; k <= 5; ++k) ell.emplace_back(0.01 * k, 0, 0);
  for (int k = 1; k <= 5; ++k) ell.emplace_back(0.05, 0.01 * k, 0);
  CHECK(rdp_simplify(ell, 1e-3) == std::vector<size_t>{0, 5, 10});

  std::vector<Vec3> closed{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 0, 0}};  // first == last: distance to a point
  CHECK(rdp_simplify(closed, 0.1) == std::vector<size_t>{0, 1, 2, 3});

  std::vector<Vec3> with_nan = ell;
  with_nan[3] = Vec3(kNaN, 0, 0);
  with_nan[0] = Vec3(0, kNaN, 0);
  CHECK(rdp_simplify(with_nan, 1e-3) == std::vector<size_t>{1, 5, 10});
  CHECK(rdp_simplify(std::vector<Vec3>{}, 1e-3).empty());
}

TEST_CASE("arc-length resampling spaces points evenly and interpolates their instants") {
  TimedPolyline s;
  s.points = {{0, 0, 0}, {0.4, 0, 0}, {0.4, 0.6, 0}};
  s.t_us = {0, 400, 1000};
  const TimedPolyline r = resample_by_arc_length(s, 0.25);
  const std::vector<Vec3> expected{{0, 0, 0}, {0.25, 0, 0}, {0.4, 0.1, 0}, {0.4, 0.35, 0}, {0.4, 0.6, 0}};
  REQUIRE(r.points.size() == expected.size());
  for (size_t k = 0; k < expected.size(); ++k) CHECK((r.points[k] - expected[k]).norm() < 1e-12);
  CHECK(r.t_us == std::vector<int64_t>{0, 250, 500, 750, 1000});

  const TimedPolyline uneven = resample_by_arc_length(s, 0.3);  // 0, 0.3, 0.6, 0.9 and the end at 1.0
  REQUIRE(uneven.points.size() == 5);
  CHECK((uneven.points[3] - Vec3(0.4, 0.5, 0)).norm() < 1e-12);
  CHECK((uneven.points[4] - Vec3(0.4, 0.6, 0)).norm() < 1e-12);
}

TEST_CASE("arc-length resampling: degenerate and non-finite input") {
  TimedPolyline still;
  still.points = {{1, 1, 1}, {1, 1, 1}, {1, 1, 1}};
  still.t_us = {0, 10, 20};
  CHECK(resample_by_arc_length(still, 0.1).points.size() == 1);
  CHECK(resample_by_arc_length(still, 0.0).points.empty());
  CHECK(resample_by_arc_length(still, kNaN).points.empty());
  CHECK(resample_by_arc_length(TimedPolyline{}, 0.1).points.empty());

  TimedPolyline gap;
  gap.points = {{0, 0, 0}, {kNaN, 0, 0}, {1, 0, 0}};
  gap.t_us = {0, 5, 10};
  const TimedPolyline r = resample_by_arc_length(gap, 0.5);
  REQUIRE(r.points.size() == 3);
  for (const Vec3& p : r.points) CHECK(p.allFinite());
  CHECK(r.t_us == std::vector<int64_t>{0, 5, 10});
}
