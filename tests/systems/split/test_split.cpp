// Each split case on a hand-made square, with exact counts and incidences; every rejection; delete and
// the join it triggers; undo/redo returning identical pools.
#include <algorithm>

#include <catch2/catch.hpp>

#include "tests/engine/test_helpers.hpp"

using namespace fire;
using namespace fire::test;

namespace {

// Runs `cmd` through a history and checks undo gives back the pools before it, and redo the pools after it.
void apply_undo_redo(Mesh& m, EditHistory& h, const EditCommand& cmd) {
  Mesh before = m;
  REQUIRE(h.apply(m, cmd).ok());
  REQUIRE(m.validate() == "");
  Mesh after = m;
  REQUIRE(h.undo(m).ok());
  REQUIRE(m.validate() == "");
  CHECK(m.same_pools(before));
  CHECK(m.hash() == before.hash());
  REQUIRE(h.redo(m).ok());
  CHECK(m.same_pools(after));
}

// The square split in half by a vertical curve (through `h`); returns that curve's edge.
EdgeIndex split_square(Mesh& m, EditHistory& h) {
  REQUIRE(h.apply(m, split(0, {0, 2}, {2, 2}, line({0.5, 0, 0}, {0.5, 1, 0}))).ok());
  EdgeIndex middle;
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
    if (m.edge_alive(e) && !m.is_border_edge(e)) middle = e;
  REQUIRE(middle != kNone);
  return middle;
}

size_t border_edges(const Mesh& m) {
  size_t n = 0;
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
    if (m.edge_alive(e) && m.is_border_edge(e)) ++n;
  return n;
}

}  // namespace

TEST_CASE("border polygon: four strokes and a snapping close make one face", "[split]") {
  Mesh m = square();
  CHECK(m.vertex_count() == 4);
  CHECK(m.edge_count() == 4);
  CHECK(m.face_count() == 1);
  CHECK(m.faces.edge_count[0] == 4);
  CHECK(m.live_point_count() == 20);
  // The closing stroke ended 1 mm off; its last point is now exactly the first vertex.
  CHECK(at(m, 3, 4) == Vec3(0, 0, 0));
  for (uint32_t e = 0; e < 4; ++e) {
    CHECK(m.edges.face[e][0] == 0);
    CHECK(m.edges.face[e][1] == kNone);
  }
}

TEST_CASE("split edge-edge: two new vertices, four edge halves, one new edge", "[split]") {
  EditHistory h;
  Mesh m = square(&h);
  const EdgeId bottom = m.edge_id(EdgeIndex{0}), top = m.edge_id(EdgeIndex{2});
  auto cmd = split(0, {0, 2}, {2, 2}, line({0.5, 0, 0}, {0.5, 1, 0}, 7));
  apply_undo_redo(m, h, cmd);
  CHECK(m.vertex_count() == 6);
  CHECK(m.edge_count() == 7);
  CHECK(m.face_count() == 2);
  CHECK(face_sizes(m) == std::vector<uint32_t>{4, 4});
  CHECK(border_edges(m) == 6);
  CHECK_FALSE(m.valid(bottom));  // the split edges are gone; their slots may be reused, with a new generation
  CHECK_FALSE(m.valid(top));
  // The new vertices sit on the old polylines' middle points and have valence 3.
  VertexIndex a, b;
  for (VertexIndex v{0}; v < m.vertex_slots(); ++v) {
    if (!m.vertex_alive(v)) continue;
    if (m.vertices.position[v] == Vec3(0.5, 0, 0)) a = v;
    if (m.vertices.position[v] == Vec3(0.5, 1, 0)) b = v;
  }
  REQUIRE(a != kNone);
  REQUIRE(b != kNone);
  CHECK(m.valence(a) == 3);
  CHECK(m.valence(b) == 3);
  uint32_t e = edge_between(m, a, b);
  REQUIRE(e != kNone);
  CHECK(m.edges.point_count[e] == 7);
  CHECK(m.edges.face[e][0] != kNone);
  CHECK(m.edges.face[e][1] != kNone);
  // Each half of the bottom edge keeps its 3 points.
  CHECK(m.edges.point_count[edge_between(m, 0, a)] == 3);
  CHECK(m.edges.point_count[edge_between(m, a, 1)] == 3);
}

TEST_CASE("split vertex-edge and edge-vertex", "[split]") {
  SECTION("vertex-edge") {
    EditHistory h;
    Mesh m = square(&h);
    apply_undo_redo(m, h, split(0, {0, 0}, {2, 2}, line({0, 0, 0}, {0.5, 1, 0})));
    CHECK(m.vertex_count() == 5);
    CHECK(m.edge_count() == 6);
    CHECK(face_sizes(m) == std::vector<uint32_t>{3, 4});
    CHECK(m.valence(VertexIndex{0}) == 3);
  }
  SECTION("edge-vertex") {
    EditHistory h;
    Mesh m = square(&h);
    apply_undo_redo(m, h, split(0, {0, 2}, {1, 4}, line({0.5, 0, 0}, {1, 1, 0})));
    CHECK(m.vertex_count() == 5);
    CHECK(m.edge_count() == 6);
    CHECK(face_sizes(m) == std::vector<uint32_t>{3, 4});
    CHECK(m.valence(VertexIndex{2}) == 3);
  }
}

