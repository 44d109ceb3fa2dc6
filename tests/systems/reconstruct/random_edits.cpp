// The random edits of networks.hpp, without Catch, so the soak in perf/soak/ builds them too.
#include <algorithm>
#include <cmath>

#include "networks.hpp"

namespace fire::test {

EditCommand random_split(const Mesh& m, std::mt19937_64& rng) {
  std::vector<FaceIndex> live;
  for (FaceIndex f{0}; f < m.face_slots(); ++f)
    if (m.face_alive(f)) live.push_back(f);
  EditCommand c;
  c.kind = EditKind::SplitFace;
  c.face = live[rng() % live.size()];
  const auto loop = m.face_loop(c.face);
  const bool anywhere = rng() % 16 == 0;
  auto pick = [&](EdgeIndex e) {
    const uint32_t n = m.edges.point_count[e];
    return CurveEnd{e, anywhere || n < 3 ? uint32_t(rng() % n) : 1 + uint32_t(rng() % (n - 2))};
  };
  const size_t first = rng() % loop.size();
  const size_t second = anywhere || loop.size() < 2 ? rng() % loop.size() : (first + 1 + rng() % (loop.size() - 1)) % loop.size();
  c.start = pick(edge_of(loop[first]));
  c.end = pick(edge_of(loop[second]));
  const Vec3 a = m.polyline(c.start.edge)[c.start.point], b = m.polyline(c.end.edge)[c.end.point];
  const int n = 3 + int(rng() % 8);
  // A bow of its own: two curves between the same two points must not share a point between them.
  const double bow = 0.15 + 0.1 * double(rng() % 1024) / 1024;
  for (int k = 0; k < n; ++k) {
    const double s = double(k) / (n - 1);
    c.points.push_back(a + (b - a) * s + Vec3(0, 0, bow * std::sin(M_PI * s)));
  }
  return c;
}


std::optional<EditCommand> random_crossing(const Mesh& m, std::mt19937_64& rng) {
  std::vector<FaceIndex> faces;
  for (FaceIndex f{0}; f < m.face_slots(); ++f)
    if (m.face_alive(f)) faces.push_back(f);
  if (faces.empty()) return std::nullopt;
  // Mostly inside a curve; one time in eight at either end, a vertex.
  auto pick = [&](EdgeIndex e) {
    const uint32_t n = m.edges.point_count[e];
    return CurveEnd{e, rng() % 8 == 0 || n < 3 ? uint32_t(rng() % 2) * (n - 1) : 1 + uint32_t(rng() % (n - 2))};
  };
  auto position = [&](const CurveEnd& at) { return m.polyline(at.edge)[at.point]; };
  EditCommand c;
  c.kind = EditKind::CrossCurves;
  c.face = faces[rng() % faces.size()];
  FaceIndex face = c.face;
  EdgeIndex last_edge = edge_of(m.face_loop(face)[rng() % m.face_loop(face).size()]);
  c.start = pick(last_edge);
  std::vector<Vec3> cuts{position(c.start)};
  // Each piece leaves its face by another curve than it came in by.
  for (size_t crossings = 1 + rng() % 5; c.crossings.size() < crossings;) {
    std::vector<EdgeIndex> inner;
    for (OrientedEdge oe : m.face_loop(face))
      if (m.other_face(edge_of(oe), face) != kNone && edge_of(oe) != last_edge) inner.push_back(edge_of(oe));
    if (inner.empty()) break;
    const EdgeIndex e = last_edge = inner[rng() % inner.size()];
    face = m.other_face(e, face);
    c.crossings.push_back({pick(e), 0, face});
    cuts.push_back(position(c.crossings.back().at));
  }
  if (c.crossings.empty()) return std::nullopt;
  std::vector<EdgeIndex> exits;
  for (OrientedEdge oe : m.face_loop(face))
    if (edge_of(oe) != last_edge) exits.push_back(edge_of(oe));
  if (exits.empty()) return std::nullopt;
  c.end = pick(exits[rng() % exits.size()]);
  cuts.push_back(position(c.end));
  // Each piece a few points bowed up; its last is the next piece's first.
  c.points.push_back(cuts.front());
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    const int n = 2 + int(rng() % 4);
    const double bow = 0.05 + 0.1 * double(rng() % 1024) / 1024;
    for (int k = 1; k <= n; ++k) {
      const double s = double(k) / n;
      c.points.push_back(cuts[i] + (cuts[i + 1] - cuts[i]) * s + Vec3(0, 0, bow * std::sin(M_PI * s)));
    }
    c.points.back() = cuts[i + 1];
    if (i < c.crossings.size()) c.crossings[i].point = uint32_t(c.points.size() - 1);
  }
  return c;
}

