#include "systems/reconstruct/geometry.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace fire::reconstruct {

double polyline_length(std::span<const Vec3> line) {
  double length = 0;
  for (size_t i = 1; i < line.size(); ++i) length += (line[i] - line[i - 1]).norm();
  return length;
}

std::vector<double> arc_parameters(std::span<const Vec3> line) {
  std::vector<double> t(line.size(), 0.0);
  double length = 0;
  for (size_t i = 1; i < line.size(); ++i) {
    length += (line[i] - line[i - 1]).norm();
    t[i] = length;
  }
  if (length > 0)
    for (double& x : t) x /= length;
  if (!t.empty()) t.back() = 1.0;
  return t;
}

Vec3 sample_polyline(std::span<const Vec3> line, std::span<const double> params, double t, Sampling mode) {
  if (t <= 0) return line.front();
  if (t >= 1) return line.back();
  // First index whose parameter is >= t; t lies in (params[hi-1], params[hi]].
  size_t hi = static_cast<size_t>(std::lower_bound(params.begin(), params.end(), t) - params.begin());
  hi = std::clamp<size_t>(hi, 1, line.size() - 1);
  const size_t lo = hi - 1;
  if (mode == Sampling::Nearest) return (t - params[lo] <= params[hi] - t) ? line[lo] : line[hi];
  const double span = params[hi] - params[lo];
  if (!(span > 0)) return line[lo];
  const double w = (t - params[lo]) / span;
  if (mode == Sampling::Linear || line.size() < 3) return line[lo] * (1.0 - w) + line[hi] * w;
  // The derivative at sample i of the parabola through it and its two nearest samples.
  auto tangent = [&](size_t i) -> Vec3 {
    const size_t a = std::clamp<size_t>(i, 1, line.size() - 2) - 1;
    const double h1 = params[a + 1] - params[a], h2 = params[a + 2] - params[a + 1];
    if (!(h1 > 0) || !(h2 > 0)) return Vec3((line[hi] - line[lo]) / span);  // a repeated sample: the chord
    const Vec3 d1 = (line[a + 1] - line[a]) / h1, d2 = (line[a + 2] - line[a + 1]) / h2;
    const double x = params[i] - params[a + 1];  // where on the parabola, from its middle sample
    return (d1 * h2 + d2 * h1) / (h1 + h2) + (d2 - d1) * (2 * x / (h1 + h2));
  };
  const double w2 = w * w, w3 = w2 * w;
  return line[lo] * (2 * w3 - 3 * w2 + 1) + tangent(lo) * (span * (w3 - 2 * w2 + w)) + line[hi] * (3 * w2 - 2 * w3) +
         tangent(hi) * (span * (w3 - w2));
}

uint32_t middle_sample(std::span<const double> params) {
  uint32_t best = 0;
  double best_distance = std::numeric_limits<double>::infinity();
  for (uint32_t i = 1; i + 1 < params.size(); ++i) {
    const double d = std::abs(params[i] - 0.5);
    if (d < best_distance) {
      best_distance = d;
      best = i;
    }
  }
  return best;
}

void split_polyline(std::span<const Vec3> line, std::vector<Vec3>& first, std::vector<Vec3>& second) {
  const std::vector<double> params = arc_parameters(line);
  const uint32_t m = middle_sample(params);
  if (m == 0) {
    const Vec3 mid = (line.front() + line.back()) * 0.5;
    first = {line.front(), mid};
    second = {mid, line.back()};
    return;
  }
  first.assign(line.begin(), line.begin() + m + 1);
  second.assign(line.begin() + m, line.end());
}

std::vector<Vec3> straight_polyline(const Vec3& a, const Vec3& b, uint32_t segments) {
  segments = std::max<uint32_t>(segments, 1);
  std::vector<Vec3> out(segments + 1);
  out.front() = a;
  out.back() = b;
  for (uint32_t i = 1; i < segments; ++i) {
    const double w = double(i) / segments;
    out[i] = a * (1.0 - w) + b * w;
  }
  return out;
}

namespace {

Vec3 centroid(const std::array<Vec3, 4>& q) { return (q[0] + q[1] + q[2] + q[3]) * 0.25; }

double squared_distances_to_plane(const std::array<Vec3, 4>& q, const Vec3& c, const Vec3& unit_normal) {
  double sum = 0;
  for (const Vec3& p : q) sum += std::pow((p - c).dot(unit_normal), 2);
  return sum;
}

Vec3 least_squares_normal(const std::array<Vec3, 4>& q, const Vec3& c) {
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Vec3& p : q) covariance += (p - c) * (p - c).transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance, Eigen::ComputeFullU);
  return svd.matrixU().col(2);  // singular values are sorted decreasing
}

