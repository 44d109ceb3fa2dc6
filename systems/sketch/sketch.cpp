#include "systems/sketch/sketch.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>  // cross products
#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>

#include "engine/text.hpp"

namespace fire {

namespace {

// Moves a stroke so that it starts at `start` and ends at `end`, spreading each end's correction by arc length
// over the fraction `reach` of the stroke next to that end: snapping bends the curve a little instead of kinking
// its last sample, and a surface that passes through the curve shows no fold there. With a reach under 1 the
// stroke's middle stays where the pen drew it (SketchSettings::blend_reach).
void blend_ends(std::vector<Vec3>& stroke, const Vec3& start, const Vec3& end, double reach) {
  std::vector<double> arc(stroke.size(), 0.0);
  for (size_t i = 1; i < stroke.size(); ++i) arc[i] = arc[i - 1] + (stroke[i] - stroke[i - 1]).norm();
  const double total = arc.back();
  const Vec3 d0 = start - stroke.front(), d1 = end - stroke.back();
  for (size_t i = 0; i < stroke.size(); ++i) {
    const double t = total > 0 ? arc[i] / total : double(i) / double(stroke.size() - 1);
    const double w0 = reach >= 1 ? 1.0 - t : std::max(0.0, 1.0 - t / reach);
    const double w1 = reach >= 1 ? t : std::max(0.0, 1.0 - (1.0 - t) / reach);
    stroke[i] += w0 * d0 + w1 * d1;
  }
  stroke.front() = start;
  stroke.back() = end;
}

// Drops the samples a stroke spends near each of its ends, within `start_radius` of `start` and `end_radius` of
// `end` (searched in the half of the stroke next to that end): a pen pauses when it is put down and lifted, and
// the samples of a pause wander within the tracking error while the stroke's length grows. Left in, a curve
// spends part of its length on the spot, and the surface, whose rows follow the curves by length, is crumpled
// where several such curves meet (the simulated drawing's pole, perf/notes/quality.md). The end samples stay, for
// blend_ends to move onto the ends.
void drop_pauses(std::vector<Vec3>& stroke, const Vec3& start, double start_radius, const Vec3& end, double end_radius) {
  const size_t n = stroke.size(), half = n / 2;
  size_t first = 1, last = n - 1;  // keep [first, last) between the end samples
  for (size_t i = 1; i < half; ++i)
    if ((stroke[i] - start).norm() < start_radius) first = i + 1;
  for (size_t i = n - 1; i-- > half;)
    if ((stroke[i] - end).norm() < end_radius) last = i;
  if (first >= last) return;  // a stroke all pause: nothing to go by, keep it as drawn
  std::vector<Vec3> kept{stroke.front()};
  kept.insert(kept.end(), stroke.begin() + std::ptrdiff_t(first), stroke.begin() + std::ptrdiff_t(last));
  kept.push_back(stroke.back());
  stroke = std::move(kept);
}

// The vertex of `face` nearest to p, or to the curve point p snapped to, if it lies within `radius`, as a
// curve end; else `end` as it was. A curve point that close to a vertex is the vertex within the pen's error,
// and a new vertex there would leave a curve piece shorter than the radius beside it.
CurveEnd at_vertex(const Mesh& mesh, std::span<const OrientedEdge> loop, const CurveEnd& end, const Vec3& p, double radius) {
  CurveEnd best = end;
  double nearest = radius;
  const Vec3 snapped = mesh.polyline(end.edge)[end.point];
  for (OrientedEdge oriented : loop) {
    const EdgeIndex e = edge_of(oriented);
    const std::span<const Vec3> line = mesh.polyline(e);
    for (uint32_t k : {uint32_t(0), uint32_t(line.size() - 1)})
      if (const double d = std::min((line[k] - p).norm(), (line[k] - snapped).norm()); d < nearest) {
        nearest = d;
        best = {e, k};
      }
  }
  return best;
}

// Where a stroke across a hole lands: both ends on border loops, the nearest border point to each end within
// `limit`, the end's on the start's loop where there is one (a curve across that loop's hole), else on another
// loop (a curve joining the two, `join`).
struct HoleSnap {
  std::vector<OrientedEdge> rim;  // the start's border loop, as Mesh::border_loop walks it; empty when there is none
  std::vector<OrientedEdge> end_rim;  // the end's: `rim` unless `join`
  CurveEnd start, end;
  bool join = false;
};

HoleSnap snap_to_hole(const Mesh& m, const SnapIndex& index, const Vec3& start, const Vec3& end, double limit) {
  // The nearest of `hits` on a border curve with a face, and the nearest of those on `rim` (when given).
  auto nearest_border = [&](const std::vector<SnapHit>& hits, const std::vector<OrientedEdge>* rim) {
    SnapHit best, best_on_rim;
    auto better = [](const SnapHit& h, const SnapHit& than) {
      return !than.found() || h.distance < than.distance || (h.distance == than.distance && h.edge < than.edge);
    };
    for (const SnapHit& h : hits) {
      if (!m.is_border_edge(h.edge) || m.is_loose_edge(h.edge)) continue;
      if (better(h, best)) best = h;
      if (rim && std::any_of(rim->begin(), rim->end(), [&](OrientedEdge oe) { return edge_of(oe) == h.edge; }) && better(h, best_on_rim))
        best_on_rim = h;
    }
    return std::pair{best, best_on_rim};
  };
  std::vector<SnapHit> hits;
  HoleSnap out;
  index.nearest_per_edge(start, limit, hits);
  const SnapHit a = nearest_border(hits, nullptr).first;
  if (!a.found()) return out;
  std::vector<OrientedEdge> rim = m.border_loop(a.edge);
  if (rim.empty()) return out;
  index.nearest_per_edge(end, limit, hits);
  const auto [any_rim, on_rim] = nearest_border(hits, &rim);
  out.join = !on_rim.found();
  const SnapHit b = out.join ? any_rim : on_rim;
  if (!b.found()) return out;
  out.end_rim = out.join ? m.border_loop(b.edge) : rim;
  if (out.end_rim.empty()) return out;
  out.rim = std::move(rim);
  out.start = {a.edge, a.point};
  out.end = {b.edge, b.point};
  return out;
}

// Which side of its boundary a face lies on at a stroke's end, seen from the camera (`viewpoint`, a point the
// pen's side of the surface faces: the cameras saw the pen draw there).
constexpr double kSideReach = 0.005;  // metres: directions from points this far along, past the pen's jitter

// The direction from `from` to the first point of `line` at least kSideReach away (or its last point).
Vec3 direction_along(std::span<const Vec3> line, const Vec3& from) {
  for (const Vec3& p : line)
    if ((p - from).norm() >= kSideReach) return (p - from).normalized();
  return (line.back() - from).normalized();
}

// The curves at a vertex in counter-clockwise order about the surface's normal there, turned toward the camera.
struct Fan {
  Vec3 normal, first;  // `first`: where angles start, in the plane
  std::vector<std::pair<double, uint32_t>> edges;  // angle about `normal`, edge
  double angle(const Vec3& d) const {
    const Vec3 w = normal.cross(first);
    const double a = std::atan2(d.dot(w), d.dot(first));
    return a < 0 ? a + 2 * std::numbers::pi : a;
  }
};

// At vertex v with three or more curves: the normal is the one their directions (and the stroke's, `d`) leave
// least of, turned toward the camera. nullopt with fewer curves.
std::optional<Fan> fan_at(const Mesh& m, VertexIndex v, const Vec3& d, const Vec3& viewpoint) {
  Fan fan;
  const Vec3& at = m.vertices.position[v];
  std::vector<EdgeIndex> incident = m.vertex_edges(v);
  std::sort(incident.begin(), incident.end());
  incident.erase(std::unique(incident.begin(), incident.end()), incident.end());
  std::vector<std::pair<EdgeIndex, Vec3>> directions;
  for (EdgeIndex e : incident) {
    if (m.is_loose_edge(e)) continue;
    const std::span<const Vec3> line = m.polyline(e);
    for (int side = 0; side < 2; ++side)
      if (m.edges.vertex[e][side] == v) {
        const std::vector<Vec3> from_v = side == 0 ? std::vector<Vec3>(line.begin(), line.end()) : std::vector<Vec3>(line.rbegin(), line.rend());
        directions.emplace_back(e, direction_along(from_v, at));
      }
  }
  if (directions.size() < 3) return std::nullopt;
  Eigen::Matrix3d moments = d * d.transpose();
  for (const auto& [e, u] : directions) moments += u * u.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(moments);
  fan.normal = solver.eigenvectors().col(0);
  if (fan.normal.dot(viewpoint - at) < 0) fan.normal = -fan.normal;
  fan.first = (directions.front().second - directions.front().second.dot(fan.normal) * fan.normal).normalized();
  for (const auto& [e, u] : directions) fan.edges.emplace_back(fan.angle(u), e);
  std::sort(fan.edges.begin(), fan.edges.end());
  return fan;
}

// +1 where the faces at a fan walk counter-clockwise about its normal (each face's curve out of the vertex is
// followed, counter-clockwise, by its curve in), -1 where clockwise; 0 where they do not say.
int fan_turn(const Mesh& m, const Fan& fan, uint32_t v) {
  const size_t n = fan.edges.size();
  auto rank = [&](uint32_t e) {
    return size_t(std::find_if(fan.edges.begin(), fan.edges.end(), [&](const auto& x) { return x.second == e; }) - fan.edges.begin());
  };
  // The faces at v: those beside its curves, each once.
  std::vector<FaceIndex> faces;
  for (const auto& [angle, e] : fan.edges)
    for (uint32_t f : m.edges.face[e])
      if (f != kNone) faces.push_back(FaceIndex{f});
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  int votes = 0;
  for (FaceIndex f : faces) {
    const std::span<const OrientedEdge> loop = m.face_loop(f);
    for (size_t i = 0; i < loop.size(); ++i) {
      const OrientedEdge in = loop[i], out = loop[(i + 1) % loop.size()];
      if (m.head(in) != v || edge_of(in) == edge_of(out)) continue;
      const size_t r_in = rank(edge_of(in)), r_out = rank(edge_of(out));
      if (r_in == n || r_out == n) continue;
      if (r_in == (r_out + 1) % n) ++votes;
      else if (r_out == (r_in + 1) % n) --votes;
    }
  }
  return votes > 0 ? 1 : votes < 0 ? -1 : 0;
}

// How far around a stroke's end the network's curves say which plane the surface lies in.
constexpr double kNormalReach = 3 * kSideReach;
// A view, or a face's loop, at least this cosine off the surface's plane tells the surface's two sides apart.
constexpr double kSideCosine = 0.1;

// The unsigned normal of the plane the network's curves within kNormalReach of q lie in (the least direction of
// their spread), if they spread over a patch of surface rather than along one curve. The direction to the camera
// is the normal only where it looks straight at the surface: on a pawn's head seen from the side it lies within
// a few degrees of the surface, and a stroke's own noise then decides its side.
std::optional<Vec3> network_normal(const Mesh& m, const SnapIndex& index, const Vec3& q) {
  std::vector<SnapHit> hits;
  index.nearest_per_edge(q, kNormalReach, hits);
  Vec3 mean = Vec3::Zero();
  Eigen::Matrix3d moments = Eigen::Matrix3d::Zero();
  size_t n = 0;
  for (const SnapHit& h : hits)
    for (const Vec3& p : m.polyline(h.edge))
      if ((p - q).norm() <= kNormalReach) {
        mean += p;
        moments += p * p.transpose();
        ++n;
      }
  if (n < 3) return std::nullopt;
  mean /= double(n);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(moments / double(n) - mean * mean.transpose());
  const Eigen::Vector3d spread = solver.eigenvalues();
  if (!(spread(1) > 0) || std::sqrt(spread(1)) < kNormalReach / 8 || spread(0) > spread(1) / 4) return std::nullopt;
  return Vec3(solver.eigenvectors().col(0));
}

// Whether a stroke leaving the boundary point `end` of face f along `path` (from that end on) goes into f. At a
// vertex, f's sector lies counter-clockwise from its curve out to its curve in about the fan's normal when the
// faces turn that way there (`turn`); elsewhere, f lies to the left of its walk about the normal. `normal`: the
// surface's normal there, toward the camera.
bool goes_into(const Mesh& m, FaceIndex f, const CurveEnd& end, std::span<const Vec3> path, const Vec3& normal, int turn) {
  const Vec3 q = m.polyline(end.edge)[end.point];
  const std::vector<Vec3> loop = m.face_boundary(f);
  const size_t n = loop.size(), at = size_t(std::find(loop.begin(), loop.end(), q) - loop.begin());
  if (at == n) return true;
  std::vector<Vec3> ahead, behind;
  for (size_t k = 1; k < n; ++k) ahead.push_back(loop[(at + k) % n]), behind.push_back(loop[(at + n - k) % n]);
  const Vec3 up = double(turn) * normal;
  auto flat = [&](const Vec3& x) { return Vec3(x - x.dot(up) * up); };
  const Vec3 u = flat(direction_along(ahead, q)).normalized(), w = up.cross(u);
  auto angle = [&](const Vec3& x) {
    const double a = std::atan2(flat(x).dot(w), flat(x).dot(u));
    return a < 0 ? a + 2 * std::numbers::pi : a;
  };
  const double beta = angle(direction_along(path, q));
  return beta > 0 && beta < angle(direction_along(behind, q));
}

// A label per vertex slot, equal for the vertices of one part (joined by live edges).
std::vector<uint32_t> part_labels(const Mesh& m) {
  std::vector<uint32_t> up(m.vertex_slots());
  std::iota(up.begin(), up.end(), 0u);
  auto find = [&](uint32_t v) {
    while (up[v] != v) v = up[v] = up[up[v]];
    return v;
  };
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e)
    if (m.edge_alive(e)) up[find(m.edges.vertex[e][0])] = find(m.edges.vertex[e][1]);
  for (uint32_t v = 0; v < up.size(); ++v) up[v] = find(v);
  return up;
}

// The nearest point to p within `radius` of a curve of the network, not of a pending chain.
SnapHit network_nearest(const Mesh& m, const SnapIndex& index, const Vec3& p, double radius) {
  const SnapHit nearest = index.nearest(p, radius);
  if (!nearest.found() || !m.is_pending(nearest.edge)) return nearest;
  std::vector<SnapHit> hits;
  index.nearest_per_edge(p, radius, hits);
  SnapHit best;
  for (const SnapHit& h : hits)
    if (!m.is_pending(h.edge) && (h.distance < best.distance || (h.distance == best.distance && h.edge < best.edge))) best = h;
  return best;
}

// The points of a pending chain's pieces, from where it began to its free end.
std::vector<Vec3> chain_points(const Mesh& m, const std::vector<EdgeIndex>& chain) {
  std::vector<Vec3> points;
  for (EdgeIndex e : chain) {
    const std::span<const Vec3> line = m.polyline(e);
    points.insert(points.end(), line.begin() + (points.empty() ? 0 : 1), line.end());
  }
  return points;
}

// The open border's first and last vertices (the first is the start of the first edge drawn).
std::pair<VertexIndex, VertexIndex> border_ends(const Mesh& m) {
  VertexIndex first, last;
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e) {
    if (!m.edge_alive(e)) continue;
    if (const VertexIndex v{m.edges.vertex[e][0]}; m.valence(v) == 1) first = v;
    if (const VertexIndex v{m.edges.vertex[e][1]}; m.valence(v) == 1) last = v;
  }
  return {first, last};
}

