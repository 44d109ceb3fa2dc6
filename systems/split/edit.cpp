#include "systems/split/edit.hpp"

#include "engine/session_dir.hpp"

#include <algorithm>
#include <span>
#include <utility>

namespace fire {

namespace {

std::string str(uint32_t x) { return std::to_string(x); }

Status check_points(const std::vector<Vec3>& points) {
  if (points.size() < 2) return Status::failure("a curve needs at least 2 points, got " + str(uint32_t(points.size())));
  for (size_t i = 0; i < points.size(); ++i)
    if (!is_finite(points[i])) return Status::failure("curve point " + str(uint32_t(i)) + " is not finite (NaN or infinity)");
  return Status::success();
}

bool has_faces(const Mesh& m) { return m.face_count() > 0; }

// The open border chain, in drawing order: its first and last vertices and its edges.
struct BorderChain {
  VertexIndex first, last;
  std::vector<EdgeIndex> edges;
};

BorderChain open_border(const Mesh& m) {
  BorderChain chain;
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
    if (m.edge_alive(e) && m.valence(VertexIndex{m.edges.vertex[e][0]}) == 1) chain.first = VertexIndex{m.edges.vertex[e][0]};
  if (chain.first == kNone) return chain;
  VertexIndex v = chain.first;
  EdgeIndex came;
  for (;;) {
    EdgeIndex next;
    for (EdgeIndex e : m.vertex_edges(v))
      if (e != came && m.edges.vertex[e][0] == v) next = e;
    if (next == kNone) break;
    chain.edges.push_back(next);
    came = next;
    v = VertexIndex{m.edges.vertex[next][1]};
  }
  chain.last = v;
  return chain;
}

// What append and close ask before the curve goes on from the open border's last vertex.
Status check_continues_border(const Mesh& m, const EditCommand& c) {
  if (m.edge_count() == 0) return Status::failure("no border polygon has been started");
  if (!m.border_in_progress()) return Status::failure("the border polygon is already closed");
  return check_points(c.points);
}

Status start_border(Mesh& m, const EditCommand& c) {
  if (m.border_in_progress()) return Status::failure("a border polygon is being drawn; close it before starting another part");
  // A border is found by its vertices of one curve, as a pending chain's ends are.
  if (m.pending_piece_count() > 0) return Status::failure("a stroke in pieces is pending; finish it or undo it before starting another part");
  if (auto ok = check_points(c.points); !ok.ok()) return ok;
  if (c.points.front() == c.points.back()) return Status::failure("the first border curve ends where it starts");
  const VertexIndex a = m.add_vertex(c.points.front());
  const VertexIndex b = m.add_vertex(c.points.back());
  m.add_edge(a, b, c.points);
  return Status::success();
}

Status append_border(Mesh& m, const EditCommand& c) {
  if (auto ok = check_continues_border(m, c); !ok.ok()) return ok;
  BorderChain chain = open_border(m);
  if (c.points.back() == m.vertices.position[chain.last])
    return Status::failure("the border curve ends where it starts (at the last border vertex)");
  for (VertexIndex v{0}; v < m.vertex_slots(); ++v)
    if (m.vertex_alive(v) && m.vertices.position[v] == c.points.back())
      return Status::failure("the border curve ends on existing vertex " + str(v) + "; close the border instead");
  const VertexIndex b = m.add_vertex(c.points.back());
  m.add_edge(chain.last, b, c.points);
  return Status::success();
}

Status close_border(Mesh& m, const EditCommand& c) {
  if (auto ok = check_continues_border(m, c); !ok.ok()) return ok;
  BorderChain chain = open_border(m);
  double gap = (c.points.back() - m.vertices.position[chain.first]).norm();
  if (!(gap <= c.snap_distance))
    return Status::failure("the closing curve ends " + std::to_string(gap) + " from the first border vertex, farther than the snap distance " + std::to_string(c.snap_distance));
  const EdgeIndex e = m.add_edge(chain.last, chain.first, c.points);
  std::vector<OrientedEdge> loop;
  for (EdgeIndex x : chain.edges) loop.push_back(make_oriented(x, false));
  loop.push_back(make_oriented(e, false));
  if (m.add_face(loop) == kNone) return Status::failure("internal: the border does not form a closed loop");
  return Status::success();
}

// Replaces the oriented edge `old` in f's loop by `with` (already oriented in f's walking direction).
void replace_in_loop(Mesh& m, FaceIndex f, EdgeIndex old_edge, const std::vector<OrientedEdge>& with) {
  std::vector<OrientedEdge> loop;
  for (OrientedEdge oe : m.face_loop(f)) {
    if (edge_of(oe) == old_edge) loop.insert(loop.end(), with.begin(), with.end());
    else loop.push_back(oe);
  }
  m.set_face_loop(f, loop);
}

// Resolves a curve end to a vertex of face f, or reports why it cannot be used.
struct ResolvedEnd {
  VertexIndex vertex{};  // the end is this vertex
  EdgeIndex edge{};      // or an interior point of this edge
  uint32_t point = 0;
};

Status resolve_point(const Mesh& m, const CurveEnd& end, const char* which, ResolvedEnd& out) {
  uint32_t count = m.edges.point_count[end.edge];
  if (end.point >= count) return Status::failure(std::string("the curve's ") + which + " names point " + str(end.point) + " of edge " + str(end.edge) + ", which has " + str(count));
  out = {};
  if (end.point == 0) out.vertex = VertexIndex{m.edges.vertex[end.edge][0]};
  else if (end.point == count - 1) out.vertex = VertexIndex{m.edges.vertex[end.edge][1]};
  else {
    out.edge = end.edge;
    out.point = end.point;
  }
  return Status::success();
}

Status resolve_end(const Mesh& m, FaceIndex f, const CurveEnd& end, const char* which, ResolvedEnd& out) {
  if (!m.edge_alive(end.edge)) return Status::failure(std::string("the curve's ") + which + " names edge " + str(end.edge) + ", which does not exist");
  if (m.loop_position(f, end.edge) == kNone)
    return Status::failure(std::string("the curve's ") + which + " lies on edge " + str(end.edge) + ", which is not on face " + str(f) + ": a curve must start and end on the same face");
  return resolve_point(m, end, which, out);
}

// The same ends checked against a hole: both on the border loop `loop` (a Mesh::border_loop).
Status resolve_hole_end(const Mesh& m, const std::vector<OrientedEdge>& loop, const CurveEnd& end, const char* which, ResolvedEnd& out) {
  if (!m.edge_alive(end.edge)) return Status::failure(std::string("the curve's ") + which + " names edge " + str(end.edge) + ", which does not exist");
  if (std::none_of(loop.begin(), loop.end(), [&](OrientedEdge oe) { return edge_of(oe) == end.edge; }))
    return Status::failure(std::string("the curve's ") + which + " lies on edge " + str(end.edge) +
                           ", which is not on the border loop of its other end: a curve across a hole starts and ends on one border loop "
                           "(joining two border loops, for a handle or two parts, is not supported yet)");
  return resolve_point(m, end, which, out);
}

// The part of closed walk `loop` from the vertex `from` to the vertex `to`; the whole loop when they are one
// vertex and `whole`, else nothing.
std::vector<OrientedEdge> arc(const Mesh& m, std::span<const OrientedEdge> loop, VertexIndex from, VertexIndex to, bool whole) {
  const size_t n = loop.size();
  size_t i = 0;
  while (i < n && m.tail(loop[i]) != from) ++i;
  std::vector<OrientedEdge> out;
  if (from == to && !whole) return out;
  for (size_t k = 0; k < n; ++k) {
    const OrientedEdge oe = loop[(i + k) % n];
    if (k > 0 && m.tail(oe) == to) break;
    out.push_back(oe);
  }
  return out;
}

// Cuts `loop` (a closed walk through va and vb) at both vertices and closes each half with the new edge
// e = va -> vb: the walk from va to vb comes back along e reversed, the walk from vb to va along e.
std::pair<std::vector<OrientedEdge>, std::vector<OrientedEdge>> cut_loop(const Mesh& m, std::span<const OrientedEdge> loop,
                                                                         VertexIndex va, VertexIndex vb, EdgeIndex e) {
  std::vector<OrientedEdge> first = arc(m, loop, va, vb, false), second = arc(m, loop, vb, va, false);
  first.push_back(make_oriented(e, true));
  second.push_back(make_oriented(e, false));
  return {std::move(first), std::move(second)};
}

// Steps 3-6 of thesis 5.4.2: the new edge va -> vb, and face f replaced by the two loops on either side of it.
// Returns the new face (the walk from vb back to va).
FaceIndex split_between(Mesh& m, FaceIndex f, VertexIndex va, VertexIndex vb, std::span<const Vec3> points) {
  const std::vector<OrientedEdge> loop(m.face_loop(f).begin(), m.face_loop(f).end());
  const EdgeIndex e = m.add_edge(va, vb, points);
  auto [first, second] = cut_loop(m, loop, va, vb, e);
  m.set_face_loop(f, first);
  return m.add_face(second);
}

Status split_face(Mesh& m, const EditCommand& c) {
  if (!has_faces(m)) return Status::failure("close the border polygon before splitting faces");
  if (!m.face_alive(c.face)) return Status::failure("face " + str(c.face) + " does not exist");
  if (auto ok = check_points(c.points); !ok.ok()) return ok;
  ResolvedEnd a, b;
  if (auto ok = resolve_end(m, c.face, c.start, "start", a); !ok.ok()) return ok;
  if (auto ok = resolve_end(m, c.face, c.end, "end", b); !ok.ok()) return ok;
  if (a.vertex != kNone && a.vertex == b.vertex)
    return Status::failure("the curve starts and ends on vertex " + str(a.vertex) + ": it would make a face with fewer than 2 edges");
  if (a.edge != kNone && a.edge == b.edge)
    return Status::failure("the curve starts and ends on the same edge " + str(a.edge) + ": it must join two different edges of the face");

  // Steps 1-2 of thesis 5.4.2: split the edges the curve ends on; faces on both sides are updated.
  const VertexIndex va = a.vertex != kNone ? a.vertex : split_edge(m, a.edge, a.point);
  const VertexIndex vb = b.vertex != kNone ? b.vertex : split_edge(m, b.edge, b.point);

  split_between(m, c.face, va, vb, c.points);
  return Status::success();
}

// A face of the surface that should be open: it goes, and its curves become border. Only a face apart from
// the border: one beside it would leave a curve with no face at all, one touching it at a corner would pinch
// the surface to a point there.
Status make_hole(Mesh& m, const EditCommand& c) {
  const FaceIndex f = c.face;
  if (!m.face_alive(f)) return Status::failure("face " + str(f) + " does not exist");
  for (OrientedEdge oe : m.face_loop(f))
    if (m.is_border_edge(edge_of(oe)))
      return Status::failure("face " + str(f) + " lies beside the border at curve " + str(edge_of(oe)) +
                             ": a hole there would leave that curve with no surface on either side (delete curves to open the border instead)");
  for (OrientedEdge oe : m.face_loop(f)) {
    const VertexIndex v = m.tail(oe);
    for (EdgeIndex g : m.vertex_edges(v))
      if (m.is_border_edge(g))
        return Status::failure("face " + str(f) + " touches the border at vertex " + str(v) + ": a hole there would pinch the surface to a point");
  }
  m.remove_face(f);
  return Status::success();
}

// The bridge waiting at a vertex of border loop `loop`, or kNone.
EdgeIndex bridge_at(const Mesh& m, const std::vector<OrientedEdge>& loop) {
  for (OrientedEdge oe : loop)
    for (EdgeIndex g : m.vertex_edges(m.tail(oe)))
      if (m.is_waiting_bridge(g)) return g;
  return EdgeIndex{};
}

bool on_loop(const Mesh& m, const std::vector<OrientedEdge>& loop, uint32_t v) {
  return std::any_of(loop.begin(), loop.end(), [&](OrientedEdge oe) { return m.tail(oe) == v; });
}

// The border loop through vertex v, walked by its hole (empty if v is on none).
std::vector<OrientedEdge> rim_at(const Mesh& m, VertexIndex v) {
  for (EdgeIndex g : m.vertex_edges(v))
    if (m.is_border_edge(g) && !m.is_loose_edge(g)) return m.border_loop(g);
  return {};
}

// Checks one end of a curve between border loops: on a border curve with one face, whose loop has a single rim.
Status border_end(const Mesh& m, const CurveEnd& end, const char* which, std::vector<OrientedEdge>& loop) {
  if (!m.edge_alive(end.edge)) return Status::failure(std::string("the curve's ") + which + " names edge " + str(end.edge) + ", which does not exist");
  if (!m.is_border_edge(end.edge) || m.is_loose_edge(end.edge))
    return Status::failure(std::string("the curve's ") + which + " lies on curve " + str(end.edge) + ", which is not on the border");
  loop = m.border_loop(end.edge);
  if (loop.empty())
    return Status::failure("the border through curve " + str(end.edge) + " passes a vertex with more than two border curves; a hole there has no single rim");
  return Status::success();
}

// A curve from one border loop to another across the hole between them. The first between two loops is a
// bridge with no face (the hole between them is not a disc yet: no surface there); the second turns it into
// two faces, each bounded by an arc of both loops and both curves.
Status join_borders(Mesh& m, const EditCommand& c) {
  if (!has_faces(m)) return Status::failure("close a border polygon before joining border loops");
  if (m.border_in_progress()) return Status::failure("a border polygon is being drawn; close it first");
  if (auto ok = check_points(c.points); !ok.ok()) return ok;
  std::vector<OrientedEdge> loop_a, loop_b;
  if (auto ok = border_end(m, c.start, "start", loop_a); !ok.ok()) return ok;
  if (auto ok = border_end(m, c.end, "end", loop_b); !ok.ok()) return ok;
  if (on_loop(m, loop_a, m.tail(loop_b.front())))
    return Status::failure("both ends lie on one border loop: the curve crosses that loop's hole, it joins no two loops");
  ResolvedEnd a, b;
  if (auto ok = resolve_point(m, c.start, "start", a); !ok.ok()) return ok;
  if (auto ok = resolve_point(m, c.end, "end", b); !ok.ok()) return ok;
  // A bridge already waiting between these two loops.
  EdgeIndex bridge;
  for (EdgeIndex g{0}; g < m.edge_slots() && bridge == kNone; ++g) {
    if (!m.edge_alive(g) || !m.is_waiting_bridge(g)) continue;
    const auto ends = m.edges.vertex[g];
    if ((on_loop(m, loop_a, ends[0]) && on_loop(m, loop_b, ends[1])) || (on_loop(m, loop_a, ends[1]) && on_loop(m, loop_b, ends[0])))
      bridge = g;
  }
  if (bridge != kNone)
    for (uint32_t v : {a.vertex, b.vertex})
      if (v != kNone && (v == m.edges.vertex[bridge][0] || v == m.edges.vertex[bridge][1]))
        return Status::failure("the curve ends at vertex " + str(v) + ", where the bridge waiting between these loops ends: the face beside them would touch itself there");
  const VertexIndex va = a.vertex != kNone ? a.vertex : split_edge(m, a.edge, a.point);
  const VertexIndex vb = b.vertex != kNone ? b.vertex : split_edge(m, b.edge, b.point);
  const EdgeIndex e = m.add_edge(va, vb, c.points);
  if (bridge == kNone) {
    m.set_edge_flag(e, kBridgeEdge, true);
    return Status::success();
  }
  const std::vector<OrientedEdge> rim_a = rim_at(m, va), rim_b = rim_at(m, vb);
  const auto ends = m.edges.vertex[bridge];
  const VertexIndex pa{on_loop(m, rim_a, ends[0]) ? ends[0] : ends[1]}, qb{pa == ends[0] ? ends[1] : ends[0]};
  const OrientedEdge bridge_forward = make_oriented(bridge, ends[0] != pa), bridge_back = make_oriented(bridge, ends[0] == pa);
  // One face walks rim a from va to pa, the bridge, rim b from qb to vb, the new curve back; the other the rest.
  std::vector<OrientedEdge> first = arc(m, rim_a, va, pa, false), second = arc(m, rim_a, pa, va, true);
  first.push_back(bridge_forward);
  const std::vector<OrientedEdge> b_first = arc(m, rim_b, qb, vb, false), b_second = arc(m, rim_b, vb, qb, true);
  first.insert(first.end(), b_first.begin(), b_first.end());
  first.push_back(make_oriented(e, true));
  second.push_back(make_oriented(e, false));
  second.insert(second.end(), b_second.begin(), b_second.end());
  second.push_back(bridge_back);
  m.set_edge_flag(bridge, kBridgeEdge, false);
  if (m.add_face(first) == kNone || m.add_face(second) == kNone)
    return Status::failure("internal: the two curves between the border loops do not bound two faces");
  return Status::success();
}

// A curve across a border loop's hole, drawn on the far side of the surface (an object turned over to draw
// its underside): the hole is a disc like any face, and the curve splits it as split_face does.
Status split_hole(Mesh& m, const EditCommand& c) {
  if (!has_faces(m)) return Status::failure("close the border polygon before drawing across its hole");
  if (m.border_in_progress()) return Status::failure("a border polygon is being drawn; close it first");
  if (auto ok = check_points(c.points); !ok.ok()) return ok;
  std::vector<OrientedEdge> loop;
  if (auto ok = border_end(m, c.start, "start", loop); !ok.ok()) return ok;
  if (bridge_at(m, loop) != kNone)
    return Status::failure("a bridge from this border loop waits for its second curve: draw that (or undo the bridge) before crossing the loop's hole");
  ResolvedEnd a, b;
  if (auto ok = resolve_hole_end(m, loop, c.start, "start", a); !ok.ok()) return ok;
  if (auto ok = resolve_hole_end(m, loop, c.end, "end", b); !ok.ok()) return ok;
  if (a.vertex != kNone && a.vertex == b.vertex)
    return Status::failure("the curve starts and ends on vertex " + str(a.vertex) + ": it would make a face with fewer than 2 edges");
  if (a.edge != kNone && a.edge == b.edge)
    return Status::failure("the curve starts and ends on the same edge " + str(a.edge) + ": it must join two different border curves");
  const VertexIndex va = a.vertex != kNone ? a.vertex : split_edge(m, a.edge, a.point);
  const VertexIndex vb = b.vertex != kNone ? b.vertex : split_edge(m, b.edge, b.point);
  // The split edges are new: the rim is walked again from one of va's border curves.
  const std::vector<OrientedEdge> rim = rim_at(m, va);
  const EdgeIndex e = m.add_edge(va, vb, c.points);
  auto [first, second] = cut_loop(m, rim, va, vb, e);
  m.add_face(first);
  m.add_face(second);
  return Status::success();
}

// Joins the two edges at a split vertex that no curve needs any more (valence 2), undoing an edge split.
void join_at(Mesh& m, VertexIndex v) {
  if (!m.vertex_alive(v) || !(m.vertices.flags[v] & kSplitVertex) || m.valence(v) != 2) return;
  auto incident = m.vertex_edges(v);
  const EdgeIndex a = incident[0], b = incident[1];
  const VertexIndex u{m.edges.vertex[a][0] == v ? m.edges.vertex[a][1] : m.edges.vertex[a][0]};
  const VertexIndex w{m.edges.vertex[b][0] == v ? m.edges.vertex[b][1] : m.edges.vertex[b][0]};
  if (u == w) return;  // joining would make an edge from a vertex to itself
  std::vector<Vec3> line;
  auto pa = m.polyline(a);
  if (m.edges.vertex[a][1] == v) line.assign(pa.begin(), pa.end());
  else line.assign(pa.rbegin(), pa.rend());
  auto pb = m.polyline(b);
  if (m.edges.vertex[b][0] == v) line.insert(line.end(), pb.begin() + 1, pb.end());
  else line.insert(line.end(), pb.rbegin() + 1, pb.rend());
  const auto faces_of_a = m.edges.face[a];
  const bool sharp = (m.edges.flags[a] & kSharpEdge) && (m.edges.flags[b] & kSharpEdge);
  const EdgeIndex c = m.add_edge(u, w, line);
  if (sharp) m.set_edge_flag(c, kSharpEdge, true);
  for (uint32_t side : faces_of_a) {
    const FaceIndex f{side};
    if (f == kNone) continue;
    std::vector<OrientedEdge> loop;
    auto old = m.face_loop(f);
    // The face walks u -> v -> w (forward c) or w -> v -> u (reversed c); drop b, put c where a was.
    for (OrientedEdge oe : old) {
      const EdgeIndex x = edge_of(oe);
      if (x == b) continue;
      if (x == a) loop.push_back(make_oriented(c, m.head(oe) == u));
      else loop.push_back(oe);
    }
    m.set_face_loop(f, loop);
  }
  m.remove_edge(a);
  m.remove_edge(b);
  m.remove_vertex(v);
}

Status delete_curve(Mesh& m, const EditCommand& c) {
  const EdgeIndex e = c.edge;
  if (!m.edge_alive(e)) return Status::failure("edge " + str(e) + " does not exist");
  if (!has_faces(m)) return Status::failure("curves can be deleted once the border polygon is closed");
  if (m.is_pending(e)) return Status::failure("edge " + str(e) + " is a piece of a stroke still pending; undo removes its last piece");
  if (m.is_waiting_bridge(e)) {  // it goes alone
    const auto ends = m.edges.vertex[e];
    m.remove_edge(e);
    join_at(m, VertexIndex{ends[0]});
    join_at(m, VertexIndex{ends[1]});
    return Status::success();
  }
  const FaceIndex f0{m.edges.face[e][0]}, f1{m.edges.face[e][1]};
  if (f0 == kNone || f1 == kNone) return Status::failure("edge " + str(e) + " is on the border polygon; only curves inside it can be deleted");
  // The merged face walks f0 after e, then f1 after e: it must stay a simple loop.
  std::vector<OrientedEdge> merged;
  auto append_after = [&](FaceIndex f) {
    auto loop = m.face_loop(f);
    uint32_t at = m.loop_position(f, e), n = static_cast<uint32_t>(loop.size());
    for (uint32_t k = 1; k < n; ++k) merged.push_back(loop[(at + k) % n]);
  };
  append_after(f0);
  append_after(f1);
  std::vector<uint32_t> seen_edges, seen_vertices;
  for (OrientedEdge oe : merged) {
    seen_edges.push_back(edge_of(oe));
    seen_vertices.push_back(m.tail(oe));
  }
  std::sort(seen_edges.begin(), seen_edges.end());
  if (std::adjacent_find(seen_edges.begin(), seen_edges.end()) != seen_edges.end())
    return Status::failure("faces " + str(f0) + " and " + str(f1) + " share another edge besides " + str(e) + "; deleting it would make a face that touches itself");
  std::sort(seen_vertices.begin(), seen_vertices.end());
  if (std::adjacent_find(seen_vertices.begin(), seen_vertices.end()) != seen_vertices.end())
    return Status::failure("faces " + str(f0) + " and " + str(f1) + " also meet at a vertex; deleting edge " + str(e) + " would pinch the merged face");
  if (merged.size() < 2) return Status::failure("deleting edge " + str(e) + " would leave a face with fewer than 2 edges");
  const auto ends = m.edges.vertex[e];
  m.remove_face(f1);
  m.set_face_loop(f0, merged);
  m.remove_edge(e);
  join_at(m, VertexIndex{ends[0]});
  join_at(m, VertexIndex{ends[1]});
  return Status::success();
}

bool on_face(const Mesh& m, FaceIndex f, const ResolvedEnd& r) {
  if (r.vertex == kNone) return m.loop_position(f, r.edge) != kNone;
  const std::span<const OrientedEdge> loop = m.face_loop(f);
  return std::any_of(loop.begin(), loop.end(), [&](OrientedEdge oe) { return m.tail(oe) == r.vertex; });
}

// Where a cut lies along face f's walk: the loop position of its edge (of its vertex's first edge), then how far
// along that edge in the walking direction.
std::pair<size_t, uint32_t> along_loop(const Mesh& m, FaceIndex f, const ResolvedEnd& r) {
  const std::span<const OrientedEdge> loop = m.face_loop(f);
  for (size_t i = 0; i < loop.size(); ++i) {
    const EdgeIndex e = edge_of(loop[i]);
    if (r.vertex != kNone && m.tail(loop[i]) == r.vertex) return {i, 0};
    if (r.vertex == kNone && e == r.edge) return {i, is_reversed(loop[i]) ? m.edges.point_count[e] - 1 - r.point : r.point};
  }
  return {loop.size(), 0};
}

// Two chords of one face cross when exactly one end of the second lies strictly inside the first's arc.
bool chords_cross(std::pair<size_t, uint32_t> a, std::pair<size_t, uint32_t> b, std::pair<size_t, uint32_t> c,
                  std::pair<size_t, uint32_t> d) {
  if (a == c || a == d || b == c || b == d) return false;
  if (b < a) std::swap(a, b);
  auto inside = [&](std::pair<size_t, uint32_t> x) { return a < x && x < b; };
  return inside(c) != inside(d);
}

bool same_place(const ResolvedEnd& a, const ResolvedEnd& b) {
  return a.vertex != kNone ? a.vertex == b.vertex : a.edge == b.edge && a.point == b.point;
}

// A stroke drawn across curves: cut where it crosses each, and each piece splits the face it runs through. One
// command, so that one undo takes the whole stroke back.
Status cross_curves(Mesh& m, const EditCommand& c) {
  if (!has_faces(m)) return Status::failure("close the border polygon before drawing across curves");
  if (auto ok = check_points(c.points); !ok.ok()) return ok;
  if (c.crossings.empty()) return Status::failure("the stroke across curves names no crossing");
  std::vector<FaceIndex> faces{c.face};
  std::vector<uint32_t> at{0};
  std::vector<CurveEnd> cuts{c.start};
  for (const Crossing& x : c.crossings) {
    faces.push_back(x.face);
    at.push_back(x.point);
    cuts.push_back(x.at);
  }
  at.push_back(uint32_t(c.points.size() - 1));
  cuts.push_back(c.end);
  std::vector<ResolvedEnd> cut(cuts.size());
  for (size_t i = 0; i < cuts.size(); ++i) {
    const std::string which = i == 0 ? "start" : i + 1 == cuts.size() ? "end" : "crossing " + str(uint32_t(i));
    if (!m.edge_alive(cuts[i].edge)) return Status::failure("the stroke's " + which + " names edge " + str(cuts[i].edge) + ", which does not exist");
    if (auto ok = resolve_point(m, cuts[i], which.c_str(), cut[i]); !ok.ok()) return ok;
    if (i > 0 && !(at[i] > at[i - 1] && at[i] < c.points.size()))
      return Status::failure("the stroke's " + which + " is at its point " + str(at[i]) + ", not after the previous cut's and within its " +
                             str(uint32_t(c.points.size())) + " points");
    if (i > 0 && i + 1 < cuts.size() && cut[i].vertex == kNone && m.is_border_edge(cut[i].edge))
      return Status::failure("the stroke's " + which + " is on border curve " + str(cut[i].edge) + ": the stroke would leave the surface there");
    for (size_t j = 0; j < i; ++j)
      if (same_place(cut[i], cut[j]))
        return Status::failure("the stroke's " + which + " is where an earlier cut of it is: a piece would close on itself");
  }
  for (size_t i = 0; i < faces.size(); ++i) {
    if (!m.face_alive(faces[i])) return Status::failure("face " + str(faces[i]) + " does not exist");
    if (i > 0 && faces[i] == faces[i - 1])
      return Status::failure("crossing " + str(uint32_t(i)) + " leads from face " + str(faces[i]) + " into itself: a crossing changes face");
    if (!on_face(m, faces[i], cut[i]) || !on_face(m, faces[i], cut[i + 1]))
      return Status::failure("piece " + str(uint32_t(i + 1)) + " of the stroke does not start and end on the boundary of face " + str(faces[i]));
  }

  // Pieces in one face must not cross there: the stroke may not cross itself.
  for (size_t i = 0; i < faces.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (faces[j] == faces[i] && chords_cross(along_loop(m, faces[i], cut[j]), along_loop(m, faces[i], cut[j + 1]),
                                               along_loop(m, faces[i], cut[i]), along_loop(m, faces[i], cut[i + 1])))
        return Status::failure("piece " + str(uint32_t(i + 1)) + " of the stroke crosses piece " + str(uint32_t(j + 1)) + " of it in face " +
                               str(faces[i]) + "; a stroke across curves may not cross itself");

  // Cut the curves. On each edge from its last cut point to its first, so the points still to cut stay on the
  // first half, which is the edge that ends at the new vertex.
  std::vector<VertexIndex> vertex(cut.size());
  std::vector<uint32_t> order;
  for (size_t i = 0; i < cut.size(); ++i) {
    if (cut[i].vertex != kNone) vertex[i] = cut[i].vertex;
    else order.push_back(uint32_t(i));
  }
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return cut[a].edge != cut[b].edge ? cut[a].edge < cut[b].edge : cut[a].point > cut[b].point;
  });
  for (size_t k = 0; k < order.size(); ++k) {
    const uint32_t i = order[k];
    const bool same_edge_as_last = k > 0 && cut[order[k - 1]].edge == cut[i].edge;
    EdgeIndex edge = cut[i].edge;
    if (same_edge_as_last)
      for (EdgeIndex e : m.vertex_edges(vertex[order[k - 1]]))
        if (m.edges.vertex[e][1] == vertex[order[k - 1]]) edge = e;
    vertex[i] = split_edge(m, edge, cut[i].point);
  }