// The normals of the four triangles (p_k, p_k+1, p_k+2), unnormalized; they follow the quad's winding.
std::array<Vec3, 4> triangle_normals(const std::array<Vec3, 4>& q) {
  std::array<Vec3, 4> n;
  for (int k = 0; k < 4; ++k) n[k] = (q[(k + 1) % 4] - q[k]).cross(q[(k + 2) % 4] - q[k]);
  return n;
}

double hough_spread(const std::array<Vec3, 4>& q, const Vec3& c) {
  const std::array<Vec3, 4> normals = triangle_normals(q);
  Vec3 mean = normals[0] + normals[1] + normals[2] + normals[3];
  if (!(mean.norm() > 0)) mean = least_squares_normal(q, c);
  mean.normalize();
  // A frame that puts the mean normal on the equator (theta = pi/2, phi = 0), where the spherical
  // parameters are well conditioned; the thesis's fixed frame is singular for normals near its z axis.
  const Vec3 helper = std::abs(mean.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 e2 = mean.cross(helper).normalized(), e3 = mean.cross(e2);
  double scale = 0;
  for (const Vec3& p : q) scale += (p - c).squaredNorm();
  scale = std::sqrt(scale / 4);
  if (!(scale > 0)) return 0;
  // The exact intersection points of the triples of Hough surfaces (the planes through each triangle),
  // which the thesis's refined accumulator approaches.
  std::vector<Vec3> points;
  for (int k = 0; k < 4; ++k) {
    const double length = normals[k].norm();
    if (!(length > 0)) continue;  // a degenerate triangle lies in every plane through its line
    Vec3 n = normals[k] / length;
    if (n.dot(mean) < 0) n = -n;
    const double theta = std::acos(std::clamp(n.dot(e3), -1.0, 1.0));
    const double phi = std::atan2(n.dot(e2), n.dot(mean));
    const double rho = n.dot(q[k] - c) / scale;
    points.emplace_back(theta, phi, rho);
  }
  double spread = 0;
  for (size_t i = 0; i < points.size(); ++i)
    for (size_t j = i + 1; j < points.size(); ++j) spread += (points[i] - points[j]).squaredNorm();
  return spread;
}

}  // namespace

double planarity_error(const std::array<Vec3, 4>& q, Planarity measure) {
  const Vec3 c = centroid(q);
  switch (measure) {
    case Planarity::LeastSquares:
      return squared_distances_to_plane(q, c, least_squares_normal(q, c));
    case Planarity::MeanNormal: {
      Vec3 mean = Vec3::Zero();
      for (const Vec3& n : triangle_normals(q))
        if (n.norm() > 0) mean += n.normalized();
      if (!(mean.norm() > 1e-12)) return squared_distances_to_plane(q, c, least_squares_normal(q, c));
      return squared_distances_to_plane(q, c, mean.normalized());
    }
    case Planarity::Hough:
      return hough_spread(q, c);
  }
  return 0;
}

std::vector<std::vector<uint32_t>> triquadrify(std::span<const Vec3> corners, Planarity measure) {
  std::vector<uint32_t> rest(corners.size());
  for (uint32_t i = 0; i < rest.size(); ++i) rest[i] = i;
  std::vector<std::vector<uint32_t>> faces;
  while (rest.size() > 4) {
    const size_t m = rest.size();
    size_t best = 0;
    double best_error = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < m; ++i) {
      std::array<Vec3, 4> q;
      for (size_t k = 0; k < 4; ++k) q[k] = corners[rest[(i + k) % m]];
      const double error = planarity_error(q, measure);
      if (error < best_error) {
        best_error = error;
        best = i;
      }
    }
    std::vector<uint32_t> quad(4);
    for (size_t k = 0; k < 4; ++k) quad[k] = rest[(best + k) % m];
    faces.push_back(quad);
    // The two corners strictly inside the cut-off quad leave the polygon.
    const uint32_t drop1 = quad[1], drop2 = quad[2];
    std::erase_if(rest, [&](uint32_t c) { return c == drop1 || c == drop2; });
  }
  faces.push_back(rest);
  return faces;
}

Vec3 coons_point(std::span<const Side> sides, double u, double v, Sampling mode) {
  const Vec3 &p0 = sides[0].start(), &p1 = sides[1].start(), &p2 = sides[2].start(), &p3 = sides[3].start();
  const Vec3 c1 = sides[0].at(u, mode), d2 = sides[1].at(v, mode);
  const Vec3 c2 = sides[2].at(1.0 - u, mode), d1 = sides[3].at(1.0 - v, mode);
  const Vec3 ruled = d1 * (1.0 - u) + d2 * u + c1 * (1.0 - v) + c2 * v;
  const Vec3 bilinear = p0 * ((1.0 - u) * (1.0 - v)) + p1 * (u * (1.0 - v)) + p2 * (u * v) + p3 * ((1.0 - u) * v);
  return ruled - bilinear;
}