// Which face of the surface each pen sample is over, told by the side of its nearest curve: a face walking that
// curve forwards lies to its left about the surface normal. A sample is over that face only within the face's
// slab: as far off the plane of its boundary as the boundary itself is, and a quarter of its size more (a face
// bulges past its curves); else it is off the surface, as the underside of an object drawn across its hole is.
// Samples within `radius` of a curve, or nearest to a curve's end (at a vertex one curve's side does not say
// which face), are not told.
inline constexpr uint32_t kUntold = kNone - 1;

class FaceBySide {
 public:
  FaceBySide(const Mesh& m, const SnapIndex& index, double radius) : m_(m), index_(index), radius_(radius) {}
  uint32_t operator()(const Vec3& p) {
    const SnapHit h = index_.nearest(p);
    if (!h.found() || h.distance <= radius_ || m_.is_loose_edge(h.edge)) return kUntold;
    const std::span<const Vec3> line = m_.polyline(h.edge);
    if (h.point == 0 || h.point + 1 == line.size()) return kUntold;
    // The curve's direction over a chord of a third of the snap radius (3 mm for a tracked pen, a few times its
    // error): where the pen rested, at a curve's ends, neighbouring samples lie a fraction of a millimetre apart
    // in any direction.
    size_t before = h.point - 1, after = h.point + 1;
    while ((line[after] - line[before]).norm() < radius_ / 3 && (before > 0 || after + 1 < line.size())) {
      if (before > 0) --before;
      if (after + 1 < line.size()) ++after;
    }
    const Vec3 tangent = line[after] - line[before];
    Vec3 normal = Vec3::Zero();
    for (uint32_t f : m_.edges.face[h.edge])
      if (f != kNone) normal += slab(f).normal;
    const bool left = tangent.cross(p - line[h.point]).dot(normal) > 0;
    const uint32_t f = m_.edges.face[h.edge][left ? 0 : 1];
    if (f == kNone) return kNone;
    const Slab& s = slab(f);
    const double height = (p - s.centroid).dot(s.normal);
    return height >= s.low && height <= s.high ? f : kNone;
  }

