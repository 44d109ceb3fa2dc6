// What the sketch system publishes about the pen (engine/pen_feedback.hpp), for scripted input logs on a
// 10 cm square drawn in the xy plane: the closing vertex in border mode, the snap target and the face under
// the pen in split mode, the face a stroke in progress would split; none of it in the replay hash. And where a
// stroke's ends land: on a vertex within the snap radius, the pen's pauses there not drawn.
#include <catch2/catch.hpp>

#include "scripted_log.hpp"

using namespace fire;
using fire::test::Log;
using fire::test::replay;

namespace {

// Three sides of the square; the fourth closes it when it ends within the default 1 cm of (0, 0, 0).
Log open_border() {
  Log log;
  log.stroke({{0, 0, 0}, {0.05, 0, 0}, {0.1, 0, 0}});
  log.stroke({{0.1, 0, 0}, {0.1, 0.05, 0}, {0.1, 0.1, 0}});
  log.stroke({{0.1, 0.1, 0}, {0.05, 0.1, 0}, {0, 0.1, 0}});
  return log;
}

// The square closed by a left curve with a point every 2 mm.
Log square_with_dense_left() {
  Log log = open_border();
  log.event("down");
  for (int k = 0; k <= 50; ++k) log.pen(0, 0.1 - 0.002 * k);
  return log.event("up");
}

// A stroke left open on the square of square_with_dense_left: the feedback shows where its end would land;
// lifted, it splits the square with that many vertices in the mesh.
void check_end_lands(Log log, const Vec3& target, uint32_t vertices) {
  auto w = replay(log);
  REQUIRE(w->mesh.face_count() == 1);
  CHECK(w->pen_feedback.target == target);
  log.event("up");
  w = replay(log);
  REQUIRE(w->mesh.face_count() == 2);
  CHECK(w->mesh.vertex_count() == vertices);
}

Log closed_square() {
  Log log = open_border();
  log.stroke({{0, 0.1, 0}, {0, 0.05, 0}, {0.002, 0.001, 0}});
  return log;
}

}  // namespace

TEST_CASE("border mode: the first vertex is marked when a stroke ending at the pen would close the border",
          "[sketch][feedback]") {
  Log near_start = open_border();
  near_start.pen(0.003, 0.002);  // hovering, pen up, 3.6 mm from the first vertex
  auto w = replay(near_start);
  REQUIRE(w->mesh.face_count() == 0);
  const PenFeedback& fb = w->pen_feedback;
  CHECK(fb.pen_seen);
  CHECK_FALSE(fb.pen_down);
  REQUIRE(w->mesh.valid(fb.first_vertex));
  CHECK(w->mesh.vertices.position[fb.first_vertex.index] == Vec3(0, 0, 0));
  CHECK(fb.closes_border);
  CHECK(fb.has_target());
  CHECK(fb.target == Vec3(0, 0, 0));
  CHECK_FALSE(fb.face.valid());

  Log far = open_border();
  far.pen(0.05, 0.05);
  w = replay(far);
  CHECK(w->mesh.valid(w->pen_feedback.first_vertex));
  CHECK_FALSE(w->pen_feedback.closes_border);
  CHECK_FALSE(w->pen_feedback.has_target());
}

TEST_CASE("split mode: the snap target and the face under the pen", "[sketch][feedback]") {
  Log log = closed_square();
  log.pen(0.051, 0.003);  // 3.2 mm from the bottom curve's middle point
  auto w = replay(log);
  REQUIRE(w->mesh.face_count() == 1);
  const PenFeedback& fb = w->pen_feedback;
  REQUIRE(w->mesh.valid(fb.target_edge));
  CHECK(fb.target_point == 1);
  CHECK(fb.target == Vec3(0.05, 0, 0));
  CHECK(w->mesh.polyline(EdgeIndex{fb.target_edge.index})[fb.target_point] == fb.target);
  REQUIRE(w->mesh.valid(fb.face));
  CHECK_FALSE(fb.closes_border);

  log.pen(0.05, 0.05);  // the middle: over the face, no curve within 1 cm
  w = replay(log);
  CHECK_FALSE(w->pen_feedback.has_target());
  CHECK(w->mesh.valid(w->pen_feedback.face));

  log.pen(0.05, 0.3);  // beside the square
  w = replay(log);
  CHECK_FALSE(w->pen_feedback.face.valid());

  log.pen(0.05, 0.05, 0.2);  // high above it
  w = replay(log);
  CHECK_FALSE(w->pen_feedback.face.valid());
}

