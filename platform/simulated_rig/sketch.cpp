// The sketch scene: a pen tracing a fixed list of strokes on an object, and the object's triangles that hide it.
#include <algorithm>
#include <cmath>
#include <limits>

#include "platform/simulated_rig/simulated_rig_detail.hpp"

namespace fire::simulation {
using namespace detail;

namespace {

constexpr double kLedRadius = 0.0015;  // the LED's centre sits this far off the surface it touches

struct PlacedMesh {
  Triangles triangles;
  double height = 0;
  Vec3 base_centre = Vec3::Zero();  // on the object's axis at its lowest point
};

Result<PlacedMesh> place_mesh(const PolygonMeshView& mesh, double height_m, double distance_m) {
  using R = Result<PlacedMesh>;
  if (mesh.positions.empty() || mesh.face_offsets.size() < 2) return R::failure("the mesh has no faces");
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& p : mesh.positions) {
    if (!p.allFinite()) return R::failure("the mesh has a non-finite vertex");
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double extent = hi.z() - lo.z();
  if (!(extent > 0)) return R::failure("the mesh is flat along z (its up axis)");
  if (!(height_m > 0) || !std::isfinite(height_m)) return R::failure("the object height must be positive");
  const double scale = height_m / extent;
  // Model (x, y, z) with z up -> world (x, -z, y): a rotation about x, up becomes -y.
  const Vec3 axis(0.5 * (lo.x() + hi.x()), 0.5 * (lo.y() + hi.y()), lo.z());
  PlacedMesh out;
  out.height = height_m;
  out.base_centre = Vec3(0, 0.5 * height_m, distance_m);
  auto place = [&](const Vec3& p) -> Vec3 {
    const Vec3 q = (p - axis) * scale;
    return Vec3(q.x(), -q.z(), q.y()) + out.base_centre;
  };
  for (size_t f = 0; f + 1 < mesh.face_offsets.size(); ++f) {
    const uint32_t first = mesh.face_offsets[f], last = mesh.face_offsets[f + 1];
    if (last < first + 3 || last > mesh.face_vertices.size()) return R::failure("face " + std::to_string(f) + " is malformed");
    for (uint32_t k = first; k < last; ++k)
      if (mesh.face_vertices[k] >= mesh.positions.size())
        return R::failure("face " + std::to_string(f) + " uses a vertex out of range");
    const Vec3 a = place(mesh.positions[mesh.face_vertices[first]]);
    for (uint32_t k = first + 1; k + 1 < last; ++k)
      out.triangles.push_back({a, place(mesh.positions[mesh.face_vertices[k]]), place(mesh.positions[mesh.face_vertices[k + 1]])});
  }
  return out;
}

// A stroke drawn from (theta0, h0) to (theta1, h1): azimuth about the object's axis (0 faces the
// cameras) and height as a fraction of the object's.
struct StrokePlan {
  double theta0_deg, h0, theta1_deg, h1;
};

constexpr StrokePlan kStrokePlans[] = {
    {0, 0.05, 0, 0.9},     {-55, 0.25, 55, 0.25},  {-30, 0.05, -30, 0.9}, {-55, 0.45, 55, 0.45},
    {-50, 0.1, 40, 0.85},  {30, 0.05, 30, 0.9},    {-55, 0.08, 55, 0.08}, {-50, 0.05, -50, 0.9},
    {-55, 0.62, 55, 0.62}, {50, 0.15, -40, 0.7},   {50, 0.05, 50, 0.9},   {-50, 0.8, 50, 0.8},
};

// Samples the surface along the plan by casting horizontal rays outward from the axis; the
// outermost hit is the surface. The radius is smoothed over a few millimetres, as a pen tip
// glides over the facets of a polygonal model, and the LED sits kLedRadius outside.
std::vector<Vec3> stroke_path(const PlacedMesh& m, const StrokePlan& plan) {
  constexpr int kSamples = 800;
  std::vector<double> radius, theta, height;
  for (int i = 0; i <= kSamples; ++i) {
    const double u = static_cast<double>(i) / kSamples;
    const double th = (plan.theta0_deg + u * (plan.theta1_deg - plan.theta0_deg)) * std::numbers::pi / 180.0;
    const double h = (plan.h0 + u * (plan.h1 - plan.h0)) * m.height;
    const Vec3 origin = m.base_centre - Vec3(0, h, 0);
    const Vec3 dir(std::sin(th), 0, -std::cos(th));
    double best = -1;
    for (const auto& tri : m.triangles)
      if (const auto t = intersect(origin, dir, tri); t && *t > best) best = *t;
    if (best <= 0) break;  // the ray left the object: the stroke ends here
    radius.push_back(best);
    theta.push_back(th);
    height.push_back(h);
  }
  std::vector<Vec3> path;
  const int n = static_cast<int>(radius.size());
  if (n < 2) return path;
  constexpr int kHalfWindow = 15;
  constexpr double kSigma = 5.0;
  for (int i = 0; i < n; ++i) {
    double sum = 0, weight = 0;
    for (int k = std::max(0, i - kHalfWindow); k <= std::min(n - 1, i + kHalfWindow); ++k) {
      const double w = std::exp(-0.5 * (k - i) * (k - i) / (kSigma * kSigma));
      sum += w * radius[static_cast<size_t>(k)];
      weight += w;
    }
    const double r = sum / weight + kLedRadius;
    const auto s = static_cast<size_t>(i);
    path.push_back(m.base_centre - Vec3(0, height[s], 0) + r * Vec3(std::sin(theta[s]), 0, -std::cos(theta[s])));
  }
  return path;
}

}  // namespace

namespace detail {

std::optional<double> intersect(const Vec3& origin, const Vec3& dir, const std::array<Vec3, 3>& tri) {
  const Vec3 e1 = tri[1] - tri[0], e2 = tri[2] - tri[0];
  const Vec3 p = dir.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-18) return std::nullopt;
  const double inv = 1.0 / det;
  const Vec3 s = origin - tri[0];
  const double u = s.dot(p) * inv;
  if (u < 0 || u > 1) return std::nullopt;
  const Vec3 q = s.cross(e1);
  const double v = dir.dot(q) * inv;
  if (v < 0 || u + v > 1) return std::nullopt;
  return e2.dot(q) * inv;
}

bool crossed(const Triangles& tris, size_t first, size_t last, const Vec3& from, const Vec3& dir, double len) {
  for (size_t k = first; k < last; ++k) {
    const auto t = intersect(from, dir, tris[k]);
    if (t && *t > 0 && *t < len) return true;
  }
  return false;
}

bool segment_blocked(const Triangles& tris, const Vec3& from, const Vec3& to) {
  const Vec3 d = to - from;
  const double len = d.norm();
  return crossed(tris, 0, tris.size(), from, d / len, len);
}

}  // namespace detail

