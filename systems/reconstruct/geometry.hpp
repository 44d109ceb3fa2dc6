#pragma once
// Geometric building blocks of reconstruction: polylines parameterized by arc length (thesis 6.2),
// the planarity measures of triquadrification (thesis 6.1), the bilinearly blended Coons patch
// (thesis 6.2, eq. 1) and its n-sided generalization used by the FIRE pipeline.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "engine/common.hpp"

namespace fire::reconstruct {

// Arc-length parameter of each point: 0 at the first, 1 at the last (thesis 6.2). A zero-length line
// gets 0 everywhere but the last point.
std::vector<double> arc_parameters(std::span<const Vec3> line);
double polyline_length(std::span<const Vec3> line);

// How a polyline is read between its samples: `nearest` is the thesis's rule (the sample whose
// parameter is closest, ties to the lower index), `linear` interpolates along the arc, `smooth` along the
// cubic Hermite curve through the samples whose tangent at each is the derivative, in the arc parameter,
// of the parabola through it and its two nearest samples (at the ends, the first or last three).
enum class Sampling : uint8_t { Nearest, Linear, Smooth };

// The point at parameter t in [0, 1]; `params` are arc_parameters(line).
Vec3 sample_polyline(std::span<const Vec3> line, std::span<const double> params, double t, Sampling mode);

// Index of the interior sample nearest to parameter 1/2 (ties to the lower index), or 0 when the line
// has no interior sample.
uint32_t middle_sample(std::span<const double> params);

// Splits a polyline at its middle sample; a 2-point line is split at its midpoint. Both halves hold the
// split point. Always computed in the line's own direction, so both faces of an edge agree bit for bit.
void split_polyline(std::span<const Vec3> line, std::vector<Vec3>& first, std::vector<Vec3>& second);

// A straight polyline from a to b with `segments` equal segments.
std::vector<Vec3> straight_polyline(const Vec3& a, const Vec3& b, uint32_t segments);

// ---- triquadrification (thesis 6.1)

enum class Planarity : uint8_t {
  LeastSquares,   // 6.1.1: squared distances to the plane through the centroid whose normal is the
                  // singular vector of the covariance's smallest singular value
  MeanNormal,     // 6.1.2: squared distances to the plane through the centroid normal to the mean of
                  // the four triangles' unit normals
  Hough,          // 6.1.3: spread of the four triangles' planes in the (theta, phi, rho) Hough space
};

// How far four points are from lying in a plane, by `measure`; 0 for coplanar points.
double planarity_error(const std::array<Vec3, 4>& quad, Planarity measure);

// Greedy triquadrification of a polygon (thesis 6.1): while more than 4 corners are left, cut off the
// quad of 4 consecutive corners with the smallest planarity error (ties to the first), then keep the
// rest. Returns the faces as corner indices in the polygon's order: quads and at most one triangle.
std::vector<std::vector<uint32_t>> triquadrify(std::span<const Vec3> corners, Planarity measure);

// ---- patches over polyline boundaries

// A side of a face as the face walks it: the stored polyline, its parameters and the walking direction.
struct Side {
  std::span<const Vec3> line;
  std::span<const double> params;
  bool reversed = false;
  // The point at walking parameter s (0 at the side's first corner, 1 at the next).
  Vec3 at(double s, Sampling mode) const { return sample_polyline(line, params, reversed ? 1.0 - s : s, mode); }
  const Vec3& start() const { return reversed ? line.back() : line.front(); }
};

// The bilinearly blended Coons patch x(u, v) of thesis 6.2 eq. (1) over four sides walked in loop order
// (side 0 from corner 0 to corner 1, ...): x(u, 0) = side 0, x(1, v) = side 1, x(u, 1) = side 2 walked
// backwards, x(0, v) = side 3 walked backwards.
Vec3 coons_point(std::span<const Side> sides, double u, double v, Sampling mode);

// The n-sided C0 patch (n >= 3) over sides walked in loop order, at a point of the regular n-gon domain
// whose corner k is (cos 2 pi k / n, sin 2 pi k / n). It interpolates every side (side k at the domain
// side from corner k to k+1, by arc length) and equals coons_point with linear sampling for n = 4.
// `sides` must outlive the patch.
class SidedPatch {
 public:
  explicit SidedPatch(std::span<const Side> sides);
  Vec3 at(const Eigen::Vector2d& domain_point) const;

 private:
  void products_but_run(const std::vector<double>& values, uint32_t run, std::vector<double>& out) const;
  std::span<const Side> sides_;
  std::vector<Eigen::Vector2d> corners_;
  // Scratch of at(), kept so that the many points of one face allocate nothing.
  mutable std::vector<double> area_, lambda_, d_, s_, blend_, prefix_, suffix_;
};
Eigen::Vector2d domain_corner(uint32_t n, uint32_t k);

}  // namespace fire::reconstruct
