#include "exhaustive_snap.hpp"

#include <limits>

namespace fire::test {

SnapHit exhaustive_nearest_on_face(const Mesh& m, FaceIndex f, const Vec3& p) {
  SnapHit best;
  for (OrientedEdge oe : m.face_loop(f)) {
    const EdgeIndex e = edge_of(oe);
    auto line = m.polyline(e);
    for (uint32_t k = 0; k < line.size(); ++k) {
      double d = (line[k] - p).norm();
      if (d < best.distance) best = {e, k, d};
    }
  }
  return best;
}

Snap exhaustive_snap_to_face(const Mesh& m, const Vec3& start, const Vec3& end, double limit) {
  Snap best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (FaceIndex f{0}; f < m.face_slots(); ++f) {
    if (!m.face_alive(f)) continue;
    SnapHit a = exhaustive_nearest_on_face(m, f, start), b = exhaustive_nearest_on_face(m, f, end);
    if (a.distance > limit || b.distance > limit) continue;
    double cost = a.distance + b.distance;
    if (cost < best_cost) {
      best_cost = cost;
      best = {f, {a.edge, a.point}, {b.edge, b.point}, a.distance, b.distance};
    }
  }
  return best;
}

EdgeIndex exhaustive_pick_edge(const Mesh& m, const Vec3& p, double limit) {
  EdgeIndex best;
  double best_d = limit;
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e) {
    if (!m.edge_alive(e)) continue;
    for (const Vec3& q : m.polyline(e)) {
      double d = (q - p).norm();
      if (d <= best_d && (best == kNone || d < best_d)) {
        best_d = d;
        best = e;
      }
    }
  }
  return best;
}

SnapHit exhaustive_nearest(const Mesh& m, const Vec3& p, double radius) {
  SnapHit best;
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e) {
    if (!m.edge_alive(e)) continue;
    auto line = m.polyline(e);
    for (uint32_t k = 0; k < line.size(); ++k) {
      double d = (line[k] - p).norm();
      if (d <= radius && d < best.distance) best = {e, k, d};
    }
  }
  return best;
}

std::vector<SnapHit> exhaustive_nearest_per_edge(const Mesh& m, const Vec3& p, double radius) {
  std::vector<SnapHit> out;
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e) {
    if (!m.edge_alive(e)) continue;
    SnapHit best;
    auto line = m.polyline(e);
    for (uint32_t k = 0; k < line.size(); ++k) {
      double d = (line[k] - p).norm();
      if (d <= radius && d < best.distance) best = {e, k, d};
    }
    if (best.found()) out.push_back(best);
  }
  return out;
}

}  // namespace fire::test
