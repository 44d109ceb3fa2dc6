#pragma once
// The exhaustive snapping searches the sketch system used before the snapping index, kept as the oracle the
// index is checked against: same answers, same tie-breaks.
#include <vector>

#include "engine/snap_index.hpp"
#include "systems/sketch/sketch.hpp"

namespace fire::test {

// Nearest point of face f's boundary, walking the loop in order; the earlier point wins on equal distance.
SnapHit exhaustive_nearest_on_face(const Mesh& m, FaceIndex f, const Vec3& p);
// sketch's snap_to_face before the index: every live face, the lowest slot winning on equal cost.
Snap exhaustive_snap_to_face(const Mesh& m, const Vec3& start, const Vec3& end, double limit);
// sketch's pick_edge before the index: the first live edge (slot order) with the least distance within limit.
EdgeIndex exhaustive_pick_edge(const Mesh& m, const Vec3& p, double limit);
// Nearest point of any live edge within radius; the lowest edge slot, then point index, wins ties.
SnapHit exhaustive_nearest(const Mesh& m, const Vec3& p, double radius);
// For every live edge with a point within radius, its nearest point (lowest index on ties), by edge slot.
std::vector<SnapHit> exhaustive_nearest_per_edge(const Mesh& m, const Vec3& p, double radius);

}  // namespace fire::test
