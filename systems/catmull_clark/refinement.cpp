// Topology refinement. Component numbering follows OpenSubdiv's Vtr (see
// subdivide.hpp) so that the oracle test can compare every level index by index.
#include <algorithm>
#include <string>

#include "systems/catmull_clark/patches.hpp"

namespace fire::catmull_clark {
namespace {

// Upper bound on the faces of the last level: beyond it the arrays would not fit a shared machine.
constexpr uint64_t kMaxFaces = uint64_t{1} << 26;

// Appends rather than `"(" + std::to_string(a)`, which trips g++ 12's -Wrestrict false positive.
std::string edge_name(uint32_t a, uint32_t b) {
  std::string name(1, '(');
  name.append(std::to_string(a)).append(", ").append(std::to_string(b)).push_back(')');
  return name;
}

Status validate_base(const BaseTopology& base) {
  const auto& offsets = base.face_offsets;
  const auto& verts = base.face_vertices;
  if (offsets.size() < 2) return Status::failure("the mesh has no faces");
  if (offsets.front() != 0)
    return Status::failure("face offsets must start with 0, not " + std::to_string(offsets.front()));
  if (offsets.back() != verts.size())
    return Status::failure("face offsets end at " + std::to_string(offsets.back()) + " but there are " +
                           std::to_string(verts.size()) + " face vertices");
  for (size_t f = 0; f + 1 < offsets.size(); ++f) {
    if (offsets[f + 1] < offsets[f] || offsets[f + 1] - offsets[f] < 3)
      return Status::failure("face " + std::to_string(f) + " has fewer than 3 vertices");
    for (uint32_t c = offsets[f]; c < offsets[f + 1]; ++c) {
      if (verts[c] >= base.vertex_count)
        return Status::failure("face " + std::to_string(f) + " refers to vertex " + std::to_string(verts[c]) +
                               " but the mesh has " + std::to_string(base.vertex_count) + " vertices");
      for (uint32_t d = offsets[f]; d < c; ++d)
        if (verts[d] == verts[c])
          return Status::failure("face " + std::to_string(f) + " uses vertex " + std::to_string(verts[c]) + " twice");
    }
  }
  if (!base.border_corners.empty() && base.border_corners.size() != base.vertex_count)
    return Status::failure("border corner flags must be one per vertex: " + std::to_string(base.border_corners.size()) +
                           " flags for " + std::to_string(base.vertex_count) + " vertices");
  if (base.sharp_edges.size() % 2 != 0)
    return Status::failure("sharp edges must be vertex pairs, got an odd count of " +
                           std::to_string(base.sharp_edges.size()) + " indices");
  return Status::success();
}

// Counts of each level, to refuse a refinement that would not fit before allocating it.
Status check_sizes(const BaseTopology& base, int levels) {
  for (int level = 1; level <= levels; ++level) {
    const uint64_t faces = faces_at_level(base.face_vertices.size(), level);
    if (faces > kMaxFaces)
      return Status::failure("level " + std::to_string(level) + " would have " + std::to_string(faces) +
                             " faces, more than the limit of " + std::to_string(kMaxFaces));
  }
  return Status::success();
}

Result<Level> build_base_level(const BaseTopology& base) {
  Level level;
  const uint32_t vertex_count = base.vertex_count;
  const uint32_t face_count = static_cast<uint32_t>(base.face_offsets.size() - 1);
  const uint32_t corner_count = static_cast<uint32_t>(base.face_vertices.size());
  level.vertex_count = vertex_count;
  level.face_offsets.assign(base.face_offsets.begin(), base.face_offsets.end());
  level.face_vertices.assign(base.face_vertices.begin(), base.face_vertices.end());
  const auto& offsets = level.face_offsets;
  const auto& fv = level.face_vertices;

  level.corner_faces.resize(corner_count);
  std::vector<uint32_t> next(corner_count), prev(corner_count);
  for (uint32_t f = 0; f < face_count; ++f) {
    const uint32_t b = offsets[f], e = offsets[f + 1];
    for (uint32_t c = b; c < e; ++c) {
      level.corner_faces[c] = f;
      next[c] = c + 1 == e ? b : c + 1;
      prev[c] = c == b ? e - 1 : c - 1;
    }
  }

  // Corners bucketed by the lower vertex of the edge leaving them (stable counting sort), so that the
  // corners of one undirected edge meet in one small bucket.
  std::vector<uint32_t> high(corner_count);
  std::vector<uint32_t> bucket_offsets(vertex_count + 1, 0);
  for (uint32_t c = 0; c < corner_count; ++c) {
    const uint32_t a = fv[c], b = fv[next[c]];
    high[c] = std::max(a, b);
    ++bucket_offsets[std::min(a, b) + 1];
  }
  for (uint32_t v = 0; v < vertex_count; ++v) bucket_offsets[v + 1] += bucket_offsets[v];
  std::vector<uint32_t> bucket_corners(corner_count);
  {
    std::vector<uint32_t> cursor(bucket_offsets.begin(), bucket_offsets.end() - 1);
    for (uint32_t c = 0; c < corner_count; ++c) bucket_corners[cursor[std::min(fv[c], fv[next[c]])]++] = c;
  }
  // first[c]: the lowest corner with the same undirected edge as c.
  std::vector<uint32_t> first(corner_count);
  for (uint32_t v = 0; v < vertex_count; ++v) {
    for (uint32_t i = bucket_offsets[v]; i < bucket_offsets[v + 1]; ++i) {
      const uint32_t c = bucket_corners[i];
      first[c] = c;
      for (uint32_t j = bucket_offsets[v]; j < i; ++j) {
        if (high[bucket_corners[j]] == high[c]) {
          first[c] = first[bucket_corners[j]];
          break;
        }
      }
    }
  }

  // An edge in more than two faces, named with all its faces.
  {
    std::vector<uint32_t> uses(corner_count, 0);
    for (uint32_t c = 0; c < corner_count; ++c) ++uses[first[c]];
    for (uint32_t c = 0; c < corner_count; ++c) {
      if (uses[c] <= 2) continue;
      const uint32_t lo = std::min(fv[c], fv[next[c]]);
      std::string faces;
      for (uint32_t j = bucket_offsets[lo]; j < bucket_offsets[lo + 1]; ++j)
        if (high[bucket_corners[j]] == high[c])
          faces.append(faces.empty() ? "" : ", ").append(std::to_string(level.corner_faces[bucket_corners[j]]));
      return Result<Level>::failure("edge " + edge_name(fv[c], fv[next[c]]) + " is shared by more than 2 faces (" +
                                    faces + "): the mesh is not manifold");
    }
  }

  // Edges in order of first appearance, as OpenSubdiv's Level::completeTopologyFromFaceVertices.
  level.face_edges.resize(corner_count);
  level.edge_vertices.reserve(corner_count);
  level.edge_corners.reserve(corner_count);
  for (uint32_t c = 0; c < corner_count; ++c) {
    const uint32_t u = fv[c], w = fv[next[c]];
    if (first[c] == c) {
      level.face_edges[c] = level.edge_count();
      level.edge_vertices.insert(level.edge_vertices.end(), {u, w});
      level.edge_corners.insert(level.edge_corners.end(), {c, kNone});
      continue;
    }
    const uint32_t e = level.face_edges[first[c]];
    if (level.edge_vertices[2 * e] == u)
      return Result<Level>::failure("edge " + edge_name(u, w) + " runs the same way in faces " +
                                    std::to_string(level.edge_face(e, 0)) + " and " +
                                    std::to_string(level.corner_faces[c]) +
                                    ": the faces are not oriented consistently");
    level.face_edges[c] = e;
    level.edge_corners[2 * e + 1] = c;
  }

  const uint32_t edge_count = level.edge_count();
  level.edge_sharp.resize(edge_count);
  for (uint32_t e = 0; e < edge_count; ++e) level.edge_sharp[e] = level.edge_corners[2 * e + 1] == kNone;
  for (size_t i = 0; i < base.sharp_edges.size(); i += 2) {
    const uint32_t a = base.sharp_edges[i], b = base.sharp_edges[i + 1];
    uint32_t edge = kNone;
    if (a < vertex_count && b < vertex_count) {
      const uint32_t lo = std::min(a, b), hi = std::max(a, b);
      for (uint32_t j = bucket_offsets[lo]; j < bucket_offsets[lo + 1] && edge == kNone; ++j)
        if (high[bucket_corners[j]] == hi) edge = level.face_edges[bucket_corners[j]];
    }
    if (edge == kNone)
      return Result<Level>::failure("sharp edge " + edge_name(a, b) + " is not an edge of the mesh");
    level.edge_sharp[edge] = 1;
  }

  // Corners around each vertex, in corner order (the lowest is in the lowest face).
  std::vector<uint32_t> vertex_offsets(vertex_count + 1, 0);
  for (uint32_t c = 0; c < corner_count; ++c) ++vertex_offsets[fv[c] + 1];
  for (uint32_t v = 0; v < vertex_count; ++v) vertex_offsets[v + 1] += vertex_offsets[v];
  std::vector<uint32_t> vertex_corners(corner_count);
  {
    std::vector<uint32_t> cursor(vertex_offsets.begin(), vertex_offsets.end() - 1);
    for (uint32_t c = 0; c < corner_count; ++c) vertex_corners[cursor[fv[c]]++] = c;
  }

  // Rings: walk counter-clockwise from the leading boundary edge, or from the lowest face.
  level.ring_offsets.resize(vertex_count + 1);
  level.ring_edges.reserve(corner_count + edge_count);
  level.ring_neighbors.reserve(corner_count + edge_count);
  level.ring_corners.reserve(corner_count + edge_count);
  level.vertex_rules.resize(vertex_count);
  for (uint32_t v = 0; v < vertex_count; ++v) {
    level.ring_offsets[v] = static_cast<uint32_t>(level.ring_edges.size());
    const uint32_t face_total = vertex_offsets[v + 1] - vertex_offsets[v];
    if (face_total == 0) {
      level.vertex_rules[v] = VertexRule::Corner;
      continue;
    }
    uint32_t start = vertex_corners[vertex_offsets[v]];
    bool boundary = false;
    for (uint32_t i = vertex_offsets[v]; i < vertex_offsets[v + 1]; ++i) {
      const uint32_t c = vertex_corners[i];
      if (level.edge_corners[2 * level.face_edges[c] + 1] == kNone) {
        start = c;
        boundary = true;
        break;
      }
    }
    uint32_t visited = 0, sharp_count = 0;
    uint32_t c = start;
    while (true) {
      const uint32_t out = level.face_edges[c];
      level.ring_edges.push_back(out);
      level.ring_neighbors.push_back(fv[next[c]]);
      level.ring_corners.push_back(c);
      sharp_count += level.edge_sharp[out];
      ++visited;
      const uint32_t in = level.face_edges[prev[c]];
      if (level.edge_corners[2 * in + 1] == kNone) {
        level.ring_edges.push_back(in);
        level.ring_neighbors.push_back(fv[prev[c]]);
        level.ring_corners.push_back(kNone);
        sharp_count += 1;
        break;
      }
      c = level.edge_corners[2 * in] == prev[c] ? level.edge_corners[2 * in + 1] : level.edge_corners[2 * in];
      if (c == start) break;
    }
    if (visited != face_total)
      return Result<Level>::failure("vertex " + std::to_string(v) + " is not manifold: its " +
                                    std::to_string(face_total) + " faces do not form a single fan");
    const bool given = !base.border_corners.empty();
    if (boundary && given) {
      level.vertex_rules[v] = base.border_corners[v] || sharp_count > 2 ? VertexRule::Corner : VertexRule::Crease;
    } else if (boundary && visited == 1) {
      level.vertex_rules[v] = VertexRule::Corner;
    } else {
      level.vertex_rules[v] = sharp_count == 0   ? VertexRule::Smooth
                              : sharp_count == 1 ? VertexRule::Dart
                              : sharp_count == 2 ? VertexRule::Crease
                                                 : VertexRule::Corner;
    }
  }
  level.ring_offsets[vertex_count] = static_cast<uint32_t>(level.ring_edges.size());
  return level;
}

// Position of a role within the child quad of corner j of a parent face: OpenSubdiv rotates the child
// quads of a quad so that each starts at the parent's corner index; other faces' children start at 0.
// Roles: 0 the parent vertex, 1 the next edge's point, 2 the face point, 3 the previous edge's point.
inline uint32_t role_position(bool quad, uint32_t j, uint32_t role) { return quad ? (j + role) & 3u : role; }

// Builds the child level from its parent with index arithmetic only (no searches).
class ChildBuilder {
 public:
  ChildBuilder(const Level& parent, Level& child)
      : p_(parent), c_(child),
        V_(parent.vertex_count), F_(parent.face_count()), E_(parent.edge_count()), C_(parent.corner_count()) {}

