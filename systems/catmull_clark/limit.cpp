// Limit position and tangent masks of Catmull-Clark vertices (the masks OpenSubdiv's Sdc::Scheme<CATMARK>
// uses: Halstead et al. for smooth vertices, Biermann et al. across creases), for all-quad levels.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "systems/catmull_clark/catmull_clark.hpp"

namespace fire::catmull_clark {
namespace {

// Row layout for a vertex with n ring edges and m ring faces: [vertex, edge neighbours 0..n-1, the
// vertices opposite it in faces 0..m-1].
struct Row {
  double* position;
  double* tangent1;
  double* tangent2;
  uint32_t n, m;
  // Weight slots of the layout.
  uint32_t edge(uint32_t i) const { return 1 + i; }
  uint32_t face(uint32_t i) const { return 1 + n + i; }
};

void corner_masks(Row& row) {
  row.position[0] = 1.0;
  row.tangent1[0] = -1.0;
  row.tangent1[row.edge(0)] = 1.0;
  row.tangent2[0] = -1.0;
  row.tangent2[row.edge(1)] = 1.0;
}

// A smooth vertex's masks depend on its valence alone: computed once per valence a build meets (most of
// a level's vertices are regular), then copied.
struct SmoothMasks {
  double center = 0, edge = 0, face = 0;
  std::vector<double> tangent_edge, tangent_face;  // tangent1's weights; tangent2 is them one slot on
};

SmoothMasks smooth_masks_of(uint32_t n) {
  SmoothMasks masks;
  const double dn = n;
  const double face_weight = 1.0 / (dn * (dn + 5.0));
  masks.center = dn / (dn + 5.0);
  masks.edge = 4.0 * face_weight;
  masks.face = face_weight;
  const double theta = 2.0 * std::numbers::pi / dn;
  const double cos_theta = std::cos(theta);
  const double lambda =
      5.0 / 16.0 + (cos_theta + std::cos(0.5 * theta) * std::sqrt(2.0 * (9.0 + cos_theta))) / 16.0;
  const double face_scale = 1.0 / (4.0 * lambda - 1.0);
  for (uint32_t i = 0; i < n; ++i) {
    masks.tangent_edge.push_back(4.0 * std::cos(i * theta));
    masks.tangent_face.push_back(face_scale * (std::cos(i * theta) + std::cos((i + 1) * theta)));
  }
  return masks;
}

void smooth_masks(Row& row, std::vector<SmoothMasks>& by_valence) {
  const uint32_t n = row.n;
  if (by_valence.size() <= n) by_valence.resize(n + 1);
  if (by_valence[n].tangent_edge.empty()) by_valence[n] = smooth_masks_of(n);
  const SmoothMasks& masks = by_valence[n];
  row.position[0] = masks.center;
  for (uint32_t i = 0; i < n; ++i) {
    row.position[row.edge(i)] = masks.edge;
    row.position[row.face(i)] = masks.face;
  }
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t next = i + 1 == n ? 0 : i + 1;
    row.tangent1[row.edge(i)] = masks.tangent_edge[i];
    row.tangent1[row.face(i)] = masks.tangent_face[i];
    row.tangent2[row.edge(next)] = masks.tangent_edge[i];
    row.tangent2[row.face(next)] = masks.tangent_face[i];
  }
}

// c0 < c1: ring slots of the two sharp edges. The cross tangent is taken over the faces from c0 to c1.
void crease_masks(Row& row, uint32_t c0, uint32_t c1) {
  row.position[0] = 2.0 / 3.0;
  row.position[row.edge(c0)] = 1.0 / 6.0;
  row.position[row.edge(c1)] = 1.0 / 6.0;
  row.tangent1[row.edge(c0)] = 0.5;
  row.tangent1[row.edge(c1)] = -0.5;

  double* t = row.tangent2;
  const uint32_t interior = c1 - c0 - 1;
  if (interior == 0) {
    t[0] = -6.0;
    t[row.edge(c0)] = 3.0;
    t[row.edge(c1)] = 3.0;
  } else if (interior == 1) {
    t[0] = -4.0 / 6.0;
    t[row.edge(c0)] = -1.0 / 6.0;
    t[row.edge(c0 + 1)] = 4.0 / 6.0;
    t[row.edge(c1)] = -1.0 / 6.0;
    t[row.face(c0)] = 1.0 / 6.0;
    t[row.face(c0 + 1)] = 1.0 / 6.0;
  } else {
    const double k = interior + 1;
    const double theta = std::numbers::pi / k;
    const double cos_theta = std::cos(theta), sin_theta = std::sin(theta);
    const double denom = 1.0 / (k * (3.0 + cos_theta));
    const double r = (cos_theta + 1.0) / sin_theta;
    t[0] = 4.0 * r * (cos_theta - 1.0) * denom;
    t[row.edge(c0)] = -r * (1.0 + 2.0 * cos_theta) * denom;
    t[row.edge(c1)] = -r * (1.0 + 2.0 * cos_theta) * denom;
    t[row.face(c0)] = sin_theta * denom;
    for (uint32_t i = 1; i <= interior; ++i) {
      t[row.edge(c0 + i)] = 4.0 * std::sin(i * theta) * denom;
      t[row.face(c0 + i)] = (std::sin(i * theta) + std::sin((i + 1) * theta)) * denom;
    }
  }
}

}  // namespace

