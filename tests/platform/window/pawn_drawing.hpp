#pragma once
// A mouse drawing that covers the whole pawn, written as an `fire app --script`: the strokes a person would
// make, each drawn from a view that sees all of it, with right-drag orbits between them.
#include <cstdint>
#include <string>

#include "engine/common.hpp"
#include "systems/evaluate/evaluate.hpp"

namespace fire::test {

struct PawnDrawing {
  std::string script;
  uint32_t faces = 0, edges = 0;  // the network the strokes make, the undone one left out
};

// `reference` is what `fire app --reference` draws on (the pawn's limit surface at its --reference-levels),
// in a window of width x height. The network is a latitude-longitude one: a border round the bottom ring in
// four strokes; six meridians from it to the top, the first two as one stroke over the top, the others each
// ending at the top's vertex; then in each of the six sectors, five ring arcs from one meridian to the next.
// One more arc is drawn and undone (Ctrl+Z); E exports the surface; then the window closes.
// Fails, naming the stroke, when a view cannot see all of a stroke.
Result<PawnDrawing> pawn_drawing(const evaluate::TriangleMesh& reference, uint32_t width, uint32_t height);

}  // namespace fire::test