  // Each piece splits the part of its face (as earlier pieces left it) that holds both its ends.
  std::vector<std::pair<FaceIndex, FaceIndex>> parts;  // (face the stroke was drawn over, a face it has become)
  for (FaceIndex f : faces) parts.emplace_back(f, f);
  for (size_t i = 0; i + 1 < cut.size(); ++i) {
    const VertexIndex va = vertex[i], vb = vertex[i + 1];
    std::vector<FaceIndex> holding;
    for (const auto& [drawn, part] : parts) {
      if (drawn != faces[i] || std::count(holding.begin(), holding.end(), part)) continue;
      if (on_face(m, part, {va}) && on_face(m, part, {vb})) holding.push_back(part);
    }
    if (holding.size() != 1)  // non-crossing pieces leave one part of a disc with both ends: only a pinched face has more
      return Status::failure("piece " + str(uint32_t(i + 1)) + " of the stroke could run through " + str(uint32_t(holding.size())) +
                             " parts of face " + str(faces[i]) + "; draw it in strokes that cross fewer curves");
    std::vector<Vec3> points(c.points.begin() + at[i], c.points.begin() + at[i + 1] + 1);
    points.front() = m.vertices.position[va];
    points.back() = m.vertices.position[vb];
    parts.emplace_back(faces[i], split_between(m, holding.front(), va, vb, points));
  }
  return Status::success();
}

// The pending chain whose last piece is `last`, in drawing order; empty when `last` is no chain's last piece.
std::vector<EdgeIndex> chain_ending(const Mesh& m, EdgeIndex last) {
  if (!m.edge_alive(last) || !m.is_pending(last)) return {};
  for (std::vector<EdgeIndex>& chain : m.pending_chains())
    if (chain.back() == last) return std::move(chain);
  return {};
}

// A stroke that ends off the network: a new pending chain from the network, or the next piece of one.
Status extend_chain(Mesh& m, const EditCommand& c) {
  if (!has_faces(m)) return Status::failure("close the border polygon before drawing a stroke in pieces");
  if (auto ok = check_points(c.points); !ok.ok()) return ok;
  if (c.points.front() == c.points.back()) return Status::failure("the piece ends where it starts");
  VertexIndex from;
  if (c.edge != kNone) {
    if (chain_ending(m, c.edge).empty()) return Status::failure("edge " + str(c.edge) + " is not the last piece of a pending chain");
    from = VertexIndex{m.edges.vertex[c.edge][1]};
    if (c.points.front() != m.vertices.position[from]) return Status::failure("the piece does not start at the chain's free end");
  } else {
    from = m.add_vertex(c.points.front());
  }
  const EdgeIndex e = m.add_edge(from, m.add_vertex(c.points.back()), c.points);
  m.set_edge_flag(e, kPendingEdge, true);
  return Status::success();
}

// The pieces of a finished chain go: the curve that finished it holds their points.
void remove_chain(Mesh& m, const std::vector<EdgeIndex>& chain) {
  for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
    const auto ends = m.edges.vertex[*it];
    m.remove_edge(*it);
    m.remove_vertex(VertexIndex{ends[1]});
    if (it + 1 == chain.rend()) m.remove_vertex(VertexIndex{ends[0]});
  }
}

