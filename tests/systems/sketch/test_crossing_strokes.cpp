// Strokes that cross curves (issue 40), through every system of the frame: cut where they change side of a
// curve, each piece splitting its own face, one edit and one undo however many pieces. Crossing at a vertex,
// running along a curve, touching one, and crossing one curve three times each have their outcome here.
#include <cmath>

#include <catch2/catch.hpp>

#include "scripted_log.hpp"

using namespace fire;
using fire::test::line;
using fire::test::Log;
using fire::test::rejections;
using fire::test::replay;
using fire::test::strips;

namespace {

// A stroke through the corners of a polyline, a sample every 5 mm.
Log& path(Log& log, std::initializer_list<Vec3> corners) {
  log.event("down");
  const Vec3* previous = nullptr;
  for (const Vec3& c : corners) {
    if (previous) {
      const int n = std::max(1, int(std::ceil((c - *previous).norm() / 0.005)));
      for (int k = 1; k <= n; ++k) {
        const Vec3 p = *previous + (double(k) / n) * (c - *previous);
        log.pen(p.x(), p.y(), p.z());
      }
    } else {
      log.pen(c.x(), c.y(), c.z());
    }
    previous = &c;
  }
  return log.event("up");
}

// The live vertex at p (within 0.1 mm), or kNone.
VertexIndex vertex_at(const Mesh& m, const Vec3& p) {
  for (VertexIndex v{0}; v < m.vertex_slots(); ++v)
    if (m.vertex_alive(v) && (m.vertices.position[v] - p).norm() < 1e-4) return v;
  return VertexIndex{};
}

}  // namespace

TEST_CASE("a stroke across 1, 2 or 5 curves splits every face it crosses, and one undo takes it all back", "[sketch][crossing]") {
  const auto before = replay(strips());
  INFO(rejections(*before));
  REQUIRE(before->rejections.empty());
  REQUIRE(before->mesh.face_count() == 6);
  struct Case {
    Vec3 from, to;
    size_t crossed;
  };
  for (const Case& c : {Case{{0.03, 0, 0}, {0.07, 0.1, 0}, 1}, Case{{0.03, 0, 0}, {0.12, 0.1, 0}, 2}, Case{{0, 0.05, 0}, {0.3, 0.05, 0}, 5}}) {
    Log log = strips();
    line(log, c.from, c.to);
    auto w = replay(log);
    INFO(c.crossed << " curves crossed\n" << rejections(*w));
    CHECK(w->rejections.empty());
    CHECK(w->mesh.face_count() == 6 + c.crossed + 1);
    CHECK(w->mesh.validate().empty());
    CHECK(w->mesh.edge_count() == before->mesh.edge_count() + 2 * c.crossed + 3);  // a curve cut at each crossing and each end, and the pieces
    REQUIRE(w->surface.level > 0);
    CHECK(w->surface.quads.size() > before->surface.quads.size());
    log.event("cmd undo");
    w = replay(log);
    CHECK(w->rejections.empty());
    CHECK(w->mesh.same_pools(before->mesh));
  }
}

TEST_CASE("a stroke through a vertex is cut at that vertex, not beside it", "[sketch][crossing]") {
  Log log = strips();
  line(log, {0, 0.05, 0}, {0.3, 0.05, 0});  // vertices at (x, 5 cm) on every strip's curve
  auto w = replay(log);
  REQUIRE(w->rejections.empty());
  const VertexIndex centre = vertex_at(w->mesh, {0.10, 0.05, 0});
  REQUIRE(centre != kNone);
  REQUIRE(w->mesh.valence(centre) == 4);
  const size_t vertices = w->mesh.vertex_count(), faces = w->mesh.face_count();
  line(log, {0.07, 0, 0}, {0.13, 0.1, 0});  // the diagonal through (10, 5) cm, from the second strip's foot to the third's head
  w = replay(log);
  INFO(rejections(*w));
  CHECK(w->rejections.empty());
  CHECK(w->mesh.valence(centre) == 6);
  CHECK(w->mesh.vertex_count() == vertices + 2);  // only its two ends are new
  CHECK(w->mesh.face_count() == faces + 2);
  CHECK(w->mesh.validate().empty());
}

TEST_CASE("a stroke that runs along a curve or touches it and leaves on its own side stays in its face", "[sketch][crossing]") {
  for (const double gap : {0.004, 0.0015}) {  // along the curve at 4 mm for 4 cm, or just touching it at 1.5 mm
    Log log = strips();
    const double run = gap > 0.002 ? 0.02 : 0.0;
    path(log, {{0.03, 0, 0}, {0.05 - gap, 0.05 - run, 0}, {0.05 - gap, 0.05 + run, 0}, {0.03, 0.1, 0}});
    const auto w = replay(log);
    INFO("gap " << gap << "\n" << rejections(*w));
    CHECK(w->rejections.empty());
    CHECK(w->mesh.face_count() == 7);  // one split of the first strip
    CHECK(w->mesh.validate().empty());
  }
  // Along the curve and off on its other side: one crossing, cut where the stroke ran nearest to it.
  Log log = strips();
  path(log, {{0.03, 0, 0}, {0.046, 0.03, 0}, {0.046, 0.07, 0}, {0.07, 0.1, 0}});
  const auto w = replay(log);
  INFO(rejections(*w));
  CHECK(w->rejections.empty());
  CHECK(w->mesh.face_count() == 8);
}

TEST_CASE("a stroke across one curve three times cuts it three times, one undo", "[sketch][crossing]") {
  const auto before = replay(strips());
  Log log = strips();
  path(log, {{0.07, 0, 0}, {0.13, 0.03, 0}, {0.07, 0.06, 0}, {0.13, 0.1, 0}});
  auto w = replay(log);
  INFO(rejections(*w));
  CHECK(w->rejections.empty());
  CHECK(w->mesh.face_count() == 6 + 4);
  CHECK(w->mesh.validate().empty());
  log.event("cmd undo");
  w = replay(log);
  CHECK(w->mesh.same_pools(before->mesh));
}
