// The snapping index answers exactly as the exhaustive searches do (same points, same distances, same
// tie-breaks), on a tiny network with hand-checked ties and on random networks through random splits,
// deletes, undos, redos and compactions, kept in step by incremental updates.
#include <random>

#include <catch2/catch.hpp>

#include "engine/snap_index.hpp"
#include "exhaustive_snap.hpp"
#include "systems/sketch/sketch.hpp"
#include "test_helpers.hpp"

using namespace fire;
using namespace fire::test;

namespace {

std::vector<uint32_t> all_slots(const Mesh& m) {
  std::vector<uint32_t> out(m.edge_slots());
  for (uint32_t e = 0; e < out.size(); ++e) out[e] = e;
  return out;
}

// Exactly the edge slots whose life or polyline differ between two states of a mesh.
std::vector<uint32_t> diff_slots(const Mesh& before, const Mesh& after) {
  std::vector<uint32_t> out;
  for (EdgeIndex e{0}; e < std::max(before.edge_slots(), after.edge_slots()); ++e) {
    const bool a = before.edge_alive(e), b = after.edge_alive(e);
    if (a != b) {
      out.push_back(e);
    } else if (a) {
      auto p = before.polyline(e), q = after.polyline(e);
      if (!std::equal(p.begin(), p.end(), q.begin(), q.end())) out.push_back(e);
    }
  }
  return out;
}

void require_same(const Snap& a, const Snap& b) {
  REQUIRE(a.face == b.face);
  REQUIRE(a.start.edge == b.start.edge);
  REQUIRE(a.start.point == b.start.point);
  REQUIRE(a.end.edge == b.end.edge);
  REQUIRE(a.end.point == b.end.point);
  REQUIRE(a.start_distance == b.start_distance);
  REQUIRE(a.end_distance == b.end_distance);
}

std::vector<FaceIndex> live_faces(const Mesh& m) {
  std::vector<FaceIndex> out;
  for (FaceIndex f{0}; f < m.face_slots(); ++f)
    if (m.face_alive(f)) out.push_back(f);
  return out;
}


// A query point: on a polyline point (ties at vertices), halfway between two neighbours (ties between
// points), near the network at several scales, or far from it.
Vec3 random_query(const Mesh& m, std::mt19937_64& rng, FaceIndex face = FaceIndex{}) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const uint64_t kind = rng() % 6;
  if (kind == 5) return Vec3(5 * unit(rng), 5 * unit(rng), 5 * unit(rng));
  EdgeIndex e;
  if (face != kNone) {
    auto loop = m.face_loop(face);
    e = edge_of(loop[rng() % loop.size()]);
  } else {
    do e = EdgeIndex{uint32_t(rng() % m.edge_slots())};
    while (!m.edge_alive(e));
  }
  auto line = m.polyline(e);
  const uint32_t k = uint32_t(rng() % line.size());
  if (kind == 0) return line[k];
  if (kind == 1) return line[rng() % 2 ? 0 : line.size() - 1];
  if (kind == 2 && k + 1 < line.size()) return 0.5 * (line[k] + line[k + 1]);
  const double scale = kind == 3 ? 1e-3 : 2e-2;
  return line[k] + scale * Vec3(unit(rng), unit(rng), unit(rng));
}

// Every query kind against the oracle.
void check_queries(const Mesh& m, const SnapIndex& index, std::mt19937_64& rng, int count) {
  REQUIRE(index.validate(m) == "");
  if (m.edge_count() == 0) return;
  const double radii[] = {0.0, 1e-3, 1e-2, 5e-2, 0.3, SnapIndex::kUnbounded};
  const std::vector<FaceIndex> faces = live_faces(m);
  for (int i = 0; i < count; ++i) {
    const Vec3 p = random_query(m, rng);
    const double r = radii[rng() % std::size(radii)];
    INFO("query " << p.transpose() << " radius " << r);
    REQUIRE(index.nearest(p, r) == exhaustive_nearest(m, p, r));
    REQUIRE(pick_edge(index, p, r) == exhaustive_pick_edge(m, p, r));
    std::vector<SnapHit> per_edge;
    index.nearest_per_edge(p, r, per_edge);
    REQUIRE(per_edge == exhaustive_nearest_per_edge(m, p, r));
    if (faces.empty()) continue;
    const FaceIndex f = faces[rng() % faces.size()];
    const SnapHit on_face = exhaustive_nearest_on_face(m, f, p);
    REQUIRE(index.nearest_on_face(m, f, p) == on_face);
    REQUIRE(index.nearest_on_face(m, f, p, r) == (on_face.distance <= r ? on_face : SnapHit{}));
    // A stroke from near one boundary point of f to near another, snapped as the sketch system does.
    const Vec3 a = random_query(m, rng, f), b = random_query(m, rng, f);
    require_same(snap_to_face(m, index, a, b, r), exhaustive_snap_to_face(m, a, b, r));
  }
}

}  // namespace

TEST_CASE("changed slots come from stamps", "[snap]") {
  const std::vector<Frame> stamps = {3, 7, 7, 2, 9, 0};
  CHECK(changed_slots(stamps, 0) == std::vector<uint32_t>{0, 1, 2, 3, 4});
  CHECK(changed_slots(stamps, 3) == std::vector<uint32_t>{1, 2, 4});
  CHECK(changed_slots(stamps, 7) == std::vector<uint32_t>{4});
  CHECK(changed_slots(stamps, 9).empty());
  CHECK(changed_slots(std::span<const Frame>{}, 0).empty());
}

