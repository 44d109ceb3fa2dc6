// The building blocks: arc-length polylines, planarity measures, triquadrification, the patches.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "systems/reconstruct/geometry.hpp"

using namespace fire;
using namespace fire::reconstruct;

namespace {

// A curved side on the surface z = 0.3 sin(x) cos(y), from a to b (xy straight), with n points.
std::vector<Vec3> curved(Eigen::Vector2d a, Eigen::Vector2d b, int n) {
  std::vector<Vec3> out;
  for (int i = 0; i < n; ++i) {
    const double w = double(i) / (n - 1);
    const Eigen::Vector2d p = a + (b - a) * (w + 0.15 * w * (1 - w));  // uneven spacing
    out.emplace_back(p.x(), p.y(), 0.3 * std::sin(2 * p.x()) * std::cos(p.y()));
  }
  return out;
}

struct Square {
  // Sides stored in mixed directions: sides 1 and 2 are stored backwards and walked reversed.
  std::vector<Vec3> s0 = curved({0, 0}, {1, 0}, 7), s1 = curved({1, 1}, {1, 0}, 5), s2 = curved({0, 1}, {1, 1}, 9),
                    s3 = curved({0, 1}, {0, 0}, 6);
  std::vector<double> t0 = arc_parameters(s0), t1 = arc_parameters(s1), t2 = arc_parameters(s2),
                      t3 = arc_parameters(s3);
  std::vector<Side> sides() const { return {{s0, t0, false}, {s1, t1, true}, {s2, t2, true}, {s3, t3, false}}; }
};

}  // namespace

TEST_CASE("polylines are read by arc length: nearest sample or linear", "[geometry]") {
  const std::vector<Vec3> line{{0, 0, 0}, {1, 0, 0}, {1, 3, 0}};  // segments of length 1 and 3
  const std::vector<double> t = arc_parameters(line);
  CHECK(t == std::vector<double>{0, 0.25, 1});
  CHECK(sample_polyline(line, t, 0.1, Sampling::Nearest) == line[0]);
  CHECK(sample_polyline(line, t, 0.2, Sampling::Nearest) == line[1]);
  CHECK(sample_polyline(line, t, 0.7, Sampling::Nearest) == line[2]);
  CHECK(sample_polyline(line, t, 0.625, Sampling::Linear).isApprox(Vec3(1, 1.5, 0), 1e-15));
  CHECK(sample_polyline(line, t, 1.0, Sampling::Linear) == line[2]);
  CHECK(middle_sample(t) == 1);
  // Ties go to the lower index: 0.125 is as far from 0 as from 0.25.
  CHECK(sample_polyline(line, t, 0.125, Sampling::Nearest) == line[0]);
}

TEST_CASE("smooth sampling passes through the samples and follows the curve between them", "[geometry]") {
  // A quarter circle of radius 1, sampled at 9 points: the chords' midpoints lie 4.8e-3 inside it.
  std::vector<Vec3> arc;
  for (int i = 0; i <= 8; ++i) {
    const double a = std::numbers::pi / 2 * i / 8;
    arc.emplace_back(std::cos(a), std::sin(a), 0);
  }
  const std::vector<double> t = arc_parameters(arc);
  double linear_error = 0, smooth_error = 0;
  for (int k = 0; k <= 160; ++k) {
    const double s = k / 160.0;
    linear_error = std::max(linear_error, std::abs(sample_polyline(arc, t, s, Sampling::Linear).norm() - 1));
    smooth_error = std::max(smooth_error, std::abs(sample_polyline(arc, t, s, Sampling::Smooth).norm() - 1));
  }
  CHECK(linear_error > 4e-3);
  CHECK(smooth_error < linear_error / 20);
  for (size_t i = 0; i < arc.size(); ++i) CHECK(sample_polyline(arc, t, t[i], Sampling::Smooth).isApprox(arc[i], 1e-14));
  // A straight polyline stays straight and keeps the arc parameter.
  const std::vector<Vec3> line{{0, 0, 0}, {1, 0, 0}, {3, 0, 0}, {4, 0, 0}};
  const std::vector<double> u = arc_parameters(line);
  CHECK(sample_polyline(line, u, 0.6, Sampling::Smooth).isApprox(Vec3(2.4, 0, 0), 1e-14));
}

