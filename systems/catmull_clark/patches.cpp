// The plan of evaluate()'s regular-patch path (see RegularPatches in subdivide.hpp): which base quads
// are regular, the 4x4 base points around each, which of their side points each writes, the mesh of
// the other faces, and the last level renumbered in that order.
#include <algorithm>
#include <array>

#include "systems/catmull_clark/patches.hpp"

namespace fire::catmull_clark::detail {
namespace {

struct Cell {
  uint32_t u, v;
};
Cell middle(Cell a, Cell b) { return {(a.u + b.u) / 2, (a.v + b.v) / 2}; }

// Where the last-level quads below one quad put their vertices: for each point of the quad's grid (side
// 2^depth + 1, row by row) the quad d below it (d in [0, 4^depth), the first child's digit most
// significant) and the slot t of the point in that quad. The same for every quad: the child quad of
// corner j of a quad lists the corner, the next edge's point, the centre and the previous edge's point
// from slot j on (the numbering in subdivide.hpp), so a last-level quad's place depends only on its
// digits. The quad's own corners sit at (0,0), (s,0), (s,s), (0,s) in its slot order.
struct Slot {
  uint32_t quad, slot;
};
void place_quads(uint32_t depth, uint32_t d, const std::array<Cell, 4>& at, uint32_t side, std::vector<Slot>& slots) {
  if (depth == 0) {
    for (uint32_t t = 0; t < 4; ++t) slots[size_t{at[t].v} * side + at[t].u] = {d, t};
    return;
  }
  const Cell centre = middle(at[0], at[2]);
  std::array<Cell, 4> mid;
  for (uint32_t j = 0; j < 4; ++j) mid[j] = middle(at[j], at[(j + 1) & 3]);
  for (uint32_t j = 0; j < 4; ++j) {
    const std::array<Cell, 4> roles{at[j], mid[j], centre, mid[(j + 3) & 3]};
    std::array<Cell, 4> child;
    for (uint32_t role = 0; role < 4; ++role) child[(j + role) & 3] = roles[role];
    place_quads(depth - 1, 4 * d + j, child, side, slots);
  }
}

std::vector<Slot> quad_slots(uint32_t depth) {
  const uint32_t side = (1u << depth) + 1, s = side - 1;
  std::vector<Slot> slots(size_t{side} * side);
  place_quads(depth, 0, {{{0, 0}, {s, 0}, {s, s}, {0, s}}}, side, slots);
  return slots;
}

// The last-level vertex at each grid point of quad q of `level` (a quad; its children are the faces
// first_child .. first_child+3 of the next level), from the last level's faces.
struct QuadGrid {
  const Level& last;
  const std::vector<Slot>& slots;
  uint32_t depth;
  uint32_t vertex(uint32_t first_child, uint32_t cell) const {
    const Slot& s = slots[cell];
    return last.face_vertices[4 * ((size_t{first_child} << (2 * (depth - 1))) + s.quad) + s.slot];
  }
};

uint32_t face_size(const Level& level, uint32_t f) { return level.face_offsets[f + 1] - level.face_offsets[f]; }

// Smooth, valence 4, and its four faces are quads.
bool regular_vertex(const Level& base, uint32_t v) {
  const uint32_t r0 = base.ring_offsets[v], r1 = base.ring_offsets[v + 1];
  if (base.vertex_rules[v] != VertexRule::Smooth || r1 - r0 != 4) return false;
  for (uint32_t r = r0; r < r1; ++r)
    if (base.ring_corners[r] == kNone || face_size(base, base.corner_face(base.ring_corners[r])) != 4) return false;
  return true;
}

// The 4x4 base vertices around regular quad f, rows along its first edge, f's corners at (1,1), (2,1),
// (2,2), (1,2). False if the neighbourhood is not a consistent grid.
bool patch_controls(const Level& base, uint32_t f, std::array<uint32_t, 16>& controls) {
  controls.fill(kNone);
  const uint32_t b = base.face_offsets[f];
  const std::array<Cell, 4> at{{{1, 1}, {2, 1}, {2, 2}, {1, 2}}};
  auto put = [&controls](int u, int v, uint32_t id) {
    uint32_t& slot = controls[size_t(v) * 4 + size_t(u)];
    if (slot != kNone && slot != id) return false;
    slot = id;
    return true;
  };
  for (uint32_t j = 0; j < 4; ++j) {
    const uint32_t c = b + j, v = base.face_vertices[c];
    const int u0 = int(at[j].u), v0 = int(at[j].v);
    // Directions to the next and previous corner of f, then their opposites: the ring's order.
    const Cell next = at[(j + 1) & 3], prev = at[(j + 3) & 3];
    const int du = int(next.u) - u0, dv = int(next.v) - v0, eu = int(prev.u) - u0, ev = int(prev.v) - v0;
    const std::array<std::array<int, 2>, 4> dirs{{{du, dv}, {eu, ev}, {-du, -dv}, {-eu, -ev}}};
    const uint32_t r0 = base.ring_offsets[v];
    uint32_t s = 0;
    while (s < 4 && base.ring_corners[r0 + s] != c) ++s;
    if (s == 4 || !put(u0, v0, v)) return false;
    for (uint32_t t = 0; t < 4; ++t) {
      const uint32_t slot = r0 + ((s + t) & 3);
      const auto& d = dirs[t];
      const auto& d_next = dirs[(t + 1) & 3];
      if (!put(u0 + d[0], v0 + d[1], base.ring_neighbors[slot])) return false;
      // The face between ring edges t and t+1, a quad: its corner opposite v is diagonal.
      const uint32_t corner = base.ring_corners[slot], fb = base.face_offsets[base.corner_face(corner)];
      const uint32_t opposite = base.face_vertices[fb + ((corner - fb + 2) & 3)];
      if (!put(u0 + d[0] + d_next[0], v0 + d[1] + d_next[1], opposite)) return false;
    }
  }
  return true;
}

// The 1D weights of the points along a patch side over the 4 base points of their row, base point by
// base point (side values each): each base
// point's unit sequence refined `levels` times by the cubic B-spline rules (midpoints, and 1/8, 3/4,
// 1/8 at inner points), with a one-point margin until the last level. Dyadic, so exact.
std::vector<double> side_weights(uint32_t levels) {
  std::vector<double> weights;
  std::array<std::vector<double>, 4> sequences;
  for (uint32_t a = 0; a < 4; ++a) {
    sequences[a].assign(4, 0.0);
    sequences[a][a] = 1.0;
  }
  for (uint32_t step = 1; step <= levels; ++step) {
    const bool margin = step < levels;
    for (std::vector<double>& s : sequences) {
      std::vector<double> next;
      for (size_t i = 0; i + 1 < s.size(); ++i) {
        if (i > 0) next.push_back(0.125 * (s[i - 1] + s[i + 1]) + 0.75 * s[i]);
        if (margin || (i > 0 && i + 2 < s.size())) next.push_back(0.5 * (s[i] + s[i + 1]));
      }
      s = std::move(next);
    }
  }
  for (const std::vector<double>& s : sequences) weights.insert(weights.end(), s.begin(), s.end());
  return weights;
}

// The faces sharing a vertex with the irregular ones, closed so that every vertex's faces in it form
// one fan (as build_levels requires): a vertex whose faces there fall into several runs brings all of
// its faces.
std::vector<uint8_t> rest_faces(const Level& base, std::span<const uint32_t> irregular) {
  std::vector<uint8_t> in(base.face_count(), 0);
  auto add_vertex_faces = [&](uint32_t v) {
    for (uint32_t r = base.ring_offsets[v]; r < base.ring_offsets[v + 1]; ++r)
      if (base.ring_corners[r] != kNone) in[base.corner_face(base.ring_corners[r])] = 1;
  };
  for (uint32_t f : irregular)
    for (uint32_t c = base.face_offsets[f]; c < base.face_offsets[f + 1]; ++c) add_vertex_faces(base.face_vertices[c]);
  for (bool changed = true; changed;) {
    changed = false;
    for (uint32_t v = 0; v < base.vertex_count; ++v) {
      const uint32_t r0 = base.ring_offsets[v], r1 = base.ring_offsets[v + 1];
      uint32_t included = 0, starts = 0;
      for (uint32_t r = r0; r < r1; ++r) {
        const uint32_t corner = base.ring_corners[r];
        const bool here = corner != kNone && in[base.corner_face(corner)];
        // The face before slot r: slot r-1's, cyclic on an interior vertex, none before a boundary's first.
        const uint32_t before = base.ring_corners[r == r0 ? r1 - 1 : r - 1];
        const bool before_here = before != kNone && in[base.corner_face(before)];
        included += here;
        starts += here && !before_here;
      }
      if (included == 0 || starts == 1 || (starts == 0 && included == r1 - r0)) continue;
      add_vertex_faces(v);
      changed = true;
    }
  }
  return in;
}

// Renumbers the last level's vertices: order[i] is the old number of new vertex i, rank the inverse.
// The rings are gathered in the new order, each fetched a few vertices ahead: its offsets then its
// entries lie anywhere in arrays of several MB, and without the prefetches each vertex waits for them.
void renumber_last_level(Level& last, const std::vector<uint32_t>& order, const std::vector<uint32_t>& rank) {
  for (uint32_t& v : last.face_vertices) v = rank[v];
  if (!last.has_adjacency()) return;
  for (uint32_t& v : last.edge_vertices) v = rank[v];
  const uint32_t n = last.vertex_count;
  std::vector<uint32_t> offsets(size_t{n} + 1, 0), edges(last.ring_edges.size()), neighbors(edges.size()),
      corners(edges.size());
  std::vector<VertexRule> rules(n);
  constexpr uint32_t kOffsetsAhead = 32, kRingsAhead = 16;
  for (uint32_t v = 0; v < n; ++v) {
    if (v + kOffsetsAhead < n) __builtin_prefetch(&last.ring_offsets[order[v + kOffsetsAhead]]);
    if (v + kRingsAhead < n) {
      const uint32_t ahead = last.ring_offsets[order[v + kRingsAhead]];
      __builtin_prefetch(&last.ring_edges[ahead]);
      __builtin_prefetch(&last.ring_neighbors[ahead]);
      __builtin_prefetch(&last.ring_corners[ahead]);
    }
    const uint32_t old = order[v], r0 = last.ring_offsets[old], r1 = last.ring_offsets[old + 1];
    uint32_t o = offsets[v];
    for (uint32_t r = r0; r < r1; ++r, ++o) {
      edges[o] = last.ring_edges[r];
      neighbors[o] = rank[last.ring_neighbors[r]];
      corners[o] = last.ring_corners[r];
    }
    offsets[v + 1] = o;
    rules[v] = last.vertex_rules[old];
  }
  last.ring_offsets = std::move(offsets);
  last.ring_edges = std::move(edges);
  last.ring_neighbors = std::move(neighbors);
  last.ring_corners = std::move(corners);
  last.vertex_rules = std::move(rules);
}

}  // namespace

void plan_regular_patches(const BaseTopology& topology, Refinement& refinement) {
  const std::span<const Level> levels = refinement.levels;
  const Level& base = levels[0];
  const uint32_t depth = static_cast<uint32_t>(levels.size() - 1);
  RegularPatches plan;
  plan.side = (1u << depth) + 1;
  plan.weights = side_weights(depth);
  const uint32_t side = plan.side, cells = side * side, s = side - 1;
  const std::vector<Slot> slots = quad_slots(depth);
  const QuadGrid grid{refinement.last(), slots, depth};
  const uint32_t vertex_count = refinement.last().vertex_count;
  // The bit of `owned` each grid point depends on; -1 inside.
  std::vector<int8_t> border_bits(cells);
  for (uint32_t v = 0; v < side; ++v)
    for (uint32_t u = 0; u < side; ++u) {
      int8_t& bit = border_bits[size_t{v} * side + u];
      if (v == 0) bit = u == 0 ? 4 : u == s ? 5 : 0;
      else if (v == s) bit = u == 0 ? 7 : u == s ? 6 : 2;
      else bit = u == 0 ? 3 : u == s ? 1 : -1;
    }

  std::vector<uint8_t> regular(base.vertex_count);
  for (uint32_t v = 0; v < base.vertex_count; ++v) regular[v] = regular_vertex(base, v);

  // order: the old (OpenSubdiv) number of each last-level vertex in the new numbering. A point on a
  // patch's side or corner goes to the first patch that has it, so a side is written whole or not at all.
  // The points inside a patch belong to it alone, and their old numbers lie at the same offsets from a
  // few starts in every patch: found once, on the first patch, as runs of consecutive numbers (whose
  // starts are then read per patch, and checked by their ends); the rest are looked up one by one.
  std::vector<uint8_t> written(vertex_count, 0);
  std::vector<uint32_t> order, irregular, ids(cells);
  order.reserve(vertex_count);
  std::vector<uint32_t> run_first_cells, run_last_cells, run_lengths, starts;
  std::vector<uint32_t> cell_run(cells, kNone), cell_offset(cells, 0);
  std::array<uint32_t, 16> controls;
  const uint32_t* last_faces = refinement.last().face_vertices.data();
  const size_t block = size_t{4} << (2 * depth);  // corners of the last-level faces below a base quad
  for (uint32_t f = 0; f < base.face_count(); ++f) {
    const uint32_t b = base.face_offsets[f];
    // The next face's last-level faces, read below, are not in cache: fetch them while this one is done.
    if (f + 1 < base.face_count() && face_size(base, f + 1) == 4)
      for (size_t k = 0; k < block; k += 16) __builtin_prefetch(last_faces + size_t{base.face_offsets[f + 1]} * (block / 4) + k);
    bool ok = face_size(base, f) == 4;
    for (uint32_t c = b; ok && c < b + 4; ++c) ok = regular[base.face_vertices[c]];
    ok = ok && patch_controls(base, f, controls);
    if (ok && run_lengths.empty()) {
      std::vector<std::pair<uint32_t, uint32_t>> inside;  // (old number, cell)
      for (uint32_t cell = 0; cell < cells; ++cell)
        if (border_bits[cell] < 0) inside.emplace_back(grid.vertex(b, cell), cell);
      std::sort(inside.begin(), inside.end());
      for (size_t i = 0; i < inside.size(); ++i) {
        if (i == 0 || inside[i].first != inside[i - 1].first + 1) {
          run_first_cells.push_back(inside[i].second);
          run_lengths.push_back(0);
        }
        cell_run[inside[i].second] = static_cast<uint32_t>(run_lengths.size() - 1);
        cell_offset[inside[i].second] = run_lengths.back()++;
        if (i + 1 == inside.size() || inside[i + 1].first != inside[i].first + 1)
          run_last_cells.push_back(inside[i].second);
      }
    }
    starts.clear();
    for (size_t r = 0; ok && r < run_lengths.size(); ++r) {
      starts.push_back(grid.vertex(b, run_first_cells[r]));
      ok = grid.vertex(b, run_last_cells[r]) == starts[r] + run_lengths[r] - 1;
    }
    if (!ok) {
      irregular.push_back(f);
      continue;
    }
    uint32_t seen[8] = {}, fresh[8] = {};
    for (uint32_t cell = 0; cell < cells; ++cell) {
      if (const int bit = border_bits[cell]; bit >= 0) {
        ids[cell] = grid.vertex(b, cell);
        ++seen[bit];
        fresh[bit] += !written[ids[cell]];
      } else {
        ids[cell] = starts[cell_run[cell]] + cell_offset[cell];
      }
    }
    uint8_t owned = 0;
    for (int bit = 0; bit < 8; ++bit) {
      if (fresh[bit] != 0 && fresh[bit] != seen[bit]) return;  // not a consistent grid: level by level
      if (fresh[bit] != 0) owned |= uint8_t(1u << bit);
    }
    for (uint32_t cell = 0; cell < cells; ++cell) {
      const int bit = border_bits[cell];
      if (bit >= 0) {
        if (!(owned >> bit & 1)) continue;
        written[ids[cell]] = 1;
      }
      order.push_back(ids[cell]);
    }
    plan.controls.insert(plan.controls.end(), controls.begin(), controls.end());
    plan.owned.push_back(owned);
  }
  if (plan.controls.empty()) return;

  if (!irregular.empty()) {
    const std::vector<uint8_t> in = rest_faces(base, irregular);
    std::vector<uint32_t> face_map(base.face_count(), kNone), vertex_map(base.vertex_count, kNone);
    std::vector<uint32_t> offsets{0}, vertices;
    for (uint32_t f = 0; f < base.face_count(); ++f) {
      if (!in[f]) continue;
      face_map[f] = static_cast<uint32_t>(offsets.size() - 1);
      for (uint32_t c = base.face_offsets[f]; c < base.face_offsets[f + 1]; ++c) {
        uint32_t& mapped = vertex_map[base.face_vertices[c]];
        if (mapped == kNone) {
          mapped = static_cast<uint32_t>(plan.rest_controls.size());
          plan.rest_controls.push_back(base.face_vertices[c]);
        }
        vertices.push_back(mapped);
      }
      offsets.push_back(static_cast<uint32_t>(vertices.size()));
    }
    // The marked sharp edges that are edges of the rest.
    std::vector<uint32_t> sharp;
    for (size_t i = 0; i + 1 < topology.sharp_edges.size(); i += 2) {
      const uint32_t a = topology.sharp_edges[i], b = topology.sharp_edges[i + 1];
      for (uint32_t r = base.ring_offsets[a]; r < base.ring_offsets[a + 1]; ++r) {
        if (base.ring_neighbors[r] != b) continue;
        const uint32_t e = base.ring_edges[r], f0 = base.edge_face(e, 0), f1 = base.edge_face(e, 1);
        if (in[f0] || (f1 != kNone && in[f1])) sharp.insert(sharp.end(), {vertex_map[a], vertex_map[b]});
        break;
      }
    }
    // A vertex on the rest's border that is inside the whole mesh moves no point the rest is used for, so
    // its flag does not matter.
    std::vector<uint8_t> corners;
    if (!topology.border_corners.empty())
      for (uint32_t v : plan.rest_controls) corners.push_back(topology.border_corners[v]);
    const BaseTopology rest_topology{static_cast<uint32_t>(plan.rest_controls.size()), offsets, vertices, sharp, corners};
    Result<Refinement> rest = build_levels(rest_topology, {static_cast<int>(depth), false});
    if (!rest) return;
    plan.rest = std::move(rest->levels);

    // The child quads of each irregular face: the same grid point is the same point in both refinements.
    const std::vector<Slot> child_slots = quad_slots(depth - 1);
    const QuadGrid full_grid{refinement.last(), child_slots, depth - 1};
    const QuadGrid rest_grid{plan.rest.back(), child_slots, depth - 1};
    for (uint32_t f : irregular) {
      const uint32_t g = face_map[f];
      for (uint32_t j = 0; j < face_size(base, f); ++j) {
        const uint32_t q = base.face_offsets[f] + j, rest_q = plan.rest[0].face_offsets[g] + j;
        for (uint32_t cell = 0; cell < child_slots.size(); ++cell) {
          const uint32_t id = full_grid.vertex(4 * q, cell);
          if (written[id]) continue;
          written[id] = 1;
          order.push_back(id);
          plan.rest_sources.push_back(rest_grid.vertex(4 * rest_q, cell));
        }
      }
    }
  }
  // A vertex in no face is in no grid: leave such meshes to the level-by-level path.
  if (order.size() != vertex_count) return;

  std::vector<uint32_t> rank(vertex_count, kNone);
  for (uint32_t v = 0; v < vertex_count; ++v) {
    if (rank[order[v]] != kNone) return;  // a point twice: not a consistent grid
    rank[order[v]] = v;
  }
  renumber_last_level(refinement.levels.back(), order, rank);
  refinement.patches = std::move(plan);
  refinement.last_from_osd = std::move(rank);
}

}  // namespace fire::catmull_clark::detail
