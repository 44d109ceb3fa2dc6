// Strokes that change the network's topology, through every system of the frame: a curve across a border
// loop's hole closes the object, `cmd hole` opens a face again (and undo closes it), a border drawn apart from
// the network starts a second part. The surface follows: closed, with one border loop, in two pieces.
#include <cmath>
#include <numbers>

#include <catch2/catch.hpp>

#include "scripted_log.hpp"
#include "systems/evaluate/evaluate.hpp"

using namespace fire;
using fire::test::Log;
using fire::test::rejections;
using fire::test::replay;

namespace {

// A stroke of 11 samples from a to b, lifted by `bulge` along z at its middle (a sine arch).
Log& arc(Log& log, const Vec3& a, const Vec3& b, double bulge = 0) {
  log.event("down");
  for (int k = 0; k <= 10; ++k) {
    const double t = k / 10.0;
    const Vec3 p = a + t * (b - a) + Vec3(0, 0, bulge * std::sin(std::numbers::pi * t));
    log.pen(p.x(), p.y(), p.z());
  }
  return log.event("up");
}

// A 10 cm square offset by x0 along x at height z, closed, a sample every centimetre.
Log& square(Log& log, double x0 = 0, double z = 0) {
  arc(log, {x0, 0, z}, {x0 + 0.1, 0, z});
  arc(log, {x0 + 0.1, 0, z}, {x0 + 0.1, 0.1, z});
  arc(log, {x0 + 0.1, 0.1, z}, {x0, 0.1, z});
  return arc(log, {x0, 0.1, z}, {x0 + 0.001, 0.001, z});
}

// The square, its top split by an arch, and a curve under it from near one corner to near the opposite one:
// its ends lie on the boundaries of different faces, so it crosses the border loop's hole.
Log closed_box() {
  Log log;
  square(log);
  arc(log, {0.05, 0, 0}, {0.05, 0.1, 0}, 0.03);
  arc(log, {0.02, 0, 0}, {0.08, 0.1, 0}, -0.03);
  return log;
}

evaluate::Topology surface_topology(const World& w) {
  std::vector<uint32_t> offsets;
  for (size_t q = 0; q <= w.surface.quads.size(); q += 4) offsets.push_back(uint32_t(q));
  return evaluate::topology(w.surface.positions, offsets, w.surface.quads);
}

}  // namespace

TEST_CASE("a stroke across the border loop's hole closes the object, and its surface", "[sketch][topology]") {
  const auto w = replay(closed_box());
  INFO(rejections(*w));
  CHECK(w->rejections.empty());
  CHECK(w->mesh.face_count() == 4);
  for (uint32_t e = 0; e < w->mesh.edge_slots(); ++e)
    if (w->mesh.edge_alive(e)) CHECK_FALSE(w->mesh.is_border_edge(e));
  REQUIRE(w->surface.level > 0);
  const evaluate::Topology t = surface_topology(*w);
  CHECK(t.border_loops == 0);
  CHECK(t.nonmanifold_edges == 0);
  CHECK(t.euler_characteristic == 2);
}

TEST_CASE("cmd hole opens the face under the point, undo closes it again, nothing under is refused", "[sketch][topology]") {
  Log log = closed_box();
  log.event("cmd hole 0.01 0.05 -0.02");
  auto w = replay(log);
  INFO(rejections(*w));
  CHECK(w->rejections.empty());
  CHECK(w->mesh.face_count() == 3);
  REQUIRE(w->surface.level > 0);
  evaluate::Topology t = surface_topology(*w);
  CHECK(t.border_loops == 1);
  CHECK(t.euler_characteristic == 1);

  log.event("cmd undo");
  w = replay(log);
  CHECK(w->mesh.face_count() == 4);
  t = surface_topology(*w);
  CHECK(t.border_loops == 0);
  CHECK(t.euler_characteristic == 2);

  log.event("cmd hole 1 1 1");
  const uint64_t before = world_hash(*w);
  w = replay(log);
  REQUIRE(w->rejections.size() == 1);
  CHECK_THAT(w->rejections[0].reason, Catch::Matchers::Contains("hole: no face under the picked point"));
  CHECK(world_hash(*w) == before);
}

