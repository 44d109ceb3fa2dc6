// Sampled two-sided surface distances and the reference limit surface.
#include <algorithm>
#include <cmath>
#include <string>

#include "systems/evaluate/evaluate.hpp"
#include "systems/catmull_clark/catmull_clark.hpp"

namespace fire::evaluate {

double OneSided::rms() const { return samples == 0 ? 0 : std::sqrt(sum_squared / static_cast<double>(samples)); }

OneSided distances_to(std::span<const Vec3> points, const TriangleBvh& target) {
  OneSided out;
  uint32_t hint = kNoTriangle;  // samples come in surface order, so the last hit is usually near the next
  for (const Vec3& p : points) {
    const TriangleBvh::Hit hit = target.closest(p, hint);
    hint = hit.triangle;
    out.sum_squared += hit.distance_squared;
    const double distance = std::sqrt(hit.distance_squared);
    if (distance > out.max) {
      out.max = distance;
      out.max_index = out.samples;
    }
    ++out.samples;
  }
  return out;
}

SurfaceDistance surface_distance(const TriangleMesh& a, const TriangleBvh& a_bvh, const TriangleMesh& b,
                                 const TriangleBvh& b_bvh, double spacing, double scale) {
  SurfaceDistance out;
  // One side's samples at a time: on a dense surface each set is tens of megabytes.
  {
    const std::vector<Vec3> samples = sample_triangles(a, spacing);
    out.a_to_b = distances_to(samples, b_bvh);
    if (!samples.empty()) out.hausdorff_at = samples[out.a_to_b.max_index];
  }
  {
    const std::vector<Vec3> samples = sample_triangles(b, spacing);
    out.b_to_a = distances_to(samples, a_bvh);
    if (out.b_to_a.max > out.a_to_b.max) out.hausdorff_at = samples[out.b_to_a.max_index];
  }
  const double samples = static_cast<double>(out.a_to_b.samples + out.b_to_a.samples);
  out.rms = samples == 0 ? 0 : std::sqrt((out.a_to_b.sum_squared + out.b_to_a.sum_squared) / samples) / scale;
  out.hausdorff = std::max(out.a_to_b.max, out.b_to_a.max) / scale;
  return out;
}

Result<TriangleMesh> reference_limit_surface(std::span<const Vec3> positions, std::span<const uint32_t> face_offsets,
                                             std::span<const uint32_t> face_vertices, int levels,
                                             std::span<const uint32_t> sharp_edges, std::span<const uint8_t> border_corners) {
  using R = Result<TriangleMesh>;
  // Measuring against the reference costs about half a kilobyte per quad (limit points, triangles, BVH,
  // samples): a dense surface given as the control mesh would exhaust memory, so it is refused up front.
  const uint64_t quads = levels > 0 ? catmull_clark::faces_at_level(face_vertices.size(), levels) : 0;
  if (quads > kMaxReferenceQuads)
    return R::failure(std::to_string(face_offsets.size() - 1) + " faces make " + std::to_string(quads) +
                      " quads at " + std::to_string(levels) + " Catmull-Clark levels, more than the " +
                      std::to_string(kMaxReferenceQuads) +
                      " a reference may have; give the coarse control mesh, not a dense surface");
  auto sub = catmull_clark::subdivide({{positions, face_offsets, face_vertices}, sharp_edges, border_corners}, levels);
  if (!sub) return R::failure(sub.error());
  TriangleMesh mesh;
  mesh.positions = std::move(sub->limit_positions);
  for (size_t v = 0; v < mesh.positions.size(); ++v)
    if (!is_finite(mesh.positions[v]))
      return R::failure("limit position " + std::to_string(v) + " is not finite");
  const std::vector<uint32_t>& q = sub->quads;
  mesh.triangles.reserve(q.size() / 4 * 6);
  for (size_t f = 0; f + 3 < q.size(); f += 4) {
    const Vec3 &p0 = mesh.positions[q[f]], &p1 = mesh.positions[q[f + 1]], &p2 = mesh.positions[q[f + 2]],
               &p3 = mesh.positions[q[f + 3]];
    // The shorter diagonal keeps the piecewise-linear reference closer to the curved limit surface.
    if ((p2 - p0).squaredNorm() <= (p3 - p1).squaredNorm())
      mesh.triangles.insert(mesh.triangles.end(), {q[f], q[f + 1], q[f + 2], q[f], q[f + 2], q[f + 3]});
    else
      mesh.triangles.insert(mesh.triangles.end(), {q[f], q[f + 1], q[f + 3], q[f + 1], q[f + 2], q[f + 3]});
  }
  return mesh;
}

}  // namespace fire::evaluate
