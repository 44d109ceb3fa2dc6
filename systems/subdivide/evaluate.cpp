// Level-by-level evaluation: each level's stencils applied straight from its index arrays, the
// weights following from the vertex rule and valence. Against explicit (source, weight) rows this
// reads no weights and gathers each parent point fewer times; perf/RESULTS.md has the measurements.
// Also the one-call subdivide().
#include <algorithm>
#include <string>

#include "systems/subdivide/subdivide.hpp"

namespace fire::subdivide {
namespace {

inline void add3(double* acc, const double* p) {
  acc[0] += p[0];
  acc[1] += p[1];
  acc[2] += p[2];
}

// The vertex point of parent vertex v, whose out slot holds its ring sum (the sum of its neighbours
// plus the sum of its face points) when its rule is smooth or dart.
inline void finish_vertex(const Level& p, uint32_t v, const double* in, double* out) {
  const double* self = in + 3 * size_t{v};
  double* q = out + 3 * size_t{v};
  const uint32_t r0 = p.ring_offsets[v], r1 = p.ring_offsets[v + 1];
  switch (p.vertex_rules[v]) {
    case VertexRule::corner:
      for (int k = 0; k < 3; ++k) q[k] = self[k];
      break;
    case VertexRule::crease: {
      // 3/4 of the vertex, 1/8 of each of its two sharp neighbours.
      double sum[3] = {0, 0, 0};
      for (uint32_t r = r0; r < r1; ++r)
        if (p.edge_sharp[p.ring_edges[r]]) add3(sum, in + 3 * size_t{p.ring_neighbors[r]});
      for (int k = 0; k < 3; ++k) q[k] = 0.75 * self[k] + 0.125 * sum[k];
      break;
    }
    default: {
      // (n-2)/n of the vertex plus 1/n^2 of the ring sum.
      const uint32_t n = r1 - r0;
      const double inverse = n == 4 ? 0.25 : 1.0 / n;
      const double self_weight = 1.0 - 2.0 * inverse, ring_weight = inverse * inverse;
      for (int k = 0; k < 3; ++k) q[k] = self_weight * self[k] + ring_weight * q[k];
      break;
    }
  }
}

// Child points of one level: vertex points [0, V), face points [V, V+F), edge points [V+F, V+F+E).
// Any level, faces of any size; used for the base level (later levels go by blocks, below).
void refine_any_level(const Level& p, const double* in, double* out) {
  const uint32_t V = p.vertex_count, F = p.face_count(), E = p.edge_count();
  double* face_points = out + 3 * size_t{V};
  double* edge_points = face_points + 3 * size_t{F};
  const uint32_t* fv = p.face_vertices.data();

  for (uint32_t f = 0; f < F; ++f) {
    double* q = face_points + 3 * size_t{f};
    double sum[3] = {0, 0, 0};
    const uint32_t b = p.face_offsets[f], e = p.face_offsets[f + 1];
    for (uint32_t c = b; c < e; ++c) add3(sum, in + 3 * size_t{fv[c]});
    const double scale = 1.0 / (e - b);
    for (int k = 0; k < 3; ++k) q[k] = scale * sum[k];
  }

  // Edge points. Each edge also adds its far end and the mean of its two face points to the ring sum
  // of both its ends (kept in the vertex-point slots): over a smooth vertex's edges that makes the sum
  // of its neighbours plus the sum of its face points, with no further gathers. Consecutive edges
  // mostly share their first end (OpenSubdiv numbers the edges of a face point, and the two halves of
  // an edge, together), so that end's sum runs in registers until it changes.
  std::fill(out, out + 3 * size_t{V}, 0.0);
  const uint32_t* ev = p.edge_vertices.data();
  const uint32_t* ec = p.edge_corners.data();
  const uint8_t* sharp = p.edge_sharp.data();
  uint32_t run_vertex = 0;
  double run[3] = {0, 0, 0};
  for (uint32_t e = 0; e < E; ++e) {
    const uint32_t ia = ev[2 * e], ib = ev[2 * e + 1];
    const double* a = in + 3 * size_t{ia};
    const double* b = in + 3 * size_t{ib};
    double* q = edge_points + 3 * size_t{e};
    const uint32_t c1 = ec[2 * e + 1];
    if (c1 == kNone) {  // a boundary edge: its ends are creases or corners, which use no ring sum
      for (int k = 0; k < 3; ++k) q[k] = 0.5 * (a[k] + b[k]);
      continue;
    }
    const uint32_t f0 = p.corner_face(ec[2 * e]);
    const uint32_t f1 = p.corner_face(c1);
    const double* c = face_points + 3 * size_t{f0};
    const double* d = face_points + 3 * size_t{f1};
    if (ia != run_vertex) {
      add3(out + 3 * size_t{run_vertex}, run);
      run_vertex = ia;
      run[0] = run[1] = run[2] = 0.0;
    }
    double* sum_b = out + 3 * size_t{ib};
    const bool smooth = !sharp[e];
    for (int k = 0; k < 3; ++k) {
      const double half_faces = 0.5 * (c[k] + d[k]);
      q[k] = smooth ? 0.5 * (0.5 * (a[k] + b[k]) + half_faces) : 0.5 * (a[k] + b[k]);
      run[k] += b[k] + half_faces;
      sum_b[k] += a[k] + half_faces;
    }
  }
  add3(out + 3 * size_t{run_vertex}, run);

  for (uint32_t v = 0; v < V; ++v) finish_vertex(p, v, in, out);
}

// What every block of one level shares (see refine_by_blocks).
struct Blocks {
  const double* in;
  double* out;
  double* face_points;
  double* edge_points;
  uint32_t centre0;  // level-l index of the centre of grand face g: centre0 + g
  uint32_t side0;    // level-l index of the point on grand edge e: side0 + e
};

// Block g with n corners; corner_ids and side_edges are the grand face's vertices and edges, first its
// first corner index (which numbers its quads and inner edges). kN = 4 fixes n at compile time (every
// block after the first level); kN = 0 takes n at run time.
template <uint32_t kN>
void refine_block(const Blocks& x, uint32_t g, uint32_t n, const uint32_t* corner_ids, const uint32_t* side_edges,
                  uint32_t first) {
  if constexpr (kN != 0) n = kN;
  auto point = [&x](uint32_t id) { return x.in + 3 * size_t{id}; };
  const double* centre = point(x.centre0 + g);
  double centre_sum[3] = {0, 0, 0};
  // Quad j is (corner j, side j, centre, side j-1); walk them keeping the previous face point, and
  // quad 0's for the last inner edge.
  const double* side = point(x.side0 + side_edges[0]);
  double face_first[3], face_prev[3];
  {
    const double* corner = point(corner_ids[0]);
    const double* side_prev = point(x.side0 + side_edges[n - 1]);
    for (int k = 0; k < 3; ++k) {
      face_first[k] = face_prev[k] = 0.25 * ((corner[k] + side[k]) + (centre[k] + side_prev[k]));
      x.face_points[3 * size_t{first} + k] = face_first[k];
    }
  }
  for (uint32_t j = 0; j < n; ++j) {
    const uint32_t jn = j + 1 == n ? 0 : j + 1;
    const double* side_next = point(x.side0 + side_edges[jn]);
    const double* corner_next = point(corner_ids[jn]);
    double face_next[3];
    for (int k = 0; k < 3; ++k) {
      face_next[k] = jn == 0 ? face_first[k] : 0.25 * ((corner_next[k] + side_next[k]) + (centre[k] + side[k]));
      if (jn != 0) x.face_points[3 * size_t{first + jn} + k] = face_next[k];
    }
    // Inner edge j joins the centre to side j, between quads j and j+1; it is never sharp.
    double* q = x.edge_points + 3 * size_t{first + j};
    double* side_sum = x.out + 3 * size_t{x.side0 + side_edges[j]};
    for (int k = 0; k < 3; ++k) {
      const double half_faces = 0.5 * (face_prev[k] + face_next[k]);
      q[k] = 0.5 * (0.5 * (centre[k] + side[k]) + half_faces);
      side_sum[k] += centre[k] + half_faces;
      centre_sum[k] += side[k] + half_faces;
      face_prev[k] = face_next[k];
    }
    side = side_next;
  }
  // The centre: smooth, valence n.
  const double inverse = n == 4 ? 0.25 : 1.0 / n;
  const double self_weight = 1.0 - 2.0 * inverse, ring_weight = inverse * inverse;
  double* q = x.out + 3 * size_t{x.centre0 + g};
  for (int k = 0; k < 3; ++k) q[k] = self_weight * centre[k] + ring_weight * centre_sum[k];
}

// The points of level l+1 from level l (>= 1), going by the faces of level l-1 ("blocks"): a block of
// n corners is, at level l, n quads around one centre, with a point on each of its n sides and its n
// corners. Those 2n+1 points are gathered once and give the block's n face points, its n inner edge
// points and its centre's vertex point: about half the gathers of going edge by edge. The edge points
// on block sides follow, and ring sums of sides and corners are accumulated as in refine_any_level.
void refine_by_blocks(const Level& grand, const Level& p, const double* in, double* out) {
  const uint32_t GV = grand.vertex_count, GF = grand.face_count(), GC = grand.corner_count();
  const uint32_t GE = grand.edge_count();
  const uint32_t V = p.vertex_count, F = p.face_count();
  double* face_points = out + 3 * size_t{V};
  double* edge_points = face_points + 3 * size_t{F};
  const uint32_t* gfv = grand.face_vertices.data();
  const uint32_t* gfe = grand.face_edges.data();
  const uint32_t side0 = GV + GF;

  // Ring sums start at zero for corners and side points; centres are written whole by their block.
  std::fill(out, out + 3 * size_t{GV}, 0.0);
  std::fill(out + 3 * size_t{side0}, out + 3 * size_t{V}, 0.0);

  const Blocks blocks{in, out, face_points, edge_points, GV, side0};
  for (uint32_t g = 0; g < GF; ++g) {
    const uint32_t b = grand.face_offsets[g], n = grand.face_offsets[g + 1] - b;
    if (n == 4)
      refine_block<4>(blocks, g, 4, gfv + b, gfe + b, b);
    else
      refine_block<0>(blocks, g, n, gfv + b, gfe + b, b);
  }

  // Block sides: the two halves of grand edge e join its point to the edge's ends.
  const uint32_t* gev = grand.edge_vertices.data();
  const uint32_t* ec = p.edge_corners.data();
  const uint8_t* sharp = p.edge_sharp.data();
  for (uint32_t e = 0; e < GE; ++e) {
    const uint32_t im = side0 + e;
    const double* m = in + 3 * size_t{im};
    double m_sum[3] = {0, 0, 0};
    for (uint32_t half = 0; half < 2; ++half) {
      const uint32_t edge = GC + 2 * e + half, ix = gev[2 * e + half];
      const double* x = in + 3 * size_t{ix};
      double* q = edge_points + 3 * size_t{edge};
      const uint32_t c1 = ec[2 * edge + 1];
      if (c1 == kNone) {  // a boundary edge: its ends are creases or corners, which use no ring sum
        for (int k = 0; k < 3; ++k) q[k] = 0.5 * (m[k] + x[k]);
        continue;
      }
      const double* f0 = face_points + 3 * size_t{ec[2 * edge] >> 2};
      const double* f1 = face_points + 3 * size_t{c1 >> 2};
      double* x_sum = out + 3 * size_t{ix};
      const bool smooth = !sharp[edge];
      for (int k = 0; k < 3; ++k) {
        const double half_faces = 0.5 * (f0[k] + f1[k]);
        q[k] = smooth ? 0.5 * (0.5 * (m[k] + x[k]) + half_faces) : 0.5 * (m[k] + x[k]);
        m_sum[k] += x[k] + half_faces;
        x_sum[k] += m[k] + half_faces;
      }
    }
    add3(out + 3 * size_t{im}, m_sum);
  }

  // Corners and side points from their ring sums (centres are done).
  for (uint32_t v = 0; v < GV; ++v) finish_vertex(p, v, in, out);
  for (uint32_t v = side0; v < V; ++v) finish_vertex(p, v, in, out);
}

// Level l+1's points from level l's.
void refine_points(const Refinement& refinement, size_t l, std::span<const Vec3> in, std::vector<Vec3>& out) {
  const Level& parent = refinement.levels[l];
  out.resize(size_t{parent.vertex_count} + parent.face_count() + parent.edge_count());
  if (l == 0)
    refine_any_level(parent, in.data()->data(), out.data()->data());
  else
    refine_by_blocks(refinement.levels[l - 1], parent, in.data()->data(), out.data()->data());
}

}  // namespace

void evaluate(const Refinement& refinement, std::span<const Vec3> base_points, std::vector<Vec3>& last_level_points,
              std::vector<Vec3>& scratch) {
  const size_t steps = refinement.levels.size() - 1;
  if (steps == 0) {
    last_level_points.assign(base_points.begin(), base_points.end());
    return;
  }
  // Alternate between the two buffers so that the last step writes last_level_points.
  std::span<const Vec3> src = base_points;
  for (size_t l = 0; l < steps; ++l) {
    std::vector<Vec3>& dst = (steps - 1 - l) % 2 == 0 ? last_level_points : scratch;
    refine_points(refinement, l, src, dst);
    src = dst;
  }
}

void evaluate_all_levels(const Refinement& refinement, std::span<const Vec3> base_points,
                         std::vector<std::vector<Vec3>>& level_points) {
  level_points.resize(refinement.levels.size());
  level_points[0].assign(base_points.begin(), base_points.end());
  for (size_t l = 0; l + 1 < refinement.levels.size(); ++l)
    refine_points(refinement, l, level_points[l], level_points[l + 1]);
}

Result<SubdividedMesh> subdivide(const SubdivisionInput& input, int levels) {
  if (levels < 1)
    return Result<SubdividedMesh>::failure("subdivide needs at least 1 level, got " + std::to_string(levels));
  for (size_t v = 0; v < input.positions.size(); ++v)
    if (!is_finite(input.positions[v]))
      return Result<SubdividedMesh>::failure("vertex " + std::to_string(v) + " has a non-finite coordinate");
  const BaseTopology base{static_cast<uint32_t>(input.positions.size()), input.face_offsets, input.face_vertices,
                          input.sharp_edges};
  Result<Refinement> refinement = build_refinement(base, {levels, true});
  if (!refinement) return Result<SubdividedMesh>::failure(refinement.error());
  Result<LimitStencils> limit = build_limit_stencils(*refinement);
  if (!limit) return Result<SubdividedMesh>::failure(limit.error());

  SubdividedMesh mesh;
  std::vector<Vec3> scratch;
  evaluate(*refinement, input.positions, mesh.positions, scratch);
  mesh.quads = refinement->last().face_vertices;
  evaluate_limit(*limit, mesh.positions, mesh.limit_positions, mesh.limit_normals);
  return mesh;
}

}  // namespace fire::subdivide
