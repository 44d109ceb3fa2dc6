// The random edits of networks.hpp, without Catch, so the soak in perf/soak/ builds them too.
#include <algorithm>
#include <cmath>

#include "networks.hpp"

namespace fire::test {

EditCommand random_split(const Mesh& m, std::mt19937_64& rng) {
  std::vector<uint32_t> live;
  for (uint32_t f = 0; f < m.face_slots(); ++f)
    if (m.face_alive(f)) live.push_back(f);
  EditCommand c;
  c.kind = EditKind::SplitFace;
  c.face = live[rng() % live.size()];
  const auto loop = m.face_loop(c.face);
  const bool anywhere = rng() % 16 == 0;
  auto pick = [&](uint32_t e) {
    const uint32_t n = m.edges.point_count[e];
    return CurveEnd{e, anywhere || n < 3 ? uint32_t(rng() % n) : 1 + uint32_t(rng() % (n - 2))};
  };
  const size_t first = rng() % loop.size();
  const size_t second = anywhere || loop.size() < 2 ? rng() % loop.size() : (first + 1 + rng() % (loop.size() - 1)) % loop.size();
  c.start = pick(loop[first] >> 1);
  c.end = pick(loop[second] >> 1);
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
  std::vector<uint32_t> faces;
  for (uint32_t f = 0; f < m.face_slots(); ++f)
    if (m.face_alive(f)) faces.push_back(f);
  if (faces.empty()) return std::nullopt;
  // Mostly inside a curve; one time in eight at either end, a vertex.
  auto pick = [&](uint32_t e) {
    const uint32_t n = m.edges.point_count[e];
    return CurveEnd{e, rng() % 8 == 0 || n < 3 ? uint32_t(rng() % 2) * (n - 1) : 1 + uint32_t(rng() % (n - 2))};
  };
  auto position = [&](const CurveEnd& at) { return m.polyline(at.edge)[at.point]; };
  EditCommand c;
  c.kind = EditKind::CrossCurves;
  c.face = faces[rng() % faces.size()];
  uint32_t face = c.face, last_edge = edge_of(m.face_loop(face)[rng() % m.face_loop(face).size()]);
  c.start = pick(last_edge);
  std::vector<Vec3> cuts{position(c.start)};
  // Each piece leaves its face by another curve than it came in by.
  for (size_t crossings = 1 + rng() % 5; c.crossings.size() < crossings;) {
    std::vector<uint32_t> inner;
    for (uint32_t oe : m.face_loop(face))
      if (m.other_face(edge_of(oe), face) != kNone && edge_of(oe) != last_edge) inner.push_back(edge_of(oe));
    if (inner.empty()) break;
    const uint32_t e = last_edge = inner[rng() % inner.size()];
    face = m.other_face(e, face);
    c.crossings.push_back({pick(e), 0, face});
    cuts.push_back(position(c.crossings.back().at));
  }
  if (c.crossings.empty()) return std::nullopt;
  std::vector<uint32_t> exits;
  for (uint32_t oe : m.face_loop(face))
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

std::optional<EditCommand> random_topology_edit(const Mesh& m, std::mt19937_64& rng) {
  std::vector<uint32_t> rim, faces;
  for (uint32_t e = 0; e < m.edge_slots(); ++e)
    if (m.edge_alive(e) && m.is_border_edge(e) && !m.is_loose_edge(e)) rim.push_back(e);
  for (uint32_t f = 0; f < m.face_slots(); ++f)
    if (m.face_alive(f)) faces.push_back(f);
  if (faces.empty()) return std::nullopt;
  if (rng() % 3 == 0) return random_crossing(m, rng);
  EditCommand c;
  if (rim.empty() || rng() % 2 == 0) {
    c.kind = EditKind::MakeHole;
    c.face = faces[rng() % faces.size()];
    return c;
  }
  const std::vector<uint32_t> loop = m.border_loop(rim[rng() % rim.size()]);
  if (loop.size() < 2) return std::nullopt;
  auto pick = [&](uint32_t e) { return CurveEnd{e, uint32_t(rng() % m.edges.point_count[e])}; };
  // One time in two, towards another border loop where there is one: a curve joining the two.
  std::vector<uint32_t> other;
  for (uint32_t e : rim)
    if (std::none_of(loop.begin(), loop.end(), [&](uint32_t oe) { return edge_of(oe) == e; })) other.push_back(e);
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
  std::vector<uint32_t> interior;
  for (uint32_t e = 0; e < m.edge_slots(); ++e)
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