TEST_CASE("while drawing: the face the stroke would split and where its end would snap", "[sketch][feedback]") {
  Log log = closed_square();
  log.event("down").pen(0.05, 0.001).pen(0.05, 0.05, 0.01).pen(0.049, 0.097);
  auto w = replay(log);
  const PenFeedback& fb = w->pen_feedback;
  CHECK(fb.pen_down);
  REQUIRE(w->mesh.valid(fb.face));
  REQUIRE(w->mesh.valid(fb.target_edge));
  CHECK(fb.target == Vec3(0.05, 0.1, 0));  // the top curve's middle point

  // The pen goes up: the stroke splits the square, and nothing is shown until the pen is seen again.
  log.event("up");
  w = replay(log);
  REQUIRE(w->mesh.face_count() == 2);
  CHECK_FALSE(w->pen_feedback.pen_seen);
  CHECK_FALSE(w->pen_feedback.face.valid());
  CHECK_FALSE(w->pen_feedback.has_target());
  // Then the pen over each half names a different face.
  log.pen(0.02, 0.05);
  w = replay(log);
  REQUIRE(w->mesh.face_count() == 2);
  const FaceId left = w->pen_feedback.face;
  log.pen(0.08, 0.05);
  w = replay(log);
  const FaceId right = w->pen_feedback.face;
  CHECK(w->mesh.valid(left));
  CHECK(w->mesh.valid(right));
  CHECK(left.index != right.index);
}

TEST_CASE("the pen's feedback is not part of the replay hash", "[sketch][feedback][replay]") {
  Log plain = closed_square();
  Log hovering = closed_square();
  hovering.pen(0.051, 0.003).pen(0.05, 0.05);
  const auto a = replay(plain), b = replay(hovering);
  CHECK(b->pen_feedback.pen_seen);
  CHECK(world_hash(*a) == world_hash(*b));
}

TEST_CASE("a mouse stroke's end lands on a vertex within its logged snap radius, and the feedback shows that vertex",
          "[sketch][feedback]") {
  // A polyline point of the left curve lies nearer the pen than the corner (0, 0.1) does.
  const Log log = square_with_dense_left();
  Log plain = log, mouse = log;
  // Each ends 1.1 mm from the left curve's point (0, 0.098) and 2.7 mm from the corner.
  plain.event("down").pen(0.05, 0).pen(0.03, 0.05).pen(0.001, 0.0975);
  mouse.event("down").pen(0.05, 0).pen(0.03, 0.05).event("pen 0.001 0.0975 0 0.005");

  // The corners and the bottom's middle: no new vertex beside the corner.
  check_end_lands(mouse, Vec3(0, 0.1, 0), 5);
  // Without a logged radius (and no vertex snap in the session), the nearest polyline point.
  check_end_lands(plain, Vec3(0, 0.098, 0), 6);
}

TEST_CASE("a stroke end whose curve point lies within the vertex radius of a vertex lands on that vertex",
          "[sketch][feedback]") {
  // The pen ends 3.2 mm from the corner (0, 0.1), beyond the logged 3 mm, but 2.5 mm from the left curve's
  // point (0, 0.098), which is 2 mm from the corner: a vertex there would leave a curve piece of 2 mm beside
  // the corner, shorter than the pen's own error.
  Log log = square_with_dense_left();
  log.event("down").pen(0.05, 0).pen(0.03, 0.05).event("pen 0.0025 0.098 0 0.003");
  check_end_lands(log, Vec3(0, 0.1, 0), 5);
}

TEST_CASE("a stroke's pauses at its ends are not drawn: no curve point lingers within the vertex snap of its ends",
          "[sketch]") {
  // A diagonal from corner to corner, the pen resting 21 samples on each end first (jittering within 1 mm)
  // and moving in 1 cm steps between; the samples carry a 3 mm radius, as the mouse's do.
  const auto split = [](double radius) {
    Log log = closed_square();
    log.event("down");
    const auto sample = [&](double x, double y) {
      std::string event = "pen " + format_double(x) + " " + format_double(y) + " 0";
      if (radius > 0) event.append(" ").append(format_double(radius));
      log.event(event);
    };
    for (int k = 0; k <= 20; ++k) sample(0.0005 + 0.0005 * ((k * 7) % 3), 0.0005 + 0.0004 * ((k * 5) % 3));
    for (int k = 1; k <= 8; ++k) sample(0.011 * k, 0.011 * k);
    for (int k = 0; k <= 20; ++k) sample(0.0995 - 0.0005 * ((k * 7) % 3), 0.0995 - 0.0004 * ((k * 5) % 3));
    log.event("up");
    return replay(log);
  };
  const auto diagonal = [](const World& w) -> std::span<const Vec3> {
    for (EdgeIndex e{0}; e < w.mesh.edge_slots(); ++e)
      if (w.mesh.edge_alive(e)) {
        const auto line = w.mesh.polyline(e);
        if ((line.front() - line.back()).norm() > 0.12) return line;  // only the diagonal spans the square
      }
    FAIL("no diagonal");
    return {};
  };

  const auto w = split(0.003);
  REQUIRE(w->mesh.face_count() == 2);
  const auto line = diagonal(*w);
  CHECK(line.size() == 10);  // the two ends and the 8 moving samples
  for (size_t i = 1; i + 1 < line.size(); ++i) {
    CHECK((line[i] - line.front()).norm() > 0.003);
    CHECK((line[i] - line.back()).norm() > 0.003);
  }
  // Without a snap radius for vertices, the stroke is kept as drawn (each pause less its repeated samples).
  const auto kept = split(0);
  REQUIRE(kept->mesh.face_count() == 2);
  CHECK(diagonal(*kept).size() > 20);
}