 private:
  struct Slab {
    uint32_t face;
    Vec3 centroid, normal;
    double low, high;
  };
  const Slab& slab(uint32_t f) {
    for (const Slab& s : slabs_)
      if (s.face == f) return s;
    const std::vector<Vec3> boundary = m_.face_boundary(FaceIndex{f});
    const LoopPlane plane = loop_plane(boundary);
    double low = 0, high = 0, extent = 0;
    for (const Vec3& q : boundary) {
      const double height = (q - plane.centroid).dot(plane.normal);
      low = std::min(low, height);
      high = std::max(high, height);
      extent = std::max(extent, (q - plane.centroid).norm());
    }
    const double margin = std::max(radius_, extent / 4);
    slabs_.push_back({f, plane.centroid, plane.normal, low - margin, high + margin});
    return slabs_.back();
  }
  const Mesh& m_;
  const SnapIndex& index_;
  double radius_;
  std::vector<Slab> slabs_;
};

// The faces a stroke runs over, in order, each with the samples told to be over it (first, last).
struct FaceRun {
  uint32_t face;
  size_t first, last;
};

std::vector<FaceRun> face_runs(const std::vector<Vec3>& stroke, FaceBySide& face_of) {
  std::vector<FaceRun> runs;
  for (size_t i = 0; i < stroke.size(); ++i) {
    const uint32_t f = face_of(stroke[i]);
    if (f == kUntold) continue;
    if (!runs.empty() && runs.back().face == f) runs.back().last = i;
    else runs.push_back({f, i, i});
  }
  return runs;
}

