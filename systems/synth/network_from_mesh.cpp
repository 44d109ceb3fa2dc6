#include "systems/synth/network_from_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <numbers>
#include <numeric>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <unordered_map>

#include "systems/catmull_clark/catmull_clark.hpp"

namespace fire {

namespace {

// Union by smaller index, so every root is the smallest member: ids come out independent of merge order.
struct UnionFind {
  std::vector<uint32_t> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  uint32_t find(uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(uint32_t a, uint32_t b) {
    a = find(a);
    b = find(b);
    if (a < b) parent[b] = a;
    else if (b < a) parent[a] = b;
  }
};

// Box-Muller on mt19937_64 rather than std::normal_distribution, whose output differs between standard
// libraries: the same seed gives the same network on every machine (with the same libm).
class Gaussian {
 public:
  explicit Gaussian(uint64_t seed) : rng_(seed) {}
  double next() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = 1.0 - uniform();  // (0, 1]: the logarithm stays finite
    const double u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    const double angle = 2.0 * std::numbers::pi * u2;
    spare_ = r * std::sin(angle);
    has_spare_ = true;
    return r * std::cos(angle);
  }

 private:
  double uniform() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }
  std::mt19937_64 rng_;
  double spare_ = 0;
  bool has_spare_ = false;
};

// White noise (one unit-variance sample per inner polyline point; zero at the ends) made correlated along
// the line: each point's offset is a Gaussian-weighted mean over arc length (standard deviation
// `length`, cut at 3 of them) of its neighbours' samples, scaled back to unit variance. A tracked,
// filtered pen errs like this: smoothly along the stroke, not independently per sample.
std::vector<Vec3> correlate_along(std::span<const Vec3> line, std::span<const Vec3> white, double length) {
  std::vector<double> arc(line.size(), 0.0);
  for (size_t i = 1; i < line.size(); ++i) arc[i] = arc[i - 1] + (line[i] - line[i - 1]).norm();
  std::vector<Vec3> out(line.size(), Vec3::Zero());
  for (size_t i = 1; i + 1 < line.size(); ++i) {
    Vec3 sum = Vec3::Zero();
    double squares = 0;
    for (size_t j = 1; j + 1 < line.size(); ++j) {
      const double d = (arc[j] - arc[i]) / length;
      if (std::abs(d) > 3) continue;
      const double w = std::exp(-0.5 * d * d);
      sum += w * white[j];
      squares += w * w;
    }
    out[i] = sum / std::sqrt(squares);
  }
  return out;
}

std::string obj_vertex(uint32_t v) { return std::to_string(v + 1); }

// Half-edge h is the side of face half_face[h] from corner h to the next corner (h indexes face_vertices).
struct Control {
  std::span<const Vec3> positions;
  std::vector<uint32_t> half_face, half_next, half_edge;
  std::vector<std::array<uint32_t, 2>> edge_half;  // first half-edge seen, then its twin (kNone on the border)
  std::vector<std::vector<uint32_t>> vertex_edges;  // ascending edge ids
  std::vector<std::vector<uint32_t>> vertex_corners;  // half-edges arriving at the vertex
  std::span<const uint32_t> face_vertices;