std::optional<EditCommand> random_chain(const Mesh& m, std::mt19937_64& rng) {
  const std::vector<std::vector<EdgeIndex>> chains = m.pending_chains();
  EditCommand c;
  // A piece from a point off the network (a free end, or a random curve point) up into the air.
  auto piece_from = [&](const Vec3& a) {
    const Vec3 b = a + Vec3(0.02 * double(rng() % 64) / 64 - 0.01, 0.02 * double(rng() % 64) / 64 - 0.01, 0.05 + 0.05 * double(rng() % 64) / 64);
    for (int k = 0; k < 4; ++k) c.points.push_back(a + (b - a) * (k / 4.0));
    c.points.push_back(b);
  };
  if (chains.empty() || rng() % 3 == 0) {
    std::vector<EdgeIndex> curves;
    for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
      if (m.edge_alive(e) && !m.is_loose_edge(e)) curves.push_back(e);
    if (curves.empty()) return std::nullopt;
    const EdgeIndex e = curves[rng() % curves.size()];
    c.kind = EditKind::ExtendChain;
    piece_from(m.polyline(e)[rng() % m.edges.point_count[e]]);
    return c;
  }
  const std::vector<EdgeIndex>& chain = chains[rng() % chains.size()];
  c.edge = chain.back();
  const Vec3 free_end = m.vertices.position[m.edges.vertex[chain.back()][1]];
  if (rng() % 2 == 0) {
    c.kind = EditKind::ExtendChain;
    piece_from(free_end);
    return c;
  }
  // Finished: down to a random point of a face beside the curve point where the chain began.
  const Vec3 began = m.vertices.position[m.edges.vertex[chain.front()][0]];
  for (EdgeIndex e{0}; e < m.edge_slots() && c.start.edge == kNone; ++e)
    if (m.edge_alive(e) && !m.is_loose_edge(e))
      for (uint32_t k = 0; k < m.edges.point_count[e]; ++k)
        if (m.polyline(e)[k] == began) c.start = {e, k};
  if (c.start.edge == kNone) return std::nullopt;  // that curve was deleted: the chain waits for an undo
  c.kind = EditKind::SplitFace;
  c.face = FaceIndex{m.edges.face[c.start.edge][m.edges.face[c.start.edge][0] == kNone ? 1 : 0]};
  const std::span<const OrientedEdge> loop = m.face_loop(c.face);
  const EdgeIndex e = edge_of(loop[rng() % loop.size()]);
  c.end = {e, 1 + uint32_t(rng() % std::max<uint32_t>(1, m.edges.point_count[e] - 2))};
  const Vec3 end = m.polyline(e)[std::min(c.end.point, m.edges.point_count[e] - 1)];
  for (EdgeIndex g : chain)
    for (uint32_t k = c.points.empty() ? 0 : 1; k < m.edges.point_count[g]; ++k) c.points.push_back(m.polyline(g)[k]);
  for (int k = 1; k < 4; ++k) c.points.push_back(free_end + (end - free_end) * (k / 4.0));
  c.points.push_back(end);
  return c;
}

std::optional<EditCommand> random_topology_edit(const Mesh& m, std::mt19937_64& rng) {
  std::vector<EdgeIndex> rim;
  std::vector<FaceIndex> faces;
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
    if (m.edge_alive(e) && m.is_border_edge(e) && !m.is_loose_edge(e)) rim.push_back(e);
  for (FaceIndex f{0}; f < m.face_slots(); ++f)
    if (m.face_alive(f)) faces.push_back(f);
  if (faces.empty()) return std::nullopt;
  if (const uint64_t kind = rng() % 6; kind < 2) return random_crossing(m, rng);
  else if (kind < 4) return random_chain(m, rng);
  EditCommand c;
  if (rim.empty() || rng() % 2 == 0) {
    c.kind = EditKind::MakeHole;
    c.face = faces[rng() % faces.size()];
    return c;
  }
  const std::vector<OrientedEdge> loop = m.border_loop(rim[rng() % rim.size()]);
  if (loop.size() < 2) return std::nullopt;
  auto pick = [&](EdgeIndex e) { return CurveEnd{e, uint32_t(rng() % m.edges.point_count[e])}; };
  // One time in two, towards another border loop where there is one: a curve joining the two.
  std::vector<EdgeIndex> other;
  for (EdgeIndex e : rim)
    if (std::none_of(loop.begin(), loop.end(), [&](OrientedEdge oe) { return edge_of(oe) == e; })) other.push_back(e);
  if (!other.empty() && rng() % 2 == 0) {
    c.kind = EditKind::JoinBorders;
    c.start = pick(edge_of(loop[rng() % loop.size()]));
    c.end = pick(other[rng() % other.size()]);
  } else {
    c.kind = EditKind::SplitHole;
    const size_t first = rng() % loop.size(), second = (first + 1 + rng() % (loop.size() - 1)) % loop.size();
    c.start = pick(edge_of(loop[first]));
    c.end = pick(edge_of(loop[second]));
  }
  const Vec3 a = m.polyline(c.start.edge)[c.start.point], b = m.polyline(c.end.edge)[c.end.point];
  const int n = 3 + int(rng() % 8);
  for (int k = 0; k < n; ++k) {
    const double s = double(k) / (n - 1);
    c.points.push_back(a + (b - a) * s - Vec3(0, 0, 0.2 * std::sin(M_PI * s)));
  }
  return c;
}

std::optional<EditCommand> random_delete(const Mesh& m, std::mt19937_64& rng) {
  std::vector<EdgeIndex> interior;
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
    if (m.edge_alive(e) && !m.is_border_edge(e)) interior.push_back(e);
  if (interior.empty()) return std::nullopt;
  EditCommand del;
  del.kind = EditKind::DeleteCurve;
  del.edge = interior[rng() % interior.size()];
  return del;
}

std::optional<Status> random_edit(Mesh& net, EditHistory& history, std::mt19937_64& rng, bool split, uint64_t dice,
                                  uint64_t delete_below, uint64_t undo_below) {
  if (split) {
    if (rng() % 8 == 0)
      if (const std::optional<EditCommand> topology = random_topology_edit(net, rng)) return history.apply(net, *topology);
    return history.apply(net, random_split(net, rng));
  }
  if (dice < delete_below) {
    const std::optional<EditCommand> del = random_delete(net, rng);
    if (!del) return std::nullopt;
    return history.apply(net, *del);
  }
  if (dice < undo_below) return history.undo(net);
  return history.redo(net);
}

}  // namespace fire::test
