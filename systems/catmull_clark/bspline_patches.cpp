// The limit surface as bicubic patches (see bspline_patches.hpp): regular quads exactly, the rest
// subdivided locally, level by level, with the faces each depends on, and fitted at the end.
#include "systems/catmull_clark/bspline_patches.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>

namespace fire::catmull_clark {
namespace {

using Grid = std::array<Vec3, 16>;  // control point (i, j) at 4 j + i, i along u
struct Cell {
  int u, v;
};

uint32_t face_size(const Level& level, uint32_t f) { return level.face_offsets[f + 1] - level.face_offsets[f]; }

// The uniform B-spline control points of quad f of `level` when f is one bicubic B-spline patch: f's
// corners at (1,1), (2,1), (2,2), (1,2), the rest from each corner's faces on f's side of the sharp edges
// there (all four faces of a smooth corner; the two of a crease corner; f alone at a corner vertex), and the
// rows or columns that lie across a sharp edge as phantoms 2 B - I. False for any other f.
bool regular_grid(const Level& level, std::span<const Vec3> points, uint32_t f, Grid& grid) {
  if (face_size(level, f) != 4) return false;
  std::array<uint32_t, 16> ids;
  ids.fill(kNone);
  auto put = [&ids](Cell at, uint32_t id) {
    uint32_t& slot = ids[size_t(at.v) * 4 + size_t(at.u)];
    if (slot != kNone && slot != id) return false;
    slot = id;
    return true;
  };
  const uint32_t b = level.face_offsets[f];
  static constexpr std::array<Cell, 4> kAt{{{1, 1}, {2, 1}, {2, 2}, {1, 2}}};
  for (uint32_t j = 0; j < 4; ++j) {
    const uint32_t c = b + j, v = level.face_vertices[c];
    const Cell at = kAt[j], next = kAt[(j + 1) & 3], prev = kAt[(j + 3) & 3];
    // The directions of ring edges 0, 1, 2, 3 counted from the one to f's next corner (the ring's order).
    const Cell d0{next.u - at.u, next.v - at.v}, d1{prev.u - at.u, prev.v - at.v};
    const std::array<Cell, 4> dirs{{d0, d1, {-d0.u, -d0.v}, {-d1.u, -d1.v}}};
    auto dir = [&dirs](int t) { return dirs[size_t(((t % 4) + 4) % 4)]; };
    const uint32_t r0 = level.ring_offsets[v], n = level.ring_offsets[v + 1] - r0;
    uint32_t s = 0;
    while (s < n && level.ring_corners[r0 + s] != c) ++s;
    if (s == n) return false;
    auto slot = [&](int t) { return r0 + uint32_t(((int(s) + t) % int(n) + int(n)) % int(n)); };
    auto sharp = [&](int t) { return level.edge_sharp[level.ring_edges[slot(t)]] != 0; };
    // f's sector at v: ring faces lo .. hi counted from f's, and the ring edges lo .. last between them.
    int lo = 0, hi = 0, last = 0;
    switch (level.vertex_rules[v]) {
      case VertexRule::Smooth:
        if (n != 4) return false;
        hi = 3, last = 3;
        break;
      case VertexRule::Crease:
        while (hi < int(n) && !sharp(hi + 1)) ++hi;
        while (lo > -int(n) && !sharp(lo)) --lo;
        if (hi - lo != 1) return false;
        last = hi + 1;
        break;
      case VertexRule::Corner:
        if (!sharp(0) || !sharp(1)) return false;
        last = 1;
        break;
      case VertexRule::Dart:
        return false;
    }
    if (!put(at, v)) return false;
    for (int t = lo; t <= last; ++t)
      if (!put({at.u + dir(t).u, at.v + dir(t).v}, level.ring_neighbors[slot(t)])) return false;
    for (int t = lo; t <= hi; ++t) {
      const uint32_t corner = level.ring_corners[slot(t)];
      if (corner == kNone) return false;
      const uint32_t g = level.corner_face(corner), gb = level.face_offsets[g];
      if (face_size(level, g) != 4) return false;
      const Cell d = {dir(t).u + dir(t + 1).u, dir(t).v + dir(t + 1).v};
      if (!put({at.u + d.u, at.v + d.v}, level.face_vertices[gb + ((corner - gb + 2) & 3)])) return false;
    }
  }
  auto missing = [&ids](int u, int v) { return ids[size_t(v) * 4 + size_t(u)] == kNone; };
  const bool row0 = missing(1, 0) && missing(2, 0), row3 = missing(1, 3) && missing(2, 3);
  const bool col0 = missing(0, 1) && missing(0, 2), col3 = missing(3, 1) && missing(3, 2);
  auto phantom_row = [&](int v) { return (v == 0 && row0) || (v == 3 && row3); };
  auto at = [&grid](int u, int v) -> Vec3& { return grid[size_t(v) * 4 + size_t(u)]; };
  for (int v = 0; v < 4; ++v)
    for (int u = 0; u < 4; ++u) {
      const bool phantom = phantom_row(v) || (u == 0 && col0) || (u == 3 && col3);
      if (phantom != missing(u, v)) return false;
      if (!phantom) at(u, v) = points[ids[size_t(v) * 4 + size_t(u)]];
    }
  for (int v = 0; v < 4; ++v) {
    if (phantom_row(v)) continue;
    if (col0) at(0, v) = 2.0 * at(1, v) - at(2, v);
    if (col3) at(3, v) = 2.0 * at(2, v) - at(1, v);
  }
  for (int u = 0; u < 4; ++u) {
    if (row0) at(u, 0) = 2.0 * at(u, 1) - at(u, 2);
    if (row3) at(u, 3) = 2.0 * at(u, 2) - at(u, 1);
  }
  return true;
}

// One span of a uniform cubic B-spline in Bezier form.
std::array<Vec3, 4> span_to_bezier(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& p3) {
  return {(p0 + 4.0 * p1 + p2) / 6.0, (2.0 * p1 + p2) / 3.0, (p1 + 2.0 * p2) / 3.0, (p1 + 4.0 * p2 + p3) / 6.0};
}

Grid grid_to_bezier(const Grid& g) {
  Grid rows, out;
  for (size_t j = 0; j < 4; ++j) {
    const auto b = span_to_bezier(g[4 * j], g[4 * j + 1], g[4 * j + 2], g[4 * j + 3]);
    for (size_t i = 0; i < 4; ++i) rows[4 * j + i] = b[i];
  }
  for (size_t i = 0; i < 4; ++i) {
    const auto b = span_to_bezier(rows[i], rows[4 + i], rows[8 + i], rows[12 + i]);
    for (size_t j = 0; j < 4; ++j) out[4 * j + i] = b[j];
  }
  return out;
}

std::array<double, 4> bernstein(double t) {
  const double s = 1.0 - t;
  return {s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t};
}
std::array<double, 4> bernstein_derivative(double t) {
  const double s = 1.0 - t;
  return {-3.0 * s * s, 3.0 * s * s - 6.0 * t * s, 6.0 * t * s - 3.0 * t * t, 3.0 * t * t};
}

Vec3 bezier_point(const Grid& g, double u, double v, Vec3* du = nullptr, Vec3* dv = nullptr) {
  const auto bu = bernstein(u), bv = bernstein(v);
  Vec3 p = Vec3::Zero();
  for (size_t j = 0; j < 4; ++j)
    for (size_t i = 0; i < 4; ++i) p += bu[i] * bv[j] * g[4 * j + i];
  if (du && dv) {
    const auto du_b = bernstein_derivative(u), dv_b = bernstein_derivative(v);
    du->setZero();
    dv->setZero();
    for (size_t j = 0; j < 4; ++j)
      for (size_t i = 0; i < 4; ++i) {
        *du += du_b[i] * bv[j] * g[4 * j + i];
        *dv += bu[i] * dv_b[j] * g[4 * j + i];
      }
  }
  return p;
}

Vec3 curve_point(const std::array<Vec3, 4>& c, double t, Vec3* dt = nullptr) {
  const auto b = bernstein(t);
  if (dt) {
    const auto d = bernstein_derivative(t);
    *dt = d[0] * c[0] + d[1] * c[1] + d[2] * c[2] + d[3] * c[3];
  }
  return b[0] * c[0] + b[1] * c[1] + b[2] * c[2] + b[3] * c[3];
}

// Gauss-Newton steps towards the parameter of the point of the curve (or patch) nearest to `x`, kept in [0, 1].
constexpr int kProjectionSteps = 8;
constexpr double kProjectionStop = 1e-12;  // a parameter step this small moves the point by nothing that counts
double project_to_curve(const std::array<Vec3, 4>& c, const Vec3& x, double t) {
  for (int step = 0; step < kProjectionSteps; ++step) {
    Vec3 d;
    const Vec3 p = curve_point(c, t, &d);
    const double dd = d.squaredNorm();
    if (dd == 0) break;
    const double next = std::clamp(t + d.dot(x - p) / dd, 0.0, 1.0);
    if (std::abs(next - t) < kProjectionStop) return next;
    t = next;
  }
  return t;
}
void project_to_patch(const Grid& g, const Vec3& x, double& u, double& v) {
  for (int step = 0; step < kProjectionSteps; ++step) {
    Vec3 du, dv;
    const Vec3 r = x - bezier_point(g, u, v, &du, &dv);
    const double a = du.dot(du), b = du.dot(dv), c = dv.dot(dv), det = a * c - b * b;
    if (!(det > 0)) break;
    const double ru = du.dot(r), rv = dv.dot(r);
    const double u1 = std::clamp(u + (c * ru - b * rv) / det, 0.0, 1.0);
    const double v1 = std::clamp(v + (a * rv - b * ru) / det, 0.0, 1.0);
    const bool settled = std::abs(u1 - u) + std::abs(v1 - v) < kProjectionStop;
    u = u1, v = v1;
    if (settled) return;
  }
}

// Rounds of least squares, each followed by moving every sample's parameter to its nearest point: a limit
// face at an extraordinary vertex is parametrized unlike a polynomial (its sub-faces shrink by the
// subdominant eigenvalue, not by half), so only the distance to the surface, not to the same (u, v), can
// become small.
constexpr int kFitRounds = 4;
// A fit is kept when its samples lie within this fraction of the tolerance: between them the distance can be
// larger (by 3 % with 17 x 17 samples, 40 % with 9 x 9, on the pawn's pole and the cube in the tests).
constexpr double kSampleMargin = 0.8;

// The cubic through x.front() and x.back() nearest to the samples x (at parameters i / (n - 1) to begin with).
std::array<Vec3, 4> fit_curve(std::span<const Vec3> x) {
  const size_t n = x.size();
  std::vector<double> t(n);
  for (size_t i = 0; i < n; ++i) t[i] = double(i) / double(n - 1);
  std::array<Vec3, 4> c{x.front(), x.front(), x.back(), x.back()};
  for (int round = 0; round < kFitRounds; ++round) {
    Eigen::Matrix2d a = Eigen::Matrix2d::Zero();
    Eigen::Matrix<double, 2, 3> r = Eigen::Matrix<double, 2, 3>::Zero();
    for (size_t i = 1; i + 1 < n; ++i) {
      const auto b = bernstein(t[i]);
      const Vec3 rest = x[i] - b[0] * c[0] - b[3] * c[3];
      a(0, 0) += b[1] * b[1], a(0, 1) += b[1] * b[2], a(1, 1) += b[2] * b[2];
      r.row(0) += b[1] * rest.transpose();
      r.row(1) += b[2] * rest.transpose();
    }
    a(1, 0) = a(0, 1);
    const Eigen::Matrix<double, 2, 3> m = a.ldlt().solve(r);
    c[1] = m.row(0).transpose();
    c[2] = m.row(1).transpose();
    for (size_t i = 1; i + 1 < n; ++i) t[i] = project_to_curve(c, x[i], t[i]);
  }
  return c;
}

// The mesh being converted at one level: the faces still to convert (targets) with every face sharing a
// vertex with them, which is all their limit surface depends on.
struct Work {
  std::vector<Vec3> points;
  std::vector<uint32_t> face_offsets{0}, face_vertices, sharp;
  std::vector<uint8_t> corners;
  std::vector<uint32_t> targets;             // faces of this mesh
  std::vector<std::vector<uint32_t>> paths;  // per target: its path from its base face (BsplineConversion)
  std::vector<uint32_t> base_faces;          // per target
  BaseTopology topology() const {
    return {static_cast<uint32_t>(points.size()), face_offsets, face_vertices, sharp, corners};
  }
};

void add_patch(BsplineConversion& out, const Grid& bezier, bool fitted, uint32_t base_face,
               const std::vector<uint32_t>& path) {
  out.patches.controls.insert(out.patches.controls.end(), bezier.begin(), bezier.end());
  out.patches.fitted.push_back(fitted);
  out.patch_face.push_back(base_face);
  out.path_corners.insert(out.path_corners.end(), path.begin(), path.end());
  out.path_offsets.push_back(static_cast<uint32_t>(out.path_corners.size()));
  ++(fitted ? out.fitted : out.exact);
}

// The faces `targets` of `level` (with adjacency) with every face sharing a vertex with them, and, where
// those leave a vertex's faces in several fans, all its faces (build_refinement takes fans only): `points`,
// `corners` (border corner flags per vertex of `level`, or none) and the `sharp` vertex pairs of `level`
// carried over. The targets keep their paths and base faces.
Work gather(const Level& level, std::span<const Vec3> points, std::span<const uint8_t> corners,
            std::span<const uint32_t> sharp, std::span<const uint32_t> targets, std::vector<std::vector<uint32_t>> paths,
            std::vector<uint32_t> base_faces) {
  std::vector<uint8_t> in(level.face_count(), 0);
  auto add_vertex_faces = [&](uint32_t v) {
    for (uint32_t r = level.ring_offsets[v]; r < level.ring_offsets[v + 1]; ++r)
      if (level.ring_corners[r] != kNone) in[level.corner_face(level.ring_corners[r])] = 1;
  };
  for (uint32_t f : targets)
    for (uint32_t c = level.face_offsets[f]; c < level.face_offsets[f + 1]; ++c) add_vertex_faces(level.face_vertices[c]);
  for (bool changed = true; changed;) {
    changed = false;
    for (uint32_t v = 0; v < level.vertex_count; ++v) {
      const uint32_t r0 = level.ring_offsets[v], r1 = level.ring_offsets[v + 1];
      uint32_t included = 0, starts = 0;
      for (uint32_t r = r0; r < r1; ++r) {
        const uint32_t corner = level.ring_corners[r];
        const bool here = corner != kNone && in[level.corner_face(corner)];
        const uint32_t before = level.ring_corners[r == r0 ? r1 - 1 : r - 1];
        included += here;
        starts += here && !(before != kNone && in[level.corner_face(before)]);
      }
      if (included == 0 || starts == 1 || (starts == 0 && included == r1 - r0)) continue;
      add_vertex_faces(v);
      changed = true;
    }
  }
  Work work;
  std::vector<uint32_t> face_map(level.face_count(), kNone), vertex_map(level.vertex_count, kNone);
  for (uint32_t f = 0; f < level.face_count(); ++f) {
    if (!in[f]) continue;
    face_map[f] = static_cast<uint32_t>(work.face_offsets.size() - 1);
    for (uint32_t c = level.face_offsets[f]; c < level.face_offsets[f + 1]; ++c) {
      const uint32_t v = level.face_vertices[c];
      if (vertex_map[v] == kNone) {
        vertex_map[v] = static_cast<uint32_t>(work.points.size());
        work.points.push_back(points[v]);
        if (!corners.empty()) work.corners.push_back(corners[v]);
      }
      work.face_vertices.push_back(vertex_map[v]);
    }
    work.face_offsets.push_back(static_cast<uint32_t>(work.face_vertices.size()));
  }
  for (size_t i = 0; i + 1 < sharp.size(); i += 2) {
    const uint32_t a = sharp[i], b = sharp[i + 1];
    for (uint32_t r = level.ring_offsets[a]; r < level.ring_offsets[a + 1]; ++r) {
      if (level.ring_neighbors[r] != b) continue;
      const uint32_t e = level.ring_edges[r], f0 = level.edge_face(e, 0), f1 = level.edge_face(e, 1);
      if (in[f0] || (f1 != kNone && in[f1])) work.sharp.insert(work.sharp.end(), {vertex_map[a], vertex_map[b]});
      break;
    }
  }
  for (uint32_t f : targets) work.targets.push_back(face_map[f]);
  work.paths = std::move(paths);
  work.base_faces = std::move(base_faces);
  return work;
}

// The irregular targets of `work` (indices into its targets) with what their limit surface depends on.
Work irregular_work(const Work& work, const Level& level, std::span<const uint32_t> irregular) {
  std::vector<uint32_t> faces, base_faces;
  std::vector<std::vector<uint32_t>> paths;
  for (uint32_t t : irregular) {
    faces.push_back(work.targets[t]);
    paths.push_back(work.paths[t]);
    base_faces.push_back(work.base_faces[t]);
  }
  return gather(level, work.points, work.corners, work.sharp, faces, std::move(paths), std::move(base_faces));
}

// The next level's work: the children of the irregular targets of `work`, from its refinement by one level.
Work next_work(const Work& work, const Refinement& refined, std::span<const Vec3> level1,
               std::span<const uint32_t> irregular) {
  const Level& parent = refined.levels[0];
  const Level& child = refined.levels[1];
  // A vertex keeps its flag; the new ones, edge and face points, are no corners.
  std::vector<uint8_t> corners;
  if (!work.corners.empty()) {
    corners.assign(child.vertex_count, 0);
    std::copy(work.corners.begin(), work.corners.end(), corners.begin());
  }
  // A marked sharp edge gives its two halves, each from the edge's point to one of its ends.
  std::vector<uint32_t> sharp;
  for (size_t i = 0; i + 1 < work.sharp.size(); i += 2) {
    const uint32_t a = work.sharp[i], b = work.sharp[i + 1];
    for (uint32_t r = parent.ring_offsets[a]; r < parent.ring_offsets[a + 1]; ++r) {
      if (parent.ring_neighbors[r] != b) continue;
      const uint32_t point = parent.vertex_count + parent.face_count() + parent.ring_edges[r];
      sharp.insert(sharp.end(), {point, a, point, b});
      break;
    }
  }
  std::vector<uint32_t> children, base_faces;
  std::vector<std::vector<uint32_t>> paths;
  for (uint32_t t : irregular) {
    const uint32_t f = work.targets[t];
    for (uint32_t j = 0; j < face_size(parent, f); ++j) {
      children.push_back(parent.face_offsets[f] + j);
      paths.push_back(work.paths[t]);
      paths.back().push_back(j);
      base_faces.push_back(work.base_faces[t]);
    }
  }
  return gather(child, level1, corners, sharp, children, std::move(paths), std::move(base_faces));
}

// The corners of the child quad of corner j of a quad whose corners are `at`, in subdivide.hpp's numbering:
// OpenSubdiv rotates a quad's children so that the child of corner j starts at it, then the next edge's
// point, the centre and the previous edge's point.
std::array<Cell, 4> child_cells(const std::array<Cell, 4>& at, uint32_t j) {
  const Cell corner = at[j], next = at[(j + 1) & 3], opposite = at[(j + 2) & 3], prev = at[(j + 3) & 3];
  const std::array<Cell, 4> roles{{corner,
                                   {(corner.u + next.u) / 2, (corner.v + next.v) / 2},
                                   {(corner.u + opposite.u) / 2, (corner.v + opposite.v) / 2},
                                   {(corner.u + prev.u) / 2, (corner.v + prev.v) / 2}}};
  std::array<Cell, 4> child;
  for (uint32_t role = 0; role < 4; ++role) child[(j + role) & 3] = roles[role];
  return child;
}

// The limit surface of each target quad of `work` at (2^levels + 1)^2 points, row by row, u from its
// first corner to its second: the targets refined `levels` times, one level at a time with only the faces
// their descendants depend on, and the limit positions of their descendants' corners.
Result<std::vector<Vec3>> limit_samples(Work work, uint32_t levels) {
  using R = Result<std::vector<Vec3>>;
  const int s = 1 << levels, side = s + 1;
  const size_t grid = size_t(side) * size_t(side), count = work.targets.size();
  std::vector<std::array<Cell, 4>> cells(count, {{{0, 0}, {s, 0}, {s, s}, {0, s}}});
  std::vector<uint32_t> owner(count);
  for (uint32_t t = 0; t < owner.size(); ++t) owner[t] = t;
  std::vector<uint32_t> all;
  std::vector<Vec3> points, scratch;
  for (uint32_t step = 0; step < levels; ++step) {
    Result<Refinement> refined = build_refinement(work.topology(), {1, true});
    if (!refined) return R::failure(refined.error());
    evaluate(*refined, work.points, points, scratch);
    all.resize(work.targets.size());
    for (uint32_t t = 0; t < all.size(); ++t) all[t] = t;
    // next_work lists the children target by target, corner by corner.
    std::vector<std::array<Cell, 4>> child_cells_of;
    std::vector<uint32_t> child_owner;
    for (uint32_t t : all)
      for (uint32_t j = 0; j < 4; ++j) {
        child_cells_of.push_back(child_cells(cells[t], j));
        child_owner.push_back(owner[t]);
      }
    work = next_work(work, *refined, points, all);
    cells = std::move(child_cells_of);
    owner = std::move(child_owner);
  }
  Result<Refinement> refined = build_refinement(work.topology(), {0, true});
  if (!refined) return R::failure(refined.error());
  Result<LimitStencils> stencils = build_limit_stencils(*refined);
  if (!stencils) return R::failure(stencils.error());
  std::vector<Vec3> limit, normals;
  evaluate_limit(*stencils, work.points, limit, normals);
  std::vector<Vec3> samples(grid * count);
  for (uint32_t t = 0; t < work.targets.size(); ++t) {
    const uint32_t b = work.face_offsets[work.targets[t]];
    for (uint32_t k = 0; k < 4; ++k)
      samples[grid * owner[t] + size_t(cells[t][k].v) * size_t(side) + size_t(cells[t][k].u)] =
          limit[work.face_vertices[b + k]];
  }
  return samples;
}

struct Fits {
  std::vector<Grid> patches;    // per target
  std::vector<double> errors;   // per target: the largest distance of a limit sample to its patch
  std::vector<uint32_t> group;  // per target: the first target of the faces it is joined to by sides
};

// Fits a patch to the limit surface of each target of `work` (quads).
Result<Fits> fit_faces(const Work& work, uint32_t levels) {
  Result<Refinement> topology = build_refinement(work.topology(), {0, true});
  if (!topology) return Result<Fits>::failure(topology.error());
  Result<std::vector<Vec3>> limit = limit_samples(work, levels);
  if (!limit) return Result<Fits>::failure(limit.error());
  const Level& base = topology->levels[0];
  const int s = 1 << levels, side = s + 1;
  const size_t grid = size_t(side) * size_t(side);
  auto cell = [side](int u, int v) { return size_t(v) * size_t(side) + size_t(u); };
  // Side k of a face runs from its corner k to corner k+1: its samples and its control points.
  auto side_cell = [&](uint32_t k, int i) {
    const std::array<Cell, 4> from{{{i, 0}, {s, i}, {s - i, s}, {0, s - i}}};
    return cell(from[k].u, from[k].v);
  };
  auto side_control = [](uint32_t k, int i) {
    const std::array<Cell, 4> from{{{i, 0}, {3, i}, {3 - i, 3}, {0, 3 - i}}};
    return size_t(from[k].v) * 4 + size_t(from[k].u);
  };
  // The fitted curve of each side, from its first vertex to its second, shared by both its faces.
  std::vector<uint32_t> curve_of_edge(base.edge_count(), kNone);
  std::vector<std::array<Vec3, 4>> curves;
  std::vector<uint32_t> edge_target;  // per curve: the first target that has it
  Fits fits;
  std::vector<uint32_t> parent(work.targets.size());
  for (uint32_t t = 0; t < parent.size(); ++t) parent[t] = t;
  auto root = [&parent](uint32_t t) {
    while (parent[t] != t) t = parent[t] = parent[parent[t]];
    return t;
  };
  auto join = [&](uint32_t a, uint32_t b) { parent[std::max(root(a), root(b))] = std::min(root(a), root(b)); };
  std::vector<Vec3> along(static_cast<size_t>(side));
  std::vector<double> us(grid), vs(grid);
  for (uint32_t t = 0; t < work.targets.size(); ++t) {
    const std::span<const Vec3> samples = std::span<const Vec3>(*limit).subspan(grid * t, grid);
    const uint32_t f = work.targets[t], b = base.face_offsets[f];
    Grid g;
    for (uint32_t k = 0; k < 4; ++k) {
      const uint32_t e = base.face_edges[b + k];
      const bool forward = base.edge_vertices[2 * e] == base.face_vertices[b + k];
      if (curve_of_edge[e] == kNone) {
        for (int i = 0; i <= s; ++i) along[size_t(forward ? i : s - i)] = samples[side_cell(k, i)];
        curve_of_edge[e] = static_cast<uint32_t>(curves.size());
        curves.push_back(fit_curve(along));
        edge_target.push_back(t);
      } else {
        join(t, edge_target[curve_of_edge[e]]);
      }
      const std::array<Vec3, 4>& c = curves[curve_of_edge[e]];
      for (int i = 0; i < 4; ++i) g[side_control(k, i)] = c[size_t(forward ? i : 3 - i)];
    }
    for (int v = 0; v <= s; ++v)
      for (int u = 0; u <= s; ++u) us[cell(u, v)] = double(u) / s, vs[cell(u, v)] = double(v) / s;
    // The inner control points (1,1), (2,1), (1,2), (2,2), by least squares over the inner samples.
    static constexpr std::array<size_t, 4> kInner{5, 6, 9, 10};
    for (int round = 0; round < kFitRounds; ++round) {
      Eigen::Matrix4d a = Eigen::Matrix4d::Zero();
      Eigen::Matrix<double, 4, 3> r = Eigen::Matrix<double, 4, 3>::Zero();
      for (int v = 1; v < s; ++v)
        for (int u = 1; u < s; ++u) {
          const size_t at = cell(u, v);
          const auto bu = bernstein(us[at]), bv = bernstein(vs[at]);
          Vec3 rest = samples[at];
          std::array<double, 4> w;
          for (size_t j = 0; j < 4; ++j)
            for (size_t i = 0; i < 4; ++i) {
              const size_t control = 4 * j + i;
              const auto inner = std::find(kInner.begin(), kInner.end(), control);
              if (inner == kInner.end()) rest -= bu[i] * bv[j] * g[control];
              else w[size_t(inner - kInner.begin())] = bu[i] * bv[j];
            }
          for (size_t x = 0; x < 4; ++x) {
            for (size_t y = 0; y < 4; ++y) a(x, y) += w[x] * w[y];
            r.row(x) += w[x] * rest.transpose();
          }
        }
      const Eigen::Matrix<double, 4, 3> m = a.ldlt().solve(r);
      for (size_t x = 0; x < 4; ++x) g[kInner[x]] = m.row(x).transpose();
      for (size_t at = 0; at < grid; ++at) project_to_patch(g, samples[at], us[at], vs[at]);
    }
    double error = 0;
    for (size_t at = 0; at < grid; ++at) error = std::max(error, (bezier_point(g, us[at], vs[at]) - samples[at]).norm());
    fits.patches.push_back(g);
    fits.errors.push_back(error);
  }
  for (uint32_t t = 0; t < parent.size(); ++t) fits.group.push_back(root(t));
  return fits;
}

}  // namespace

Vec3 evaluate_patch(const BsplinePatches& patches, size_t p, double u, double v) {
  Grid g;
  std::copy_n(patches.controls.begin() + std::ptrdiff_t(16 * p), 16, g.begin());
  return bezier_point(g, u, v);
}

double distance_to_patch(const BsplinePatches& patches, size_t p, const Vec3& x, double u, double v) {
  Grid g;
  std::copy_n(patches.controls.begin() + std::ptrdiff_t(16 * p), 16, g.begin());
  project_to_patch(g, x, u, v);
  return (bezier_point(g, u, v) - x).norm();
}

Result<BsplineConversion> bspline_patches(const Cage& cage, const BsplineOptions& options) {
  const BaseTopology topology{static_cast<uint32_t>(cage.mesh.positions.size()), cage.mesh.face_offsets,
                              cage.mesh.face_vertices, cage.sharp_edges, cage.border_corners};
  return bspline_patches(topology, cage.mesh.positions, options);
}

Result<BsplineConversion> bspline_patches(const BaseTopology& topology, std::span<const Vec3> points,
                                          const BsplineOptions& options) {
  using R = Result<BsplineConversion>;
  if (!(options.tolerance > 0) || !std::isfinite(options.tolerance))
    return R::failure("B-spline tolerance must be a positive number, not " + std::to_string(options.tolerance));
  if (options.max_depth < 1 || options.max_depth > uint32_t(kMaxRefinementLevels))
    return R::failure("B-spline depth must be 1 to " + std::to_string(kMaxRefinementLevels) + ", not " +
                      std::to_string(options.max_depth));
  // Two levels at least: a side's two inner control points need more than one inner sample.
  if (options.sample_levels < 2 || options.sample_levels > uint32_t(kMaxPatchLevels))
    return R::failure("B-spline sample levels must be 2 to " + std::to_string(kMaxPatchLevels) + ", not " +
                      std::to_string(options.sample_levels));
  if (points.size() != topology.vertex_count)
    return R::failure("the cage has " + std::to_string(topology.vertex_count) + " vertices but " +
                      std::to_string(points.size()) + " points");
  for (size_t v = 0; v < points.size(); ++v)
    if (!is_finite(points[v])) return R::failure("cage vertex " + std::to_string(v) + " is not finite");

  Work work;
  work.points.assign(points.begin(), points.end());
  work.face_offsets.assign(topology.face_offsets.begin(), topology.face_offsets.end());
  work.face_vertices.assign(topology.face_vertices.begin(), topology.face_vertices.end());
  work.sharp.assign(topology.sharp_edges.begin(), topology.sharp_edges.end());
  work.corners.assign(topology.border_corners.begin(), topology.border_corners.end());
  const uint32_t face_count = static_cast<uint32_t>(work.face_offsets.size() - 1);
  for (uint32_t f = 0; f < face_count; ++f) {
    work.targets.push_back(f);
    work.base_faces.push_back(f);
  }
  work.paths.resize(face_count);

  BsplineConversion out;
  std::vector<Vec3> level1, scratch;
  for (uint32_t level = 0;; ++level) {
    Result<Refinement> refined = build_refinement(work.topology(), {1, true});
    if (!refined) return R::failure(refined.error());
    evaluate(*refined, work.points, level1, scratch);
    if (level == 0) {
      Result<LimitStencils> stencils = build_limit_stencils(*refined);
      if (!stencils) return R::failure(stencils.error());
      std::vector<Vec3> limit, normals;
      evaluate_limit(*stencils, level1, limit, normals);
      out.diagonal = bounding_box_diagonal(limit);
    }
    const Level& base = refined->levels[0];
    std::vector<uint32_t> irregular;
    Grid grid;
    for (uint32_t t = 0; t < work.targets.size(); ++t) {
      if (regular_grid(base, work.points, work.targets[t], grid))
        add_patch(out, grid_to_bezier(grid), false, work.base_faces[t], work.paths[t]);
      else
        irregular.push_back(t);
    }
    if (irregular.empty()) break;
    // From level 1 on (every face a quad), each group of irregular faces joined by sides keeps its fit when
    // the fit is close enough; the others go one level further.
    std::vector<uint32_t> further;
    if (level == 0) {
      further = irregular;
    } else {
      Result<Fits> fits = fit_faces(irregular_work(work, base, irregular), options.sample_levels);
      if (!fits) return R::failure(fits.error());
      std::vector<double> group_error(irregular.size(), 0);
      for (size_t i = 0; i < irregular.size(); ++i)
        group_error[fits->group[i]] = std::max(group_error[fits->group[i]], fits->errors[i]);
      for (size_t i = 0; i < irregular.size(); ++i) {
        const double error = group_error[fits->group[i]];
        if (error > kSampleMargin * options.tolerance * out.diagonal && level < options.max_depth) {
          further.push_back(irregular[i]);
          continue;
        }
        add_patch(out, fits->patches[i], true, work.base_faces[irregular[i]], work.paths[irregular[i]]);
        out.fit_level = level;
        if (out.diagonal > 0) out.max_fit_error = std::max(out.max_fit_error, error / out.diagonal);
      }
    }
    if (further.empty()) break;
    work = next_work(work, *refined, level1, further);
  }
  return out;
}

}  // namespace fire::catmull_clark