// A crease for subdivision along an inner curve; the border is a crease already.
Status toggle_sharp(Mesh& m, const EditCommand& c) {
  const EdgeIndex e = c.edge;
  if (!m.edge_alive(e)) return Status::failure("edge " + str(e) + " does not exist");
  if (m.is_pending(e)) return Status::failure("edge " + str(e) + " is a piece of a stroke still pending, not a curve yet");
  if (m.is_border_edge(e))
    return Status::failure("edge " + str(e) + " is on the border polygon, which is always a crease; only curves inside it can be marked sharp");
  m.set_edge_flag(e, kSharpEdge, !(m.edges.flags[e] & kSharpEdge));
  return Status::success();
}

}  // namespace

VertexIndex split_edge(Mesh& m, EdgeIndex e, uint32_t point) {
  auto line = m.polyline(e);
  std::vector<Vec3> first(line.begin(), line.begin() + point + 1);
  std::vector<Vec3> second(line.begin() + point, line.end());
  const auto ends = m.edges.vertex[e];
  const auto sides = m.edges.face[e];
  const bool sharp = m.edges.flags[e] & kSharpEdge;
  const VertexIndex v = m.add_vertex(first.back(), kSplitVertex);
  const EdgeIndex ea = m.add_edge(VertexIndex{ends[0]}, v, first);
  const EdgeIndex eb = m.add_edge(v, VertexIndex{ends[1]}, second);
  if (sharp) {
    m.set_edge_flag(ea, kSharpEdge, true);
    m.set_edge_flag(eb, kSharpEdge, true);
  }
  if (sides[0] != kNone) replace_in_loop(m, FaceIndex{sides[0]}, e, {make_oriented(ea, false), make_oriented(eb, false)});
  if (sides[1] != kNone) replace_in_loop(m, FaceIndex{sides[1]}, e, {make_oriented(eb, true), make_oriented(ea, true)});
  m.remove_edge(e);
  return v;
}