TEST_CASE("a border drawn apart from the network starts a second part with its own surface", "[sketch][topology]") {
  Log log;
  square(log);
  square(log, 0.5);
  const auto w = replay(log);
  INFO(rejections(*w));
  CHECK(w->rejections.empty());
  CHECK(w->mesh.face_count() == 2);
  REQUIRE(w->surface.level > 0);
  const evaluate::Topology t = surface_topology(*w);
  CHECK(t.border_loops == 2);
  CHECK(t.euler_characteristic == 2);  // two discs
}

TEST_CASE("a stroke that starts away from every curve and ends on one is still refused in words", "[sketch][topology][reject]") {
  Log log;
  square(log);
  arc(log, {0.05, 0.3, 0}, {0.05, 0, 0});
  const auto w = replay(log);
  REQUIRE(w->rejections.size() == 1);
  CHECK_THAT(w->rejections[0].reason, Catch::Matchers::Contains("does not start and end on the boundary of one face"));
  CHECK(w->mesh.face_count() == 1);
}

TEST_CASE("a version-1 log replays by version 1's rules: the same strokes are refused as they were", "[sketch][topology][replay]") {
  Log closed = closed_box();
  Log separate;
  square(separate);
  square(separate, 0.5);
  for (Log* log : {&closed, &separate}) {
    const std::string version2 = log->text;
    log->text.replace(0, std::string("FIRE-LOG 2").size(), "FIRE-LOG 1");
    const auto old = replay(*log);
    REQUIRE(old->log.version == 1);
    CHECK(old->mesh.face_count() == (log == &closed ? 2 : 1));
    REQUIRE_FALSE(old->rejections.empty());
    CHECK_THAT(old->rejections.back().reason, Catch::Matchers::Contains("does not start and end on the boundary of one face"));
    log->text = version2;
    CHECK(replay(*log)->log.version == 2);
  }
}

TEST_CASE("strokes between two parts' border loops: the first waits with no surface, the second makes the band", "[sketch][topology]") {
  // Two squares 10 cm apart, one above the other, joined by two curves bowed outwards: a closed box; with
  // both squares made holes, a tube open at both ends.
  Log log;
  square(log);
  square(log, 0, 0.1);
  log.event("down");
  for (int k = 0; k <= 10; ++k) log.pen(0.05, -0.03 * std::sin(std::numbers::pi * k / 10.0), 0.01 * k);
  log.event("up");
  auto w = replay(log);
  INFO(rejections(*w));
  CHECK(w->rejections.empty());
  CHECK(w->mesh.pending_bridge_count() == 1);
  CHECK(w->mesh.face_count() == 2);
  log.event("down");
  for (int k = 0; k <= 10; ++k) log.pen(0.05, 0.1 + 0.03 * std::sin(std::numbers::pi * k / 10.0), 0.01 * k);
  log.event("up");
  w = replay(log);
  CHECK(w->rejections.empty());
  CHECK(w->mesh.pending_bridge_count() == 0);
  CHECK(w->mesh.face_count() == 4);
  REQUIRE(w->surface.level > 0);
  evaluate::Topology t = surface_topology(*w);
  CHECK(t.border_loops == 0);
  CHECK(t.euler_characteristic == 2);
  log.event("cmd hole 0.05 0.05 -0.002");
  log.event("cmd hole 0.05 0.05 0.102");
  w = replay(log);
  INFO(rejections(*w));
  CHECK(w->rejections.empty());
  CHECK(w->mesh.face_count() == 2);
  t = surface_topology(*w);
  CHECK(t.border_loops == 2);
  CHECK(t.euler_characteristic == 0);
}
