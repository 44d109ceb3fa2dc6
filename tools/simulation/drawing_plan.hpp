#pragma once
// The simulated person's plan for drawing a curve network of any kind a person puts on a table: one or
// several border loops, none (closed), handles. It follows the sketch's rules (systems/sketch, systems/split)
// on a model of the drawing that it keeps as it goes: the network's faces and, over each border loop the first
// disc does not have and each end of a handle, a cap that is drawn around and then opened with `cmd hole`.
//
// The layout: the first border loop closes to a disc that covers every face but the far side. A handle is a
// ring of faces (a band) left out of the disc, its two rims capped; a closed object without one leaves out
// the two faces at its top. Strokes split the disc (an ear decomposition, fewest curves and shortest first,
// each inside one face); a cap, once a face of its own, becomes a hole; then strokes across the far side, with
// both ends on border loops, turn it into faces: one from a loop back to itself (a hole split), two between
// the rims of a band (a bridge, then the wall). Each stroke is drawn in the pose nearest the current one that
// shows it whole; one no pose shows whole is drawn in pieces, each ending off the network, the object turned
// and registered again between them. Parts are drawn one after another, each from its own border loop.
#include <functional>
#include <vector>

#include "engine/common.hpp"
#include "tools/simulation/simulate.hpp"

namespace fire::simulation {

std::vector<Vec3> chain_points(const DrawingNetwork& net, const Chain& chain);

struct PlanStep {
  enum class Kind { Register, Stroke, Undo, Hole, Sharp } kind;
  int pose = 0;
  // Stroke: the pen's path (object frame); Hole: one point, where the pen touches the face; Sharp: one point, where
  // it touches the curve.
  std::vector<Vec3> points;
};

struct DrawingPlan {
  std::vector<PlanStep> steps;
  int border_strokes = 0;
  int holes = 0;
  int sharp = 0;   // touches of cmd sharp
  int pieces = 0;  // strokes that end off the network, a curve drawn in pieces from several poses
  size_t curves_drawn = 0;
};

// What the plan asks of the rig: the poses nearest `current` first (every pose the object may take), and
// whether both cameras see point i of a curve in a pose (with enough marks to register on there).
struct PoseQuestions {
  std::function<std::vector<int>(int current)> order;
  std::function<bool(int pose, uint32_t curve, size_t point)> sees;
};

// Fails, naming the first curve it cannot draw and why, unless every curve is drawn or `max_strokes` (> 0)
// strokes are. `undo_after` (> 0): that split stroke is undone and drawn again.
Result<DrawingPlan> plan_drawing(const DrawingNetwork& net, const PoseQuestions& poses, int max_strokes, int undo_after);

// Whether a network has no border loop: its underside is drawn with the object upside down.
bool network_closed(const DrawingNetwork& net);

}  // namespace fire::simulation