TEST_CASE("splitting a polyline at its middle sample, a 2-point line at its midpoint", "[geometry]") {
  const std::vector<Vec3> line{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {2, 5, 0}};
  std::vector<Vec3> a, b;
  split_polyline(line, a, b);  // parameters 0, 1/7, 2/7, 1: sample 2 is nearest to 1/2
  CHECK(a == std::vector<Vec3>{line[0], line[1], line[2]});
  CHECK(b == std::vector<Vec3>{line[2], line[3]});
  const std::vector<Vec3> two{{0, 0, 0}, {2, 4, 6}};
  split_polyline(two, a, b);
  CHECK(a == std::vector<Vec3>{two[0], Vec3(1, 2, 3)});
  CHECK(b == std::vector<Vec3>{Vec3(1, 2, 3), two[1]});
}

TEST_CASE("the Coons patch interpolates four curved sides", "[geometry][coons]") {
  const Square sq;
  const std::vector<Side> sides = sq.sides();
  for (Sampling mode : {Sampling::Nearest, Sampling::Linear}) {
    for (uint32_t k = 0; k < 4; ++k) {
      // Every sample of every side, at its own walking parameter.
      const Side& side = sides[k];
      for (size_t i = 0; i < side.line.size(); ++i) {
        const double s = side.reversed ? 1.0 - side.params[i] : side.params[i];
        const Vec3 expected = side.line[i];
        const double u = k == 0 ? s : k == 1 ? 1.0 : k == 2 ? 1.0 - s : 0.0;
        const double v = k == 0 ? 0.0 : k == 1 ? s : k == 2 ? 1.0 : 1.0 - s;
        CHECK((coons_point(sides, u, v, mode) - expected).norm() < 1e-15);
      }
    }
  }
  // Inside, the patch is the sum of the two ruled surfaces minus the bilinear one (thesis 6.2 eq. 1).
  const double u = 0.3, v = 0.6;
  const Vec3 ruled_u = sides[0].at(u, Sampling::Linear) * (1 - v) + sides[2].at(1 - u, Sampling::Linear) * v;
  const Vec3 ruled_v = sides[3].at(1 - v, Sampling::Linear) * (1 - u) + sides[1].at(v, Sampling::Linear) * u;
  const Vec3 bilinear = sq.s0.front() * ((1 - u) * (1 - v)) + sq.s0.back() * (u * (1 - v)) + sq.s2.back() * (u * v) +
                        sq.s2.front() * ((1 - u) * v);
  CHECK((coons_point(sides, u, v, Sampling::Linear) - (ruled_u + ruled_v - bilinear)).norm() < 1e-15);
}

TEST_CASE("the n-sided patch is the bilinear Coons patch for n = 4", "[geometry][patch]") {
  const Square sq;
  const std::vector<Side> sides = sq.sides();
  // The square domain (corners at angles 0, 90, 180, 270 degrees) maps bilinearly to (u, v).
  for (double u : {0.1, 0.5, 0.77})
    for (double v : {0.2, 0.5, 0.9}) {
      const Eigen::Vector2d p = domain_corner(4, 0) * ((1 - u) * (1 - v)) + domain_corner(4, 1) * (u * (1 - v)) +
                                domain_corner(4, 2) * (u * v) + domain_corner(4, 3) * ((1 - u) * v);
      CHECK((SidedPatch(sides).at(p) - coons_point(sides, u, v, Sampling::Linear)).norm() < 1e-12);
    }
}