  uint32_t tail(uint32_t h) const { return face_vertices[h]; }
  uint32_t head(uint32_t h) const { return face_vertices[half_next[h]]; }
  uint32_t twin(uint32_t h) const {
    const auto& eh = edge_half[half_edge[h]];
    return eh[0] == h ? eh[1] : eh[0];
  }
  bool border(uint32_t e) const { return edge_half[e][1] == kNone; }
  uint32_t edge_tail(uint32_t e) const { return tail(edge_half[e][0]); }
  uint32_t edge_head(uint32_t e) const { return head(edge_half[e][0]); }
  uint32_t other_end(uint32_t e, uint32_t v) const { return edge_tail(e) == v ? edge_head(e) : edge_tail(e); }
  size_t edge_count() const { return edge_half.size(); }
  size_t vertex_count() const { return positions.size(); }
  uint32_t face_size(uint32_t f, std::span<const uint32_t> offsets) const { return offsets[f + 1] - offsets[f]; }
};

Status check_input(const PolygonMeshView& in, const UnrefineOptions& o, const std::string& src) {
  if (o.unrefine < 1) return Status::failure(src + ": unrefine must be at least 1");
  if (o.samples_per_edge < kMinSamplesPerEdge || o.samples_per_edge > 65536)
    return Status::failure(src + ": samples per edge must be between 8 and 65536, not " + std::to_string(o.samples_per_edge));
  if (!std::isfinite(o.noise_percent) || o.noise_percent < 0)
    return Status::failure(src + ": noise percent must be a finite number >= 0");
  if (!std::isfinite(o.noise_correlation_percent) || o.noise_correlation_percent < 0)
    return Status::failure(src + ": noise correlation length must be a finite number >= 0");
  const auto& off = in.face_offsets;
  if (off.size() < 2 || off[0] != 0 || off.back() != in.face_vertices.size())
    return Status::failure(src + ": no faces, or face offsets that do not cover the face vertex list");
  for (size_t p = 0; p < in.positions.size(); ++p)
    if (!is_finite(in.positions[p])) return Status::failure(src + ": vertex " + obj_vertex(uint32_t(p)) + " has a non-finite coordinate");
  for (size_t f = 0; f + 1 < off.size(); ++f) {
    if (off[f + 1] < off[f] + 3) return Status::failure(src + ": face " + std::to_string(f + 1) + " has fewer than 3 vertices");
    for (uint32_t i = off[f]; i < off[f + 1]; ++i) {
      if (in.face_vertices[i] >= in.positions.size())
        return Status::failure(src + ": face " + std::to_string(f + 1) + " uses vertex " + obj_vertex(in.face_vertices[i]) + " that does not exist");
      for (uint32_t j = off[f]; j < i; ++j)
        if (in.face_vertices[j] == in.face_vertices[i])
          return Status::failure(src + ": face " + std::to_string(f + 1) + " uses vertex " + obj_vertex(in.face_vertices[i]) + " twice");
    }
  }
  return Status::success();
}

// Edges from faces; rejects an edge with more than two faces (first in file order) and two faces walking
// one edge the same way, since a polyline mesh edge has one face on each side.
Status build_control(const PolygonMeshView& in, const std::string& src, Control& c) {
  c.positions = in.positions;
  c.face_vertices = in.face_vertices;
  const size_t nh = in.face_vertices.size();
  c.half_face.resize(nh);
  c.half_next.resize(nh);
  c.half_edge.resize(nh);
  std::unordered_map<uint64_t, uint32_t> edge_of_pair;
  std::vector<uint32_t> extra_face;  // per edge, a third face if one appears
  for (uint32_t f = 0; f + 1 < in.face_offsets.size(); ++f) {
    const uint32_t begin = in.face_offsets[f], end = in.face_offsets[f + 1];
    for (uint32_t h = begin; h < end; ++h) {
      c.half_face[h] = f;
      c.half_next[h] = h + 1 < end ? h + 1 : begin;
    }
  }
  for (uint32_t h = 0; h < nh; ++h) {
    const uint32_t a = c.tail(h), b = c.head(h);
    const uint64_t key = uint64_t(std::min(a, b)) << 32 | std::max(a, b);
    auto [it, fresh] = edge_of_pair.try_emplace(key, uint32_t(c.edge_half.size()));
    const uint32_t e = it->second;
    c.half_edge[h] = e;
    if (fresh) {
      c.edge_half.push_back({h, kNone});
      continue;
    }
    if (c.edge_half[e][1] != kNone)
      return Status::failure(src + ": edge between vertices " + obj_vertex(std::min(a, b)) + " and " + obj_vertex(std::max(a, b)) +
                             " (OBJ numbering) is shared by 3 faces; a polyline mesh needs a manifold mesh");
    c.edge_half[e][1] = h;
  }
  for (uint32_t e = 0; e < c.edge_count(); ++e) {
    const auto [h0, h1] = c.edge_half[e];
    if (h1 != kNone && c.tail(h0) == c.tail(h1))
      return Status::failure(src + ": faces " + std::to_string(c.half_face[h0] + 1) + " and " + std::to_string(c.half_face[h1] + 1) +
                             " (OBJ numbering) both walk the edge from vertex " + obj_vertex(c.tail(h0)) + " to vertex " +
                             obj_vertex(c.head(h0)) + "; the faces must be oriented consistently");
  }
  c.vertex_edges.resize(c.vertex_count());
  c.vertex_corners.resize(c.vertex_count());
  for (uint32_t e = 0; e < c.edge_count(); ++e) {
    c.vertex_edges[c.edge_tail(e)].push_back(e);
    c.vertex_edges[c.edge_head(e)].push_back(e);
  }
  for (uint32_t h = 0; h < nh; ++h) c.vertex_corners[c.head(h)].push_back(h);
  return Status::success();
}

struct EdgeLoops {
  UnionFind loops;         // root: the loop's smallest edge
  std::vector<uint8_t> regular;  // vertex where loops run straight through (see edge_loops)
};

// Pairs of edges that continue each other through a vertex, making edge loops. At an interior vertex of
// valence 4 surrounded by quads, the edge two steps around continues an edge; at a border vertex of
// valence 3 between two quads, the two border edges continue each other. Elsewhere (extraordinary
// vertices, triangles, n-gons, non-manifold fans) loops stop. Those two cases and the valence-2 corner of
// one quad are the regular vertices of a quad grid.
EdgeLoops edge_loops(const Control& c, std::span<const uint32_t> offsets) {
  EdgeLoops out{UnionFind(c.edge_count()), std::vector<uint8_t>(c.vertex_count(), 0)};
  for (uint32_t v = 0; v < c.vertex_count(); ++v) {
    const auto& edges = c.vertex_edges[v];
    const auto& corners = c.vertex_corners[v];
    bool quads = std::all_of(corners.begin(), corners.end(), [&](uint32_t h) { return c.face_size(c.half_face[h], offsets) == 4; });
    if (!quads) continue;
    // The corner at v joins edge(h) (arriving) and edge(next h) (leaving): the fan around v.
    auto neighbours = [&](uint32_t e) {
      std::vector<uint32_t> n;
      for (uint32_t h : corners) {
        if (c.half_edge[h] == e) n.push_back(c.half_edge[c.half_next[h]]);
        if (c.half_edge[c.half_next[h]] == e) n.push_back(c.half_edge[h]);
      }
      return n;
    };
    if (edges.size() == 4 && corners.size() == 4) {
      const uint32_t e0 = edges[0];
      auto n0 = neighbours(e0);
      if (n0.size() != 2) continue;
      const uint32_t e1 = n0[0];
      auto n1 = neighbours(e1);
      if (n1.size() != 2) continue;
      const uint32_t e2 = n1[0] == e0 ? n1[1] : n1[0];
      auto n2 = neighbours(e2);
      if (n2.size() != 2 || e2 == e0) continue;
      const uint32_t e3 = n2[0] == e1 ? n2[1] : n2[0];
      auto n3 = neighbours(e3);
      // One cycle of four distinct edges, not two fans meeting at v.
      if (n3.size() != 2 || e3 == e1 || e3 == e0 || (n3[0] != e0 && n3[1] != e0)) continue;
      out.loops.unite(e0, e2);
      out.loops.unite(e1, e3);
      out.regular[v] = 1;
    } else if (edges.size() == 3 && corners.size() == 2) {
      std::vector<uint32_t> border, inner;
      for (uint32_t e : edges) (c.border(e) ? border : inner).push_back(e);
      if (border.size() != 2 || neighbours(inner[0]).size() != 2) continue;
      out.loops.unite(border[0], border[1]);
      out.regular[v] = 1;
    } else if (edges.size() == 2 && corners.size() == 1) {
      out.regular[v] = 1;
    }
  }
  return out;
}

// Which edges survive unrefinement by K. Loops form families: a quad's opposite edges lie in adjacent
// loops of one family (the parallel loops of a quad strip). Only quads whose four corners are regular
// link loops: around an extraordinary vertex the strips turn (a pole's spokes lie opposite ring edges),
// and linking there would merge the two directions into one family and count across the turn. Loops are
// numbered within their family and those numbered 0, K, 2K, ... are kept:
// - a family whose loops form a cycle (around a torus or a surface of revolution) is numbered along the
//   cycle from its first loop, so K that does not divide the cycle's length still keeps loops K apart
//   except for one shorter gap;
// - any other family is numbered by breadth-first distance from its border loops (the border is always
//   kept, so the kept loops are spaced K from it too), or from its first loop when it has none.
// A loop with no linked neighbour is a family of its own and is kept.
// Border loops and creases (`creased`, per edge) are always kept, and the count of loops starts from them.
std::vector<uint8_t> kept_edges(const Control& c, std::span<const uint32_t> offsets, uint32_t k, const std::vector<uint8_t>& creased) {
  const size_t ne = c.edge_count();
  EdgeLoops el = edge_loops(c, offsets);
  UnionFind& loops = el.loops;
  std::vector<std::vector<uint32_t>> adjacent(ne);  // indexed by loop root
  UnionFind families(ne);
  for (uint32_t f = 0; f + 1 < offsets.size(); ++f) {
    if (c.face_size(f, offsets) != 4) continue;
    const uint32_t h = offsets[f];
    bool regular = true;
    for (uint32_t s = 0; s < 4; ++s) regular = regular && el.regular[c.tail(h + s)];
    if (!regular) continue;
    for (uint32_t s = 0; s < 2; ++s) {
      const uint32_t a = loops.find(c.half_edge[h + s]), b = loops.find(c.half_edge[h + s + 2]);
      if (a == b) continue;
      adjacent[a].push_back(b);
      adjacent[b].push_back(a);
      families.unite(a, b);
    }
  }
  std::vector<uint8_t> seed_loop(ne, 0);  // indexed by loop root: a border or a crease
  for (uint32_t e = 0; e < ne; ++e)
    if (c.border(e) || creased[e]) seed_loop[loops.find(e)] = 1;
  std::vector<std::vector<uint32_t>> members(ne);  // indexed by family root, ascending loop roots
  for (uint32_t l = 0; l < ne; ++l) {
    if (loops.find(l) != l) continue;
    auto& adj = adjacent[l];
    std::sort(adj.begin(), adj.end());
    adj.erase(std::unique(adj.begin(), adj.end()), adj.end());
    members[families.find(l)].push_back(l);
  }

  constexpr uint32_t kFar = 0xFFFFFFFFu;
  std::vector<uint32_t> number(ne, kFar);
  for (const auto& family : members) {
    if (family.empty()) continue;
    std::vector<uint32_t> seeds;
    for (uint32_t l : family)
      if (seed_loop[l]) seeds.push_back(l);
    if (seeds.empty()) seeds.push_back(family[0]);
    const bool cycle = family.size() >= 3 &&
                       std::all_of(family.begin(), family.end(), [&](uint32_t l) { return adjacent[l].size() == 2; });
    if (cycle) {
      uint32_t previous = kFar, current = seeds[0];
      for (uint32_t i = 0; i < family.size(); ++i) {
        number[current] = i;
        const auto& adj = adjacent[current];
        const uint32_t next = adj[0] != previous ? adj[0] : adj[1];
        previous = current;
        current = next;
      }
      continue;
    }
    std::deque<uint32_t> queue(seeds.begin(), seeds.end());
    for (uint32_t l : seeds) number[l] = 0;
    while (!queue.empty()) {
      const uint32_t l = queue.front();
      queue.pop_front();
      for (uint32_t m : adjacent[l])
        if (number[m] == kFar) {
          number[m] = number[l] + 1;
          queue.push_back(m);
        }
    }
  }
  std::vector<uint8_t> kept(ne, 0);
  for (uint32_t e = 0; e < ne; ++e) kept[e] = c.border(e) || creased[e] || number[loops.find(e)] % k == 0;
  return kept;
}

// Drops kept edges that end in a vertex with no other kept edge, until none is left.
void prune_dangling(const Control& c, std::vector<uint8_t>& kept, std::vector<uint32_t>& kept_valence) {
  kept_valence.assign(c.vertex_count(), 0);
  for (uint32_t e = 0; e < c.edge_count(); ++e)
    if (kept[e]) {
      ++kept_valence[c.edge_tail(e)];
      ++kept_valence[c.edge_head(e)];
    }
  std::vector<uint32_t> stack;
  for (uint32_t v = 0; v < c.vertex_count(); ++v)
    if (kept_valence[v] == 1) stack.push_back(v);
  while (!stack.empty()) {
    const uint32_t v = stack.back();
    stack.pop_back();
    if (kept_valence[v] != 1) continue;
    for (uint32_t e : c.vertex_edges[v]) {
      if (!kept[e]) continue;
      kept[e] = 0;
      const uint32_t w = c.other_end(e, v);
      --kept_valence[v];
      if (--kept_valence[w] == 1) stack.push_back(w);
      break;
    }
  }
}

struct Chain {
  std::vector<uint32_t> vertices;  // control vertices, first and last survive
};

}  // namespace

