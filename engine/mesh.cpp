#include "engine/mesh.hpp"

#include "engine/hash.hpp"
#include "engine/session_dir.hpp"

#include <Eigen/Geometry>  // cross products
#include <algorithm>
#include <cstring>
#include <type_traits>

namespace fire {

namespace {

constexpr std::array<uint32_t, 2> kNoPair{kNone, kNone};

}  // namespace

// Visits every journaled column with the stamps its writes go to: per slot for the pools' columns, as a
// range for the point and loop columns, none for the free lists (a slot's life shows in its flags).
template <class F>
void Mesh::for_each_stamped_column(F&& f) {
  f(vertices.position, &vertices.changes, true);
  f(vertices.first_edge, &vertices.changes, true);
  f(vertices.generation, &vertices.changes, true);
  f(vertices.flags, &vertices.changes, true);
  f(vertices.free_list, nullptr, false);
  f(edges.vertex, &edges.changes, true);
  f(edges.face, &edges.changes, true);
  f(edges.next, &edges.changes, true);
  f(edges.point_offset, &edges.changes, true);
  f(edges.point_count, &edges.changes, true);
  f(edges.generation, &edges.changes, true);
  f(edges.flags, &edges.changes, true);
  f(edges.free_list, nullptr, false);
  f(faces.edge_offset, &faces.changes, true);
  f(faces.edge_count, &faces.changes, true);
  f(faces.generation, &faces.changes, true);
  f(faces.flags, &faces.changes, true);
  f(faces.free_list, nullptr, false);
  f(points, &point_changes, false);
  f(face_edges, &face_edge_changes, false);
}

template <class F>
void Mesh::for_each_column(F&& f) {
  for_each_stamped_column([&](auto& column, ChangeStamps*, bool) { f(column); });
}

template <class F>
void Mesh::for_each_column(F&& f) const {
  const_cast<Mesh*>(this)->for_each_column([&](auto& column) { f(std::as_const(column)); });
}

namespace {
size_t count_alive(const Column<uint8_t>& flags) {
  return static_cast<size_t>(
      std::count_if(flags.values().begin(), flags.values().end(), [](uint8_t f) { return f & kAlive; }));
}
}  // namespace

size_t Mesh::vertex_count() const { return count_alive(vertices.flags); }
size_t Mesh::edge_count() const { return count_alive(edges.flags); }
size_t Mesh::face_count() const { return count_alive(faces.flags); }
size_t Mesh::live_point_count() const {
  size_t n = 0;
  for (EdgeIndex e{0}; e < edge_slots(); ++e)
    if (edge_alive(e)) n += edges.point_count[e];
  return n;
}

std::vector<EdgeIndex> Mesh::vertex_edges(VertexIndex v) const {
  FIRE_ASSERT(vertex_alive(v), "a dead vertex's edge list is another vertex's");
  std::vector<EdgeIndex> out;
  for (EdgeIndex e{vertices.first_edge[v]}; e != kNone;) {
    out.push_back(e);
    e = EdgeIndex{edges.next[e][edges.vertex[e][0] == v ? 0 : 1]};
  }
  return out;
}

uint32_t Mesh::valence(VertexIndex v) const {
  FIRE_ASSERT(vertex_alive(v), "a dead vertex has no valence");
  uint32_t n = 0;
  for (uint32_t e = vertices.first_edge[v]; e != kNone; e = edges.next[e][edges.vertex[e][0] == v ? 0 : 1]) ++n;
  return n;
}

uint32_t Mesh::loop_position(FaceIndex f, EdgeIndex e) const {
  FIRE_ASSERT(face_alive(f), "a dead face's loop is stale");
  auto loop = face_loop(f);
  for (uint32_t k = 0; k < loop.size(); ++k)
    if (edge_of(loop[k]) == e) return k;
  return kNone;
}

std::vector<OrientedEdge> Mesh::border_loop(EdgeIndex e) const {
  auto one_face = [&](EdgeIndex g) { return edge_alive(g) && is_border_edge(g) && !is_loose_edge(g); };
  if (!one_face(e)) return {};
  std::vector<OrientedEdge> loop{hole_side(e)};
  for (;;) {
    const VertexIndex v = head(loop.back());
    OrientedEdge next;
    uint32_t border_curves = 0;
    for (EdgeIndex g : vertex_edges(v)) {
      if (!one_face(g)) continue;
      ++border_curves;
      if (g != edge_of(loop.back())) next = hole_side(g);
    }
    if (border_curves != 2 || tail(next) != v) return {};
    if (edge_of(next) == e) return loop;
    if (loop.size() >= edge_count()) return {};
    loop.push_back(next);
  }
}

bool Mesh::border_in_progress() const {
  for (EdgeIndex e{0}; e < edge_slots(); ++e)
    if (edge_alive(e) && is_loose_edge(e) && !is_waiting_bridge(e) && !is_pending(e)) return true;
  return false;
}

size_t Mesh::pending_piece_count() const {
  size_t n = 0;
  for (EdgeIndex e{0}; e < edge_slots(); ++e) n += edge_alive(e) && is_pending(e);
  return n;
}

std::vector<std::vector<EdgeIndex>> Mesh::pending_chains() const {
  std::vector<std::vector<EdgeIndex>> chains;
  for (EdgeIndex e{0}; e < edge_slots(); ++e) {
    if (!edge_alive(e) || !is_pending(e) || valence(VertexIndex{edges.vertex[e][0]}) != 1) continue;  // a chain's first piece
    std::vector<EdgeIndex> chain{e};
    for (bool more = true; more && chain.size() <= edge_slots();) {
      more = false;
      for (EdgeIndex g : vertex_edges(VertexIndex{edges.vertex[chain.back()][1]}))
        if (g != chain.back() && is_pending(g) && edges.vertex[g][0] == edges.vertex[chain.back()][1]) {
          chain.push_back(g);
          more = true;
          break;
        }
    }
    chains.push_back(std::move(chain));
  }
  return chains;
}

size_t Mesh::pending_bridge_count() const {
  size_t n = 0;
  for (EdgeIndex e{0}; e < edge_slots(); ++e) n += edge_alive(e) && is_waiting_bridge(e);
  return n;
}

size_t Mesh::border_loop_count() const {
  std::vector<uint8_t> walked(edge_slots(), 0);
  size_t loops = 0;
  for (EdgeIndex e{0}; e < edge_slots(); ++e) {
    if (walked[e] || !edge_alive(e) || !is_border_edge(e) || is_loose_edge(e)) continue;
    const std::vector<OrientedEdge> loop = border_loop(e);
    for (OrientedEdge oe : loop) walked[edge_of(oe)] = 1;
    loops += loop.empty() ? 0 : 1;
  }
  return loops;
}

LoopPlane loop_plane(std::span<const Vec3> loop) {
  LoopPlane plane;
  for (size_t i = 0; i < loop.size(); ++i) {
    plane.centroid += loop[i];
    plane.normal += loop[i].cross(loop[(i + 1) % loop.size()]);
  }
  if (!loop.empty()) plane.centroid /= double(loop.size());
  if (plane.normal.norm() > 0) plane.normal.normalize();
  return plane;
}

std::vector<Vec3> Mesh::face_boundary(FaceIndex f) const {
  FIRE_ASSERT(face_alive(f), "a dead face's loop is stale");
  std::vector<Vec3> out;
  for (OrientedEdge oe : face_loop(f)) {
    auto line = polyline(edge_of(oe));
    if (is_reversed(oe)) out.insert(out.end(), line.rbegin(), line.rend() - 1);
    else out.insert(out.end(), line.begin(), line.end() - 1);
  }
  return out;
}

uint32_t Mesh::allocate(Column<uint32_t>& free_list, Column<uint32_t>& generation, Column<uint8_t>& flags,
                        ChangeStamps& changes) {
  uint32_t slot;
  if (!free_list.empty()) {
    slot = free_list[free_list.size() - 1];
    free_list.pop_back();
    flags.set(slot, kAlive);
  } else {
    slot = static_cast<uint32_t>(flags.size());
    generation.push_back(0);
    flags.push_back(kAlive);
  }
  changes.touch(slot, frame_);
  return slot;
}

void Mesh::release(uint32_t slot, Column<uint32_t>& free_list, Column<uint32_t>& generation, Column<uint8_t>& flags,
                   ChangeStamps& changes) {
  flags.set(slot, 0);
  generation.set(slot, generation[slot] + 1);
  free_list.push_back(slot);
  changes.touch(slot, frame_);
}

VertexIndex Mesh::add_vertex(const Vec3& p, uint8_t extra_flags) {
  bool fresh = vertices.free_list.empty();
  const VertexIndex v{allocate(vertices.free_list, vertices.generation, vertices.flags, vertices.changes)};
  if (fresh) {
    vertices.position.push_back(p);
    vertices.first_edge.push_back(kNone);
  } else {
    vertices.position.set(v, p);
    vertices.first_edge.set(v, kNone);
  }
  vertices.flags.set(v, static_cast<uint8_t>(kAlive | extra_flags));
  return v;
}

void Mesh::link_edge(EdgeIndex e) {
  auto next = edges.next[e];
  for (int s = 0; s < 2; ++s) {
    uint32_t v = edges.vertex[e][s];
    next[s] = vertices.first_edge[v];
    vertices.first_edge.set(v, e);
    vertices.changes.touch(v, frame_);
  }
  edges.next.set(e, next);
}

void Mesh::unlink_edge(EdgeIndex e) {
  for (int s = 0; s < 2; ++s) {
    uint32_t v = edges.vertex[e][s];
    vertices.changes.touch(v, frame_);
    uint32_t after = edges.next[e][s];
    if (vertices.first_edge[v] == e) {
      vertices.first_edge.set(v, after);
      continue;
    }
    for (uint32_t x = vertices.first_edge[v]; x != kNone;) {
      int xs = edges.vertex[x][0] == v ? 0 : 1;
      if (edges.next[x][xs] == e) {
        auto n = edges.next[x];
        n[xs] = after;
        edges.next.set(x, n);
        break;
      }
      x = edges.next[x][xs];
    }
  }
}

EdgeIndex Mesh::add_edge(VertexIndex v0, VertexIndex v1, std::span<const Vec3> polyline) {
  FIRE_ASSERT(polyline.size() >= 2, "a polyline joins its two vertices: it has at least 2 points");
  FIRE_ASSERT(vertex_alive(v0) && vertex_alive(v1), "an edge joins live vertices");
  bool fresh = edges.free_list.empty();
  const EdgeIndex e{allocate(edges.free_list, edges.generation, edges.flags, edges.changes)};
  uint32_t offset = static_cast<uint32_t>(points.size());
  for (size_t i = 0; i < polyline.size(); ++i) {
    if (i == 0) points.push_back(vertices.position[v0]);
    else if (i + 1 == polyline.size()) points.push_back(vertices.position[v1]);
    else points.push_back(polyline[i]);
  }
  uint32_t count = static_cast<uint32_t>(polyline.size());
  point_changes.note(offset, offset + count, frame_);
  if (fresh) {
    edges.vertex.push_back({v0, v1});
    edges.face.push_back(kNoPair);
    edges.next.push_back(kNoPair);
    edges.point_offset.push_back(offset);
    edges.point_count.push_back(count);
  } else {
    edges.vertex.set(e, {v0, v1});
    edges.face.set(e, kNoPair);
    edges.next.set(e, kNoPair);
    edges.point_offset.set(e, offset);
    edges.point_count.set(e, count);
  }
  link_edge(e);
  return e;
}

bool Mesh::loop_fits(std::span<const OrientedEdge> loop, FaceIndex f) const {
  if (loop.empty()) return false;
  for (size_t k = 0; k < loop.size(); ++k) {
    const OrientedEdge oe = loop[k];
    const EdgeIndex e = edge_of(oe);
    if (!edge_alive(e)) return false;
    const uint32_t side = edges.face[e][is_reversed(oe)];
    if (side != kNone && side != f) return false;
    if (head(oe) != tail(loop[(k + 1) % loop.size()])) return false;
    for (size_t q = 0; q < k; ++q)
      if (edge_of(loop[q]) == e) return false;
  }
  return true;
}

void Mesh::set_loop_sides(std::span<const OrientedEdge> loop, FaceIndex face) {
  for (OrientedEdge oe : loop) {
    auto fs = edges.face[edge_of(oe)];
    fs[is_reversed(oe)] = face;
    edges.face.set(edge_of(oe), fs);
    edges.changes.touch(edge_of(oe), frame_);
  }
}

uint32_t Mesh::append_loop(std::span<const OrientedEdge> loop, FaceIndex face) {
  const uint32_t offset = static_cast<uint32_t>(face_edges.size());
  for (OrientedEdge oe : loop) face_edges.push_back(oe);
  face_edge_changes.note(offset, static_cast<uint32_t>(face_edges.size()), frame_);
  set_loop_sides(loop, face);
  return offset;
}

FaceIndex Mesh::add_face(std::span<const OrientedEdge> loop) {
  if (!loop_fits(loop, FaceIndex{})) return FaceIndex{};
  const bool fresh = faces.free_list.empty();
  const FaceIndex f{allocate(faces.free_list, faces.generation, faces.flags, faces.changes)};
  const uint32_t offset = append_loop(loop, f);
  if (fresh) {
    faces.edge_offset.push_back(offset);
    faces.edge_count.push_back(static_cast<uint32_t>(loop.size()));
  } else {
    faces.edge_offset.set(f, offset);
    faces.edge_count.set(f, static_cast<uint32_t>(loop.size()));
  }
  return f;
}

bool Mesh::set_face_loop(FaceIndex f, std::span<const OrientedEdge> loop) {
  FIRE_ASSERT(face_alive(f), "only a live face keeps its slot and handle");
  if (!loop_fits(loop, f)) return false;
  set_loop_sides(face_loop(f), FaceIndex{});
  faces.edge_offset.set(f, append_loop(loop, f));
  faces.edge_count.set(f, static_cast<uint32_t>(loop.size()));
  faces.changes.touch(f, frame_);
  return true;
}

void Mesh::remove_face(FaceIndex f) {
  FIRE_ASSERT(face_alive(f), "a face is removed once");
  set_loop_sides(face_loop(f), FaceIndex{});
  release(f, faces.free_list, faces.generation, faces.flags, faces.changes);
}

void Mesh::remove_edge(EdgeIndex e) {
  FIRE_ASSERT(edge_alive(e), "an edge is removed once");
  FIRE_ASSERT(edges.face[e][0] == kNone && edges.face[e][1] == kNone, "the faces of an edge go before it");
  unlink_edge(e);
  release(e, edges.free_list, edges.generation, edges.flags, edges.changes);
}

void Mesh::remove_vertex(VertexIndex v) {
  FIRE_ASSERT(vertex_alive(v), "a vertex is removed once");
  FIRE_ASSERT(vertices.first_edge[v] == kNone, "the edges of a vertex go before it");
  release(v, vertices.free_list, vertices.generation, vertices.flags, vertices.changes);
}

void Mesh::set_edge_flag(EdgeIndex e, uint8_t flag, bool on) {
  FIRE_ASSERT(edge_alive(e), "a dead edge's flags hold its liveness");
  FIRE_ASSERT(!(flag & kAlive), "liveness is the pools' to set");
  uint8_t f = edges.flags[e];
  edges.flags.set(e, static_cast<uint8_t>(on ? (f | flag) : (f & ~flag)));
  edges.changes.touch(e, frame_);
}

void Mesh::move_vertex(VertexIndex v, const Vec3& p) {
  FIRE_ASSERT(vertex_alive(v), "a dead vertex's slot may be reused");
  vertices.position.set(v, p);
  vertices.changes.touch(v, frame_);
  for (EdgeIndex e : vertex_edges(v)) {
    uint32_t at = edges.vertex[e][0] == v ? edges.point_offset[e] : edges.point_offset[e] + edges.point_count[e] - 1;
    points.set(at, p);
    point_changes.note(at, at + 1, frame_);
    edges.changes.touch(e, frame_);
  }
}

MeshMark Mesh::begin_transaction() {
  MeshMark m;
  for_each_column([&](auto& column) { m.columns.push_back(column.begin()); });
  return m;
}

void Mesh::end_transaction() {
  for_each_column([](auto& column) { column.end(); });
}

void Mesh::rollback(const MeshMark& m) {
  FIRE_ASSERT(m.columns.size() == journal_marks().columns.size(), "a mark names every column of these pools");
  size_t k = 0;
  for_each_stamped_column([&](auto& column, ChangeStamps* stamps, bool per_slot) {
    column.end();
    column.rollback(m.columns[k++], [&](uint32_t begin, uint32_t end) {
      if (!stamps) return;
      if (!per_slot) return stamps->note(begin, end, frame_);
      for (uint32_t i = begin; i < end; ++i) stamps->touch(i, frame_);
    });
  });
}

bool Mesh::written_after(Frame f) const {
  for (const ChangeStamps* c : {&vertices.changes, &edges.changes, &faces.changes})
    for (Frame stamp : c->stamp)
      if (stamp > f) return true;
  return false;
}

void Mesh::begin_frame(Frame f) {
  FIRE_ASSERT(f >= frame_, "frames never go back: consumers would miss the writes in between");
  frame_ = f;
}

MeshMark Mesh::journal_marks() const {
  MeshMark m;
  for_each_column([&](const auto& column) {
    m.columns.push_back({static_cast<uint32_t>(column.size()), static_cast<uint32_t>(column.journal().size())});
  });
  return m;
}

void Mesh::forget_history() {
  for_each_column([](auto& column) { column.forget_journal(); });
}

const CompactionMap& Mesh::compact() {
  CompactionMap map;
  auto build = [](const Column<uint8_t>& flags, std::vector<uint32_t>& m) {
    m.assign(flags.size(), kNone);
    uint32_t n = 0;
    for (uint32_t i = 0; i < flags.size(); ++i)
      if (flags[i] & kAlive) m[i] = n++;
    return n;
  };
  uint32_t nv = build(vertices.flags, map.vertex);
  uint32_t ne = build(edges.flags, map.edge);
  uint32_t nf = build(faces.flags, map.face);

  auto gather = [](const auto& column, const std::vector<uint32_t>& m, uint32_t n) {
    using T = std::decay_t<decltype(column[0])>;
    std::vector<T> out(n);
    for (uint32_t i = 0; i < m.size(); ++i)
      if (m[i] != kNone) out[m[i]] = column[i];
    return out;
  };
  auto remap = [](uint32_t x, const std::vector<uint32_t>& m) { return x == kNone ? kNone : m[x]; };

  Mesh c;
  c.vertices.position.assign(gather(vertices.position, map.vertex, nv));
  // Compaction invalidates every handle (callers remap with the returned map), so generations restart.
  c.vertices.generation.assign(std::vector<uint32_t>(nv, 0));
  c.vertices.flags.assign(gather(vertices.flags, map.vertex, nv));
  c.vertices.first_edge.assign(std::vector<uint32_t>(nv, kNone));
  c.edges.generation.assign(std::vector<uint32_t>(ne, 0));
  c.edges.flags.assign(gather(edges.flags, map.edge, ne));
  c.faces.generation.assign(std::vector<uint32_t>(nf, 0));
  c.faces.flags.assign(gather(faces.flags, map.face, nf));

  std::vector<std::array<uint32_t, 2>> ev(ne), ef(ne), en(ne, kNoPair);
  std::vector<uint32_t> po(ne), pc(ne);
  std::vector<Vec3> pts;
  pts.reserve(live_point_count());
  for (EdgeIndex e{0}; e < edge_slots(); ++e) {
    uint32_t n = map.edge[e];
    if (n == kNone) continue;
    ev[n] = {map.vertex[edges.vertex[e][0]], map.vertex[edges.vertex[e][1]]};
    ef[n] = {remap(edges.face[e][0], map.face), remap(edges.face[e][1], map.face)};
    po[n] = static_cast<uint32_t>(pts.size());
    pc[n] = edges.point_count[e];
    auto line = polyline(e);
    pts.insert(pts.end(), line.begin(), line.end());
  }
  // Rebuild the vertex-edge lists as adding the edges in order would, so a compacted mesh equals the same
  // network loaded from a file.
  std::vector<uint32_t> first(nv, kNone);
  for (uint32_t e = 0; e < ne; ++e)
    for (int s = 0; s < 2; ++s) {
      en[e][s] = first[ev[e][s]];
      first[ev[e][s]] = e;
    }
  c.vertices.first_edge.assign(std::move(first));
  c.edges.vertex.assign(std::move(ev));
  c.edges.face.assign(std::move(ef));
  c.edges.next.assign(std::move(en));
  c.edges.point_offset.assign(std::move(po));
  c.edges.point_count.assign(std::move(pc));
  c.points.assign(std::move(pts));

  std::vector<uint32_t> fo(nf), fc(nf);
  std::vector<OrientedEdge> fe;
  for (FaceIndex f{0}; f < face_slots(); ++f) {
    uint32_t n = map.face[f];
    if (n == kNone) continue;
    fo[n] = static_cast<uint32_t>(fe.size());
    fc[n] = faces.edge_count[f];
    for (OrientedEdge oe : face_loop(f)) fe.push_back(make_oriented(EdgeIndex{map.edge[edge_of(oe)]}, is_reversed(oe)));
  }
  c.faces.edge_offset.assign(std::move(fo));
  c.faces.edge_count.assign(std::move(fc));
  c.face_edges.assign(std::move(fe));
  // Survivors keep their stamps, so a consumer that remaps through the map recomputes only real changes.
  auto keep_stamps = [&](const ChangeStamps& old, const std::vector<uint32_t>& m, uint32_t n, ChangeStamps& out) {
    out.stamp.assign(n, frame_);
    for (uint32_t i = 0; i < m.size(); ++i)
      if (m[i] != kNone && i < old.stamp.size()) out.stamp[m[i]] = old.stamp[i];
    out.note(0, n, frame_);
  };
  keep_stamps(vertices.changes, map.vertex, nv, c.vertices.changes);
  keep_stamps(edges.changes, map.edge, ne, c.edges.changes);
  keep_stamps(faces.changes, map.face, nf, c.faces.changes);
  c.point_changes.note(0, static_cast<uint32_t>(c.points.size()), frame_);
  c.face_edge_changes.note(0, static_cast<uint32_t>(c.face_edges.size()), frame_);
  c.frame_ = frame_;
  c.last_compaction_ = {last_compaction_.count + 1, frame_, std::move(map)};
  *this = std::move(c);
  return last_compaction_.map;
}

uint64_t Mesh::hash() const {
  Fnv1a h;
  for_each_column([&](const auto& column) { h.mix_array(column.values()); });
  return h.value;
}

namespace {

void save_stamps(SnapshotWriter& out, const ChangeStamps& c) {
  out.put(c.stamp);
  out.put(c.frame);
  out.put(c.range.begin);
  out.put(c.range.end);
}

bool load_stamps(SnapshotReader& in, ChangeStamps& c) {
  return in.get(c.stamp) && in.get(c.frame) && in.get(c.range.begin) && in.get(c.range.end);
}

}  // namespace

void Mesh::save(SnapshotWriter& out) const {
  for_each_column([&](const auto& column) {
    out.put(column.values());
    out.put(column.journal());
  });
  for (const ChangeStamps* c : {&vertices.changes, &edges.changes, &faces.changes, &point_changes, &face_edge_changes})
    save_stamps(out, *c);
  out.put(frame_);
  out.put(last_compaction_.count);
  out.put(last_compaction_.frame);
  out.put(last_compaction_.map.vertex);
  out.put(last_compaction_.map.edge);
  out.put(last_compaction_.map.face);
}

bool Mesh::load(SnapshotReader& in) {
  for_each_column([&](auto& column) {
    using Values = std::remove_cvref_t<decltype(column.values())>;
    using Journal = std::remove_cvref_t<decltype(column.journal())>;
    Values values;
    Journal journal;
    in.get(values);
    in.get(journal);
    column.restore(std::move(values), std::move(journal));
  });
  for (ChangeStamps* c : {&vertices.changes, &edges.changes, &faces.changes, &point_changes, &face_edge_changes})
    load_stamps(in, *c);
  in.get(frame_);
  in.get(last_compaction_.count);
  in.get(last_compaction_.frame);
  in.get(last_compaction_.map.vertex);
  in.get(last_compaction_.map.edge);
  in.get(last_compaction_.map.face);
  // The pools' columns grow together; validate() checks the rest once the caller has everything.
  const size_t v = vertex_slots(), e = edge_slots(), f = face_slots();
  if (vertices.position.size() != v || vertices.first_edge.size() != v || vertices.generation.size() != v ||
      edges.vertex.size() != e || edges.face.size() != e || edges.next.size() != e || edges.point_offset.size() != e ||
      edges.point_count.size() != e || edges.generation.size() != e || faces.edge_offset.size() != f ||
      faces.edge_count.size() != f || faces.generation.size() != f)
    in.fail();
  // Every slot has a stamp (rollback truncates slots, never stamps).
  if (vertices.changes.stamp.size() < v || edges.changes.stamp.size() < e || faces.changes.stamp.size() < f) in.fail();
  return in.ok();
}

bool Mesh::same_pools(const Mesh& other) const {
  std::vector<std::pair<const void*, size_t>> mine, theirs;
  for_each_column([&](const auto& c) { mine.emplace_back(c.values().data(), c.size() * sizeof(c[0])); });
  other.for_each_column([&](const auto& c) { theirs.emplace_back(c.values().data(), c.size() * sizeof(c[0])); });
  for (size_t k = 0; k < mine.size(); ++k) {
    if (mine[k].second != theirs[k].second) return false;
    if (mine[k].second && std::memcmp(mine[k].first, theirs[k].first, mine[k].second) != 0) return false;
  }
  return true;
}

size_t Mesh::pool_bytes() const {
  size_t n = 0;
  for_each_column([&](const auto& c) { n += c.bytes(); });
  return n;
}

size_t Mesh::journal_bytes() const {
  size_t n = 0;
  for_each_column([&](const auto& c) { n += c.journal_bytes(); });
  return n;
}

}  // namespace fire