  void build(bool adjacency) {
    c_.vertex_count = V_ + F_ + E_;
    build_faces(adjacency);
    if (adjacency) {
      build_edges_from_edges();
      build_rings();
    }
  }

 private:
  uint32_t face_begin(uint32_t f) const { return p_.face_offsets[f]; }
  uint32_t face_size(uint32_t f) const { return p_.face_offsets[f + 1] - p_.face_offsets[f]; }
  // The child edge of parent edge e that touches parent vertex v.
  uint32_t half_edge(uint32_t e, uint32_t v) const { return C_ + 2 * e + (p_.edge_vertices[2 * e] != v); }

  // Child faces (one per parent corner), and with adjacency the child edges inside parent faces.
  void build_faces(bool adjacency) {
    c_.face_offsets.resize(C_ + 1);
    for (uint32_t i = 0; i <= C_; ++i) c_.face_offsets[i] = 4 * i;
    c_.face_vertices.resize(4 * size_t{C_});
    const uint32_t child_edges = C_ + 2 * E_;
    if (adjacency) {
      c_.face_edges.resize(4 * size_t{C_});
      c_.edge_vertices.resize(2 * size_t{child_edges});
      c_.edge_corners.resize(2 * size_t{child_edges});
      c_.edge_sharp.resize(child_edges);
    }
    const uint32_t edge_point0 = V_ + F_;
    for (uint32_t f = 0; f < F_; ++f) {
      const uint32_t b = face_begin(f), n = face_size(f), face_point = V_ + f;
      const bool quad = n == 4;
      for (uint32_t j = 0; j < n; ++j) {
        const uint32_t c = b + j, c_prev = j == 0 ? b + n - 1 : c - 1;
        const uint32_t v = p_.face_vertices[c];
        const uint32_t e_next = p_.face_edges[c], e_prev = p_.face_edges[c_prev];
        const uint32_t q = 4 * c;
        const uint32_t p0 = role_position(quad, j, 0), p1 = role_position(quad, j, 1),
                       p2 = role_position(quad, j, 2), p3 = role_position(quad, j, 3);
        c_.face_vertices[q + p0] = v;
        c_.face_vertices[q + p1] = edge_point0 + e_next;
        c_.face_vertices[q + p2] = face_point;
        c_.face_vertices[q + p3] = edge_point0 + e_prev;
        if (!adjacency) continue;
        c_.face_edges[q + p0] = half_edge(e_next, v);
        c_.face_edges[q + p1] = c;
        c_.face_edges[q + p2] = c_prev;
        c_.face_edges[q + p3] = half_edge(e_prev, v);
        // Interior edge c joins the face point to the next edge's point; it borders this child quad
        // and the next corner's.
        c_.edge_vertices[2 * c] = face_point;
        c_.edge_vertices[2 * c + 1] = edge_point0 + e_next;
        c_.edge_sharp[c] = 0;
        c_.edge_corners[2 * c] = q + p1;
        c_.edge_corners[2 * c_prev + 1] = q + p2;
      }
    }
  }