// Whether faces a and b share a corner (and so maybe a curve).
bool faces_touch(const Mesh& m, FaceIndex a, FaceIndex b) {
  const std::span<const OrientedEdge> la = m.face_loop(a), lb = m.face_loop(b);
  return std::any_of(la.begin(), la.end(), [&](OrientedEdge oa) {
    return std::any_of(lb.begin(), lb.end(), [&](OrientedEdge ob) { return m.tail(oa) == m.tail(ob); });
  });
}

// Where a stroke passing from face a to face b over samples [from, to] crosses: the point of a curve between them
// nearest to those samples (a corner they share, where they share no curve), and the sample nearest to it.
struct Cut {
  CurveEnd at;
  size_t sample = 0;
};

std::optional<Cut> crossing_between(const Mesh& m, FaceIndex a, FaceIndex b, const std::vector<Vec3>& stroke, size_t from, size_t to,
                                    double vertex_radius) {
  std::optional<Cut> best;
  double best_distance = std::numeric_limits<double>::infinity();
  auto consider = [&](EdgeIndex e, uint32_t k) {
    const Vec3& q = m.polyline(e)[k];
    for (size_t j = from; j <= to; ++j)
      if (const double d = (stroke[j] - q).norm(); d < best_distance) {
        best_distance = d;
        best = Cut{{e, k}, j};
      }
  };
  const std::span<const OrientedEdge> loop = m.face_loop(a);
  for (OrientedEdge oe : loop)
    if (m.other_face(edge_of(oe), a) == b)
      for (uint32_t k = 0; k < m.edges.point_count[edge_of(oe)]; ++k) consider(edge_of(oe), k);
  if (!best) {
    const std::span<const OrientedEdge> other = m.face_loop(b);
    for (OrientedEdge oe : loop)
      if (std::any_of(other.begin(), other.end(), [&](OrientedEdge ob) { return m.tail(ob) == m.tail(oe); }))
        consider(edge_of(oe), is_reversed(oe) ? m.edges.point_count[edge_of(oe)] - 1 : 0);
  }
  if (best) best->at = at_vertex(m, loop, best->at, stroke[best->sample], vertex_radius);
  return best;
}

// A stroke over several faces (issue 40): cut where it crosses a curve, each piece splitting the face it runs
// through, as one command. A crossing is a change of side of a curve on the surface: a stroke that runs along a
// curve, or touches one and leaves on the side it came from, stays in its face. Nothing when the stroke stays in
// one face, leaves the surface, or does not start and end on the curves of the faces it runs over (the other
// sketch rules then say what it is); `refusal` says why a stroke over several faces cannot be drawn.
std::optional<EditCommand> plan_crossing(const Mesh& m, const SnapIndex& index, std::vector<Vec3> stroke, double start_radius,
                                         double end_radius, double start_vertex_radius, double end_vertex_radius, double vertex_radius,
                                         double blend_reach, std::string& refusal) {
  FaceBySide face_of(m, index, std::max(start_radius, end_radius));
  // A crossing within the radius of an end is not told by side: the end's curve tells the face the stroke
  // starts in (or ends in) then, where one face by it touches the nearest told one.
  std::vector<SnapHit> hits;
  auto runs_with_ends = [&] {
    std::vector<FaceRun> runs = face_runs(stroke, face_of);
    if (runs.empty()) return runs;
    auto end_face = [&](const Vec3& p, double radius, uint32_t told) {
      if (told == kNone) return kNone;
      index.nearest_per_edge(p, radius, hits);
      std::vector<uint32_t> touching;
      for (const SnapHit& h : hits)
        for (uint32_t f : m.edges.face[h.edge]) {
          if (f == told) return told;
          if (f != kNone && !std::count(touching.begin(), touching.end(), f) && faces_touch(m, FaceIndex{f}, FaceIndex{told}))
            touching.push_back(f);
        }
      return touching.size() == 1 ? touching.front() : kNone;
    };
    if (const uint32_t f = end_face(stroke.front(), start_radius, runs.front().face); f != kNone && f != runs.front().face)
      runs.insert(runs.begin(), FaceRun{f, 0, 0});
    if (const uint32_t f = end_face(stroke.back(), end_radius, runs.back().face); f != kNone && f != runs.back().face)
      runs.push_back(FaceRun{f, stroke.size() - 1, stroke.size() - 1});
    return runs;
  };
  std::vector<FaceRun> runs = runs_with_ends();
  if (runs.size() < 2 || std::any_of(runs.begin(), runs.end(), [](const FaceRun& r) { return r.face == kNone; })) return std::nullopt;
  EditCommand c;
  c.kind = EditKind::CrossCurves;
  c.face = FaceIndex{runs.front().face};
  const FaceIndex last_face{runs.back().face};
  const SnapHit a = index.nearest_on_face(m, c.face, stroke.front(), start_radius);
  const SnapHit b = index.nearest_on_face(m, last_face, stroke.back(), end_radius);
  if (!a.found() || !b.found()) return std::nullopt;
  c.start = at_vertex(m, m.face_loop(c.face), {a.edge, a.point}, stroke.front(), start_vertex_radius);
  c.end = at_vertex(m, m.face_loop(last_face), {b.edge, b.point}, stroke.back(), end_vertex_radius);
  const Vec3 start = m.polyline(c.start.edge)[c.start.point], end = m.polyline(c.end.edge)[c.end.point];
  drop_pauses(stroke, start, start_vertex_radius, end, end_vertex_radius);
  runs = runs_with_ends();
  if (runs.size() < 2 || runs.front().face != c.face || runs.back().face != last_face) return std::nullopt;
  std::vector<Vec3> cuts{start};
  for (size_t r = 0; r + 1 < runs.size(); ++r) {
    const std::optional<Cut> cut = crossing_between(m, FaceIndex{runs[r].face}, FaceIndex{runs[r + 1].face}, stroke, runs[r].last, runs[r + 1].first, vertex_radius);
    if (!cut) return std::nullopt;  // faces that do not touch: not a stroke over the surface
    const size_t sample = std::max<size_t>(cut->sample, (c.crossings.empty() ? 0 : c.crossings.back().point) + 1);
    if (sample + 1 >= stroke.size()) {
      refusal = "the stroke crosses curves closer together than its pen samples; draw it more slowly";
      return std::nullopt;
    }
    c.crossings.push_back({cut->at, uint32_t(sample), FaceIndex{runs[r + 1].face}});
    cuts.push_back(m.polyline(cut->at.edge)[cut->at.point]);
  }
  cuts.push_back(end);
  // Each piece's ends move onto its cuts, as a single curve's do onto its ends.
  std::vector<size_t> at{0};
  for (const Crossing& x : c.crossings) at.push_back(x.point);
  at.push_back(stroke.size() - 1);
  for (size_t i = 0; i + 1 < at.size(); ++i) {
    std::vector<Vec3> piece(stroke.begin() + std::ptrdiff_t(at[i]), stroke.begin() + std::ptrdiff_t(at[i + 1] + 1));
    blend_ends(piece, cuts[i], cuts[i + 1], blend_reach);
    std::copy(piece.begin(), piece.end(), stroke.begin() + std::ptrdiff_t(at[i]));
  }
  c.points = std::move(stroke);
  return c;
}

}  // namespace

