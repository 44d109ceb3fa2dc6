#pragma once
// The sketch system: turns pen strokes and user commands into edit requests (thesis 5.4 and 5.5).
// A stroke is the pen samples between `down` and `up`. Its ends are snapped to the nearest polyline
// point of a face that holds both ends, found through the snapping index (engine/snap_index.hpp), which
// gives the answers of an exhaustive search (thesis 5.5.1); strokes that cannot be placed are rejected
// with a reason, and nothing already drawn changes.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "engine/input_log.hpp"
#include "engine/edit_command.hpp"
#include "engine/mesh.hpp"
#include "engine/pen_feedback.hpp"
#include "engine/snap_index.hpp"

namespace fire {

struct SketchSettings {
  double snap_distance = 0.01;  // how far a stroke end may be from the polyline it snaps to (model units),
                                // unless the end's pen sample carries its own radius (InputEvent::snap)
  uint32_t close_samples = 16;  // points on the straight edge made by `cmd close`
  // A split's end within this distance of one of its face's vertices, or whose nearest polyline point is, lands
  // on that vertex (0: off, the nearest polyline point always). A tracked pen never ends exactly on a vertex;
  // a new vertex a millimetre from an old one leaves a sliver of an edge and faces with extra sides. An end whose pen sample carries its own radius
  // (the mouse) lands on a vertex within the larger of the two: a cursor cannot hit a vertex exactly either.
  // The stroke's samples within that radius of where an end lands are the pen pausing there, and are not drawn.
  double vertex_snap = 0;
  // A split's end corrections spread over this fraction of the stroke from each end (1: the whole
  // stroke; a border's always do). Under 1 the middle stays where it was drawn, so a curve snapped onto curves that were themselves
  // moved does not inherit their moves: over a drawing of many curves drawn onto each other they add up.
  double blend_reach = 1;
  // Strokes that change the topology (engine/INPUT_LOG.md, version 2): a stroke that no face holds may cross one
  // border loop's hole (the far side of the surface), and one with both ends far from every curve starts a new
  // part's border. Off for a version-1 log, where such strokes were refused, so it replays as it was drawn.
  bool topology_strokes = true;
  // Where several faces hold both ends of a stroke that no camera saw (the mouse), the face its middle sample
  // lies in takes it, not the nearest. Off for a log before version 3, which gave it the nearest face.
  bool middle_picks_face = true;
};

// For a pen tracked by the rig: vertex_snap (metres), a few times the tracked pen's error at rest, and
// blend_reach. Measured on the simulated drawing in perf/notes/drawing.md.
inline constexpr double kTrackedVertexSnap = 0.003;
inline constexpr double kTrackedBlendReach = 1.0 / 3;

// Which way the faces of one part of the mesh turn about the object's outside, seen from the cameras: +1
// counter-clockwise, -1 clockwise. Set by the part's first split, whose stroke goes into the part's one face.
struct OutsideTurn {
  VertexId at;  // a vertex of the part
  int8_t turn = 0;
};

struct SketchState {
  bool pen_down = false;
  std::vector<OutsideTurn> outside;  // one per part whose first split was drawn through the rig
  std::vector<Vec3> stroke;
  double start_snap = 0, end_snap = 0;  // the snap radii logged with the stroke's first and last samples (0: none)
  std::vector<InputEvent> pending;  // events after this frame's request, handled next frame
};

// Where a stroke end lands: the face, and the polyline point on that face's boundary.
struct Snap {
  FaceIndex face;
  CurveEnd start, end;
  double start_distance = 0, end_distance = 0;
};

// The face whose boundary passes closest to both points (sum of distances), each within `limit`; on equal
// sums the lowest face slot, and on each boundary the point first in loop order. `index` is in step with `mesh`.
// With `accept`, only the faces whose snap it accepts are chosen.
Snap snap_to_face(const Mesh& mesh, const SnapIndex& index, const Vec3& start, const Vec3& end, double limit,
                  const std::function<bool(const Snap&)>& accept = {});
// The live edge with a polyline point nearest to p within `limit` (the lowest slot on ties), or kNone.
EdgeIndex pick_edge(const SnapIndex& index, const Vec3& p, double limit);

// The live face the pen is over: the pen projects inside its boundary, seen along the boundary's mean normal
// (Newell), and lies off that plane by at most the boundary's distance from its centroid; of several, the one
// nearest its plane (the lowest slot on ties). kNone when there is none.
FaceIndex face_under(const Mesh& mesh, const Vec3& p);

// Emits at most one request per frame (see `pending`). `snap` is in step with `mesh`. Publishes `feedback`
// (engine/pen_feedback.hpp) for the mesh as this frame found it, from the last pen sample handled.
// `viewpoint`: where camera 0 is in the object's frame, once the rig is registered. With it, a stroke whose ends
// one face's border curves hold, but which leaves that face at both ends as the camera sees it, crosses the
// border loop's hole (the far side, drawn with the object turned over) instead of splitting the face.
void sketch_system(const std::vector<InputEvent>& frame_events, const Mesh& mesh, const SnapIndex& snap,
                   const SketchSettings& settings, const std::optional<Vec3>& viewpoint, SketchState& state,
                   std::vector<EditRequest>& requests, std::vector<Rejection>& rejections, PenFeedback& feedback);

}  // namespace fire