TEST_CASE("split vertex-vertex: no new vertex", "[split]") {
  EditHistory h;
  Mesh m = square(&h);
  apply_undo_redo(m, h, split(0, {0, 0}, {2, 0}, line({0, 0, 0}, {1, 1, 0})));
  CHECK(m.vertex_count() == 4);
  CHECK(m.edge_count() == 5);
  CHECK(face_sizes(m) == std::vector<uint32_t>{3, 3});
  CHECK(m.valence(VertexIndex{0}) == 3);
  CHECK(m.valence(VertexIndex{2}) == 3);
  CHECK(m.valence(VertexIndex{1}) == 2);
}

TEST_CASE("split between adjacent vertices makes a two-sided face", "[split]") {
  EditHistory h;
  Mesh m = square(&h);
  apply_undo_redo(m, h, split(0, {0, 0}, {0, 4}, line({0, 0, 0}, {1, 0, 0.2})));
  CHECK(face_sizes(m) == std::vector<uint32_t>{2, 4});
}

TEST_CASE("splitting an interior edge updates the face on its other side", "[split]") {
  EditHistory h;
  Mesh m = square(&h);
  REQUIRE(h.apply(m, split(0, {0, 2}, {2, 2}, line({0.5, 0, 0}, {0.5, 1, 0}, 5))).ok());
  EdgeIndex middle, right;
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e) {
    if (!m.edge_alive(e)) continue;
    if (!m.is_border_edge(e)) middle = e;
    if (e == 1) right = e;
  }
  REQUIRE(middle != kNone);
  const FaceIndex right_face{m.edges.face[right][0]};
  uint32_t left_face = m.other_face(middle, right_face);
  REQUIRE(m.faces.edge_count[left_face] == 4);
  apply_undo_redo(m, h, split(right_face, CurveEnd{middle, 2}, CurveEnd{right, 2}, line({0.5, 0.5, 0}, {1, 0.5, 0})));
  CHECK(m.vertex_count() == 8);
  CHECK(m.edge_count() == 10);
  CHECK(face_sizes(m) == std::vector<uint32_t>{4, 4, 5});
  CHECK(m.faces.edge_count[left_face] == 5);  // the left face now walks both halves of the middle curve
  CHECK(m.vertex_count() - m.edge_count() + m.face_count() == 1);  // still a disk
}

TEST_CASE("every bad edit is rejected with a reason and changes nothing", "[split][reject]") {
  EditHistory h;
  Mesh m = square(&h);
  REQUIRE(h.apply(m, split(0, {0, 2}, {2, 2}, line({0.5, 0, 0}, {0.5, 1, 0}))).ok());
  const uint32_t left = m.edges.face[3][0];
  const uint32_t right = m.edges.face[1][0];
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  struct Case {
    const char* name;
    EditCommand cmd;
    const char* reason_part;
  };
  std::vector<Case> cases = {
      {"ends on another face's edge", split(left, {3, 2}, {1, 2}, line({0, 0.5, 0}, {1, 0.5, 0})), "same face"},
      {"both ends on one vertex", split(left, {3, 0}, {3, 0}, line({0, 1, 0}, {0, 1, 0.1})), "fewer than 2 edges"},
      {"both ends on one edge", split(left, {3, 1}, {3, 3}, line({0, 0.75, 0}, {0, 0.25, 0})), "same edge"},
      {"NaN point", split(left, {3, 2}, {3, 0}, {{0, 0.5, 0}, {nan, 0.5, 0}, {0, 1, 0}}), "not finite"},
      {"infinite point", split(left, {3, 2}, {3, 0}, {{0, 0.5, 0}, {0.1, inf, 0}, {0, 1, 0}}), "not finite"},
      {"one point", split(left, {3, 2}, {3, 0}, {{0, 0.5, 0}}), "at least 2 points"},
      {"missing face", split(99, {3, 2}, {3, 0}, line({0, 0.5, 0}, {0, 1, 0})), "does not exist"},
      {"point index past the polyline", split(left, {3, 9}, {3, 0}, line({0, 0.5, 0}, {0, 1, 0})), "has 5"},
      {"edge past the pool", split(left, {500, 1}, {3, 0}, line({0, 0.5, 0}, {0, 1, 0})), "does not exist"},
      {"append after close", make(EditKind::AppendBorder, line({0, 0, 1}, {1, 0, 1})), "already closed"},
      {"delete a border edge", remove(1), "border"},
      {"delete a missing edge", remove(77), "does not exist"},
  };
  (void)right;
  for (const Case& c : cases) {
    INFO(c.name);
    Mesh before = m;
    Status r = h.apply(m, c.cmd);
    CHECK_FALSE(r.ok());
    CHECK_THAT(r.error, Catch::Matchers::Contains(c.reason_part));
    CHECK(m.same_pools(before));
    CHECK(m.validate() == "");
  }
}

