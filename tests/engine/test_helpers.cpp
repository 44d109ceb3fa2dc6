#include "test_helpers.hpp"

#include <algorithm>

#include <catch2/catch.hpp>

namespace fire::test {

std::vector<Vec3> line(const Vec3& a, const Vec3& b, int n) {
  std::vector<Vec3> out;
  for (int i = 0; i < n; ++i) out.push_back(a + (b - a) * (double(i) / (n - 1)));
  return out;
}

Mesh square(EditHistory* history) {
  Mesh m;
  const Vec3 c[4] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  auto run = [&](EditCommand cmd) {
    Status r = history ? history->apply(m, cmd) : execute_edit(m, cmd);
    REQUIRE(r.ok());
    REQUIRE(m.validate() == "");
  };
  run(make(EditKind::StartBorder, line(c[0], c[1])));
  run(make(EditKind::AppendBorder, line(c[1], c[2])));
  run(make(EditKind::AppendBorder, line(c[2], c[3])));
  EditCommand close = make(EditKind::CloseBorder, line(c[3], c[0] + Vec3(0.001, 0, 0)));
  close.snap_distance = 0.01;
  run(close);
  return m;
}

EditCommand make(EditKind kind, std::vector<Vec3> points) {
  EditCommand c;
  c.kind = kind;
  c.points = std::move(points);
  return c;
}

EditCommand remove(uint32_t e) {
  EditCommand c = make(EditKind::DeleteCurve);
  c.edge = EdgeIndex{e};
  return c;
}

EditCommand split(uint32_t face, CurveEnd a, CurveEnd b, const std::vector<Vec3>& points) {
  EditCommand c = make(EditKind::SplitFace, points);
  c.face = FaceIndex{face};
  c.start = a;
  c.end = b;
  return c;
}

EditCommand split(uint32_t face, SlotEnd a, SlotEnd b, const std::vector<Vec3>& points) {
  return split(face, CurveEnd{EdgeIndex{a.edge}, a.point}, CurveEnd{EdgeIndex{b.edge}, b.point}, points);
}

Vec3 at(const Mesh& m, uint32_t e, uint32_t k) { return m.polyline(EdgeIndex{e})[k]; }

std::vector<uint32_t> face_sizes(const Mesh& m) {
  std::vector<uint32_t> s;
  for (FaceIndex f{0}; f < m.face_slots(); ++f)
    if (m.face_alive(f)) s.push_back(m.faces.edge_count[f]);
  std::sort(s.begin(), s.end());
  return s;
}

EdgeIndex edge_between(const Mesh& m, uint32_t a, uint32_t b) {
  for (EdgeIndex e : m.vertex_edges(VertexIndex{a}))
    if (m.edges.vertex[e][0] == b || m.edges.vertex[e][1] == b) return e;
  return EdgeIndex{};
}

EditCommand random_split(const Mesh& m, std::mt19937_64& rng, int max_points) {
  std::vector<FaceIndex> live;
  for (FaceIndex f{0}; f < m.face_slots(); ++f)
    if (m.face_alive(f)) live.push_back(f);
  const FaceIndex f = live[rng() % live.size()];
  auto loop = m.face_loop(f);
  auto pick = [&] {
    const EdgeIndex e = edge_of(loop[rng() % loop.size()]);
    return CurveEnd{e, uint32_t(rng() % m.edges.point_count[e])};
  };
  CurveEnd a = pick(), b = pick();
  Vec3 pa = m.polyline(a.edge)[a.point], pb = m.polyline(b.edge)[b.point];
  std::uniform_real_distribution<double> lift(0.0, 0.1);
  std::vector<Vec3> pts = line(pa, pb, 2 + int(rng() % uint64_t(max_points - 2)));
  for (size_t k = 1; k + 1 < pts.size(); ++k) pts[k].z() += lift(rng);
  return split(f, a, b, pts);
}

}  // namespace fire::test
