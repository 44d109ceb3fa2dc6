#pragma once
// Edit commands: the data the sketch system produces and the split system applies.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "engine/mesh.hpp"

namespace fire {

// Where a curve ends: a polyline point of an edge. Point 0 and the last point are the edge's vertices.
struct CurveEnd {
  EdgeIndex edge;
  uint32_t point = 0;
};

// Kinds are appended, never reordered: snapshots hold them as bytes.
enum class EditKind : uint8_t { StartBorder, AppendBorder, CloseBorder, SplitFace, DeleteCurve, ToggleSharp, MakeHole, SplitHole,
                                JoinBorders, CrossCurves, ExtendChain };

// CrossCurves: one place where the stroke crosses a curve of the network.
struct Crossing {
  CurveEnd at;           // the crossed curve's polyline point (a vertex at its first or last point) where the stroke is cut
  uint32_t point = 0;    // the stroke's point there, an index into EditCommand::points: the pieces either side share it
  FaceIndex face;        // the face the stroke runs into after the crossing
};

struct EditCommand {
  EditKind kind = EditKind::StartBorder;
  std::vector<Vec3> points;  // the new curve's polyline (the border and split kinds)
  FaceIndex face;            // SplitFace: the face the curve crosses; MakeHole: the face that becomes a hole;
                             // CrossCurves: the face the stroke starts in
  CurveEnd start, end;       // SplitFace: where the curve starts and ends on that face's boundary; SplitHole: on
                             // one border loop, whose hole the curve crosses; JoinBorders: on two border loops;
                             // CrossCurves: on the boundaries of the first and the last face it runs through
  std::vector<Crossing> crossings;  // CrossCurves: in stroke order, at least one
  EdgeIndex edge;            // DeleteCurve, ToggleSharp (sharp becomes smooth, smooth sharp); ExtendChain and the
                             // kinds that split (SplitFace, SplitHole, JoinBorders, CrossCurves): the last piece of
                             // the pending chain the stroke goes on from (kNone: none; points then hold the whole
                             // chain and the stroke, from where the chain began)
  double snap_distance = 0;  // CloseBorder: how far the last point may lie from the first vertex
};

// A request from the sketch system to the split system.
enum class RequestKind : uint8_t { Edit, Undo, Redo };

struct EditRequest {
  RequestKind kind = RequestKind::Edit;
  EditCommand command;
  int64_t t_us = 0;
  uint32_t line = 0;  // input log line that completed the request
};

// Something the person did that did not become an edit, and why.
struct Rejection {
  int64_t t_us = 0;
  uint32_t line = 0;
  std::string reason;
};

}  // namespace fire