namespace {

Status run_kind(Mesh& mesh, const EditCommand& c) {
  switch (c.kind) {
    case EditKind::StartBorder: return start_border(mesh, c);
    case EditKind::AppendBorder: return append_border(mesh, c);
    case EditKind::CloseBorder: return close_border(mesh, c);
    case EditKind::SplitFace: return split_face(mesh, c);
    case EditKind::DeleteCurve: return delete_curve(mesh, c);
    case EditKind::ToggleSharp: return toggle_sharp(mesh, c);
    case EditKind::MakeHole: return make_hole(mesh, c);
    case EditKind::SplitHole: return split_hole(mesh, c);
    case EditKind::JoinBorders: return join_borders(mesh, c);
    case EditKind::CrossCurves: return cross_curves(mesh, c);
    case EditKind::ExtendChain: return extend_chain(mesh, c);
  }
  return Status::failure("unknown edit command");
}

}  // namespace

Status execute_edit(Mesh& mesh, const EditCommand& c) {
  // A curve that finishes a pending chain: the curve first, which checks before it writes, then the chain goes.
  const bool splits = c.kind == EditKind::SplitFace || c.kind == EditKind::SplitHole || c.kind == EditKind::JoinBorders ||
                      c.kind == EditKind::CrossCurves;
  std::vector<EdgeIndex> chain;
  if (splits && c.edge != kNone) {
    chain = chain_ending(mesh, c.edge);
    if (chain.empty()) return Status::failure("edge " + str(c.edge) + " is not the last piece of a pending chain");
    if (c.points.front() == c.points.back()) return Status::failure("the chain and the stroke that finishes it end where they start");
  }
  Status outcome = run_kind(mesh, c);
  if (outcome.ok()) remove_chain(mesh, chain);
  return outcome;
}