Result<SimulatedSession> simulate_sketch(const RigOptions& o, const SketchOptions& sk, const PolygonMeshView& mesh) {
  using R = Result<SimulatedSession>;
  Result<SimulatedRig> rig = make_simulated_rig(o);
  if (!rig) return R::failure(rig.error());
  if (!(sk.duration_s > 0 && sk.duration_s <= 3600)) return R::failure("sketch duration must be within (0, 3600] s");
  if (sk.strokes < 1 || sk.strokes > 1000) return R::failure("strokes must be within 1..1000");
  if (!(sk.speed_m_s > 0.01 && sk.speed_m_s <= 5)) return R::failure("pen speed must be within (0.01, 5] m/s");
  if (!(sk.hold_s >= 0 && sk.hold_s <= 60)) return R::failure("hold must be within [0, 60] s");
  Result<PlacedMesh> placed = place_mesh(mesh, sk.height_m, o.target_distance_m);
  if (!placed) return R::failure(placed.error());

  constexpr double kAccel = 5.0;      // m/s^2, a brisk but human start and stop
  constexpr double kTravel_s = 0.6;   // unlit move from one stroke to the next
  constexpr double kLeadIn_s = 0.5;   // unlit before the first stroke
  std::vector<Polyline> strokes;
  std::vector<Segment> timeline;
  double t = kLeadIn_s;
  const size_t plan_count = std::size(kStrokePlans);
  for (int i = 0; i < sk.strokes && t < sk.duration_s; ++i) {
    StrokePlan plan = kStrokePlans[static_cast<size_t>(i) % plan_count];
    // Later rounds of the plan list turn by a few degrees, so that no stroke repeats.
    const double turn = 7.0 * static_cast<double>(static_cast<size_t>(i) / plan_count);
    plan.theta0_deg += turn;
    plan.theta1_deg += turn;
    Polyline path = make_polyline(stroke_path(*placed, plan));
    if (path.points.size() < 2) continue;
    const int id = static_cast<int>(strokes.size());
    const Vec3 start = path.points.front(), end = path.points.back();
    const Vec3 prev = timeline.empty() ? start : timeline.back().from;
    if (timeline.empty()) {
      timeline.push_back({Phase::Travel, 0, t, id, start, start});
    } else {
      timeline.push_back({Phase::Travel, t, t + kTravel_s, id, prev, start});
      t += kTravel_s;
    }
    const double move = SpeedProfile{path.arc.back(), sk.speed_m_s, kAccel}.duration();
    timeline.push_back({Phase::Hold, t, t + sk.hold_s, id, start, start});
    t += sk.hold_s;
    timeline.push_back({Phase::Move, t, t + move, id, start, end});
    t += move;
    timeline.push_back({Phase::Hold, t, t + sk.hold_s, id, end, end});
    t += sk.hold_s;
    strokes.push_back(std::move(path));
  }
  if (strokes.empty()) return R::failure("no stroke could be placed on the mesh (does its +z axis point up?)");
  const double duration = std::min(sk.duration_s, t + 0.3);
  timeline.push_back({Phase::Travel, t, std::numeric_limits<double>::infinity(), -1, timeline.back().from,
                      timeline.back().from});

  Scene scene = [&](double time) { return pen_at(timeline, strokes, PenMotion{sk.speed_m_s, kAccel}, time); };
  std::vector<InputEvent> header = common_header("sketch", o);
  add_meta(header, "mesh", sk.mesh_name + " height_m=" + format_double(sk.height_m));
  add_meta(header, "sketch", "strokes=" + std::to_string(strokes.size()) + " speed_m_s=" + format_double(sk.speed_m_s) +
                                 " hold_s=" + format_double(sk.hold_s));
  const Occluded occluded = [&](double, const Vec3& light, const Vec3& centre) {
    return segment_blocked(placed->triangles, light, centre);
  };
  Result<SimulatedSession> session = run_session(o, Scenario::Sketch, *rig, duration, scene, occluded, std::move(header));
  if (session) session->stats.strokes = static_cast<int>(strokes.size());
  return session;
}

}  // namespace fire::simulation