void sample_chain_linear(std::span<const Vec3> positions, std::span<const uint32_t> chain, uint32_t samples_per_edge,
                         std::vector<Vec3>& out) {
  for (size_t i = 0; i + 1 < chain.size(); ++i) {
    const Vec3& a = positions[chain[i]];
    const Vec3& b = positions[chain[i + 1]];
    for (uint32_t j = 0; j < samples_per_edge; ++j) {
      const double t = double(j) / samples_per_edge;
      out.push_back((1.0 - t) * a + t * b);
    }
  }
  out.push_back(positions[chain.back()]);
}

Result<Mesh> network_from_mesh(const PolygonMeshView& control, const UnrefineOptions& o) {
  const std::string src = control.source.empty() ? std::string("mesh") : std::string(control.source);
  auto fail = [](std::string why) { return Result<Mesh>::failure(std::move(why)); };
  if (auto s = check_input(control, o, src); !s) return fail(s.error);
  Control c;
  if (auto s = build_control(control, src, c); !s) return fail(s.error);
  const auto offsets = control.face_offsets;
  const size_t nv = c.vertex_count(), ne = c.edge_count(), nf = offsets.size() - 1;

  std::set<std::pair<uint32_t, uint32_t>> crease;
  for (size_t i = 0; i + 1 < o.sharp_edges.size(); i += 2) crease.insert(std::minmax(o.sharp_edges[i], o.sharp_edges[i + 1]));
  std::vector<uint8_t> creased(ne, 0);
  for (uint32_t e = 0; e < ne; ++e) creased[e] = crease.contains(std::minmax(c.edge_tail(e), c.edge_head(e)));
  std::vector<uint8_t> kept = kept_edges(c, offsets, o.unrefine, creased);
  std::vector<uint32_t> kept_valence;
  prune_dangling(c, kept, kept_valence);

  // Network faces: control faces merged across dropped edges. Each must be a disk bounded by one loop.
  UnionFind regions(nf);
  for (uint32_t e = 0; e < ne; ++e)
    if (!kept[e]) regions.unite(c.half_face[c.edge_half[e][0]], c.half_face[c.edge_half[e][1]]);
  std::vector<uint32_t> region_faces(nf, 0), region_edges(nf, 0), region_vertices(nf, 0), region_border(nf, 0);
  std::vector<uint32_t> first_border_half(nf, kNone);
  for (uint32_t f = 0; f < nf; ++f) ++region_faces[regions.find(f)];
  for (uint32_t e = 0; e < ne; ++e)
    if (!kept[e]) ++region_edges[regions.find(c.half_face[c.edge_half[e][0]])];
  for (uint32_t h = 0; h < c.half_face.size(); ++h) {
    if (!kept[c.half_edge[h]]) continue;
    const uint32_t r = regions.find(c.half_face[h]);
    ++region_edges[r];
    ++region_border[r];
    if (first_border_half[r] == kNone) first_border_half[r] = h;
  }
  for (uint32_t v = 0; v < nv; ++v) {
    std::vector<uint32_t> around;
    for (uint32_t h : c.vertex_corners[v]) around.push_back(regions.find(c.half_face[h]));
    std::sort(around.begin(), around.end());
    around.erase(std::unique(around.begin(), around.end()), around.end());
    for (uint32_t r : around) ++region_vertices[r];
  }
  auto not_a_disk = [&](uint32_t r, const std::string& why) {
    return fail("unrefine " + std::to_string(o.unrefine) + " too coarse for " + src + ": the region merged from " +
                std::to_string(region_faces[r]) + " faces around face " + std::to_string(r + 1) +
                " (OBJ numbering) is not a disk (" + why + ")");
  };
  for (uint32_t e = 0; e < ne; ++e)
    if (kept[e] && !c.border(e) &&
        regions.find(c.half_face[c.edge_half[e][0]]) == regions.find(c.half_face[c.edge_half[e][1]]))
      return not_a_disk(regions.find(c.half_face[c.edge_half[e][0]]),
                        "the kept edge between vertices " + obj_vertex(c.edge_tail(e)) + " and " + obj_vertex(c.edge_head(e)) +
                            " runs through it");

  // The region's border half-edge after h: turn around head(h) through the region's faces until a kept edge.
  auto next_border = [&](uint32_t h) {
    uint32_t g = c.half_next[h];
    for (size_t turns = 0; !kept[c.half_edge[g]] && turns <= c.vertex_corners[c.head(h)].size(); ++turns)
      g = c.half_next[c.twin(g)];
    return g;
  };
  std::vector<std::vector<uint32_t>> border_walk(nf);
  for (uint32_t r = 0; r < nf; ++r) {
    if (regions.find(r) != r) continue;
    if (region_border[r] == 0) return not_a_disk(r, "it has no border");
    const int64_t euler = int64_t(region_vertices[r]) - region_edges[r] + region_faces[r];
    if (euler != 1) return not_a_disk(r, "its Euler characteristic is " + std::to_string(euler) + ", not 1");
    auto& walk = border_walk[r];
    uint32_t h = first_border_half[r];
    do {
      walk.push_back(h);
      h = next_border(h);
    } while (h != first_border_half[r] && walk.size() <= region_border[r]);
    if (walk.size() != region_border[r]) return not_a_disk(r, "its border is not one closed loop");
  }

  // Network vertices: kept valence 3 or more, and every vertex of the border polygon (thesis figure 63
  // collapses only the interior vertices of valence 2).
  std::vector<uint8_t> on_border(nv, 0);
  for (uint32_t e = 0; e < ne; ++e)
    if (c.border(e)) on_border[c.edge_tail(e)] = on_border[c.edge_head(e)] = 1;
  std::vector<uint8_t> survives(nv, 0);
  for (uint32_t v = 0; v < nv; ++v) survives[v] = kept_valence[v] >= 3 || (on_border[v] && kept_valence[v] >= 2);

  std::vector<std::vector<uint32_t>> kept_at(nv);
  for (uint32_t v = 0; v < nv; ++v)
    for (uint32_t e : c.vertex_edges[v])
      if (kept[e]) kept_at[v].push_back(e);

  std::vector<Chain> chains;
  std::vector<uint32_t> edge_chain(ne, kNone), chain_enters_from(ne, kNone);
  auto walk_chain = [&](uint32_t v, uint32_t e) {
    Chain chain{{v}};
    const uint32_t id = uint32_t(chains.size());
    for (;;) {
      edge_chain[e] = id;
      chain_enters_from[e] = v;
      v = c.other_end(e, v);
      chain.vertices.push_back(v);
      if (survives[v]) break;
      e = kept_at[v][0] == e ? kept_at[v][1] : kept_at[v][0];
    }
    chains.push_back(std::move(chain));
  };
  // An edge may not join a vertex to itself, so a closed curve keeps two of its valence-2 vertices: the
  // first of a loop with no vertex at all, then the middle of every chain that returns to its start.
  for (bool changed = true; changed;) {
    changed = false;
    chains.clear();
    std::fill(edge_chain.begin(), edge_chain.end(), kNone);
    for (uint32_t v = 0; v < nv; ++v)
      if (survives[v])
        for (uint32_t e : kept_at[v])
          if (edge_chain[e] == kNone) walk_chain(v, e);
    for (uint32_t e = 0; e < ne; ++e)
      if (kept[e] && edge_chain[e] == kNone) {
        survives[c.edge_tail(e)] = 1;
        walk_chain(c.edge_tail(e), e);
        changed = true;
      }
    for (const Chain& chain : chains)
      if (chain.vertices.front() == chain.vertices.back()) {
        survives[chain.vertices[chain.vertices.size() / 2]] = 1;
        changed = true;
      }
    // A face needs 3 sides for the thesis's reconstruction (it has no rule for 2-sided faces): where
    // collapsing left fewer, the middle vertex of the longest collapsed run on its border stays.
    for (uint32_t r = 0; r < nf && !changed; ++r) {
      if (regions.find(r) != r) continue;
      const auto& walk = border_walk[r];
      size_t corners = 0;
      for (uint32_t h : walk) corners += survives[c.tail(h)];
      if (corners == 0 || corners >= 3 || walk.size() < 3) continue;
      size_t start = 0;
      while (!survives[c.tail(walk[start])]) ++start;
      size_t best_first = 0, best_length = 0;
      for (size_t i = 1, run = 0; i <= walk.size(); ++i) {
        if (i < walk.size() && !survives[c.tail(walk[(start + i) % walk.size()])]) {
          if (++run > best_length) best_length = run, best_first = i + 1 - run;
        } else {
          run = 0;
        }
      }
      survives[c.tail(walk[(start + best_first + (best_length - 1) / 2) % walk.size()])] = 1;
      changed = true;
    }
  }

  std::optional<LimitCurves> limit;
  if (o.limit) {
    auto built = LimitCurves::build(control, o.samples_per_edge, o.sharp_edges, o.border_corners);
    if (!built) return fail(built.error());
    limit = std::move(*built);
  }

  Mesh mesh;
  std::vector<VertexIndex> net_vertex(nv);
  for (uint32_t v = 0; v < nv; ++v)
    if (survives[v]) net_vertex[v] = mesh.add_vertex(limit ? limit->vertex(v) : c.positions[v]);

  double total_length = 0;
  for (uint32_t e = 0; e < ne; ++e) total_length += (c.positions[c.edge_head(e)] - c.positions[c.edge_tail(e)]).norm();
  const double sigma = o.noise_percent / 100.0 * (total_length / double(ne));
  const double correlation = o.noise_correlation_percent / 100.0 * (total_length / double(ne));
  Gaussian noise(o.seed);
  std::vector<EdgeIndex> chain_edge(chains.size());
  std::vector<Vec3> line;
  for (size_t k = 0; k < chains.size(); ++k) {
    const auto& cv = chains[k].vertices;
    line.clear();
    if (!limit) sample_chain_linear(c.positions, cv, o.samples_per_edge, line);
    else if (!limit->sample_chain(cv, line)) return fail(src + ": internal error: a chain leaves the control edges");
    if (sigma > 0) {
      std::vector<Vec3> white(line.size(), Vec3::Zero());
      for (size_t i = 1; i + 1 < line.size(); ++i) {
        // Drawn one by one: the order of evaluation of constructor arguments is unspecified.
        const double dx = noise.next();
        const double dy = noise.next();
        const double dz = noise.next();
        white[i] = Vec3(dx, dy, dz);
      }
      const std::vector<Vec3> offsets = correlation > 0 ? correlate_along(line, white, correlation) : white;
      for (size_t i = 1; i + 1 < line.size(); ++i) {
        line[i] += sigma * offsets[i];
        if (!is_finite(line[i])) return fail(src + ": noise of " + std::to_string(o.noise_percent) + " percent overflows the coordinates");
      }
    }
    chain_edge[k] = mesh.add_edge(net_vertex[cv.front()], net_vertex[cv.back()], line);
    bool sharp = !o.sharp_edges.empty();
    for (size_t i = 0; i + 1 < cv.size() && sharp; ++i) sharp = crease.contains(std::minmax(cv[i], cv[i + 1]));
    if (sharp) mesh.set_edge_flag(chain_edge[k], kSharpEdge, true);
  }

  for (uint32_t r = 0; r < nf; ++r) {
    if (regions.find(r) != r) continue;
    const auto& walk = border_walk[r];
    // Start at a network vertex so that every chain's half-edges are consecutive.
    size_t start = 0;
    while (!survives[c.tail(walk[start])]) ++start;
    std::vector<OrientedEdge> loop;
    for (size_t i = 0; i < walk.size(); ++i) {
      const uint32_t h = walk[(start + i) % walk.size()];
      if (!survives[c.tail(h)]) continue;
      const uint32_t e = c.half_edge[h];
      loop.push_back(make_oriented(chain_edge[edge_chain[e]], chain_enters_from[e] != c.tail(h)));
    }
    if (mesh.add_face(loop) == kNone) return fail(src + ": internal error: region of face " + std::to_string(r + 1) + " gives no face loop");
  }
  if (auto why = mesh.validate(); !why.empty()) return fail(src + ": internal error: the network is invalid: " + why);
  return mesh;
}

}  // namespace fire