TEST_CASE("the n-sided patch interpolates its sides", "[geometry][patch]") {
  // 35 sides: the pawn's undrawn rest a third of the way through its drawing.
  for (uint32_t n : {3u, 5u, 6u, 12u, 35u}) {
    std::vector<std::vector<Vec3>> lines;
    std::vector<std::vector<double>> params;
    for (uint32_t k = 0; k < n; ++k) {
      const Eigen::Vector2d a = domain_corner(n, k) * 2.0, b = domain_corner(n, k + 1) * 2.0;
      lines.push_back(curved(a, b, 8));
      params.push_back(arc_parameters(lines.back()));
    }
    std::vector<Side> sides;
    for (uint32_t k = 0; k < n; ++k) sides.push_back({lines[k], params[k], false});
    for (uint32_t k = 0; k < n; ++k)
      for (double s : {0.2, 0.5, 0.9}) {
        const Eigen::Vector2d p = domain_corner(n, k) + (domain_corner(n, k + 1) - domain_corner(n, k)) * s;
        CHECK((SidedPatch(sides).at(p) - sides[k].at(s, Sampling::Linear)).norm() < 1e-9);
      }
    // A flat polygon gives a flat patch: its centre lies in the plane of the sides.
    std::vector<std::vector<Vec3>> flat(n);
    std::vector<std::vector<double>> flat_params(n);
    std::vector<Side> flat_sides;
    for (uint32_t k = 0; k < n; ++k) {
      for (Vec3 p : lines[k]) flat[k].push_back(Vec3(p.x(), p.y(), 0.5));
      flat_params[k] = arc_parameters(flat[k]);
    }
    for (uint32_t k = 0; k < n; ++k) flat_sides.push_back({flat[k], flat_params[k], false});
    CHECK(std::abs(SidedPatch(flat_sides).at(Eigen::Vector2d::Zero()).z() - 0.5) < 1e-14);
  }
}

TEST_CASE("planarity measures are zero for a plane and grow with the twist", "[geometry][triquad]") {
  const std::array<Vec3, 4> flat{Vec3(0, 0, 1), Vec3(2, 0, 1), Vec3(2, 1, 1), Vec3(0, 1.5, 1)};
  const std::array<Vec3, 4> bent{Vec3(0, 0, 0), Vec3(2, 0, 0.1), Vec3(2, 1, 0), Vec3(0, 1.5, 0.1)};
  const std::array<Vec3, 4> twisted{Vec3(0, 0, 0), Vec3(2, 0, 0.5), Vec3(2, 1, 0), Vec3(0, 1.5, 0.5)};
  for (Planarity m : {Planarity::LeastSquares, Planarity::MeanNormal, Planarity::Hough}) {
    CHECK(planarity_error(flat, m) < 1e-24);
    CHECK(planarity_error(bent, m) > 1e-6);
    CHECK(planarity_error(twisted, m) > planarity_error(bent, m));
  }
  // Least squares: four points alternating +-h off a plane are h^2 from it each (when h is small
  // against their spread the best plane is the middle one).
  const std::array<Vec3, 4> alternating{Vec3(-1, -1, 0.01), Vec3(1, -1, -0.01), Vec3(1, 1, 0.01), Vec3(-1, 1, -0.01)};
  CHECK(planarity_error(alternating, Planarity::LeastSquares) == Approx(4e-4).epsilon(1e-12));
}

TEST_CASE("greedy triquadrification cuts off the flattest quads", "[geometry][triquad]") {
  auto ring = [](uint32_t n) {
    std::vector<Vec3> c;
    for (uint32_t k = 0; k < n; ++k) c.emplace_back(std::cos(2 * std::numbers::pi * k / n), std::sin(2 * std::numbers::pi * k / n), 0);
    return c;
  };
  for (Planarity m : {Planarity::LeastSquares, Planarity::MeanNormal, Planarity::Hough}) {
    std::vector<Vec3> pentagon = ring(5);
    pentagon[2].z() = 1;  // only the quad 3,4,0,1 avoids the raised corner
    const auto faces = triquadrify(pentagon, m);
    REQUIRE(faces.size() == 2);
    CHECK(faces[0] == std::vector<uint32_t>{3, 4, 0, 1});
    CHECK(faces[1] == std::vector<uint32_t>{1, 2, 3});
    auto sizes = [&](uint32_t n) {
      std::vector<size_t> s;
      for (const auto& f : triquadrify(ring(n), m)) s.push_back(f.size());
      return s;
    };
    CHECK(sizes(3) == std::vector<size_t>{3});
    CHECK(sizes(4) == std::vector<size_t>{4});
    CHECK(sizes(6) == std::vector<size_t>{4, 4});
    CHECK(sizes(7) == std::vector<size_t>{4, 4, 3});
    CHECK(sizes(10) == std::vector<size_t>{4, 4, 4, 4});
  }
}