TEST_CASE("border rejections", "[split][reject]") {
  Mesh m;
  CHECK_FALSE(execute_edit(m, make(EditKind::AppendBorder, line({0, 0, 0}, {1, 0, 0}))).ok());
  CHECK_FALSE(execute_edit(m, split(0, {0, 0}, {0, 1}, line({0, 0, 0}, {1, 0, 0}))).ok());
  CHECK_FALSE(execute_edit(m, make(EditKind::StartBorder, {{0, 0, 0}, {0, 0, 0}})).ok());
  REQUIRE(execute_edit(m, make(EditKind::StartBorder, line({0, 0, 0}, {1, 0, 0}))).ok());
  REQUIRE(execute_edit(m, make(EditKind::AppendBorder, line({1, 0, 0}, {1, 1, 0}))).ok());
  EditCommand far = make(EditKind::CloseBorder, line({1, 1, 0}, {0.2, 0, 0}));
  far.snap_distance = 0.01;
  Mesh before = m;
  Status r = execute_edit(m, far);
  CHECK_FALSE(r.ok());
  CHECK_THAT(r.error, Catch::Matchers::Contains("snap distance"));
  CHECK(m.same_pools(before));
  CHECK(m.face_count() == 0);
  EditCommand near = make(EditKind::CloseBorder, line({1, 1, 0}, {0.005, 0, 0}));
  near.snap_distance = 0.01;
  REQUIRE(execute_edit(m, near).ok());
  CHECK(face_sizes(m) == std::vector<uint32_t>{3});
  CHECK(m.validate() == "");
}

TEST_CASE("deleting a curve merges its faces and joins the edge splits it needed", "[split][delete]") {
  EditHistory h;
  Mesh m = square(&h);
  std::vector<Vec3> bottom(m.polyline(EdgeIndex{0}).begin(), m.polyline(EdgeIndex{0}).end());
  const EdgeIndex middle{split_square(m, h)};
  EditCommand del = make(EditKind::DeleteCurve);
  del.edge = middle;
  apply_undo_redo(m, h, del);
  CHECK(m.vertex_count() == 4);
  CHECK(m.edge_count() == 4);
  CHECK(face_sizes(m) == std::vector<uint32_t>{4});
  // The bottom edge is whole again, with the same points.
  EdgeIndex e = edge_between(m, 0, 1);
  REQUIRE(e != kNone);
  auto joined = m.polyline(e);
  std::vector<Vec3> got(joined.begin(), joined.end());
  if (m.edges.vertex[e][0] != 0) std::reverse(got.begin(), got.end());
  CHECK(got == bottom);
}

TEST_CASE("deleting a curve keeps a vertex other curves still need", "[split][delete]") {
  EditHistory h;
  Mesh m = square(&h);
  REQUIRE(h.apply(m, split(0, {0, 2}, {2, 2}, line({0.5, 0, 0}, {0.5, 1, 0}))).ok());
  // A second curve from the bottom split vertex to the top-right corner.
  VertexIndex a;
  for (VertexIndex v{0}; v < m.vertex_slots(); ++v)
    if (m.vertex_alive(v) && m.vertices.position[v] == Vec3(0.5, 0, 0)) a = v;
  uint32_t right_edge_half = edge_between(m, a, 1);
  uint32_t f = m.edges.face[right_edge_half][0] != kNone ? m.edges.face[right_edge_half][0] : m.edges.face[right_edge_half][1];
  uint32_t at_a = m.edges.vertex[right_edge_half][0] == a ? 0 : m.edges.point_count[right_edge_half] - 1;
  REQUIRE(h.apply(m, split(f, {right_edge_half, at_a}, {1, 4}, line({0.5, 0, 0}, {1, 1, 0}))).ok());
  EdgeIndex middle;
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
    if (m.edge_alive(e) && !m.is_border_edge(e) && m.edges.point_count[e] == 5 &&
        m.polyline(e)[4] == Vec3(0.5, 1, 0))
      middle = e;
  REQUIRE(middle != kNone);
  EditCommand del = make(EditKind::DeleteCurve);
  del.edge = middle;
  REQUIRE(h.apply(m, del).ok());
  CHECK(m.validate() == "");
  CHECK(m.vertex_alive(a));  // still holds the second curve
  CHECK(m.valence(a) == 3);
  CHECK(face_sizes(m) == std::vector<uint32_t>{3, 4});
}

TEST_CASE("marking a curve sharp flips its flag, undoes and redoes bit for bit, the border is refused", "[split][sharp]") {
  EditHistory h;
  Mesh m = square(&h);
  const EdgeIndex middle{split_square(m, h)};
  EditCommand sharp = make(EditKind::ToggleSharp);
  sharp.edge = middle;
  const size_t depth = h.undo_depth();
  m.begin_frame(7);
  apply_undo_redo(m, h, sharp);
  CHECK((m.edges.flags[middle] & kSharpEdge) != 0);
  CHECK(m.edges.changes.stamp[middle] == 7);  // stamped: refine sees the crease
  CHECK(h.undo_depth() == depth + 1);
  apply_undo_redo(m, h, sharp);  // again: smooth
  CHECK((m.edges.flags[middle] & kSharpEdge) == 0);
  CHECK(m.validate() == "");

  const Mesh before = m;
  EditCommand border = make(EditKind::ToggleSharp);
  border.edge = edge_between(m, 1, 2);
  REQUIRE(border.edge != kNone);
  const Status refused = h.apply(m, border);
  CHECK_FALSE(refused.ok());
  CHECK_THAT(refused.error, Catch::Contains("border"));
  EditCommand missing = make(EditKind::ToggleSharp);
  missing.edge = EdgeIndex{999};
  CHECK_THAT(h.apply(m, missing).error, Catch::Contains("does not exist"));
  CHECK(m.same_pools(before));
  CHECK(h.undo_depth() == depth + 2);
}