  void build_edges_from_edges() {
    for (uint32_t e = 0; e < E_; ++e) {
      const uint32_t edge_point = V_ + F_ + e;
      for (uint32_t k = 0; k < 2; ++k) {
        const uint32_t child = C_ + 2 * e + k, end = p_.edge_vertices[2 * e + k];
        c_.edge_vertices[2 * child] = edge_point;
        c_.edge_vertices[2 * child + 1] = end;
        c_.edge_sharp[child] = p_.edge_sharp[e];
        for (uint32_t side = 0; side < 2; ++side) {
          const uint32_t corner = p_.edge_corners[2 * e + side];
          if (corner == kNone) {
            c_.edge_corners[2 * child + side] = kNone;
            continue;
          }
          const uint32_t f = p_.corner_face(corner);
          const uint32_t b = face_begin(f), n = face_size(f), j = corner - b;
          const bool quad = n == 4;
          if (p_.face_vertices[corner] == end) {
            // The half leaves the parent corner: "next edge" side of that corner's child quad.
            c_.edge_corners[2 * child + side] = 4 * corner + role_position(quad, j, 0);
          } else {
            // The half ends at the next corner: "previous edge" side of the next corner's child quad.
            const uint32_t jn = j + 1 == n ? 0 : j + 1;
            c_.edge_corners[2 * child + side] = 4 * (b + jn) + role_position(quad, jn, 3);
          }
        }
      }
    }
  }

