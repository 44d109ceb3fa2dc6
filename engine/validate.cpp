// Mesh::validate: every invariant of the polyline mesh (thesis 5.1) and of the pools, first violation in words.
#include <string>
#include <vector>

#include "engine/mesh.hpp"

namespace fire {

namespace {

std::string str(uint32_t x) { return x == kNone ? std::string("none") : std::to_string(x); }

}  // namespace

std::string Mesh::validate() const {
  const size_t nv = vertex_slots(), ne = edge_slots(), nf = face_slots();
  if (vertices.position.size() != nv || vertices.first_edge.size() != nv || vertices.generation.size() != nv)
    return "vertex pool arrays have different lengths";
  if (edges.vertex.size() != ne || edges.face.size() != ne || edges.next.size() != ne ||
      edges.point_offset.size() != ne || edges.point_count.size() != ne || edges.generation.size() != ne)
    return "edge pool arrays have different lengths";
  if (faces.edge_offset.size() != nf || faces.edge_count.size() != nf || faces.generation.size() != nf)
    return "face pool arrays have different lengths";

  // Free lists hold exactly the dead slots, once each.
  auto check_free = [](const Column<uint32_t>& free_list, const Column<uint8_t>& flags, const char* kind) -> std::string {
    std::vector<uint8_t> seen(flags.size(), 0);
    for (uint32_t s : free_list.values()) {
      if (s >= flags.size()) return std::string(kind) + " free list names slot " + std::to_string(s) + " beyond the pool";
      if (flags[s] & kAlive) return std::string(kind) + " " + std::to_string(s) + " is on the free list but alive";
      if (seen[s]++) return std::string(kind) + " " + std::to_string(s) + " is on the free list twice";
    }
    for (uint32_t s = 0; s < flags.size(); ++s)
      if (!(flags[s] & kAlive) && !seen[s]) return std::string(kind) + " " + std::to_string(s) + " is dead but not on the free list";
    return {};
  };
  if (auto w = check_free(vertices.free_list, vertices.flags, "vertex"); !w.empty()) return w;
  if (auto w = check_free(edges.free_list, edges.flags, "edge"); !w.empty()) return w;
  if (auto w = check_free(faces.free_list, faces.flags, "face"); !w.empty()) return w;

  for (VertexIndex v{0}; v < nv; ++v) {
    if (!vertex_alive(v)) continue;
    if (!is_finite(vertices.position[v])) return "vertex " + str(v) + " has a non-finite position";
  }

  // Face ranges before the edges: an edge's check walks the loops of the faces it names.
  for (FaceIndex f{0}; f < nf; ++f) {
    if (!face_alive(f)) continue;
    const uint32_t off = faces.edge_offset[f], cnt = faces.edge_count[f];
    if (cnt < 2) return "face " + str(f) + " has " + std::to_string(cnt) + " edge(s); a face needs at least 2";
    if (size_t(off) + cnt > face_edges.size()) return "face " + str(f) + "'s edge list runs past the face-edge array";
  }

  size_t incidences = 0;
  for (EdgeIndex e{0}; e < ne; ++e) {
    if (!edge_alive(e)) continue;
    const auto ev = edges.vertex[e];
    const std::string name = "edge " + str(e);
    if (!vertex_alive(VertexIndex{ev[0]}) || !vertex_alive(VertexIndex{ev[1]})) return name + " joins a dead or missing vertex (" + str(ev[0]) + ", " + str(ev[1]) + ")";
    if (ev[0] == ev[1]) return name + " joins vertex " + str(ev[0]) + " to itself";
    const uint32_t off = edges.point_offset[e], cnt = edges.point_count[e];
    if (cnt < 2) return name + " has a polyline of " + std::to_string(cnt) + " point(s); at least 2 are needed";
    if (size_t(off) + cnt > points.size()) return name + "'s polyline runs past the point pool";
    auto line = polyline(e);
    for (uint32_t i = 0; i < cnt; ++i)
      if (!is_finite(line[i])) return name + " has a non-finite polyline point " + std::to_string(i);
    if (line.front() != vertices.position[ev[0]]) return name + "'s polyline does not start at its vertex " + str(ev[0]);
    if (line.back() != vertices.position[ev[1]]) return name + "'s polyline does not end at its vertex " + str(ev[1]);
    const auto ef = edges.face[e];
    for (int side = 0; side < 2; ++side) {
      const FaceIndex f{ef[side]};
      if (f == kNone) continue;
      if (!face_alive(f)) return name + " refers to dead face " + str(f);
      uint32_t hits = 0;
      for (OrientedEdge oe : face_loop(f))
        if (edge_of(oe) == e) {
          ++hits;
          if (is_reversed(oe) != (side == 1)) return name + " is walked by face " + str(f) + " in the direction its other side claims";
        }
      if (hits != 1) return name + " appears " + std::to_string(hits) + " times in face " + str(f) + " that it names";
    }
    if (ef[0] != kNone && ef[0] == ef[1]) return name + " has face " + str(ef[0]) + " on both sides";
    if ((edges.flags[e] & kBridgeEdge) && (ef[0] != kNone || ef[1] != kNone)) return name + " is a bridge but has a face";
    if ((edges.flags[e] & kPendingEdge) && (ef[0] != kNone || ef[1] != kNone)) return name + " is pending but has a face";
    ++incidences;
  }

  // V -> E lists: every live edge exactly in the lists of its two vertices, nothing else.
  size_t listed = 0;
  for (VertexIndex v{0}; v < nv; ++v) {
    if (!vertex_alive(v)) continue;
    size_t steps = 0;
    for (EdgeIndex e{vertices.first_edge[v]}; e != kNone;) {
      if (!edge_alive(e)) return "vertex " + str(v) + "'s edge list holds dead edge " + str(e);
      if (edges.vertex[e][0] != v && edges.vertex[e][1] != v) return "vertex " + str(v) + "'s edge list holds edge " + str(e) + " that does not touch it";
      if (++steps > ne) return "vertex " + str(v) + "'s edge list loops";
      ++listed;
      e = EdgeIndex{edges.next[e][edges.vertex[e][0] == v ? 0 : 1]};
    }
  }
  if (listed != 2 * incidences) return "vertex edge lists hold " + std::to_string(listed) + " entries for " + std::to_string(incidences) + " edges";
  // A pending chain lies apart from the network until the stroke that finishes it.
  for (EdgeIndex e{0}; e < ne; ++e)
    if (edge_alive(e) && (edges.flags[e] & kPendingEdge))
      for (uint32_t v : edges.vertex[e])
        for (EdgeIndex g : vertex_edges(VertexIndex{v}))
          if (!(edges.flags[g] & kPendingEdge)) return "edge " + str(e) + " is pending but touches curve " + str(g) + " of the network";

  for (FaceIndex f{0}; f < nf; ++f) {
    if (!face_alive(f)) continue;
    const std::string name = "face " + str(f);
    const uint32_t cnt = faces.edge_count[f];
    auto loop = face_loop(f);
    for (uint32_t k = 0; k < cnt; ++k) {
      const EdgeIndex e = edge_of(loop[k]);
      if (!edge_alive(e)) return name + " uses dead edge " + str(e);
      if (edges.face[e][is_reversed(loop[k])] != f) return name + " uses edge " + str(e) + " which does not name it back";
      if (head(loop[k]) != tail(loop[(k + 1) % cnt]))
        return name + " is not a closed loop: edge " + str(e) + " ends at vertex " + str(head(loop[k])) + " but the next starts at " + str(tail(loop[(k + 1) % cnt]));
    }
  }
  return {};
}

}  // namespace fire