TEST_CASE("compaction squeezes tombstones and keeps the network", "[pools]") {
  EditHistory h;
  Mesh m = square(&h);
  REQUIRE(h.apply(m, split(0, {0, 2}, {2, 2}, line({0.5, 0, 0}, {0.5, 1, 0}))).ok());
  EditCommand del = remove(kNone);
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
    if (m.edge_alive(e) && !m.is_border_edge(e)) del.edge = e;
  REQUIRE(h.apply(m, del).ok());  // leaves tombstones: the joined edges' slots
  REQUIRE(m.edges.free_list.size() > 0);
  size_t v = m.vertex_count(), e = m.edge_count(), f = m.face_count(), p = m.live_point_count();
  CompactionMap map = m.compact();
  h.clear(m);
  CHECK(m.validate() == "");
  CHECK(m.vertex_slots() == v);
  CHECK(m.edge_slots() == e);
  CHECK(m.face_slots() == f);
  CHECK(m.points.size() == p);
  CHECK(m.edges.free_list.empty());
  CHECK(m.vertices.free_list.empty());
  // The map sends live slots, in order, onto 0..n-1 and dead ones nowhere.
  uint32_t next = 0;
  for (uint32_t x : map.edge)
    if (x != kNone) CHECK(x == next++);
  CHECK(next == e);
  CHECK(std::count(map.edge.begin(), map.edge.end(), kNone) > 0);
}

TEST_CASE("handles carry generations", "[pools]") {
  EditHistory h;
  Mesh m = square(&h);
  EdgeId bottom = m.edge_id(EdgeIndex{0});
  CHECK(m.valid(bottom));
  REQUIRE(h.apply(m, split(0, {0, 2}, {2, 2}, line({0.5, 0, 0}, {0.5, 1, 0}))).ok());
  CHECK_FALSE(m.valid(bottom));
  REQUIRE(h.undo(m).ok());
  CHECK(m.valid(bottom));
}

TEST_CASE("validate names the first broken invariant", "[pools]") {
  Mesh m = square();
  m.points.set(m.edges.point_offset[1], Vec3(5, 5, 5));
  CHECK_THAT(m.validate(), Catch::Matchers::Contains("edge 1's polyline does not start at its vertex"));
  Mesh n = square();
  auto fs = n.edges.face[2];
  fs[0] = kNone;
  n.edges.face.set(2, fs);
  CHECK_THAT(n.validate(), Catch::Matchers::Contains("face 0 uses edge 2 which does not name it back"));
}

TEST_CASE("change stamps mark what an edit touched", "[pools][stamps]") {
  Mesh m = square();
  m.begin_frame(1);
  const uint32_t points_before = static_cast<uint32_t>(m.points.size());
  REQUIRE(execute_edit(m, split(0, {0, 0}, {2, 0}, line({0, 0, 0}, {1, 1, 0}))).ok());
  CHECK(m.faces.changes.since(0) == std::vector<uint32_t>{0, 1});
  CHECK(m.edges.changes.changed_since(1, 0));  // now walked by the new face
  CHECK_FALSE(m.vertices.changes.changed_since(1, 0));  // untouched corner
  // The new curve's points are this frame's range of the point pool, nothing before it.
  CHECK(m.point_changes.written_in(1).begin == points_before);
  CHECK(m.point_changes.written_in(1).end == m.points.size());
  CHECK(m.point_changes.written_in(2).empty());
  // A consumer that saw frame 1 sees nothing new; one that saw frame 0 still sees the edit.
  CHECK(m.faces.changes.since(1).empty());
  CHECK(m.faces.changes.since(0).size() == 2);
}

TEST_CASE("border edits undo and redo like every other edit", "[split][undo]") {
  EditHistory h;
  Mesh empty;
  Mesh m = square(&h);
  Mesh closed = m;
  REQUIRE(h.undo_depth() == 4);
  REQUIRE(h.undo(m).ok());  // reopens the border
  CHECK(m.face_count() == 0);
  CHECK(m.edge_count() == 3);
  CHECK(m.validate() == "");
  while (h.undo_depth() > 0) REQUIRE(h.undo(m).ok());
  CHECK(m.same_pools(empty));
  CHECK_FALSE(h.undo(m).ok());
  while (h.redo_depth() > 0) REQUIRE(h.redo(m).ok());
  CHECK(m.same_pools(closed));
  CHECK_FALSE(h.redo(m).ok());
  // A new edit after undo drops what could have been redone.
  REQUIRE(h.undo(m).ok());
  REQUIRE(h.apply(m, split(0, {0, 0}, {1, 4}, line({0, 0, 0}, {1, 1, 0}))).ok() == false);  // border still open
  REQUIRE(h.redo_depth() == 1);
  EditCommand close = make(EditKind::CloseBorder, line({0, 1, 0}, {0, 0, 0}));
  close.snap_distance = 0.01;
  REQUIRE(h.apply(m, close).ok());
  CHECK(h.redo_depth() == 0);
}