Snap snap_to_face(const Mesh& m, const SnapIndex& index, const Vec3& start, const Vec3& end, double limit,
                  const std::function<bool(const Snap&)>& accept) {
  // Only faces with a boundary point within `limit` of both ends can be chosen: those of the edges near both.
  std::vector<SnapHit> near_start, near_end;
  index.nearest_per_edge(start, limit, near_start);
  index.nearest_per_edge(end, limit, near_end);
  auto faces_of = [&](const std::vector<SnapHit>& hits) {
    std::vector<FaceIndex> out;
    for (const SnapHit& h : hits)
      for (uint32_t f : m.edges.face[h.edge])
        if (f != kNone) out.push_back(FaceIndex{f});
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  };
  const std::vector<FaceIndex> a_faces = faces_of(near_start), b_faces = faces_of(near_end);
  std::vector<FaceIndex> candidates;
  std::set_intersection(a_faces.begin(), a_faces.end(), b_faces.begin(), b_faces.end(), std::back_inserter(candidates));

  Snap best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (FaceIndex f : candidates) {
    if (!m.face_alive(f)) continue;
    const SnapHit a = index.nearest_on_face(m, f, start, limit), b = index.nearest_on_face(m, f, end, limit);
    if (!a.found() || !b.found()) continue;
    const double cost = a.distance + b.distance;
    if (cost >= best_cost) continue;
    const Snap snap{f, {a.edge, a.point}, {b.edge, b.point}, a.distance, b.distance};
    if (accept && !accept(snap)) continue;
    best_cost = cost;
    best = snap;
  }
  return best;
}

EdgeIndex pick_edge(const SnapIndex& index, const Vec3& p, double limit) { return index.nearest(p, limit).edge; }

namespace {

// How far p lies off face f's plane where it projects inside the face's boundary within the boundary's reach
// from its centroid (face_under's test for one face); nothing where it does not.
std::optional<double> height_inside(const Mesh& m, FaceIndex f, const Vec3& p) {
  const std::vector<Vec3> loop = m.face_boundary(f);
  const LoopPlane lp = loop_plane(loop);
  const Vec3 &centroid = lp.centroid, &normal = lp.normal;
  if (normal.norm() == 0) return std::nullopt;  // a degenerate loop has no inside
  double extent = 0;
  for (const Vec3& q : loop) extent = std::max(extent, (q - centroid).norm());
  const double height = std::abs((p - centroid).dot(normal));
  if (height > extent) return std::nullopt;
  // Crossing test in the plane, on a basis (u, v) of it.
  const Vec3 u = normal.unitOrthogonal(), v = normal.cross(u);
  auto plane = [&](const Vec3& q) { return std::pair{(q - centroid).dot(u), (q - centroid).dot(v)}; };
  const auto [px, py] = plane(p);
  bool inside = false;
  for (size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++) {
    const auto [xi, yi] = plane(loop[i]);
    const auto [xj, yj] = plane(loop[j]);
    if ((yi > py) != (yj > py) && px < xj + (py - yj) * (xi - xj) / (yi - yj)) inside = !inside;
  }
  return inside ? std::optional<double>(height) : std::nullopt;
}

}  // namespace

FaceIndex face_under(const Mesh& m, const Vec3& p) {
  FaceIndex best;
  double best_height = std::numeric_limits<double>::infinity();
  for (FaceIndex f{0}; f < m.face_slots(); ++f) {
    if (!m.face_alive(f)) continue;
    const std::optional<double> height = height_inside(m, f, p);
    if (height && *height < best_height) {
      best = f;
      best_height = *height;
    }
  }
  return best;
}

