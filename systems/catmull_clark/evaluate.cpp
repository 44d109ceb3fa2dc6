// Evaluation: regular patches straight from their 4x4 base points where the refinement has them, and
// level by level elsewhere, each level's stencils applied straight from its index arrays, the weights
// following from the vertex rule and valence. Against explicit (source, weight) rows this reads no
// weights and gathers each parent point fewer times; perf/notes/subdivide.md has the measurements. Also the
// one-call subdivide().
#include <algorithm>
#include <cstring>
#include <string>

#include "systems/catmull_clark/catmull_clark.hpp"

namespace fire::catmull_clark {
namespace {

// A point as an x,y pair and z: two arithmetic instructions per operation instead of three (the GCC
// and Clang vector extension, SSE2 on x86-64; the same IEEE operations per coordinate as scalar code).
typedef double Pair __attribute__((vector_size(16)));
struct P3 {
  Pair xy;
  double z;
};
inline P3 load(const double* p) {
  P3 r;
  std::memcpy(&r.xy, p, sizeof(Pair));
  r.z = p[2];
  return r;
}
inline void store(double* p, const P3& v) {
  std::memcpy(p, &v.xy, sizeof(Pair));
  p[2] = v.z;
}
inline P3 operator+(const P3& a, const P3& b) { return {a.xy + b.xy, a.z + b.z}; }
inline P3 operator*(double s, const P3& a) { return {s * a.xy, s * a.z}; }
inline P3& operator+=(P3& a, const P3& b) { return a = a + b; }

// The edge point of edge ab: the midpoint on a crease, else the mean of the midpoint and the mean of the
// edge's two face points (`half_faces`).
inline P3 edge_point(const P3& a, const P3& b, const P3& half_faces, bool sharp) {
  return sharp ? 0.5 * (a + b) : 0.5 * (0.5 * (a + b) + half_faces);
}

// The vertex rules: a crease vertex from the sum of its two sharp neighbours; a smooth (or dart) vertex
// of valence n from its ring sum, (n-2)/n of the vertex plus 1/n^2 of the ring sum.
inline P3 crease_point(const P3& self, const P3& sharp_sum) { return 0.75 * self + 0.125 * sharp_sum; }
inline P3 smooth_point(const P3& self, const P3& ring_sum, uint32_t n) {
  const double inverse = n == 4 ? 0.25 : 1.0 / n;
  return (1.0 - 2.0 * inverse) * self + (inverse * inverse) * ring_sum;
}

// The vertex point of parent vertex v, whose out slot holds its ring sum (the sum of its neighbours
// plus the sum of its face points) when its rule is smooth or dart.
inline void finish_vertex(const Level& p, uint32_t v, const double* in, double* out) {
  const double* self = in + 3 * size_t{v};
  double* q = out + 3 * size_t{v};
  const uint32_t r0 = p.ring_offsets[v], r1 = p.ring_offsets[v + 1];
  switch (p.vertex_rules[v]) {
    case VertexRule::Corner:
      store(q, load(self));
      break;
    case VertexRule::Crease: {
      P3 sum{{0, 0}, 0};
      for (uint32_t r = r0; r < r1; ++r)
        if (p.edge_sharp[p.ring_edges[r]]) sum += load(in + 3 * size_t{p.ring_neighbors[r]});
      store(q, crease_point(load(self), sum));
      break;
    }
    default:
      store(q, smooth_point(load(self), load(q), r1 - r0));
      break;
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
    P3 sum{{0, 0}, 0};
    const uint32_t b = p.face_offsets[f], e = p.face_offsets[f + 1];
    for (uint32_t c = b; c < e; ++c) sum += load(in + 3 * size_t{fv[c]});
    store(face_points + 3 * size_t{f}, (1.0 / (e - b)) * sum);
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
  P3 run{{0, 0}, 0};
  for (uint32_t e = 0; e < E; ++e) {
    const uint32_t ia = ev[2 * e], ib = ev[2 * e + 1];
    const P3 a = load(in + 3 * size_t{ia});
    const P3 b = load(in + 3 * size_t{ib});
    double* q = edge_points + 3 * size_t{e};
    const uint32_t c1 = ec[2 * e + 1];
    if (c1 == kNone) {  // a boundary edge: its ends are creases or corners, which use no ring sum
      store(q, 0.5 * (a + b));
      continue;
    }
    const P3 half_faces = 0.5 * (load(face_points + 3 * size_t{p.corner_face(ec[2 * e])}) +
                                 load(face_points + 3 * size_t{p.corner_face(c1)}));
    if (ia != run_vertex) {
      double* sum_run = out + 3 * size_t{run_vertex};
      store(sum_run, load(sum_run) + run);
      run_vertex = ia;
      run = P3{{0, 0}, 0};
    }
    double* sum_b = out + 3 * size_t{ib};
    store(q, edge_point(a, b, half_faces, sharp[e]));
    run += b + half_faces;
    store(sum_b, load(sum_b) + (a + half_faces));
  }
  double* sum_run = out + 3 * size_t{run_vertex};
  store(sum_run, load(sum_run) + run);

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
  auto point = [&x](uint32_t id) { return load(x.in + 3 * size_t{id}); };
  const P3 centre = point(x.centre0 + g);
  P3 centre_sum{{0, 0}, 0};
  // Quad j is (corner j, side j, centre, side j-1); walk them keeping the previous face point, and
  // quad 0's for the last inner edge.
  P3 side = point(x.side0 + side_edges[0]);
  const P3 face_first = 0.25 * ((point(corner_ids[0]) + side) + (centre + point(x.side0 + side_edges[n - 1])));
  store(x.face_points + 3 * size_t{first}, face_first);
  P3 face_prev = face_first;
  for (uint32_t j = 0; j < n; ++j) {
    const uint32_t jn = j + 1 == n ? 0 : j + 1;
    const P3 side_next = point(x.side0 + side_edges[jn]);
    P3 face_next = face_first;
    if (jn != 0) {
      face_next = 0.25 * ((point(corner_ids[jn]) + side_next) + (centre + side));
      store(x.face_points + 3 * size_t{first + jn}, face_next);
    }
    // Inner edge j joins the centre to side j, between quads j and j+1; it is never sharp.
    double* side_sum = x.out + 3 * size_t{x.side0 + side_edges[j]};
    const P3 half_faces = 0.5 * (face_prev + face_next);
    store(x.edge_points + 3 * size_t{first + j}, 0.5 * (0.5 * (centre + side) + half_faces));
    store(side_sum, load(side_sum) + (centre + half_faces));
    centre_sum += side + half_faces;
    face_prev = face_next;
    side = side_next;
  }
  // The centre: smooth, valence n.
  store(x.out + 3 * size_t{x.centre0 + g}, smooth_point(centre, centre_sum, n));
}

// The points of level l+1 from level l (>= 1), going by the faces of level l-1 ("blocks"): a block of
// n corners is, at level l, n quads around one centre, with a point on each of its n sides and its n
// corners. Those 2n+1 points are gathered once and give the block's n face points, its n inner edge
// points and its centre's vertex point: about half the gathers of going edge by edge. The edge points
// on block sides follow, and ring sums of sides and corners are accumulated as in refine_any_level; a
// side point's ring is complete after its side, so its vertex point is finished there.
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

  // Block sides: the two halves of grand edge e join its point to the edge's ends (and are sharp if e is).
  const uint32_t* gev = grand.edge_vertices.data();
  const uint32_t* ec = p.edge_corners.data();
  const uint8_t* grand_sharp = grand.edge_sharp.data();
  for (uint32_t e = 0; e < GE; ++e) {
    const uint32_t im = side0 + e;
    const P3 m = load(in + 3 * size_t{im});
    const bool sharp = grand_sharp[e];
    P3 m_sum{{0, 0}, 0};
    for (uint32_t half = 0; half < 2; ++half) {
      const uint32_t edge = GC + 2 * e + half, ix = gev[2 * e + half];
      const P3 x = load(in + 3 * size_t{ix});
      double* q = edge_points + 3 * size_t{edge};
      const uint32_t c1 = ec[2 * edge + 1];
      if (c1 == kNone) {  // a boundary edge: its ends are creases or corners, which use no ring sum
        store(q, 0.5 * (m + x));
        continue;
      }
      const P3 f0 = load(face_points + 3 * size_t{ec[2 * edge] >> 2});
      const P3 half_faces = 0.5 * (f0 + load(face_points + 3 * size_t{c1 >> 2}));
      double* x_sum = out + 3 * size_t{ix};
      store(q, edge_point(m, x, half_faces, sharp));
      m_sum += x + half_faces;
      store(x_sum, load(x_sum) + (m + half_faces));
    }
    // The side point's ring is complete (its blocks added theirs): valence 4, or a crease along e.
    double* m_out = out + 3 * size_t{im};
    if (sharp)
      store(m_out, crease_point(m, load(in + 3 * size_t{gev[2 * e]}) + load(in + 3 * size_t{gev[2 * e + 1]})));
    else
      store(m_out, smooth_point(m, load(m_out) + m_sum, 4));
  }

  // Corners from their ring sums (centres and side points are done).
  for (uint32_t v = 0; v < GV; ++v) finish_vertex(p, v, in, out);
}

size_t child_vertex_count(const Level& parent) {
  return size_t{parent.vertex_count} + parent.face_count() + parent.edge_count();
}

// Level l+1's points of `levels` from level l's (out holds child_vertex_count(levels[l]) points).
void refine_level(std::span<const Level> levels, size_t l, const double* in, double* out) {
  if (l == 0)
    refine_any_level(levels[0], in, out);
  else
    refine_by_blocks(levels[l - 1], levels[l], in, out);
}

// Regular patches (RegularPatches in subdivide.hpp). A last-level point of a patch is a tensor product
// of 1D weights over its 4x4 base points: per patch, each of the 4 rows of base points is first reduced
// to its points along the patch (4 taps each), and every grid point is then 4 taps across those (the
// x,y pair of one point and the z of two neighbours go through the arithmetic together). The points go
// out in the last level's order, which is this one: one sequential stream. Then the rest mesh, level
// by level, and its points after them.
inline Pair load_pair(const double* p) {
  Pair r;
  std::memcpy(&r, p, sizeof(Pair));
  return r;
}

void evaluate_by_patches(const Refinement& refinement, std::span<const Vec3> base_points, std::vector<Vec3>& last,
                         std::vector<Vec3>& scratch) {
  const RegularPatches& plan = refinement.patches;
  const uint32_t side = plan.side, s = side - 1;
  size_t rest_points = 0;
  for (size_t l = 1; l < plan.rest.size(); ++l) rest_points = std::max<size_t>(rest_points, plan.rest[l].vertex_count);
  scratch.resize(plan.rest_controls.size() + 2 * rest_points);
  last.resize(refinement.last().vertex_count);
  double* q = last.data()->data();
  const double* base = base_points.data()->data();
  const double* w0 = plan.weights.data();
  const double *w1 = w0 + side, *w2 = w1 + side, *w3 = w2 + side;
  Pair row_xy[4][kMaxPatchSide];
  double row_z[4][kMaxPatchSide + 1] = {};  // one spare: the last point's z goes in a pair too

  for (uint32_t p = 0; p < plan.patch_count(); ++p) {
    const uint32_t* controls = plan.controls.data() + 16 * size_t{p};
    for (uint32_t a = 0; a < 4; ++a) {
      const P3 c0 = load(base + 3 * size_t{controls[4 * a]}), c1 = load(base + 3 * size_t{controls[4 * a + 1]});
      const P3 c2 = load(base + 3 * size_t{controls[4 * a + 2]}), c3 = load(base + 3 * size_t{controls[4 * a + 3]});
      for (uint32_t j = 0; j < side; ++j)
        row_xy[a][j] = ((w0[j] * c0.xy + w1[j] * c1.xy) + w2[j] * c2.xy) + w3[j] * c3.xy;
      for (uint32_t j = 0; j < side; ++j) row_z[a][j] = ((w0[j] * c0.z + w1[j] * c1.z) + w2[j] * c2.z) + w3[j] * c3.z;
    }
    const uint32_t owned = plan.owned[p];
    for (uint32_t i = 0; i < side; ++i) {
      // Which of this row's points the patch writes: its first, inner and last ones.
      const bool edge_row = i == 0 || i == s;
      const bool first = owned >> (i == 0 ? 4 : i == s ? 7 : 3) & 1;
      const bool inner = !edge_row || (owned >> (i == 0 ? 0 : 2) & 1);
      const bool final = owned >> (i == 0 ? 5 : i == s ? 6 : 1) & 1;
      const double a0 = w0[i], a1 = w1[i], a2 = w2[i], a3 = w3[i];
      auto xy = [&](uint32_t j) {
        return ((a0 * row_xy[0][j] + a1 * row_xy[1][j]) + a2 * row_xy[2][j]) + a3 * row_xy[3][j];
      };
      for (uint32_t j = 0; j < side; j += 2) {
        const Pair z = ((a0 * load_pair(row_z[0] + j) + a1 * load_pair(row_z[1] + j)) + a2 * load_pair(row_z[2] + j)) +
                       a3 * load_pair(row_z[3] + j);
        if (j == 0 ? first : j == s ? final : inner) {
          store(q, {xy(j), z[0]});
          q += 3;
        }
        if (j + 1 < side && (j + 1 == s ? final : inner)) {
          store(q, {xy(j + 1), z[1]});
          q += 3;
        }
      }
    }
  }

  if (plan.rest.empty()) return;
  double* rest_base = scratch.data()->data();
  double* rest_a = rest_base + 3 * plan.rest_controls.size();
  double* rest_b = rest_a + 3 * rest_points;
  for (size_t i = 0; i < plan.rest_controls.size(); ++i)
    store(rest_base + 3 * i, load(base + 3 * size_t{plan.rest_controls[i]}));
  const double* src = rest_base;
  double* dst = rest_a;
  for (size_t l = 0; l + 1 < plan.rest.size(); ++l) {
    refine_level(plan.rest, l, src, dst);
    src = dst;
    dst = dst == rest_a ? rest_b : rest_a;
  }
  for (uint32_t v : plan.rest_sources) {
    store(q, load(src + 3 * size_t{v}));
    q += 3;
  }
}

// Level l+1's points from level l's.
void refine_points(const Refinement& refinement, size_t l, std::span<const Vec3> in, std::vector<Vec3>& out) {
  out.resize(child_vertex_count(refinement.levels[l]));
  refine_level(refinement.levels, l, in.data()->data(), out.data()->data());
}

}  // namespace

void evaluate(const Refinement& refinement, std::span<const Vec3> base_points, std::vector<Vec3>& last_level_points,
              std::vector<Vec3>& scratch) {
  const size_t steps = refinement.levels.size() - 1;
  if (steps == 0) {
    last_level_points.assign(base_points.begin(), base_points.end());
    return;
  }
  if (refinement.patches.patch_count() > 0) {
    evaluate_by_patches(refinement, base_points, last_level_points, scratch);
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
  // The last level came out in OpenSubdiv's numbering.
  if (refinement.last_from_osd.empty()) return;
  std::vector<Vec3>& last = level_points.back();
  std::vector<Vec3> renumbered(last.size());
  for (size_t v = 0; v < last.size(); ++v) renumbered[refinement.last_from_osd[v]] = last[v];
  last = std::move(renumbered);
}

Result<SubdividedMesh> subdivide(const SubdivisionInput& input, int levels) {
  if (levels < 1)
    return Result<SubdividedMesh>::failure("subdivide needs at least 1 level, got " + std::to_string(levels));
  for (size_t v = 0; v < input.mesh.positions.size(); ++v)
    if (!is_finite(input.mesh.positions[v]))
      return Result<SubdividedMesh>::failure("vertex " + std::to_string(v) + " has a non-finite coordinate");
  const BaseTopology base{static_cast<uint32_t>(input.mesh.positions.size()), input.mesh.face_offsets,
                          input.mesh.face_vertices, input.sharp_edges, input.border_corners};
  Result<Refinement> refinement = build_refinement(base, {levels, true});
  if (!refinement) return Result<SubdividedMesh>::failure(refinement.error());
  Result<LimitStencils> limit = build_limit_stencils(*refinement);
  if (!limit) return Result<SubdividedMesh>::failure(limit.error());

  SubdividedMesh mesh;
  std::vector<Vec3> scratch;
  evaluate(*refinement, input.mesh.positions, mesh.positions, scratch);
  mesh.quads = refinement->last().face_vertices;
  evaluate_limit(*limit, mesh.positions, mesh.limit_positions, mesh.limit_normals);
  return mesh;
}

}  // namespace fire::catmull_clark
