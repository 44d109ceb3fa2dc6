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
  uint32_t edge = kNone;
  uint32_t point = 0;
};

// Kinds are appended, never reordered: snapshots hold them as bytes.
enum class EditKind : uint8_t { StartBorder, AppendBorder, CloseBorder, SplitFace, DeleteCurve, ToggleSharp, MakeHole, SplitHole,
                                JoinBorders };

struct EditCommand {
  EditKind kind = EditKind::StartBorder;
  std::vector<Vec3> points;  // the new curve's polyline (the border and split kinds)
  uint32_t face = kNone;     // SplitFace: the face the curve crosses; MakeHole: the face that becomes a hole
  CurveEnd start, end;       // SplitFace: where the curve starts and ends on that face's boundary; SplitHole: on
                             // one border loop, whose hole the curve crosses; JoinBorders: on two border loops
  uint32_t edge = kNone;     // DeleteCurve, ToggleSharp (sharp becomes smooth, smooth sharp)
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
