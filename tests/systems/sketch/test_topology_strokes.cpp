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
  for (EdgeIndex e{0}; e < w->mesh.edge_slots(); ++e)
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
    log->text.replace(0, kInputLogHeader.size(), "FIRE-LOG 1");
    const auto old = replay(*log);
    REQUIRE(old->log.version == 1);
    CHECK(old->mesh.face_count() == (log == &closed ? 2 : 1));
    REQUIRE_FALSE(old->rejections.empty());
    CHECK_THAT(old->rejections.back().reason, Catch::Matchers::Contains("does not start and end on the boundary of one face"));
    log->text = version2;
    CHECK(replay(*log)->log.version == kInputLogVersion);
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

namespace {

// Replays `log` with camera 0 at `above` (object frame) until event `turned`, then at `below`: as a tracked drawing
// whose object is turned over there and registered again.
std::unique_ptr<World> replay_seen_from(const Log& log, const Vec3& above, size_t turned, const Vec3& below) {
  auto parsed = parse_input_log(log.text, "seen.log");
  REQUIRE(parsed);
  auto w = std::make_unique<World>();
  w->log = std::move(*parsed);
  Scheduler scheduler = make_scheduler(*w, fire::test::step_clock);
  ReplayHooks hooks;
  hooks.before_frame = [&](World& world) {
    world.registration.transform.emplace();
    world.registration.transform->t = world.cursor.next < turned ? above : below;
  };
  replay_headless(*w, scheduler, hooks);
  return w;
}

constexpr size_t kEventsPerArc = 13;  // down, 11 samples, up

}  // namespace

TEST_CASE("seen from the cameras, a stroke whose ends one face holds, drawn under it, crosses the hole", "[sketch][topology]") {
  // The square, its top split by an arch drawn from above; then, from below, a curve under the left half between
  // two points of its border curves. Those points are on the left face's boundary too.
  Log log;
  square(log);
  arc(log, {0.05, 0, 0}, {0.05, 0.1, 0}, 0.03);
  arc(log, {0.02, 0, 0}, {0.02, 0.1, 0}, -0.03);
  const Vec3 above(0.05, 0.05, 0.5), below(0.05, 0.05, -0.5);
  const auto seen = replay_seen_from(log, above, 5 * kEventsPerArc, below);
  INFO(rejections(*seen));
  CHECK(seen->rejections.empty());
  REQUIRE(seen->sketch.outside.size() == 1);  // the first split said which way the faces turn
  CHECK(seen->mesh.face_count() == 4);
  CHECK(seen->mesh.border_loop_count() == 0);
  // Without the cameras (a mouse), the face that holds both ends takes it, as the thesis's sketch model has it.
  const auto unseen = replay(log);
  CHECK(unseen->rejections.empty());
  CHECK(unseen->mesh.face_count() == 3);
  CHECK(unseen->mesh.border_loop_count() == 1);
  // Drawn from above, the same curve lies over the left face: it splits it.
  const auto over = replay_seen_from(log, above, 6 * kEventsPerArc, below);
  CHECK(over->mesh.face_count() == 3);
}

namespace {

// Of the two faces beside the curve bowed from x = 5 cm toward `side` (+1 or -1) along x, how many lie on that side.
int faces_beside_bowed_curve_on_its_side(const Mesh& mesh, double side) {
  EdgeIndex bowed;
  for (EdgeIndex e{0}; e < mesh.edge_slots(); ++e)
    if (mesh.edge_alive(e) && side * (mesh.polyline(e)[mesh.edges.point_count[e] / 2].x() - 0.05) > 0.02) bowed = e;
  REQUIRE(bowed != kNone);
  int on_its_side = 0;
  for (uint32_t f : mesh.edges.face[bowed]) {
    REQUIRE(f != kNone);
    Vec3 centre = Vec3::Zero();
    const std::vector<Vec3> boundary = mesh.face_boundary(FaceIndex{f});
    for (const Vec3& p : boundary) centre += p;
    on_its_side += side * (centre.x() / double(boundary.size()) - 0.05) > 0;
  }
  return on_its_side;
}

}  // namespace