namespace {

// What the pen would do now, against the mesh as the frame found it.
void publish_feedback(const Mesh& mesh, const SnapIndex& snap, const SketchState& state, double start_radius,
                      double vertex_radius, PenFeedback& fb) {
  fb.pen_down = state.pen_down;
  fb.target_edge = {};
  fb.face = {};
  fb.first_vertex = {};
  fb.closes_border = false;
  if (!fb.pen_seen || mesh.edge_count() == 0) return;
  if (mesh.border_in_progress()) {
    const VertexIndex first = border_ends(mesh).first;
    if (first == kNone) return;
    fb.first_vertex = mesh.vertex_id(first);
    fb.closes_border = (fb.pen - mesh.vertices.position[first]).norm() <= fb.radius;
    if (fb.closes_border) fb.target = mesh.vertices.position[first];
    return;
  }
  if (state.pen_down && !state.stroke.empty()) {  // where the stroke would end, as the pen going up would place it
    const Snap s = snap_to_face(mesh, snap, state.stroke.front(), fb.pen, std::max(start_radius, fb.radius));
    if (s.face != kNone) {
      const CurveEnd end = at_vertex(mesh, mesh.face_loop(s.face), s.end, fb.pen, vertex_radius);
      fb.face = mesh.face_id(s.face);
      fb.target_edge = mesh.edge_id(end.edge);
      fb.target_point = end.point;
      fb.target = mesh.polyline(end.edge)[end.point];
      return;
    }
  }
  if (const SnapHit h = snap.nearest(fb.pen, fb.radius); h.found()) {
    fb.target_edge = mesh.edge_id(h.edge);
    fb.target_point = h.point;
    fb.target = mesh.polyline(h.edge)[h.point];
  }
  if (const FaceIndex f = face_under(mesh, fb.pen); f != kNone) fb.face = mesh.face_id(f);
}

}  // namespace