Status EditHistory::run(Mesh& mesh, const EditCommand& command) {
  MeshMark mark = mesh.begin_transaction();
  Status outcome = execute_edit(mesh, command);
  mesh.end_transaction();
  if (outcome.ok()) undo_.push_back({command, std::move(mark)});
  else mesh.rollback(mark);  // commands check before they write, so this only guards against surprises
  return outcome;
}

Status EditHistory::apply(Mesh& mesh, const EditCommand& command) {
  Status outcome = run(mesh, command);
  if (outcome.ok()) redo_.clear();
  return outcome;
}

const EditCommand* EditHistory::last_drawn() const {
  for (auto it = undo_.rbegin(); it != undo_.rend(); ++it)
    if (!it->command.points.empty()) return &it->command;
  return nullptr;
}

Status EditHistory::undo(Mesh& mesh) {
  if (undo_.empty()) return Status::failure("nothing to undo");
  mesh.rollback(undo_.back().mark);
  redo_.push_back(std::move(undo_.back().command));
  undo_.pop_back();
  return Status::success();
}

Status EditHistory::redo(Mesh& mesh) {
  if (redo_.empty()) return Status::failure("nothing to redo");
  EditCommand command = std::move(redo_.back());
  redo_.pop_back();
  Status outcome = run(mesh, command);
  if (!outcome.ok()) redo_.push_back(std::move(command));
  return outcome;
}