namespace fire {

Result<LimitCurves> LimitCurves::build(const PolygonMeshView& control, uint32_t samples_per_edge, std::span<const uint32_t> sharp_edges,
                                       std::span<const uint8_t> border_corners) {
  int levels = 0;
  while ((1u << levels) < samples_per_edge) ++levels;
  levels = std::max(levels, 1);
  const catmull_clark::BaseTopology base{uint32_t(control.positions.size()), control.face_offsets, control.face_vertices, sharp_edges,
                                        border_corners};
  auto refinement = catmull_clark::build_refinement(base, {levels, true});
  if (!refinement) return Result<LimitCurves>::failure(std::string(control.source) + ": " + refinement.error());
  auto stencils = catmull_clark::build_limit_stencils(*refinement);
  if (!stencils) return Result<LimitCurves>::failure(std::string(control.source) + ": " + stencils.error());
  std::vector<Vec3> last, scratch, normals;
  catmull_clark::evaluate(*refinement, control.positions, last, scratch);
  LimitCurves curves;
  catmull_clark::evaluate_limit(*stencils, last, curves.limit_, normals);

  const catmull_clark::Level& L0 = refinement->levels[0];
  curves.base_edge_vertices_ = L0.edge_vertices;
  for (uint32_t v = 0; v < L0.vertex_count; ++v) curves.last_of_base_.push_back(catmull_clark::last_level_vertex(*refinement, v));
  curves.along_.resize(L0.edge_count());
  for (uint32_t e = 0; e < L0.edge_count(); ++e) {
    const uint32_t a = L0.edge_vertices[2 * e], b = L0.edge_vertices[2 * e + 1];
    catmull_clark::vertices_along_edge(*refinement, 0, e, a, curves.along_[e]);
    curves.edge_by_ends_.emplace_back(uint64_t(std::min(a, b)) << 32 | std::max(a, b), e);
  }
  std::sort(curves.edge_by_ends_.begin(), curves.edge_by_ends_.end());
  return curves;
}

bool LimitCurves::sample_chain(std::span<const uint32_t> chain, std::vector<Vec3>& out) const {
  for (size_t i = 0; i + 1 < chain.size(); ++i) {
    const uint32_t a = chain[i], b = chain[i + 1];
    const uint64_t key = uint64_t(std::min(a, b)) << 32 | std::max(a, b);
    auto it = std::lower_bound(edge_by_ends_.begin(), edge_by_ends_.end(), std::make_pair(key, 0u));
    if (it == edge_by_ends_.end() || it->first != key) return false;
    const auto& ids = along_[it->second];
    if (base_edge_vertices_[2 * it->second] == a)
      for (uint32_t id : ids) out.push_back(limit_[id]);
    else {
      // Walked from b: the reverse of [b .. a) is (a .. b], so start at a and drop b.
      out.push_back(vertex(a));
      for (size_t k = ids.size(); k-- > 1;) out.push_back(limit_[ids[k]]);
    }
  }
  out.push_back(vertex(chain.back()));
  return true;
}

}  // namespace fire

namespace fire {

Result<PolygonMesh> limit_mesh(const PolygonMeshView& control, int levels, std::span<const uint32_t> sharp_edges,
                               std::span<const uint8_t> border_corners) {
  Result<catmull_clark::SubdividedMesh> sub = catmull_clark::subdivide({control, sharp_edges, border_corners}, levels);
  if (!sub) return Result<PolygonMesh>::failure(std::string(control.source) + ": " + sub.error());
  PolygonMesh out;
  out.positions = std::move(sub->limit_positions);
  out.face_vertices = std::move(sub->quads);
  for (size_t f = 1; f <= out.face_vertices.size() / 4; ++f) out.face_offsets.push_back(static_cast<uint32_t>(4 * f));
  return out;
}

}  // namespace fire
