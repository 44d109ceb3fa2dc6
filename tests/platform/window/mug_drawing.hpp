#pragma once
// A mouse drawing of a whole object, written as an `fire app --script`: the simulated person's plan
// (tools/simulation/drawing_plan.hpp: the border, splits, caps over a handle's roots opened as holes, the handle
// drawn across them, curves no view shows whole drawn in pieces) for the object's curve network, each stroke drawn
// from a view of the app's orbit that sees all of it, with right-drag orbits between them. The test draws the mug
// with it, its handle included; nothing in it is the mug's but the test's choice of object.
#include <cstdint>
#include <string>

#include "engine/common.hpp"
#include "engine/polygon_mesh.hpp"
#include "systems/evaluate/evaluate.hpp"

namespace fire::test {

struct MouseDrawing {
  std::string script;
  uint32_t faces = 0, edges = 0;  // the network the strokes make
  int strokes = 0;  // pen strokes, the one drawn again after its undo included
  int holes = 0;    // faces opened with O
  int pieces = 0;   // strokes that end off the network, a curve drawn in pieces from several views
};

// The drawing of `control`'s network (network_from_mesh's at --unrefine 2 on its limit surface, without the curves
// a mouse cannot draw unambiguously: mug_drawing.cpp's mouse_network) on `reference`, what `fire app --reference`
// draws on (`control`'s limit surface at --reference-levels), in a window of width x height. The view is zoomed in
// three steps; the plan's poses are that view turned every 15 degrees about the up axis, from a little below the
// horizon to nearly straight down. One split is undone (Ctrl+Z) and drawn again, as the simulated person does; a
// cap is opened by O with the cursor on the reference where the sketch takes the point for that face; E exports
// the surface, the view turns back to the first one for the screenshot, and the window closes. Fails, naming the
// step, when the plan fails or no view shows a step.
Result<MouseDrawing> mouse_drawing(const PolygonMeshView& control, const evaluate::TriangleMesh& reference, uint32_t width, uint32_t height);

}  // namespace fire::test