TEST_CASE("a rejected edit leaves the stamps alone, undo stamps exactly what it restores", "[pools][stamps]") {
  EditHistory h;
  Mesh m = square(&h);
  m.begin_frame(1);
  REQUIRE_FALSE(h.apply(m, split(0, {0, 0}, {0, 0}, line({0, 0, 0}, {0, 0, 1}))).ok());
  CHECK(m.faces.changes.since(0).empty());
  CHECK(m.edges.changes.since(0).empty());
  CHECK(m.vertices.changes.since(0).empty());
  m.begin_frame(2);
  REQUIRE(h.undo(m).ok());  // reopens the border: removes the closing edge and the face
  // The face and the closing edge (slot 3) are gone, and every edge that named the face is restored.
  CHECK(m.faces.changes.since(1) == std::vector<uint32_t>{0});
  CHECK(m.edges.changes.since(1) == std::vector<uint32_t>{0, 1, 2, 3});
  CHECK_FALSE(m.edge_alive(EdgeIndex{3}));
  // The closing edge's two ends lose it from their edge lists; the other corners are untouched.
  for (uint32_t v : m.vertices.changes.since(1)) CHECK((v == m.edges.vertex[2][1] || v == 0));
}

TEST_CASE("compaction keeps the survivors' stamps and records its map", "[pools][stamps]") {
  EditHistory h;
  Mesh m = square(&h);
  m.begin_frame(1);
  REQUIRE(execute_edit(m, split(0, {0, 0}, {2, 0}, line({0, 0, 0}, {1, 1, 0}))).ok());
  m.begin_frame(2);
  EdgeIndex curve;
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
    if (m.edge_alive(e) && m.edges.face[e][0] != kNone && m.edges.face[e][1] != kNone) curve = e;
  REQUIRE(curve != kNone);
  EditCommand del;
  del.kind = EditKind::DeleteCurve;
  del.edge = curve;
  REQUIRE(execute_edit(m, del).ok());
  const std::vector<uint32_t> changed_in_2 = m.edges.changes.since(1);
  m.begin_frame(3);
  CHECK(m.last_compaction().count == 0);
  const CompactionMap map = m.compact();
  CHECK(m.last_compaction().count == 1);
  CHECK(m.last_compaction().frame == 3);
  CHECK(m.validate() == "");
  for (uint32_t e = 0; e < map.edge.size(); ++e) {
    if (map.edge[e] == kNone) continue;
    const bool was_changed = std::find(changed_in_2.begin(), changed_in_2.end(), e) != changed_in_2.end();
    CHECK(m.edges.changes.changed_since(map.edge[e], 1) == was_changed);
  }
}

namespace {

// A curve across the square's hole from the middle of the bottom edge to the middle of the top edge, bowed
// 0.3 below the square: the square's far side.
EditCommand across_hole(const Mesh& m) {
  EditCommand c = make(EditKind::SplitHole, {{0.5, 0, 0}, {0.5, 0.25, -0.25}, {0.5, 0.5, -0.3}, {0.5, 0.75, -0.25}, {0.5, 1, 0}});
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e) {
    if (!m.edge_alive(e)) continue;
    if (at(m, e, 2) == Vec3(0.5, 0, 0)) c.start = {e, 2};
    if (at(m, e, 2) == Vec3(0.5, 1, 0)) c.end = {e, 2};
  }
  return c;
}

int64_t euler_characteristic(const Mesh& m) {
  return int64_t(m.vertex_count()) - int64_t(m.edge_count()) + int64_t(m.face_count());
}

// The live face of the highest slot with `sides` edges, or kNone.
FaceIndex face_with_sides(const Mesh& m, uint32_t sides) {
  FaceIndex found;
  for (FaceIndex f{0}; f < m.face_slots(); ++f)
    if (m.face_alive(f) && m.faces.edge_count[f] == sides) found = f;
  return found;
}

EditCommand hole(FaceIndex face) {
  EditCommand c = make(EditKind::MakeHole);
  c.face = face;
  return c;
}

}  // namespace

TEST_CASE("a curve across a border loop's hole closes the object: two new faces, no border left", "[split][topology]") {
  EditHistory h;
  Mesh m = square(&h);
  const EditCommand cmd = across_hole(m);
  REQUIRE(cmd.start.edge != kNone);
  REQUIRE(cmd.end.edge != kNone);
  apply_undo_redo(m, h, cmd);
  CHECK(m.face_count() == 3);
  CHECK(border_edges(m) == 0);
  CHECK(euler_characteristic(m) == 2);  // a sphere
  CHECK(m.border_loop_count() == 0);
  CHECK(face_sizes(m) == std::vector<uint32_t>{4, 4, 6});
  // The new faces walk the old border against the square: each rim curve is the square's on one side.
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
    if (m.edge_alive(e)) CHECK(m.edges.face[e][0] != m.edges.face[e][1]);
}

