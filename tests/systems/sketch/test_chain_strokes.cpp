// Strokes in pieces (issue 40), through every system of the frame: a stroke that ends off the network waits as a
// pending chain, the next stroke from its free end goes on with it, and the one that reaches the network draws
// the whole curve in one edit. Undo takes off the
// last piece; a chain never finished stays, listed; a stroke that starts nowhere near a free end is refused.
#include <cmath>

#include <catch2/catch.hpp>

#include "scripted_log.hpp"
#include "systems/split/edit.hpp"

using namespace fire;
using fire::test::line;
using fire::test::Log;
using fire::test::rejections;
using fire::test::replay;
using fire::test::strips;

namespace {

size_t pending_pieces(const Mesh& m) {
  size_t n = 0;
  for (const auto& chain : m.pending_chains()) n += chain.size();
  return n;
}

}  // namespace

TEST_CASE("a stroke in three pieces draws one curve when the last reaches the network, and undo takes off one piece", "[sketch][chain]") {
  const auto before = replay(strips());
  Log log = strips();
  line(log, {0.03, 0, 0}, {0.03, 0.03, 0});     // from the foot of the first strip into its middle
  line(log, {0.031, 0.03, 0}, {0.03, 0.06, 0});  // on from its free end, 1 mm off
  auto w = replay(log);
  INFO(rejections(*w));
  CHECK(w->rejections.empty());
  CHECK(w->mesh.pending_chains().size() == 1);
  CHECK(pending_pieces(w->mesh) == 2);
  CHECK(w->mesh.face_count() == 6);
  CHECK(w->mesh.validate().empty());
  CHECK_FALSE(w->mesh.border_in_progress());

  Log undone = log;
  undone.event("cmd undo");
  w = replay(undone);
  CHECK(pending_pieces(w->mesh) == 1);
  undone.event("cmd undo");
  w = replay(undone);
  CHECK(pending_pieces(w->mesh) == 0);
  CHECK(w->mesh.same_pools(before->mesh));

  line(log, {0.03, 0.06, 0}, {0.03, 0.1, 0});  // to the head of the strip: the whole curve, one split
  w = replay(log);
  INFO(rejections(*w));
  CHECK(w->rejections.empty());
  CHECK(pending_pieces(w->mesh) == 0);
  CHECK(w->mesh.face_count() == 7);
  CHECK(w->mesh.validate().empty());
  uint32_t longest = 0;
  for (EdgeIndex e{0}; e < w->mesh.edge_slots(); ++e)
    if (w->mesh.edge_alive(e) && std::abs(w->mesh.polyline(e).front().x() - 0.03) < 1e-9) longest = std::max(longest, w->mesh.edges.point_count[e]);
  CHECK(longest >= 20);  // the three pieces' samples in one curve
  log.event("cmd undo");  // the whole curve goes, the two pieces come back
  w = replay(log);
  CHECK(pending_pieces(w->mesh) == 2);
  CHECK(w->mesh.face_count() == 6);
}

TEST_CASE("a pending stroke that crosses a curve and is finished later is one stroke across curves", "[sketch][chain][crossing]") {
  Log log = strips();
  line(log, {0.03, 0, 0}, {0.08, 0.05, 0});  // over x = 5 cm into the middle of the second strip
  auto w = replay(log);
  CHECK(w->rejections.empty());
  CHECK(pending_pieces(w->mesh) == 1);
  line(log, {0.08, 0.05, 0}, {0.12, 0.1, 0});  // on over x = 10 cm to the third strip's head
  w = replay(log);
  INFO(rejections(*w));
  CHECK(w->rejections.empty());
  CHECK(pending_pieces(w->mesh) == 0);
  CHECK(w->mesh.face_count() == 6 + 3);
  CHECK(w->mesh.validate().empty());
}

TEST_CASE("a chain never finished stays, and a stroke that starts nowhere near its free end is refused in words", "[sketch][chain][reject]") {
  Log log = strips();
  line(log, {0.03, 0, 0}, {0.03, 0.05, 0});
  const auto pending = replay(log);
  REQUIRE(pending_pieces(pending->mesh) == 1);
  line(log, {0.035, 0.08, 0}, {0.03, 0.1, 0});  // 3 cm from the free end, away from every curve
  const auto w = replay(log);
  REQUIRE(w->rejections.size() == 1);
  CHECK_THAT(w->rejections[0].reason, Catch::Matchers::Contains("from the free end of the pending stroke"));
  CHECK(w->mesh.same_pools(pending->mesh));
  CHECK(w->surface.level > 0);  // the network's surface is shown while the chain waits
}

TEST_CASE("a pending piece is no curve: delete and sharp refuse it in words, and no new part starts while it waits", "[sketch][chain][reject]") {
  Log log = strips();
  line(log, {0.03, 0, 0}, {0.03, 0.05, 0});
  const auto pending = replay(log);
  REQUIRE(pending_pieces(pending->mesh) == 1);
  log.event("cmd delete 0.03 0.03 0");
  log.event("cmd sharp 0.03 0.03 0");
  const auto w = replay(log);
  REQUIRE(w->rejections.size() == 2);
  CHECK_THAT(w->rejections[0].reason, Catch::Matchers::Contains("still pending"));
  CHECK_THAT(w->rejections[1].reason, Catch::Matchers::Contains("still pending"));
  CHECK(w->mesh.same_pools(pending->mesh));
  Mesh m = pending->mesh;
  EditCommand part;
  part.kind = EditKind::StartBorder;
  part.points = {{1, 0, 0}, {1.1, 0, 0}};
  const Status refused = execute_edit(m, part);
  CHECK_THAT(refused.error, Catch::Matchers::Contains("a stroke in pieces is pending"));
  CHECK(m.same_pools(pending->mesh));
}