namespace {

// A command's fields after its kind (a byte), as the snapshot holds them: one list for the writer and the reader.
template <class Command, class Field>
void for_each_command_field(Command& c, Field&& field) {
  field(c.points);
  field(c.face);
  field(c.start.edge);
  field(c.start.point);
  field(c.end.edge);
  field(c.end.point);
  field(c.edge);
  field(c.snap_distance);
}

void save_command(SnapshotWriter& out, const EditCommand& c) {
  out.put(uint8_t(c.kind));
  for_each_command_field(c, [&](const auto& value) { out.put(value); });
  // Only this kind holds crossings, so the snapshots of every other command keep their bytes.
  if (c.kind != EditKind::CrossCurves) return;
  out.put(uint64_t(c.crossings.size()));
  for (const Crossing& x : c.crossings) {
    out.put(x.at.edge);
    out.put(x.at.point);
    out.put(x.point);
    out.put(x.face);
  }
}

bool load_command(SnapshotReader& in, EditCommand& c) {
  uint8_t kind = 0;
  in.get(kind);
  for_each_command_field(c, [&](auto& value) { in.get(value); });
  if (kind > uint8_t(EditKind::ExtendChain)) in.fail();
  c.kind = EditKind(kind);
  if (c.kind == EditKind::CrossCurves && in.ok()) {
    uint64_t n = 0;
    in.get(n);
    if (n > c.points.size()) in.fail();  // each crossing has a stroke point of its own
    for (uint64_t k = 0; k < n && in.ok(); ++k) {
      Crossing x;
      in.get(x.at.edge);
      in.get(x.at.point);
      in.get(x.point);
      in.get(x.face);
      c.crossings.push_back(x);
    }
  }
  return in.ok();
}

}  // namespace