TEST_CASE("seen from the cameras, of two faces that hold both ends of a stroke, it splits the one it goes into", "[sketch][topology]") {
  // The square split by an arch between (5, 0) and (5, 10) cm; then a second curve between the same two vertices,
  // bowed toward +x or -x: both halves hold its ends, at the same distance.
  for (const double side : {1.0, -1.0}) {
    Log log;
    square(log);
    arc(log, {0.05, 0, 0}, {0.05, 0.1, 0}, 0.03);
    log.event("down");
    for (int k = 0; k <= 10; ++k) {
      const double t = k / 10.0, lift = std::sin(std::numbers::pi * t);
      log.pen(0.05 + side * 0.03 * lift, 0.1 * t, 0.01 * lift);
    }
    log.event("up");
    const Vec3 camera(0.05, 0.05, 0.5);
    const auto w = replay_seen_from(log, camera, 7 * kEventsPerArc, camera);
    INFO("bowed toward " << side << " x\n" << rejections(*w));
    CHECK(w->rejections.empty());
    REQUIRE(w->mesh.face_count() == 3);
    // Every face beside the new curve lies on the side it was bowed toward.
    CHECK(faces_beside_bowed_curve_on_its_side(w->mesh, side) == 2);
  }
}

TEST_CASE("with no camera (the mouse), of two faces that hold both ends of a stroke, it splits the one its middle lies in",
          "[sketch][topology]") {
  // The square split by a straight curve between (5, 0) and (5, 10) cm; a second curve between the same two
  // vertices, bowed toward +x or -x in the plane: both halves hold its ends, at the same distance.
  for (const double side : {1.0, -1.0}) {
    for (const bool version2 : {false, true}) {
      Log log;
      square(log);
      arc(log, {0.05, 0, 0}, {0.05, 0.1, 0});
      log.event("down");
      for (int k = 0; k <= 10; ++k) {
        const double t = k / 10.0;
        log.pen(0.05 + side * 0.03 * std::sin(std::numbers::pi * t), 0.1 * t, 0);
      }
      log.event("up");
      if (version2) log.text.replace(0, kInputLogHeader.size(), "FIRE-LOG 2");
      const auto w = replay(log);
      INFO("bowed toward " << side << " x, version " << w->log.version << "\n" << rejections(*w));
      CHECK(w->rejections.empty());
      REQUIRE(w->mesh.face_count() == 3);
      // The faces beside the bowed curve: both on its side from version 3. A version-2 log gives the stroke to
      // the lowest face slot, as it did when it was drawn: the +x half, so bowed toward -x the curve runs through
      // that half, with one face on each side.
      CHECK(faces_beside_bowed_curve_on_its_side(w->mesh, side) == (version2 && side < 0 ? 1 : 2));
    }
  }
}

TEST_CASE("seen along the surface, a stroke between two border points splits its face, whatever its samples' millimetre of depth",
          "[sketch][topology]") {
  // The square split by an arch seen from above; then, from a camera 4 degrees above the square's plane (a pawn's
  // head seen from the side), a stroke across the right half's corner, from the bottom curve to the right one. Its
  // samples dip and rise by a millimetre, as a tracked pen's do: the direction to the camera lies within that of the
  // surface's plane, so it cannot say which side of the border the stroke leaves on; the curves around its ends can.
  Log log;
  square(log);
  arc(log, {0.05, 0, 0}, {0.05, 0.1, 0}, 0.03);
  log.event("down");
  for (int k = 0; k <= 10; ++k) {
    const double t = k / 10.0;
    log.pen(0.09 + 0.01 * t, 0.01 * t, -0.001 * std::sin(2 * std::numbers::pi * t));
  }
  log.event("up");
  const Vec3 above(0.05, 0.05, 0.5), along = Vec3(0.095, 0.005, 0) + 10 * Vec3(-1, -1, 0.1);
  const auto w = replay_seen_from(log, above, 5 * kEventsPerArc, along);
  INFO(rejections(*w));
  CHECK(w->rejections.empty());
  CHECK(w->mesh.face_count() == 3);
  CHECK(w->mesh.border_loop_count() == 1);
  // The corner's curve has a face on both sides: it split the right half, not the hole beyond the border.
  uint32_t corner = kNone;
  for (EdgeIndex e{0}; e < w->mesh.edge_slots(); ++e)
    if (w->mesh.edge_alive(e) && (w->mesh.polyline(e)[w->mesh.edges.point_count[e] / 2] - Vec3(0.095, 0.005, 0)).norm() < 0.003) corner = e;
  REQUIRE(corner != kNone);
  CHECK(w->mesh.edges.face[corner][0] != kNone);
  CHECK(w->mesh.edges.face[corner][1] != kNone);
}