Result<LimitStencils> build_limit_stencils(const Refinement& refinement) {
  LimitStencils limit;
  if (Status s = build_limit_stencils(refinement, limit); !s) return Result<LimitStencils>::failure(s.error);
  return limit;
}

Status build_limit_stencils(const Refinement& refinement, LimitStencils& limit) {
  const Level& level = refinement.last();
  if (!level.has_adjacency())
    return Status::failure("limit masks need the last level's adjacency (build with last_level_adjacency = true)");
  for (uint32_t f = 0; f < level.face_count(); ++f)
    if (level.face_offsets[f + 1] - level.face_offsets[f] != 4)
      return Status::failure("limit masks need quads, but face " + std::to_string(f) + " of the last level has " +
                             std::to_string(level.face_offsets[f + 1] - level.face_offsets[f]) +
                             " vertices (refine at least once)");

  const uint32_t vertex_count = level.vertex_count;
  limit.offsets.resize(vertex_count + 1);
  uint32_t total = 0;
  for (uint32_t v = 0; v < vertex_count; ++v) {
    const uint32_t r0 = level.ring_offsets[v], r1 = level.ring_offsets[v + 1];
    uint32_t faces = 0;
    for (uint32_t r = r0; r < r1; ++r) faces += level.ring_corners[r] != kNone;
    limit.offsets[v] = total;
    total += 1 + (r1 - r0) + faces;
  }
  limit.offsets[vertex_count] = total;
  // resize, not assign: the previous build's pages are reused as they are, and each row is zeroed
  // below while it is in cache (fresh pages cost a page fault each).
  limit.sources.resize(total);
  limit.position.resize(total);
  limit.tangent1.resize(total);
  limit.tangent2.resize(total);

  std::vector<SmoothMasks> smooth_by_valence;
  for (uint32_t v = 0; v < vertex_count; ++v) {
    const uint32_t o = limit.offsets[v];
    const uint32_t r0 = level.ring_offsets[v], n = level.ring_offsets[v + 1] - r0;
    Row row{limit.position.data() + o, limit.tangent1.data() + o, limit.tangent2.data() + o, n,
            limit.offsets[v + 1] - o - 1 - n};
    const uint32_t size = limit.offsets[v + 1] - o;
    std::fill_n(row.position, size, 0.0);
    std::fill_n(row.tangent1, size, 0.0);
    std::fill_n(row.tangent2, size, 0.0);
    uint32_t* src = limit.sources.data() + o;
    src[0] = v;
    if (n == 0) {  // a vertex without faces stays where it is
      row.position[0] = 1.0;
      continue;
    }
    uint32_t sharp[2] = {kNone, kNone};
    uint32_t sharp_found = 0;
    for (uint32_t i = 0; i < n; ++i) {
      src[row.edge(i)] = level.ring_neighbors[r0 + i];
      if (level.edge_sharp[level.ring_edges[r0 + i]] && sharp_found < 2) sharp[sharp_found++] = i;
    }
    for (uint32_t i = 0; i < row.m; ++i) {
      const uint32_t corner = level.ring_corners[r0 + i];
      const uint32_t b = corner & ~3u;
      src[row.face(i)] = level.face_vertices[b + ((corner + 2) & 3u)];
    }
    switch (level.vertex_rules[v]) {
      case VertexRule::Smooth:
      case VertexRule::Dart:
        if (n == 2)
          corner_masks(row);
        else
          smooth_masks(row, smooth_by_valence);
        break;
      case VertexRule::Crease: crease_masks(row, sharp[0], sharp[1]); break;
      case VertexRule::Corner: corner_masks(row); break;
    }
  }
  return Status::success();
}

void evaluate_limit(const LimitStencils& limit, std::span<const Vec3> last_level_points, std::vector<Vec3>& positions,
                    std::vector<Vec3>& normals) {
  const size_t vertex_count = limit.offsets.size() - 1;
  positions.resize(vertex_count);
  normals.resize(vertex_count);
  for (size_t v = 0; v < vertex_count; ++v) {
    Vec3 p = Vec3::Zero(), t1 = Vec3::Zero(), t2 = Vec3::Zero();
    for (uint32_t k = limit.offsets[v]; k < limit.offsets[v + 1]; ++k) {
      const Vec3& q = last_level_points[limit.sources[k]];
      p += limit.position[k] * q;
      t1 += limit.tangent1[k] * q;
      t2 += limit.tangent2[k] * q;
    }
    positions[v] = p;
    const Vec3 n = t1.cross(t2);
    const double length = n.norm();
    normals[v] = length > 0.0 ? Vec3(n / length) : Vec3::Zero();
  }
}

}  // namespace fire::catmull_clark