void EditHistory::save(SnapshotWriter& out) const {
  out.put(uint64_t(undo_.size()));
  for (const Entry& e : undo_) {
    save_command(out, e.command);
    out.put(uint64_t(e.mark.columns.size()));
    for (const ColumnMark& m : e.mark.columns) {
      out.put(m.size);
      out.put(m.journal);
    }
  }
  out.put(uint64_t(redo_.size()));
  for (const EditCommand& c : redo_) save_command(out, c);
}

bool EditHistory::load(SnapshotReader& in, const Mesh& mesh) {
  // A mark must name journal entries the mesh has, in the order transactions made them, and a size the
  // column had (it shrinks only by journaled pops).
  const MeshMark now = mesh.journal_marks();
  undo_.clear();
  redo_.clear();
  uint64_t n = 0;
  if (!in.get(n)) return false;
  for (uint64_t k = 0; k < n && in.ok(); ++k) {
    Entry e;
    uint64_t columns = 0;
    load_command(in, e.command);
    in.get(columns);
    if (columns != now.columns.size()) in.fail();
    for (uint64_t c = 0; c < columns && in.ok(); ++c) {
      ColumnMark m;
      in.get(m.size);
      in.get(m.journal);
      const uint32_t floor = undo_.empty() ? 0 : undo_.back().mark.columns[c].journal;
      if (m.journal > now.columns[c].journal || m.journal < floor ||
          uint64_t(m.size) > uint64_t(now.columns[c].size) + now.columns[c].journal)
        in.fail();
      e.mark.columns.push_back(m);
    }
    undo_.push_back(std::move(e));
  }
  if (!in.get(n)) return false;
  for (uint64_t k = 0; k < n && in.ok(); ++k) {
    EditCommand c;
    load_command(in, c);
    redo_.push_back(std::move(c));
  }
  return in.ok();
}

void EditHistory::clear(Mesh& mesh) {
  undo_.clear();
  redo_.clear();
  mesh.forget_history();
}

}  // namespace fire