TEST_CASE("a hole and its undo: the face goes, its curves become border, undo brings it back", "[split][topology]") {
  EditHistory h;
  Mesh m = square(&h);
  REQUIRE(h.apply(m, across_hole(m)).ok());
  // The two faces under the square are apart from any border on a closed object.
  const FaceIndex under = face_with_sides(m, 4);
  REQUIRE(under != kNone);
  apply_undo_redo(m, h, hole(under));
  CHECK(m.face_count() == 2);
  CHECK(border_edges(m) == 4);
  CHECK(euler_characteristic(m) == 1);  // a disc again
  CHECK(m.border_loop_count() == 1);
  // The other face under the square now lies beside the border: refused, nothing changes.
  const FaceIndex other = face_with_sides(m, 4);
  REQUIRE(other != kNone);
  const Mesh before = m;
  const Status beside = h.apply(m, hole(other));
  CHECK_FALSE(beside.ok());
  CHECK_THAT(beside.error, Catch::Matchers::Contains("beside the border"));
  CHECK(m.same_pools(before));
  const Status missing = h.apply(m, hole(FaceIndex{99}));
  CHECK_THAT(missing.error, Catch::Matchers::Contains("does not exist"));
  CHECK(m.same_pools(before));
  // The hole's rim can be crossed again: the object closes once more.
  EdgeIndex rim_edge;
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
    if (m.edge_alive(e) && m.is_border_edge(e) && m.edges.point_count[e] >= 3 && rim_edge == kNone) rim_edge = e;
  REQUIRE(rim_edge != kNone);
  const std::vector<OrientedEdge> rim = m.border_loop(rim_edge);
  REQUIRE(rim.size() == 4);
  EditCommand again = make(EditKind::SplitHole);
  const EdgeIndex first = edge_of(rim[0]), third = edge_of(rim[2]);
  again.start = {first, 1};
  again.end = {third, 1};
  again.points = line(at(m, first, 1), at(m, third, 1), 7);
  again.points[3] += Vec3(0, 0, -0.2);
  apply_undo_redo(m, h, again);
  CHECK(border_edges(m) == 0);
  CHECK(euler_characteristic(m) == 2);
}

TEST_CASE("a hole touching the border at a corner is refused: it would pinch the surface", "[split][topology][reject]") {
  EditHistory h;
  Mesh m = square(&h);
  REQUIRE(h.apply(m, across_hole(m)).ok());
  // The top split by a curve between the same two points as the one below: four faces meet at each end.
  const FaceIndex top = face_with_sides(m, 6);
  REQUIRE(top != kNone);
  CurveEnd a, b;
  for (OrientedEdge oe : m.face_loop(top)) {
    const EdgeIndex e = edge_of(oe);
    for (uint32_t k : {uint32_t(0), m.edges.point_count[e] - 1}) {
      if (at(m, e, k) == Vec3(0.5, 0, 0)) a = {e, k};
      if (at(m, e, k) == Vec3(0.5, 1, 0)) b = {e, k};
    }
  }
  REQUIRE(a.edge != kNone);
  REQUIRE(b.edge != kNone);
  std::vector<Vec3> over = line({0.5, 0, 0}, {0.5, 1, 0}, 5);
  over[2] += Vec3(0, 0, 0.2);
  REQUIRE(h.apply(m, split(top, a, b, over)).ok());
  REQUIRE(m.face_count() == 4);
  // Hole one face below: the top face on the other side meets its rim only at the two corners.
  // Faces below hold a point with z < 0; of those, the one with corner (0, 0); of the top, the one with (1, 0).
  FaceIndex below_left, top_right;
  for (FaceIndex f{0}; f < m.face_slots(); ++f) {
    if (!m.face_alive(f)) continue;
    bool below = false, left = false, right = false;
    for (const Vec3& q : m.face_boundary(f)) {
      below = below || q.z() < 0;
      left = left || q == Vec3(0, 0, 0);
      right = right || q == Vec3(1, 0, 0);
    }
    if (below && left) below_left = f;
    if (!below && right) top_right = f;
  }
  REQUIRE(below_left != kNone);
  REQUIRE(top_right != kNone);
  REQUIRE(h.apply(m, hole(below_left)).ok());
  const Mesh before = m;
  const Status r = h.apply(m, hole(top_right));
  CHECK_FALSE(r.ok());
  CHECK_THAT(r.error, Catch::Matchers::Contains("pinch"));
  CHECK(m.same_pools(before));
}