TEST_CASE("the index follows explicit lists of changed slots", "[snap]") {
  EditHistory h;
  Mesh m = square(&h);
  SnapIndex index;
  index.update(m, std::vector<uint32_t>{0, 1});
  CHECK(index.edge_count() == 2);
  CHECK(index.validate(m) != "");  // edges 2 and 3 are live but not handed over yet
  index.update(m, std::vector<uint32_t>{2, 3, 3});  // a slot twice is harmless
  REQUIRE(index.validate(m) == "");
  CHECK(index.point_count() == m.live_point_count());

  // Split the square: edge 0 is replaced, new edges appear; hand over exactly what changed.
  Mesh before = m;
  REQUIRE(h.apply(m, split(0, {0, 2}, {2, 2}, line(at(m, 0, 2), at(m, 2, 2), 11))).ok());
  const std::vector<uint32_t> changed = diff_slots(before, m);
  CHECK(!changed.empty());
  index.update(m, changed);
  REQUIRE(index.validate(m) == "");
  // An unchanged slot in the list costs nothing and changes nothing.
  index.update(m, all_slots(m));
  REQUIRE(index.validate(m) == "");

  // Undo truncates the pools: the slots past the end go even if the list does not name them.
  before = m;
  REQUIRE(h.undo(m).ok());
  CHECK(m.edge_slots() < before.edge_slots());
  index.update(m, std::vector<uint32_t>{});
  CHECK(index.validate(m) != "");  // edge 0's restored polyline is not handed over yet
  index.update(m, diff_slots(before, m));
  REQUIRE(index.validate(m) == "");

  // Compaction relabels; the index follows without touching geometry.
  before = m;
  REQUIRE(h.apply(m, split(0, {0, 2}, {2, 2}, line(at(m, 0, 2), at(m, 2, 2), 11))).ok());
  index.update(m, diff_slots(before, m));
  uint32_t interior = kNone;
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
    if (m.edge_alive(e) && !m.is_border_edge(e)) interior = e;
  REQUIRE(interior != kNone);
  before = m;
  REQUIRE(h.apply(m, remove(interior)).ok());
  index.update(m, diff_slots(before, m));
  REQUIRE(index.validate(m) == "");
  h.clear(m);
  const CompactionMap map = m.compact();
  index.remap(map);
  REQUIRE(index.validate(m) == "");
}

TEST_CASE("ties break as in the exhaustive search", "[snap]") {
  Mesh m = square();
  SnapIndex index;
  index.update(m, all_slots(m));
  REQUIRE(index.validate(m) == "");
  // Corner (1,0,0) is point 4 of edge 0 and point 0 of edge 1: the lower edge slot wins the global search.
  const SnapHit corner = index.nearest(Vec3(1, 0, 0));
  CHECK(corner.edge == 0);
  CHECK(corner.point == 4);
  CHECK(corner.distance == 0);
  CHECK(pick_edge(index, Vec3(1, 0, 0), 0.01) == 0);
  // Halfway between points 1 and 2 of edge 0: the lower point index wins.
  const SnapHit half = index.nearest(Vec3(0.375, -0.1, 0));
  CHECK(half.edge == 0);
  CHECK(half.point == 1);
  // On the face, the edge first in loop order wins the corner where the loop closes.
  const FaceIndex f = live_faces(m).front();
  const EdgeIndex first = edge_of(m.face_loop(f)[0]);
  const Vec3 start = m.vertices.position[m.tail(m.face_loop(f)[0])];
  CHECK(index.nearest_on_face(m, f, start) == exhaustive_nearest_on_face(m, f, start));
  CHECK(index.nearest_on_face(m, f, start).edge == first);
  // Out of reach: nothing, as the exhaustive search.
  CHECK(!index.nearest(Vec3(3, 3, 3), 0.5).found());
  CHECK(index.nearest(Vec3(3, 3, 3)) == exhaustive_nearest(m, Vec3(3, 3, 3), SnapIndex::kUnbounded));
  CHECK(!index.nearest_on_face(m, f, Vec3(0.5, 0.5, 0), 0.1).found());
}

TEST_CASE("the index equals the exhaustive search through random edits, undos and compactions", "[snap][random]") {
  for (uint64_t seed : {20261201ull, 7ull}) {
    INFO("seed " << seed);
    std::mt19937_64 rng(seed);
    EditHistory h;
    Mesh m = square(&h);
    SnapIndex index;
    index.sync(m);
    Frame frame = 0;
    int compactions = 0, exact_lists = 0;
    for (int step = 0; step < 700; ++step) {
      INFO("step " << step);
      m.begin_frame(++frame);
      const Mesh before = m;
      const uint64_t dice = rng() % 100;
      // A refused edit (a random split that does not fit, nothing to undo) is a step of the walk like any other.
      if (dice < 55) {
        (void)h.apply(m, random_split(m, rng, 24));  // up to three leaves' worth of points per curve
      } else if (dice < 68) {
        std::vector<uint32_t> interior;
        for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
          if (m.edge_alive(e) && !m.is_border_edge(e)) interior.push_back(e);
        if (!interior.empty()) (void)h.apply(m, remove(interior[rng() % interior.size()]));
      } else if (dice < 86) {
        (void)h.undo(m);
      } else if (dice < 97) {
        (void)h.redo(m);
      } else {
        // Compaction at the sync point after this frame's edits (none here), as a session may.
        h.clear(m);
        m.compact();
        ++compactions;
      }
      // Half the frames sync from the change stamps (relabelling after a compaction), half hand over
      // exactly the slots that changed.
      if (step % 2 == 0 || (m.last_compaction().count > 0 && m.last_compaction().frame == frame)) {
        index.sync(m);
      } else {
        index.update(m, diff_slots(before, m));
        ++exact_lists;
      }
      check_queries(m, index, rng, 12);
    }
    CHECK(compactions > 5);
    CHECK(m.face_count() > 40);
    CHECK(exact_lists > 0);
  }
}