  void set_slot(uint32_t slot, uint32_t edge, uint32_t neighbor, uint32_t corner) {
    c_.ring_edges[slot] = edge;
    c_.ring_neighbors[slot] = neighbor;
    c_.ring_corners[slot] = corner;
  }

  void build_rings() {
    const uint32_t R = static_cast<uint32_t>(p_.ring_edges.size());
    const uint32_t rows = c_.vertex_count;
    const uint32_t edge_point0 = V_ + F_;
    c_.ring_offsets.resize(rows + 1);
    std::copy(p_.ring_offsets.begin(), p_.ring_offsets.end(), c_.ring_offsets.begin());
    for (uint32_t f = 0; f < F_; ++f) c_.ring_offsets[V_ + f] = R + face_begin(f);
    uint32_t total = R + C_;
    for (uint32_t e = 0; e < E_; ++e) {
      c_.ring_offsets[edge_point0 + e] = total;
      total += p_.edge_corners[2 * e + 1] == kNone ? 3 : 4;
    }
    c_.ring_offsets[rows] = total;
    c_.ring_edges.resize(total);
    c_.ring_neighbors.resize(total);
    c_.ring_corners.resize(total);
    c_.vertex_rules.resize(rows);

    // Vertex points keep their parent's ring, slot for slot; their neighbours are edge points.
    for (uint32_t v = 0; v < V_; ++v) {
      for (uint32_t r = p_.ring_offsets[v]; r < p_.ring_offsets[v + 1]; ++r) {
        const uint32_t e = p_.ring_edges[r], corner = p_.ring_corners[r];
        uint32_t child_corner = kNone;
        if (corner != kNone) {
          const uint32_t f = p_.corner_face(corner);
          child_corner = 4 * corner + role_position(face_size(f) == 4, corner - face_begin(f), 0);
        }
        set_slot(r, half_edge(e, v), edge_point0 + e, child_corner);
      }
      c_.vertex_rules[v] = p_.vertex_rules[v];
    }
    // Face points: the child quads in corner order; the edge leaving the face point in quad j is the
    // interior edge of corner j-1, towards the point of the parent edge leaving corner j-1.
    for (uint32_t f = 0; f < F_; ++f) {
      const uint32_t b = face_begin(f), n = face_size(f);
      const bool quad = n == 4;
      for (uint32_t j = 0; j < n; ++j) {
        const uint32_t c_prev = j == 0 ? b + n - 1 : b + j - 1;
        set_slot(R + b + j, c_prev, edge_point0 + p_.face_edges[c_prev], 4 * (b + j) + role_position(quad, j, 2));
      }
      c_.vertex_rules[V_ + f] = VertexRule::Smooth;
    }
    // Edge points: per parent face of the edge (in edge-face order), the child quad of the corner
    // after the edge, then the one of the corner where the edge leaves.
    for (uint32_t e = 0; e < E_; ++e) {
      uint32_t slot = c_.ring_offsets[edge_point0 + e];
      for (uint32_t side = 0; side < 2; ++side) {
        const uint32_t corner = p_.edge_corners[2 * e + side];
        if (corner == kNone) break;
        const uint32_t f = p_.corner_face(corner);
        const uint32_t b = face_begin(f), n = face_size(f), j = corner - b;
        const uint32_t jn = j + 1 == n ? 0 : j + 1, next = b + jn;
        const bool quad = n == 4;
        const uint32_t end = p_.face_vertices[next];
        set_slot(slot++, half_edge(e, end), end, 4 * next + role_position(quad, jn, 3));
        set_slot(slot++, corner, V_ + f, 4 * corner + role_position(quad, j, 1));
      }
      if (p_.edge_corners[2 * e + 1] == kNone) {
        const uint32_t end = p_.face_vertices[p_.edge_corners[2 * e]];
        set_slot(slot, half_edge(e, end), end, kNone);
      }
      c_.vertex_rules[edge_point0 + e] = p_.edge_sharp[e] ? VertexRule::Crease : VertexRule::Smooth;
    }
  }