TEST_CASE("a border drawn apart from the network starts a second part", "[split][topology]") {
  EditHistory h;
  Mesh m = square(&h);
  const Vec3 c[4] = {{3, 0, 0}, {4, 0, 0}, {4, 1, 0}, {3, 1, 0}};
  REQUIRE(h.apply(m, make(EditKind::StartBorder, line(c[0], c[1]))).ok());
  const Mesh open = m;
  CHECK(m.border_in_progress());
  const Status second = h.apply(m, make(EditKind::StartBorder, line({6, 0, 0}, {7, 0, 0})));
  CHECK_THAT(second.error, Catch::Matchers::Contains("being drawn"));
  CHECK(m.same_pools(open));
  REQUIRE(h.apply(m, make(EditKind::AppendBorder, line(c[1], c[2]))).ok());
  REQUIRE(h.apply(m, make(EditKind::AppendBorder, line(c[2], c[3]))).ok());
  EditCommand close = make(EditKind::CloseBorder, line(c[3], c[0]));
  close.snap_distance = 0.01;
  REQUIRE(h.apply(m, close).ok());
  CHECK(m.validate() == "");
  CHECK(m.face_count() == 2);
  CHECK(border_edges(m) == 8);
  CHECK(m.border_loop_count() == 2);
  // A curve from one part's rim to the other's would join two border loops: refused in words, nothing lost.
  EditCommand join = make(EditKind::SplitHole, line({0.5, 0, 0}, {3.5, 0, 0}));
  join.start = {EdgeIndex{0}, 2};
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
    if (m.edge_alive(e) && at(m, e, 2) == Vec3(3.5, 0, 0)) join.end = {e, 2};
  REQUIRE(join.end.edge != kNone);
  const Mesh two = m;
  const Status joined = h.apply(m, join);
  CHECK_THAT(joined.error, Catch::Matchers::Contains("not supported yet"));
  CHECK(m.same_pools(two));
  // An inner curve is no rim.
  REQUIRE(h.apply(m, split(0, {0, 2}, {2, 2}, line({0.5, 0, 0}, {0.5, 1, 0}))).ok());
  EdgeIndex inner;
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
    if (m.edge_alive(e) && !m.is_border_edge(e)) inner = e;
  EditCommand off_rim = join;
  off_rim.start = {inner, 2};
  const Mesh split_once = m;
  CHECK_THAT(h.apply(m, off_rim).error, Catch::Matchers::Contains("not on the border"));
  CHECK(m.same_pools(split_once));
  while (h.undo_depth() > 0) REQUIRE(h.undo(m).ok());
  CHECK(m.same_pools(Mesh{}));
}

