// Triangulation, closest points on triangles, surface sampling.
#include <Eigen/Geometry>  // cross products
#include <algorithm>
#include <cmath>
#include <string>

#include "systems/evaluate/evaluate.hpp"

namespace fire::evaluate {

Result<TriangleMesh> triangulate(std::span<const Vec3> positions, std::span<const uint32_t> face_offsets,
                                 std::span<const uint32_t> face_vertices) {
  using R = Result<TriangleMesh>;
  if (face_offsets.size() < 2) return R::failure("the surface has no faces");
  if (face_offsets.front() != 0 || face_offsets.back() != face_vertices.size())
    return R::failure("face offsets do not cover the face vertex list");
  TriangleMesh mesh;
  mesh.positions.assign(positions.begin(), positions.end());
  for (size_t v = 0; v < positions.size(); ++v)
    if (!is_finite(positions[v])) return R::failure("vertex " + std::to_string(v) + " has a non-finite coordinate");
  for (size_t f = 0; f + 1 < face_offsets.size(); ++f) {
    const uint32_t begin = face_offsets[f], end = face_offsets[f + 1];
    if (end < begin + 3 || end > face_vertices.size())
      return R::failure("face " + std::to_string(f) + " has fewer than 3 vertices");
    for (uint32_t c = begin; c < end; ++c)
      if (face_vertices[c] >= positions.size())
        return R::failure("face " + std::to_string(f) + " refers to vertex " + std::to_string(face_vertices[c]) +
                          " of " + std::to_string(positions.size()));
    for (uint32_t c = begin + 1; c + 1 < end; ++c)
      mesh.triangles.insert(mesh.triangles.end(), {face_vertices[begin], face_vertices[c], face_vertices[c + 1]});
  }
  return mesh;
}

Vec3 closest_point_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double length_squared = ab.squaredNorm();
  if (!(length_squared > 0)) return a;
  const double t = std::clamp((p - a).dot(ab) / length_squared, 0.0, 1.0);
  return a + t * ab;
}

namespace {

Vec3 closest_point_on_edges(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  Vec3 best = closest_point_on_segment(p, a, b);
  for (const Vec3& q : {closest_point_on_segment(p, b, c), closest_point_on_segment(p, c, a)})
    if ((q - p).squaredNorm() < (best - p).squaredNorm()) best = q;
  return best;
}

}  // namespace

// Ericson, Real-Time Collision Detection, 5.1.5: find the Voronoi region of p from dot products.
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a;
  // Zero-length edges make the region tests divide 0 by 0; a degenerate triangle is its edges.
  if (!(ab.cross(ac).squaredNorm() > 0)) return closest_point_on_edges(p, a, b, c);
  const Vec3 ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double sum = va + vb + vc;
  // Nearly collinear corners can round the face test to a non-positive denominator.
  if (!(sum > 0)) return closest_point_on_edges(p, a, b, c);
  return a + ab * (vb / sum) + ac * (vc / sum);
}

std::vector<Vec3> sample_triangles(const TriangleMesh& mesh, double spacing) {
  std::vector<Vec3> samples;
  std::vector<uint8_t> used(mesh.positions.size(), 0);
  for (uint32_t v : mesh.triangles) used[v] = 1;
  for (size_t v = 0; v < mesh.positions.size(); ++v)
    if (used[v]) samples.push_back(mesh.positions[v]);
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const Vec3& a = mesh.positions[mesh.triangles[3 * t]];
    const Vec3& b = mesh.positions[mesh.triangles[3 * t + 1]];
    const Vec3& c = mesh.positions[mesh.triangles[3 * t + 2]];
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    // The cap only keeps the cast defined; callers choose spacings far above longest / 1e5.
    const int n = static_cast<int>(std::clamp(std::ceil(longest / spacing), 1.0, 1e5));
    const Vec3 u = (b - a) / n, w = (c - a) / n;
    // Upright sub-triangle (i, j) has its centroid at (i + 1/3, j + 1/3), the inverted one at (i + 2/3, j + 2/3).
    for (int i = 0; i < n; ++i)
      for (int j = 0; i + j < n; ++j) {
        samples.push_back(a + (i + 1.0 / 3) * u + (j + 1.0 / 3) * w);
        if (i + j + 1 < n) samples.push_back(a + (i + 2.0 / 3) * u + (j + 2.0 / 3) * w);
      }
  }
  return samples;
}

}  // namespace fire::evaluate