Eigen::Vector2d domain_corner(uint32_t n, uint32_t k) {
  const double angle = 2.0 * std::numbers::pi * double(k % n) / double(n);
  return {std::cos(angle), std::sin(angle)};
}

// P. Salvi, "A multi-sided generalization of the C0 Coons patch", arXiv:2002.11347 (2020): a weighted
// sum of n Coons-type ribbons, ribbon i interpolating the consecutive sides i-1, i, i+1, parameterized
// by Wachspress coordinates of the regular n-gon. Ribbon i in its local coordinates (s along side i,
// d away from it), with C_j the sides and P_i = C_i(0):
//   R_i(s, d) = (1-s) C_{i-1}(1-d) + s C_{i+1}(d) + C_i(s) - (1-s) P_i - s P_{i+1}
//   s_i = l_{i+1} / (l_i + l_{i+1}),  d_i = 1 - l_i - l_{i+1}    (l: Wachspress coordinates)
// blended by B_i = prod_{j not in {i-1,i,i+1}} d_j / sum_k prod_{j not in {k-1,k,k+1}} d_j, which is 1
// on side i and vanishes on every side ribbon i does not interpolate. For n = 4 the coordinates are
// bilinear and the sum is exactly the bilinearly blended Coons patch.
SidedPatch::SidedPatch(std::span<const Side> sides) : sides_(sides) {
  const auto n = static_cast<uint32_t>(sides.size());
  corners_.resize(n);
  for (uint32_t k = 0; k < n; ++k) corners_[k] = domain_corner(n, k);
  const std::vector<double> zero(n);
  area_ = lambda_ = d_ = s_ = blend_ = zero;
  prefix_.assign(n + 1, 0);
  suffix_.assign(n + 1, 0);
}

// out[i]: the product of values[j] over every j but the `run` cyclic indices from i - 1 on. Prefix and suffix
// products where that run does not wrap round the end, the product itself for the few i where it does: O(n),
// where the product per i was O(n^2) for the many-sided faces of a drawing that has just begun.
void SidedPatch::products_but_run(const std::vector<double>& values, uint32_t run, std::vector<double>& out) const {
  const auto n = static_cast<uint32_t>(values.size());
  prefix_[0] = 1;
  for (uint32_t k = 0; k < n; ++k) prefix_[k + 1] = prefix_[k] * values[k];
  suffix_[n] = 1;
  for (uint32_t k = n; k-- > 0;) suffix_[k] = values[k] * suffix_[k + 1];
  for (uint32_t i = 0; i < n; ++i) {
    if (i >= 1 && i - 1 + run <= n) {
      out[i] = prefix_[i - 1] * suffix_[i - 1 + run];
      continue;
    }
    const uint32_t first = (i + n - 1) % n;
    double product = 1;
    for (uint32_t j = (first + run) % n; j != first; j = (j + 1) % n) product *= values[j];
    out[i] = product;
  }
}

Vec3 SidedPatch::at(const Eigen::Vector2d& p) const {
  const auto n = static_cast<uint32_t>(sides_.size());
  auto next = [n](uint32_t i) { return i + 1 == n ? 0 : i + 1; };
  auto prev = [n](uint32_t i) { return i == 0 ? n - 1 : i - 1; };
  for (uint32_t j = 0; j < n; ++j) {
    const Eigen::Vector2d a = corners_[j] - p, b = corners_[next(j)] - p;
    area_[j] = 0.5 * (a.x() * b.y() - a.y() * b.x());
  }
  // Wachspress weights w_i = prod_{j not in {i-1, i}} A_j (the corner-area factor is equal for all i on
  // a regular polygon, so it cancels).
  products_but_run(area_, 2, lambda_);
  double lambda_sum = 0;
  for (double w : lambda_) lambda_sum += w;
  for (double& l : lambda_) l /= lambda_sum;
  for (uint32_t i = 0; i < n; ++i) {
    const double pair = lambda_[i] + lambda_[next(i)];
    d_[i] = 1.0 - pair;
    s_[i] = pair > 0 ? lambda_[next(i)] / pair : 0.0;
  }
  products_but_run(d_, 3, blend_);
  double blend_sum = 0;
  for (double b : blend_) blend_sum += b;
  Vec3 sum = Vec3::Zero();
  for (uint32_t i = 0; i < n; ++i) {
    if (blend_[i] == 0) continue;
    const double si = s_[i], di = d_[i];
    const Vec3 ribbon = sides_[prev(i)].at(1.0 - di, Sampling::Linear) * (1.0 - si) +
                        sides_[next(i)].at(di, Sampling::Linear) * si + sides_[i].at(si, Sampling::Linear) -
                        sides_[i].start() * (1.0 - si) - sides_[next(i)].start() * si;
    sum += ribbon * (blend_[i] / blend_sum);
  }
  return sum;
}

}  // namespace fire::reconstruct