void sketch_system(const std::vector<InputEvent>& frame_events, const Mesh& mesh, const SnapIndex& snap,
                   const SketchSettings& settings, const std::optional<Vec3>& viewpoint, SketchState& state,
                   std::vector<EditRequest>& requests, std::vector<Rejection>& rejections, PenFeedback& feedback) {
  requests.clear();
  // At most one request per frame, so every request is placed on the mesh as the previous one left it;
  // events after it wait in `pending` for the next frame.
  auto radius = [&](double logged) { return logged > 0 ? logged : settings.snap_distance; };
  // A logged radius is the mouse's aperture: a vertex inside it takes the end, as the edge point would.
  auto vertex_radius = [&](double logged) { return std::max(settings.vertex_snap, logged); };
  std::vector<InputEvent> events = std::move(state.pending);
  state.pending.clear();
  events.insert(events.end(), frame_events.begin(), frame_events.end());
  for (size_t i = 0; i < events.size(); ++i) {
    if (!requests.empty()) {
      state.pending.assign(events.begin() + i, events.end());
      break;
    }
    const InputEvent& ev = events[i];
    auto reject = [&](std::string why) { rejections.push_back({ev.t_us, ev.line, std::move(why)}); };
    switch (ev.kind) {
      case EventKind::Down:
        if (state.pen_down) reject("pen down while already down: the unfinished stroke is dropped");
        state.pen_down = true;
        state.stroke.clear();
        break;
      case EventKind::Pen:
        feedback.pen_seen = true;
        feedback.pen = ev.p;
        feedback.radius = radius(ev.snap);
        if (!state.pen_down) break;
        if (state.stroke.empty()) state.start_snap = ev.snap;
        state.end_snap = ev.snap;
        state.stroke.push_back(ev.p);
        break;
      case EventKind::Up: {
        // Where a lifted pen is stays unknown until its next sample: the mouse sends none until the next drag,
        // and a face left tinted after the stroke would show what no longer is.
        feedback.pen_seen = false;
        if (!state.pen_down) {
          reject("pen up without pen down");
          break;
        }
        state.pen_down = false;
        EditRequest r{RequestKind::Edit, {}, ev.t_us, ev.line};
        r.command.points = std::move(state.stroke);
        state.stroke.clear();
        // A resting pen's filter can repeat a sample exactly; a curve's consecutive points differ.
        r.command.points.erase(std::unique(r.command.points.begin(), r.command.points.end()), r.command.points.end());
        if (r.command.points.size() < 2) {
          reject("the stroke has " + std::to_string(r.command.points.size()) + " pen sample(s); a curve needs at least 2");
          break;
        }
        bool finite = true;
        for (const Vec3& p : r.command.points) finite = finite && is_finite(p);
        if (!finite) {
          reject("the stroke has a pen sample that is not finite (NaN or infinity)");
          break;
        }
        const double end_snap = radius(state.end_snap), both_snap = std::max(radius(state.start_snap), end_snap);
        if (mesh.edge_count() == 0) {
          r.command.kind = EditKind::StartBorder;
        } else if (mesh.border_in_progress()) {
          auto [first, last] = border_ends(mesh);
          const Vec3& first_position = mesh.vertices.position[first];
          double gap = (r.command.points.back() - first_position).norm();
          r.command.kind = gap <= end_snap ? EditKind::CloseBorder : EditKind::AppendBorder;
          r.command.snap_distance = end_snap;
          blend_ends(r.command.points, mesh.vertices.position[last],
                     r.command.kind == EditKind::CloseBorder ? first_position : r.command.points.back(), 1);
        } else {
          // A stroke in pieces: one that ends off the network waits as a pending chain, and the next stroke from
          // its free end goes on with it, until one reaches the network and the whole curve is drawn.
          EdgeIndex chain_last;
          if (settings.topology_strokes && mesh.face_count() > 0) {
            const double start_radius = radius(state.start_snap);
            const bool end_on_network = network_nearest(mesh, snap, r.command.points.back(), end_snap).found();
            const std::vector<std::vector<EdgeIndex>> chains = mesh.pending_chains();
            double nearest_free_end = std::numeric_limits<double>::infinity();
            const std::vector<EdgeIndex>* chain = nullptr;
            for (const std::vector<EdgeIndex>& c : chains) {
              const double d = (mesh.vertices.position[mesh.edges.vertex[c.back()][1]] - r.command.points.front()).norm();
              if (d < nearest_free_end) {
                nearest_free_end = d;
                chain = &c;
              }
            }
            if (chain && nearest_free_end <= start_radius) {
              chain_last = chain->back();
              blend_ends(r.command.points, mesh.vertices.position[mesh.edges.vertex[chain_last][1]], r.command.points.back(), settings.blend_reach);
              if (!end_on_network) {
                r.command.kind = EditKind::ExtendChain;
                r.command.edge = chain_last;
                requests.push_back(std::move(r));
                break;
              }
              std::vector<Vec3> whole = chain_points(mesh, *chain);
              whole.insert(whole.end(), r.command.points.begin() + 1, r.command.points.end());
              r.command.points = std::move(whole);
            } else if (const SnapHit start_hit = network_nearest(mesh, snap, r.command.points.front(), start_radius); start_hit.found()) {
              if (!end_on_network) {
                r.command.kind = EditKind::ExtendChain;
                blend_ends(r.command.points, mesh.polyline(start_hit.edge)[start_hit.point], r.command.points.back(), settings.blend_reach);
                requests.push_back(std::move(r));
                break;
              }
            } else if (chain) {
              reject("the stroke starts " + format_mm(nearest_free_end) + " from the free end of the pending stroke, farther than " +
                     format_mm(start_radius) + ", and away from every curve: go on from that end, or undo the pending pieces");
              break;
            }
          }
          // A face holding both ends takes the stroke, as the thesis's sketch model has it. Else the stroke may run
          // over several faces, cross a border loop's hole (the far side of the surface), or, far from every
          // curve, start a new part.
          Snap s = snap_to_face(mesh, snap, r.command.points.front(), r.command.points.back(), both_snap);
          // No camera saw it (the mouse): of the faces that hold both ends, the one its middle sample lies in.
          if (s.face != kNone && settings.middle_picks_face && !viewpoint) {
            const Vec3& middle = r.command.points[r.command.points.size() / 2];
            const Snap holding = snap_to_face(mesh, snap, r.command.points.front(), r.command.points.back(), both_snap,
                                              [&](const Snap& c) { return height_inside(mesh, c.face, middle).has_value(); });
            if (holding.face != kNone) s = holding;
          }
          // Seen from the cameras, a stroke goes into the face it splits. Where several faces, or a face and a
          // border loop's hole (the far side, drawn with the object turned over), hold both ends, that tells them
          // apart: of the faces, the nearest one it goes into; into none, the hole. Which way the faces turn about
          // the outside is read where an end lands on a vertex of three or more curves. Only the ends drawn in this
          // pose are judged: a chain's start was drawn from where the camera was then.
          bool far_side = false;
          if (s.face != kNone && settings.topology_strokes && viewpoint) {
            const std::vector<Vec3>& ahead = r.command.points;
            const std::vector<Vec3> back(ahead.rbegin(), ahead.rend());
            const bool start_judged = chain_last == kNone;
            auto vertex_of = [&](const CurveEnd& e) {
              return e.point == 0 ? mesh.edges.vertex[e.edge][0]
                     : e.point + 1 == mesh.edges.point_count[e.edge] ? mesh.edges.vertex[e.edge][1] : kNone;
            };
            // Each judged end of the stroke as it lands on face c's boundary, with the path from it.
            auto judged_ends = [&](const Snap& c) {
              const std::span<const OrientedEdge> loop = mesh.face_loop(c.face);
              std::vector<std::pair<CurveEnd, std::span<const Vec3>>> out;
              if (start_judged) out.emplace_back(at_vertex(mesh, loop, c.start, ahead.front(), vertex_radius(state.start_snap)), ahead);
              out.emplace_back(at_vertex(mesh, loop, c.end, ahead.back(), vertex_radius(state.end_snap)), back);
              return out;
            };
            auto fan_of = [&](const CurveEnd& e, std::span<const Vec3> path) -> std::optional<Fan> {
              const VertexIndex v{vertex_of(e)};
              if (v == kNone) return std::nullopt;
              return fan_at(mesh, v, direction_along(path, mesh.vertices.position[v]), *viewpoint);
            };
            // The surface's normal at an end on face f's boundary, toward the camera. Where the camera looks along
            // the surface, the faces' turn about the outside, where known (`turn` not 0), orients it instead: face f
            // walks `turn` about it.
            auto normal_at = [&](const CurveEnd& e, std::span<const Vec3> path, FaceIndex f, int turn) {
              if (const std::optional<Fan> fan = fan_of(e, path)) return fan->normal;
              const Vec3 q = mesh.polyline(e.edge)[e.point];
              const Vec3 view = (*viewpoint - q).normalized();
              const std::optional<Vec3> plane = network_normal(mesh, snap, q);
              if (!plane) return view;
              Vec3 toward = view;
              if (std::abs(plane->dot(view)) < kSideCosine && turn != 0)
                if (const Vec3 walked = double(turn) * loop_plane(mesh.face_boundary(f)).normal; std::abs(plane->dot(walked)) >= kSideCosine)
                  toward = walked;
              return plane->dot(toward) < 0 ? Vec3(-*plane) : *plane;
            };
            // How many judged ends go into face c, of how many, with the faces turning `turn` about the outside (as
            // supposed, not known, while the part's first split finds it).
            auto ends_into = [&](const Snap& c, int turn, bool supposed = false) {
              const auto ends = judged_ends(c);
              size_t in = 0;
              for (const auto& [e, path] : ends)
                in += goes_into(mesh, c.face, e, path, normal_at(e, path, c.face, supposed ? 0 : turn), turn);
              return std::pair{in, ends.size()};
            };
            // The way the faces turn: as the part's first split found it; else as the fans at the judged ends say.
            const std::vector<uint32_t> part = part_labels(mesh);
            auto part_of = [&](FaceIndex f) { return part[mesh.tail(mesh.face_loop(f)[0])]; };
            auto faces_in = [&](uint32_t p) {
              size_t n = 0;
              for (FaceIndex f{0}; f < mesh.face_slots(); ++f) n += mesh.face_alive(f) && part_of(f) == p;
              return n;
            };
            // A part drawn back to its border by undo is split first again, maybe from its other side.
            std::erase_if(state.outside, [&](const OutsideTurn& o) { return !mesh.valid(o.at) || faces_in(part[o.at.index]) < 2; });
            int turn = 0;
            const uint32_t here = part_of(s.face);
            if (const auto known = std::find_if(state.outside.begin(), state.outside.end(), [&](const OutsideTurn& o) { return part[o.at.index] == here; });
                known != state.outside.end()) {
              turn = known->turn;
            } else if (faces_in(here) == 1) {
              const auto [in, judged] = ends_into(s, 1, true);
              if (in == judged || in == 0) state.outside.push_back({mesh.vertex_id(mesh.tail(mesh.face_loop(s.face)[0])), int8_t(in == 0 ? -1 : 1)});
            } else {
              for (const auto& [e, path] : judged_ends(s))
                if (const std::optional<Fan> fan = fan_of(e, path))
                  if (const int t = fan_turn(mesh, *fan, vertex_of(e)); t != 0) turn = turn == 0 || turn == t ? t : 2;
            }
            if (turn == 1 || turn == -1) {
              if (const auto [in, judged] = ends_into(s, turn); in < judged) {
                const Snap inside = snap_to_face(mesh, snap, ahead.front(), ahead.back(), both_snap, [&](const Snap& c) {
                  const auto [c_in, c_judged] = ends_into(c, turn);
                  return c_in == c_judged;
                });
                if (inside.face != kNone) {
                  s = inside;
                } else if (in == 0 && !snap_to_hole(mesh, snap, ahead.front(), ahead.back(), both_snap).rim.empty()) {
                  far_side = true;
                  s = Snap{};
                }
              }
            }
          }
          // A stroke over several faces is cut where it crosses curves.
          if (s.face == kNone && settings.topology_strokes && !far_side) {
            std::string refusal;
            std::optional<EditCommand> crossing =
                plan_crossing(mesh, snap, r.command.points, radius(state.start_snap), end_snap, vertex_radius(state.start_snap),
                              vertex_radius(state.end_snap), settings.vertex_snap, settings.blend_reach, refusal);
            if (!refusal.empty()) {
              reject(refusal);
              break;
            }
            if (crossing) {
              r.command = std::move(*crossing);
              r.command.edge = chain_last;
              requests.push_back(std::move(r));
              break;
            }
          }
          const HoleSnap h = s.face == kNone && settings.topology_strokes ? snap_to_hole(mesh, snap, r.command.points.front(), r.command.points.back(), both_snap) : HoleSnap{};
          if (s.face == kNone && h.rim.empty()) {
            const SnapHit start_hit = snap.nearest(r.command.points.front()), end_hit = snap.nearest(r.command.points.back());
            if (settings.topology_strokes && start_hit.distance > radius(state.start_snap) && end_hit.distance > end_snap) {
              r.command.kind = EditKind::StartBorder;
              requests.push_back(std::move(r));
              break;
            }
            // How far each end is from any curve tells a person which end missed.
            reject("the stroke does not start and end on the boundary of one face: no face or border loop has both ends within " +
                   format_mm(both_snap) + " (the start is " + format_mm(start_hit.distance) + " from the nearest curve, the end " +
                   format_mm(end_hit.distance) + ")");
            break;
          }
          const std::span<const OrientedEdge> loop = s.face != kNone ? mesh.face_loop(s.face) : std::span<const OrientedEdge>(h.rim);
          const std::span<const OrientedEdge> end_loop = s.face != kNone ? loop : std::span<const OrientedEdge>(h.end_rim);
          r.command.kind = s.face != kNone ? EditKind::SplitFace : h.join ? EditKind::JoinBorders : EditKind::SplitHole;
          r.command.face = s.face;
          r.command.start = at_vertex(mesh, loop, s.face != kNone ? s.start : h.start, r.command.points.front(), vertex_radius(state.start_snap));
          r.command.end = at_vertex(mesh, end_loop, s.face != kNone ? s.end : h.end, r.command.points.back(), vertex_radius(state.end_snap));
          const Vec3& start = mesh.polyline(r.command.start.edge)[r.command.start.point];
          const Vec3& end = mesh.polyline(r.command.end.edge)[r.command.end.point];
          drop_pauses(r.command.points, start, vertex_radius(state.start_snap), end, vertex_radius(state.end_snap));
          blend_ends(r.command.points, start, end, settings.blend_reach);
          r.command.edge = chain_last;
        }
        requests.push_back(std::move(r));
        break;
      }
      case EventKind::Command: {
        EditRequest r{RequestKind::Edit, {}, ev.t_us, ev.line};
        if (is_touch_command(ev.command)) {
          // The registration system's: the pen was resting on a mark, and what it drew since it went down was a
          // touch of it (a pen far from the cameras flickers in depth), not a stroke.
          state.pen_down = false;
          state.stroke.clear();
          break;
        }
        if (ev.command == CommandKind::Register) break;  // the registration system's
        if (ev.command == CommandKind::Undo) r.kind = RequestKind::Undo;
        else if (ev.command == CommandKind::Redo) r.kind = RequestKind::Redo;
        else if (ev.command == CommandKind::Close) {
          if (!mesh.border_in_progress()) {
            reject("close: there is no open border polygon");
            break;
          }
          auto [first, last] = border_ends(mesh);
          const Vec3 a = mesh.vertices.position[last], b = mesh.vertices.position[first];
          for (uint32_t k = 0; k < settings.close_samples; ++k) {
            double s = double(k) / double(settings.close_samples - 1);
            r.command.points.push_back(a + s * (b - a));
          }
          r.command.kind = EditKind::CloseBorder;
          r.command.snap_distance = settings.snap_distance;
        } else if (ev.command == CommandKind::Hole) {
          const FaceIndex f = face_under(mesh, ev.p);
          if (f == kNone) {
            reject("hole: no face under the picked point (" + format_double(ev.p.x()) + ", " + format_double(ev.p.y()) + ", " +
                   format_double(ev.p.z()) + ")");
            break;
          }
          r.command.kind = EditKind::MakeHole;
          r.command.face = f;
        } else {  // delete or sharp: the curve nearest to the picked point
          const bool remove = ev.command == CommandKind::Delete;
          const EdgeIndex e = pick_edge(snap, ev.p, settings.snap_distance);
          if (e == kNone) {
            reject(std::string(remove ? "delete" : "sharp") + ": no curve within " +
                   std::to_string(settings.snap_distance) + " of the picked point");
            break;
          }
          r.command.kind = remove ? EditKind::DeleteCurve : EditKind::ToggleSharp;
          r.command.edge = e;
        }
        requests.push_back(std::move(r));
        break;
      }
      case EventKind::Hid:
      case EventKind::Truth:
      case EventKind::Meta:
        break;  // device reports are the triangulate system's; truth and meta are not for replay
    }
  }
  publish_feedback(mesh, snap, state, radius(state.start_snap), vertex_radius(state.end_snap), feedback);
}

}  // namespace fire