TEST_CASE("two curves between two border loops: a bridge with no face, then two faces, holes make a tube", "[split][topology]") {
  EditHistory h;
  Mesh m = square(&h);
  const Vec3 c[4] = {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  REQUIRE(h.apply(m, make(EditKind::StartBorder, line(c[0], c[1]))).ok());
  REQUIRE(h.apply(m, make(EditKind::AppendBorder, line(c[1], c[2]))).ok());
  REQUIRE(h.apply(m, make(EditKind::AppendBorder, line(c[2], c[3]))).ok());
  EditCommand close = make(EditKind::CloseBorder, line(c[3], c[0]));
  close.snap_distance = 0.01;
  REQUIRE(h.apply(m, close).ok());
  auto point_at = [&](const Vec3& p) {
    for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
      if (m.edge_alive(e))
        for (uint32_t k = 0; k < m.edges.point_count[e]; ++k)
          if (at(m, e, k) == p) return CurveEnd{e, k};
    return CurveEnd{};
  };
  auto bridge = [&](double y) {
    EditCommand b = make(EditKind::JoinBorders, line({0.5, y, 0}, {0.5, y, 1}, 5));
    b.points[2] += Vec3(0, y == 0 ? -0.3 : 0.3, 0);
    b.start = point_at({0.5, y, 0});
    b.end = point_at({0.5, y, 1});
    return b;
  };
  const Mesh two_parts = m;
  apply_undo_redo(m, h, bridge(0));
  CHECK(m.pending_bridge_count() == 1);
  CHECK(m.face_count() == 2);
  CHECK(m.border_loop_count() == 2);
  CHECK_FALSE(m.border_in_progress());
  // Crossing a loop that a bridge waits on is refused; so is a bridge with both ends on one loop.
  EditCommand across = make(EditKind::SplitHole, line({0.25, 0, 0}, {1, 0.5, 0}));
  across.start = point_at({0.25, 0, 0});
  across.end = point_at({1, 0.5, 0});
  REQUIRE(across.start.edge != kNone);
  REQUIRE(across.end.edge != kNone);
  const Mesh waiting = m;
  CHECK_THAT(h.apply(m, across).error, Catch::Matchers::Contains("waits for its second curve"));
  EditCommand same = across;
  same.kind = EditKind::JoinBorders;
  CHECK_THAT(h.apply(m, same).error, Catch::Matchers::Contains("one border loop"));
  CHECK(m.same_pools(waiting));
  // A second curve from where the bridge ends would make a face that touches itself there.
  EditCommand from_bridge_end = bridge(1);
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
    if (m.edge_alive(e) && m.is_border_edge(e) && !m.is_loose_edge(e) && at(m, e, 0) == Vec3(0.5, 0, 0)) from_bridge_end.start = {e, 0};
  CHECK_THAT(h.apply(m, from_bridge_end).error, Catch::Matchers::Contains("touch itself"));
  CHECK(m.same_pools(waiting));
  // A waiting bridge can be deleted; its ends join the rims again.
  EditCommand del = remove(kNone);
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
    if (m.edge_alive(e) && (m.edges.flags[e] & kBridgeEdge)) del.edge = e;
  REQUIRE(h.apply(m, del).ok());
  CHECK(m.validate() == "");
  CHECK(m.edge_count() == two_parts.edge_count());
  CHECK(m.vertex_count() == two_parts.vertex_count());
  REQUIRE(h.undo(m).ok());
  CHECK(m.same_pools(waiting));

  apply_undo_redo(m, h, bridge(1));
  CHECK(m.pending_bridge_count() == 0);
  CHECK(m.face_count() == 4);
  CHECK(m.border_loop_count() == 0);
  CHECK(euler_characteristic(m) == 2);  // two discs and the band between them: a sphere
  // Both squares made holes: a tube open at both ends, as a lampshade.
  const FaceIndex bottom{m.edges.face[point_at({0.25, 0, 0}).edge][0]}, top{m.edges.face[point_at({0.25, 0, 1}).edge][0]};
  REQUIRE(h.apply(m, hole(bottom)).ok());
  REQUIRE(h.apply(m, hole(top)).ok());
  CHECK(m.validate() == "");
  CHECK(m.face_count() == 2);
  CHECK(m.border_loop_count() == 2);
  CHECK(euler_characteristic(m) == 0);
  while (h.undo_depth() > 0) REQUIRE(h.undo(m).ok());
  CHECK(m.same_pools(Mesh{}));
}

namespace {

// The polyline point at p exactly, as a curve end (the first found), or an end with no edge.
CurveEnd point_at(const Mesh& m, const Vec3& p) {
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
    if (m.edge_alive(e))
      for (uint32_t k = 0; k < m.edges.point_count[e]; ++k)
        if (at(m, e, k) == p) return {e, k};
  return {};
}

// The square split in half, and a stroke from (0.25, 0) on the bottom across the middle curve at (0.5, 0.5) to
// (0.75, 1) on the top.
EditCommand across_middle(const Mesh& m, EdgeIndex middle) {
  EditCommand c = make(EditKind::CrossCurves, {{0.25, 0, 0}, {0.375, 0.25, 0.1}, {0.5, 0.5, 0}, {0.625, 0.75, 0.1}, {0.75, 1, 0}});
  c.start = point_at(m, {0.25, 0, 0});
  c.end = point_at(m, {0.75, 1, 0});
  c.face = FaceIndex{m.edges.face[c.start.edge][0]};
  c.crossings.push_back({point_at(m, {0.5, 0.5, 0}), 2, m.other_face(middle, c.face)});
  return c;
}

}  // namespace

TEST_CASE("a stroke across a curve: each piece splits its face, undo takes both back at once", "[split][crossing]") {
  EditHistory h;
  Mesh m = square(&h);
  const EdgeIndex middle = split_square(m, h);
  const EditCommand cross = across_middle(m, middle);
  REQUIRE(cross.start.edge != kNone);
  REQUIRE(cross.end.edge != kNone);
  REQUIRE(cross.crossings[0].at.edge == middle);
  const size_t depth = h.undo_depth();
  apply_undo_redo(m, h, cross);
  CHECK(m.face_count() == 4);
  CHECK(face_sizes(m) == std::vector<uint32_t>{3, 3, 5, 5});  // a triangle each side between the piece and the middle curve
  CHECK(h.undo_depth() == depth + 1);
  CHECK(euler_characteristic(m) == 1);
}

TEST_CASE("a stroke across curves is refused in words when a crossing is on the border, stays in one face, or repeats a cut", "[split][crossing][reject]") {
  EditHistory h;
  Mesh m = square(&h);
  const EdgeIndex middle = split_square(m, h);
  const Mesh before = m;
  EditCommand border = across_middle(m, middle);
  border.crossings[0].at = point_at(m, {1, 0.5, 0});
  EditCommand same_face = across_middle(m, middle);
  same_face.crossings[0].face = same_face.face;
  EditCommand twice = across_middle(m, middle);
  twice.crossings.push_back(twice.crossings[0]);
  twice.crossings[1].point = 3;
  twice.crossings[1].face = twice.face;
  EditCommand backwards = across_middle(m, middle);
  backwards.crossings[0].point = 0;
  struct Case {
    const EditCommand* command;
    const char* says;
  };
  for (const Case& c : {Case{&border, "would leave the surface"}, Case{&same_face, "a crossing changes face"},
                        Case{&twice, "where an earlier cut of it is"}, Case{&backwards, "not after the previous cut"}}) {
    const Status outcome = h.apply(m, *c.command);
    INFO(outcome.error);
    CHECK_FALSE(outcome.ok());
    CHECK_THAT(outcome.error, Catch::Matchers::Contains(c.says));
    CHECK(m.same_pools(before));
  }
}