  const Level& p_;
  Level& c_;
  const uint32_t V_, F_, E_, C_;
};
}  // namespace

namespace detail {
Result<Refinement> build_levels(const BaseTopology& base, const RefinementOptions& options) {
  if (options.levels < 0 || options.levels > kMaxRefinementLevels)
    return Result<Refinement>::failure("subdivision level " + std::to_string(options.levels) +
                                       " is outside 0 .. " + std::to_string(kMaxRefinementLevels));
  if (Status valid = validate_base(base); !valid) return Result<Refinement>::failure(valid.error);
  if (Status fits = check_sizes(base, options.levels); !fits) return Result<Refinement>::failure(fits.error);
  Result<Level> base_level = build_base_level(base);
  if (!base_level) return Result<Refinement>::failure(base_level.error());

  Refinement refinement;
  refinement.levels.reserve(options.levels + 1);
  refinement.levels.push_back(std::move(*base_level));
  for (int l = 0; l < options.levels; ++l) {
    refinement.levels.emplace_back();
    const bool adjacency = options.last_level_adjacency || l + 1 < options.levels;
    ChildBuilder(refinement.levels[size_t(l)], refinement.levels[size_t(l) + 1]).build(adjacency);
  }
  return refinement;
}
}  // namespace detail

Result<Refinement> build_refinement(const BaseTopology& base, const RefinementOptions& options) {
  Result<Refinement> refinement = detail::build_levels(base, options);
  if (refinement && options.levels >= kMinPatchLevels && options.levels <= kMaxPatchLevels)
    detail::plan_regular_patches(base, *refinement);
  return refinement;
}

namespace {
// In OpenSubdiv's numbering at every level; the last level's vertices are mapped as they are found.
void along_edge(const Refinement& r, size_t level, uint32_t edge, uint32_t from, std::vector<uint32_t>& out) {
  if (level + 1 == r.levels.size()) {
    out.push_back(r.last_from_osd.empty() ? from : r.last_from_osd[from]);
    return;
  }
  const Level& lv = r.levels[level];
  const uint32_t k = lv.edge_vertices[2 * edge] == from ? 0u : 1u;
  const uint32_t mid = lv.vertex_count + lv.face_count() + edge;
  const uint32_t children = lv.corner_count() + 2 * edge;
  along_edge(r, level + 1, children + k, from, out);
  along_edge(r, level + 1, children + (1 - k), mid, out);
}
}  // namespace

void vertices_along_edge(const Refinement& r, size_t level, uint32_t edge, uint32_t from, std::vector<uint32_t>& out) {
  if (level + 1 == r.levels.size())
    out.push_back(from);
  else
    along_edge(r, level, edge, from, out);
}

}  // namespace fire::catmull_clark
