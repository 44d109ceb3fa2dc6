// A mark touched while the pen is down: what the pen drew since it went down is a touch of that mark, not a
// stroke (the registration system passes the command on when part of it was released already).
#include <catch2/catch.hpp>

#include "systems/sketch/sketch.hpp"

using namespace fire;

namespace {

InputEvent event(EventKind kind, const Vec3& p = Vec3::Zero()) {
  InputEvent e;
  e.kind = kind;
  e.p = p;
  return e;
}

}  // namespace

TEST_CASE("a mark touched during a stroke drops it, and the next stroke is drawn from its own samples", "[sketch]") {
  Mesh mesh;
  SnapIndex snap;
  SketchState state;
  std::vector<EditRequest> requests;
  std::vector<Rejection> rejections;
  PenFeedback feedback;
  auto frame = [&](std::vector<InputEvent> events) {
    requests.clear();
    sketch_system(events, mesh, snap, SketchSettings{}, std::nullopt, state, requests, rejections, feedback);
  };
  // The pen rests, flickering in depth, and a mark is touched; the registration system swallows its Up.
  InputEvent mark = event(EventKind::Command, Vec3(0.1, 0, 0));
  mark.command = CommandKind::Mark;
  frame({event(EventKind::Down), event(EventKind::Pen, Vec3(0, 0, 0)), event(EventKind::Pen, Vec3(0, 0, 0.0035)), mark});
  CHECK(requests.empty());
  CHECK(!state.pen_down);
  CHECK(state.stroke.empty());
  // A border stroke after it: its points are its own, and no "pen down while already down".
  frame({event(EventKind::Down), event(EventKind::Pen, Vec3(0.2, 0, 0)), event(EventKind::Pen, Vec3(0.25, 0, 0)),
         event(EventKind::Pen, Vec3(0.3, 0, 0)), event(EventKind::Up)});
  REQUIRE(requests.size() == 1);
  CHECK(requests[0].command.kind == EditKind::StartBorder);
  REQUIRE(requests[0].command.points.size() == 3);
  CHECK(requests[0].command.points.front().isApprox(Vec3(0.2, 0, 0)));
  CHECK(rejections.empty());
}
