// The simulated person drawing a control mesh's curve network through the rig, pose by pose, with its marks
// and registrations (simulate_drawing), by the plan of drawing_plan.hpp.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>

#include "engine/text.hpp"
#include "platform/simulated_rig/simulated_rig_detail.hpp"
#include "systems/tracking/registration.hpp"
#include "tools/simulation/drawing_plan.hpp"

namespace fire::simulation {
using namespace tracking;  // the cameras, calibration and tracking this simulation feeds and checks
using namespace detail;

namespace {

// One way the object stands before the rig: world = R * object + t.
struct Pose {
  Eigen::Matrix3d R;
  Vec3 t;
  Triangles triangles;  // the object's surface, placed
  // Bounds of each run of kTrianglesPerBox triangles: a segment that misses them misses every one.
  std::vector<std::pair<Vec3, Vec3>> boxes;
  Vec3 operator()(const Vec3& object) const { return R * object + t; }
  void place(const Triangles& object);
};

constexpr size_t kTrianglesPerBox = 32;

void Pose::place(const Triangles& object) {
  for (const auto& tri : object) triangles.push_back({(*this)(tri[0]), (*this)(tri[1]), (*this)(tri[2])});
  constexpr double kPad = 1e-6;  // metres: keeps the test conservative against rounding
  for (size_t first = 0; first < triangles.size(); first += kTrianglesPerBox) {
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (size_t k = first; k < std::min(triangles.size(), first + kTrianglesPerBox); ++k)
      for (const Vec3& p : triangles[k]) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    boxes.push_back({lo - Vec3::Constant(kPad), hi + Vec3::Constant(kPad)});
  }
}

// Whether the segment from + s dir, s in [0, len], meets the box (slab test).
bool segment_meets_box(const Vec3& from, const Vec3& dir, double len, const std::pair<Vec3, Vec3>& box) {
  double near = 0, far = len;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(dir[a]) < 1e-12) {
      if (from[a] < box.first[a] || from[a] > box.second[a]) return false;
      continue;
    }
    double t0 = (box.first[a] - from[a]) / dir[a], t1 = (box.second[a] - from[a]) / dir[a];
    if (t0 > t1) std::swap(t0, t1);
    near = std::max(near, t0);
    far = std::min(far, t1);
    if (near > far) return false;
  }
  return true;
}

// A light on the limit surface lies within a millimetre of the object's faces (its limit surface, finely), on
// either side: the object hides it only beyond this distance toward the camera.
constexpr double kSurfaceClearance = 0.006;
constexpr double kImageMargin = 16;  // pixels: a blob this close to the image's edge may leave it
constexpr double kMarkSpacing = 0.02;  // metres between marks the person adds: registration needs them apart
constexpr int kMaxTurns = 36;
// How much further than --tilt the object leans where that tilt shows too little (into a vessel, under a base).
constexpr std::array<double, 4> kFurtherTilt_deg{0, 35, 60, 80};

bool hidden(const Pose& pose, const Vec3& light, const Vec3& centre) {
  const Vec3 u = (centre - light).normalized();
  const Vec3 from = light + kSurfaceClearance * u;
  const double len = (centre - from).norm();
  const Vec3 dir = (centre - from) / len;
  for (size_t b = 0; b < pose.boxes.size(); ++b)
    if (segment_meets_box(from, dir, len, pose.boxes[b]) &&
        crossed(pose.triangles, b * kTrianglesPerBox, std::min(pose.triangles.size(), (b + 1) * kTrianglesPerBox), from, dir, len))
      return true;
  return false;
}

bool seen_by_both(const SimulatedRig& rig, const Pose& pose, const Vec3& object_point) {
  const Vec3 X = pose(object_point);
  for (const Camera& c : rig.cameras) {
    if ((c.R * X + c.t).z() <= 0) return false;
    const Vec2 px = true_projection(c, X);
    if (px.x() < kImageMargin || px.x() > kWiimoteWidth - 1 - kImageMargin || px.y() < kImageMargin ||
        px.y() > kWiimoteHeight - 1 - kImageMargin)
      return false;
    if (hidden(pose, X, c.centre())) return false;
  }
  return true;
}

Status check_drawing(const DrawingOptions& d, const PolygonMeshView& object, const DrawingNetwork& net) {
  const std::pair<const char*, double> named[] = {{"speed", d.speed_m_s}, {"hold", d.hold_s}, {"mark hold", d.mark_hold_s},
                                                   {"tilt", d.tilt_deg}, {"height", d.height_m}};
  for (const auto& [name, value] : named)
    if (!std::isfinite(value)) return Status::failure(std::string("the ") + name + " must be a finite number");
  if (!(d.speed_m_s > 0.01 && d.speed_m_s <= 5)) return Status::failure("pen speed must be within (0.01, 5] m/s");
  if (!(d.hold_s >= 0 && d.hold_s <= 10)) return Status::failure("hold must be within [0, 10] s");
  if (!(d.mark_hold_s >= 0.8 && d.mark_hold_s <= 10))
    return Status::failure("mark hold must be within [0.8, 10] s (registration averages the pen's last 0.5 s on a mark)");
  if (!(std::abs(d.tilt_deg) <= 60)) return Status::failure("tilt must be within [-60, 60] degrees");
  if (d.turns < 1 || d.turns > kMaxTurns) return Status::failure("turns must be within 1.." + std::to_string(kMaxTurns));
  if (d.undo_after < 0 || d.max_strokes < 0) return Status::failure("undo-after and max-strokes must not be negative");
  if (object.positions.empty() || object.face_offsets.size() < 2) return Status::failure("the object has no faces");
  if (net.curves.empty()) return Status::failure("the network has no curves");
  for (size_t k = 0; k < net.curves.size(); ++k) {
    const DrawingCurve& c = net.curves[k];
    if (c.a >= net.vertices.size() || c.b >= net.vertices.size() || c.a == c.b || c.points.size() < 2)
      return Status::failure("network curve " + std::to_string(k) + " is malformed (vertices out of range, a loop or fewer than 2 points)");
    for (const Vec3& p : c.points)
      if (!p.allFinite()) return Status::failure("network curve " + std::to_string(k) + " has a non-finite point");
  }
  return Status::success();
}

// How far p lies from the line through `points` (their principal axis; infinitely far from fewer than 2).
double off_line(const std::vector<Vec3>& points, const Vec3& p) {
  if (points.size() < 2) return std::numeric_limits<double>::infinity();
  Vec3 centre = Vec3::Zero();
  for (const Vec3& q : points) centre += q;
  centre /= static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Vec3& q : points) scatter += (q - centre) * (q - centre).transpose();
  const Vec3 axis = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(2);
  const Vec3 d = p - centre;
  return (d - d.dot(axis) * axis).norm();
}

// Marks on the network's curves, away from where the object rests either way up, until poses a and b both
// show 3 of them off one line: the object is registered in b on marks measured in a.
void add_shared_marks(const SimulatedRig& rig, const Pose& a, const Pose& b, const DrawingNetwork& net, double top,
                      std::vector<Vec3>& marks) {
  auto shared = [&] {
    std::vector<Vec3> out;
    for (const Vec3& m : marks)
      if (seen_by_both(rig, a, m) && seen_by_both(rig, b, m)) out.push_back(m);
    return out;
  };
  auto enough = [&](const std::vector<Vec3>& on) {
    if (on.size() < 3) return false;
    for (const Vec3& m : on)
      if (off_line(on, m) >= kMarkSpacing / 2) return true;
    return false;
  };
  for (std::vector<Vec3> now = shared(); !enough(now); now = shared()) {
    double best = kMarkSpacing;
    std::optional<Vec3> pick;
    for (const DrawingCurve& c : net.curves)
      for (const Vec3& p : c.points) {
        if (p.z() < 0.1 * top || p.z() > 0.9 * top) continue;
        double spread = off_line(now, p);
        for (const Vec3& m : marks) spread = std::min(spread, (p - m).norm());
        if (spread > best && seen_by_both(rig, a, p) && seen_by_both(rig, b, p)) best = spread, pick = p;
      }
    if (!pick) return;  // the registration in b then says so
    marks.push_back(*pick);
  }
}

// The object's farthest point from its up axis.
double object_radius(std::span<const Vec3> positions) {
  double r = 0;
  for (const Vec3& p : positions) r = std::max(r, std::hypot(p.x(), p.y()));
  return r;
}

// Three points of the table the object stands on (its base plane, z = 0, or z = its top upside down) around
// it, that both cameras see in the pose: the person touches them to give the object's +z (cmd table).
Result<std::vector<Vec3>> table_touches(const SimulatedRig& rig, const Pose& pose, double radius) {
  const bool upright = (pose.R * Vec3::UnitZ()).y() < 0;  // the world's up is -y
  double top = 0;
  for (const auto& tri : pose.triangles)
    for (const Vec3& p : tri) top = std::max(top, (pose.R.transpose() * (p - pose.t)).z());
  const double base = upright ? 0 : top;
  constexpr int kAround = 24;
  std::vector<Vec3> seen;
  for (int k = 0; k < kAround; ++k) {
    const double a = 2 * std::numbers::pi * k / kAround, r = 1.25 * radius + 0.02;
    const Vec3 p(r * std::cos(a), r * std::sin(a), base);
    if (seen_by_both(rig, pose, p)) seen.push_back(p);
  }
  if (seen.size() < 3)
    return Result<std::vector<Vec3>>::failure("--measure-marks: both cameras see the table around the object at " +
                                              std::to_string(seen.size()) + " of " + std::to_string(kAround) +
                                              " points in the first pose, its frame needs 3");
  // The two farthest apart, then the one farthest from their line.
  std::array<size_t, 3> pick{0, 1, 2};
  double best = -1;
  for (size_t i = 0; i < seen.size(); ++i)
    for (size_t j = i + 1; j < seen.size(); ++j)
      if ((seen[i] - seen[j]).norm() > best) best = (seen[i] - seen[j]).norm(), pick[0] = i, pick[1] = j;
  const Vec3 along = (seen[pick[1]] - seen[pick[0]]).normalized();
  best = -1;
  for (size_t k = 0; k < seen.size(); ++k) {
    const Vec3 d = seen[k] - seen[pick[0]];
    if (const double off = (d - d.dot(along) * along).norm(); off > best) best = off, pick[2] = k;
  }
  return std::vector<Vec3>{seen[pick[0]], seen[pick[2]], seen[pick[1]]};
}

}  // namespace

Result<std::vector<Vec3>> object_frame(std::span<const Vec3> positions, double height_m) {
  using R = Result<std::vector<Vec3>>;
  if (positions.empty()) return R::failure("the mesh has no vertices");
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& p : positions) {
    if (!p.allFinite()) return R::failure("the mesh has a non-finite vertex");
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  if (!(hi.z() > lo.z())) return R::failure("the mesh is flat along z (its up axis)");
  if (!(height_m > 0) || !std::isfinite(height_m)) return R::failure("the object height must be positive");
  const double scale = height_m / (hi.z() - lo.z());
  const Vec3 base(0.5 * (lo.x() + hi.x()), 0.5 * (lo.y() + hi.y()), lo.z());
  std::vector<Vec3> out;
  out.reserve(positions.size());
  for (const Vec3& p : positions) out.push_back((p - base) * scale);
  return out;
}

Result<int> close_small_holes(PolygonMesh& mesh, std::vector<uint32_t>& sharp_edges, std::vector<uint8_t>& border_corners,
                              double narrowest_m) {
  using R = Result<int>;
  const auto key = [](uint32_t a, uint32_t b) { return std::pair{std::min(a, b), std::max(a, b)}; };
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    const auto face = mesh.face(f);
    for (size_t k = 0; k < face.size(); ++k) ++uses[key(face[k], face[(k + 1) % face.size()])];
  }
  // Each border edge as its face walks it; a loop follows them from vertex to vertex.
  std::map<uint32_t, uint32_t> next;
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    const auto face = mesh.face(f);
    for (size_t k = 0; k < face.size(); ++k) {
      const uint32_t a = face[k], b = face[(k + 1) % face.size()];
      if (uses[key(a, b)] != 1) continue;
      if (!next.emplace(a, b).second) return R::failure("vertex " + std::to_string(a) + " lies on the border twice");
    }
  }
  std::vector<uint32_t> merged_into(mesh.positions.size());
  std::iota(merged_into.begin(), merged_into.end(), 0u);
  int closed = 0;
  std::vector<uint8_t> walked(mesh.positions.size(), 0), in_closed_loop(mesh.positions.size(), 0);
  std::vector<Vec3> position = mesh.positions;  // `mesh` is left alone unless every hole closes
  for (const auto& [start, unused] : next) {
    if (walked[start]) continue;
    std::vector<uint32_t> loop;
    bool open = false;  // a border that stops (faces turned against each other) is no hole to close
    for (uint32_t v = start; !walked[v] && !open;) {
      walked[v] = 1;
      loop.push_back(v);
      const auto after = next.find(v);
      open = after == next.end();
      if (!open) v = after->second;
    }
    if (open) continue;
    Vec3 centre = Vec3::Zero();
    for (uint32_t v : loop) centre += position[v];
    centre /= static_cast<double>(loop.size());
    double across = 0;
    for (uint32_t v : loop) across = std::max(across, 2 * (position[v] - centre).norm());
    if (across >= narrowest_m) continue;
    position[start] = centre;
    for (uint32_t v : loop) merged_into[v] = start, in_closed_loop[v] = 1;
    ++closed;
  }
  if (closed == 0) return 0;

  constexpr uint32_t kNoVertex = ~0u;
  PolygonMesh out;
  std::vector<uint32_t> number(mesh.positions.size(), kNoVertex);
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    std::vector<uint32_t> face;
    for (uint32_t v : mesh.face(f))
      if (face.empty() || merged_into[v] != face.back()) face.push_back(merged_into[v]);
    while (face.size() > 1 && face.front() == face.back()) face.pop_back();
    if (face.size() < 3) continue;
    for (uint32_t v : face) {
      if (number[v] == kNoVertex) {
        number[v] = static_cast<uint32_t>(out.positions.size());
        out.positions.push_back(position[v]);
      }
      out.face_vertices.push_back(number[v]);
    }
    out.face_offsets.push_back(static_cast<uint32_t>(out.face_vertices.size()));
  }
  std::map<std::pair<uint32_t, uint32_t>, int> uses_after;
  for (uint32_t f = 0; f < out.face_count(); ++f) {
    const auto face = out.face(f);
    for (size_t k = 0; k < face.size(); ++k)
      if (++uses_after[key(face[k], face[(k + 1) % face.size()])] > 2)
        return R::failure("closing a hole under " + format_mm(narrowest_m) + " across would give edge " + std::to_string(face[k]) +
                          "-" + std::to_string(face[(k + 1) % face.size()]) + " a third face");
  }
  std::vector<uint32_t> sharp;
  for (size_t k = 0; k + 1 < sharp_edges.size(); k += 2) {
    const uint32_t a = number[merged_into[sharp_edges[k]]], b = number[merged_into[sharp_edges[k + 1]]];
    if (a != kNoVertex && b != kNoVertex && a != b) sharp.insert(sharp.end(), {a, b});
  }
  if (!border_corners.empty()) {
    std::vector<uint8_t> corners(out.positions.size(), 0);
    for (uint32_t v = 0; v < border_corners.size(); ++v)
      if (!in_closed_loop[v] && number[v] != kNoVertex) corners[number[v]] = border_corners[v];
    border_corners = std::move(corners);
  }
  sharp_edges = std::move(sharp);
  mesh = std::move(out);
  return closed;
}

Result<SimulatedDrawing> simulate_drawing(const RigOptions& o, const DrawingOptions& d, const PolygonMeshView& object,
                                          const DrawingNetwork& net) {
  using R = Result<SimulatedDrawing>;
  Result<SimulatedRig> rig = make_simulated_rig(o);
  if (!rig) return R::failure(rig.error());
  if (Status s = check_drawing(d, object, net); !s) return R::failure(s.error);

  // The object's control mesh as triangles, and its poses: standing (+z up is the world's -y), turned by
  // 360/turns degrees about its up axis, leaning its top toward the cameras, its middle where they converge.
  Triangles triangles;
  double top = 0;
  for (const Vec3& p : object.positions) top = std::max(top, p.z());
  for (size_t f = 0; f + 1 < object.face_offsets.size(); ++f) {
    const uint32_t first = object.face_offsets[f], last = object.face_offsets[f + 1];
    if (last < first + 3 || last > object.face_vertices.size()) return R::failure("face " + std::to_string(f) + " is malformed");
    for (uint32_t k = first; k < last; ++k)
      if (object.face_vertices[k] >= object.positions.size()) return R::failure("face " + std::to_string(f) + " uses a vertex out of range");
    for (uint32_t k = first + 1; k + 1 < last; ++k)
      triangles.push_back({object.positions[object.face_vertices[first]], object.positions[object.face_vertices[k]],
                           object.positions[object.face_vertices[k + 1]]});
  }
  // The poses: standing, turned by 360/turns degrees about its up axis, leaning its top toward the cameras,
  // its middle where they converge; and, where the object needs it (a closed one always), the same upside down
  // (poses turns..2 turns-1), turned over about its x axis.
  std::vector<Pose> poses;
  std::vector<Vec3> marks;
  std::vector<std::vector<uint32_t>> marks_seen;
  std::vector<std::vector<char>> shows;
  std::vector<std::vector<std::vector<char>>> seen;
  const bool closed = network_closed(net);
  auto attempt = [&](int sides, int tilts, int turns) -> Result<DrawingPlan> {
    Eigen::Matrix3d standing;
    standing << 1, 0, 0, 0, 0, -1, 0, 1, 0;
    const Eigen::Matrix3d over = Eigen::AngleAxisd(std::numbers::pi, Vec3::UnitX()).toRotationMatrix();
    poses.clear();
    for (int side = 0; side < sides; ++side)
      for (int tilt = 0; tilt < tilts; ++tilt) {
        const double lean_deg = d.tilt_deg + kFurtherTilt_deg[static_cast<size_t>(tilt)];
        const Eigen::Matrix3d lean = Eigen::AngleAxisd(lean_deg * std::numbers::pi / 180, Vec3::UnitX()).toRotationMatrix();
        for (int j = 0; j < turns; ++j) {
          const double turn = 2 * std::numbers::pi * j / turns;
          Pose pose;
          pose.R = lean * standing * (side ? over : Eigen::Matrix3d::Identity()) * Eigen::AngleAxisd(-turn, Vec3::UnitZ()).toRotationMatrix();
          pose.t = Vec3(0, 0, o.target_distance_m) - pose.R * Vec3(0, 0, 0.5 * top);
          pose.place(triangles);
          poses.push_back(std::move(pose));
        }
      }

    // Six marks among the network's vertices: around the object every 60 degrees, at a fifth and at half its
    // height; on a closed object at a third and two thirds, where it is seen both ways up and rests on neither.
    constexpr int kMarks = 6;
    const double low = closed ? 1.0 / 3 : 0.2, high = closed ? 2.0 / 3 : 0.5;
    marks.clear();
    for (int k = 0; k < kMarks; ++k) {
      const double azimuth = 2 * k * std::numbers::pi / kMarks, height = (k % 2 ? high : low) * top;
      double best = std::numeric_limits<double>::infinity();
      const Vec3* pick = &net.vertices.front();
      for (const Vec3& p : net.vertices) {
        if (std::find(marks.begin(), marks.end(), p) != marks.end() || std::hypot(p.x(), p.y()) < 1e-6) continue;
        double off = std::abs(std::remainder(std::atan2(p.x(), -p.y()) - azimuth, 2 * std::numbers::pi));
        off += 3 * std::abs(p.z() - height) / top;
        if (off < best) best = off, pick = &p;
      }
      marks.push_back(*pick);
    }
    // A pose that sees fewer than 3 of them, or only marks on one line (the rotation about it is undetermined),
    // gets more, on its curves where both cameras see them and away from where the object rests in it (its base,
    // or its top upside down), each as far as can be from the marks it sees already and from their line.
    auto marks_in = [&](size_t pose) {
      std::vector<uint32_t> out;
      for (uint32_t m = 0; m < marks.size(); ++m)
        if (seen_by_both(*rig, poses[pose], marks[m])) out.push_back(m);
      return out;
    };
    // The line through marks (the principal axis of two or more), and how far p lies from it.
    auto off_line = [&](const std::vector<uint32_t>& on, const Vec3& p) {
      if (on.size() < 2) return std::numeric_limits<double>::infinity();
      Vec3 centre = Vec3::Zero();
      for (uint32_t m : on) centre += marks[m];
      centre /= static_cast<double>(on.size());
      Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
      for (uint32_t m : on) scatter += (marks[m] - centre) * (marks[m] - centre).transpose();
      const Vec3 axis = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(2);
      const Vec3 d = p - centre;
      return (d - d.dot(axis) * axis).norm();
    };
    auto spread_out = [&](const std::vector<uint32_t>& on) {
      if (on.size() < 3) return false;
      for (uint32_t m : on)
        if (off_line(on, marks[m]) >= kMarkSpacing / 2) return true;
      return false;
    };
    for (size_t j = 0; j < poses.size(); ++j) {
      const bool upside_down = sides == 2 && j >= poses.size() / 2;
      for (std::vector<uint32_t> now = marks_in(j); !spread_out(now); now = marks_in(j)) {
        double best = kMarkSpacing;
        std::optional<Vec3> pick;
        for (const DrawingCurve& c : net.curves)
          for (const Vec3& p : c.points) {
            if (upside_down ? p.z() > 0.9 * top : p.z() < 0.1 * top) continue;
            double spread = off_line(now, p);
            for (const Vec3& m : marks) spread = std::min(spread, (p - m).norm());
            if (spread > best && seen_by_both(*rig, poses[j], p)) best = spread, pick = p;
          }
        if (!pick) break;
        marks.push_back(*pick);
      }
    }
    marks_seen.assign(poses.size(), {});
    for (size_t j = 0; j < poses.size(); ++j) marks_seen[j] = marks_in(j);

    // Which points of each curve both cameras see in each pose (on a pose with at least 3 marks to register on).
    seen.assign(poses.size(), std::vector<std::vector<char>>(net.curves.size()));
    shows.assign(poses.size(), std::vector<char>(net.curves.size(), 0));
    for (size_t j = 0; j < poses.size(); ++j)
      for (size_t k = 0; k < net.curves.size(); ++k) {
        seen[j][k].assign(net.curves[k].points.size(), 0);
        if (marks_seen[j].size() >= 3)
          for (size_t i = 0; i < net.curves[k].points.size(); ++i) seen[j][k][i] = seen_by_both(*rig, poses[j], net.curves[k].points[i]);
        shows[j][k] = std::all_of(seen[j][k].begin(), seen[j][k].end(), [](char c) { return c != 0; });
      }
    PoseQuestions questions;
    // Poses nearest the current one first: the same way up and lean, then the other lean, then turned over.
    questions.order = [&](int current) {
      const int side = current / (tilts * turns), tilt = current / turns % tilts, turn = current % turns;
      std::vector<int> order;
      for (int s : {side, 1 - side}) {
        if (s >= sides) continue;
        std::vector<int> by_lean(static_cast<size_t>(tilts));
        std::iota(by_lean.begin(), by_lean.end(), 0);
        std::stable_sort(by_lean.begin(), by_lean.end(), [&](int x, int y) { return std::abs(x - tilt) < std::abs(y - tilt); });
        for (int t : by_lean) {
          const int base = (s * tilts + t) * turns;
          order.push_back(base + turn);
          for (int step = 1; step <= turns / 2; ++step)
            for (int j : {(turn + step) % turns, (turn - step + turns) % turns})
              if (std::find(order.begin(), order.end(), base + j) == order.end()) order.push_back(base + j);
        }
      }
      return order;
    };
    questions.sees = [&](int pose, uint32_t curve, size_t point) { return seen[static_cast<size_t>(pose)][curve][point] != 0; };
    return plan_drawing(net, questions, d.max_strokes, d.undo_after);
  };
  // Upside down, and leaning further, only where the object needs it.
  const int tilts = static_cast<int>(kFurtherTilt_deg.size());
  Result<DrawingPlan> planned = attempt(closed ? 2 : 1, 1, d.turns);
  if (!planned && !closed) planned = attempt(2, 1, d.turns);
  if (!planned) planned = attempt(2, tilts, d.turns);
  // Turned in finer steps only where the coarse ones show too little: into a cup between its handle's roots.
  if (!planned && 2 * d.turns <= kMaxTurns) planned = attempt(2, tilts, 2 * d.turns);
  if (!planned) return R::failure(planned.error());
  const std::vector<PlanStep>& plan = planned->steps;
  if (d.measure_marks) {
    // Marks measured in one pose are all the next registers on: where two poses the object is turned between
    // share fewer than 3 marks off one line, the person sticks more on where both show them.
    int from = -1;
    for (const PlanStep& step : plan) {
      if (step.kind != PlanStep::Kind::Register) continue;
      if (from >= 0 && from != step.pose) add_shared_marks(*rig, poses[size_t(from)], poses[size_t(step.pose)], net, top, marks);
      from = step.pose;
    }
    for (size_t j = 0; j < poses.size(); ++j) {
      marks_seen[j].clear();
      for (uint32_t m = 0; m < marks.size(); ++m)
        if (seen_by_both(*rig, poses[j], marks[m])) marks_seen[j].push_back(m);
    }
  }

  // The timeline: where the pen is, lit or not, and when each command is logged.
  constexpr double kAccel = 2.0;     // m/s^2, a hand drawing with care
  constexpr double kTravel_s = 0.6;  // the pen lifted from one stroke or mark to the next: longer than a gap a stroke survives
  constexpr double kTurn_s = 3.0;    // turning the object, the pen lifted
  constexpr double kUndoWait_s = 1.0;  // after a stroke, before its undo: its pen up has reached the sketch
  std::vector<Polyline> strokes;
  std::vector<Segment> timeline;
  std::vector<InputEvent> commands;
  std::vector<std::pair<double, int>> pose_from{{0.0, plan.front().pose}};
  DrawingStats stats;
  stats.curves_total = net.curves.size();
  stats.curves_drawn = planned->curves_drawn;
  double t = 0.5;
  Vec3 pen = poses[static_cast<size_t>(plan.front().pose)].t;
  auto command = [&](double at, CommandKind kind, uint32_t mark = 0, const Vec3& p = Vec3::Zero()) {
    InputEvent e;
    e.t_us = std::llround(at * 1e6);
    e.kind = EventKind::Command;
    e.command = kind;
    e.mark = mark;
    e.p = p;
    commands.push_back(std::move(e));
  };
  auto travel_to = [&](const Vec3& to, double seconds) {
    timeline.push_back({Phase::Travel, t, t + seconds, -1, pen, to});
    t += seconds;
    pen = to;
  };
  auto hold = [&](double seconds) {
    timeline.push_back({Phase::Hold, t, t + seconds, -1, pen, pen});
    t += seconds;
  };
  // The pen rests on a point of the object's frame (a mark, the table), and the command is logged.
  auto rest_on = [&](const Pose& placed, const Vec3& object_point, CommandKind kind, uint32_t mark, const Vec3& p) {
    travel_to(placed(object_point), kTravel_s);
    hold(d.mark_hold_s);
    command(t - 0.2, kind, mark, p);
  };
  std::vector<uint32_t> measured;
  bool first = true;
  for (const PlanStep& step : plan) {
    const Pose& placed = poses[static_cast<size_t>(step.pose)];
    switch (step.kind) {
      case PlanStep::Kind::Register: {
        const std::vector<uint32_t>& seen_here = marks_seen[static_cast<size_t>(step.pose)];
        auto is_measured = [&](uint32_t m) { return std::find(measured.begin(), measured.end(), m) != measured.end(); };
        if (!first && d.measure_marks) {
          // Before turning the object, the marks the next pose shows that are not measured yet are, where the
          // present pose shows them too.
          const int from = std::prev(pose_from.end())->second;
          const std::vector<uint32_t>& seen_now = marks_seen[static_cast<size_t>(from)];
          for (uint32_t m : seen_here)
            if (!is_measured(m) && std::find(seen_now.begin(), seen_now.end(), m) != seen_now.end()) {
              rest_on(poses[static_cast<size_t>(from)], marks[m], CommandKind::Measure, m, Vec3::Zero());
              measured.push_back(m);
              ++stats.mark_touches;
            }
        }
        if (!first) {
          pose_from.emplace_back(t + 0.5 * kTurn_s, step.pose);
          travel_to(pen, kTurn_s);
        }
        std::vector<uint32_t> to_measure;
        if (!d.measure_marks) {
          for (uint32_t m : seen_here) rest_on(placed, marks[m], CommandKind::Mark, m, marks[m]);
          stats.mark_touches += static_cast<int>(seen_here.size());
        } else if (first) {
          // The first round makes the object's frame: the table, then every mark seen, measured.
          Result<std::vector<Vec3>> table = table_touches(*rig, placed, object_radius(object.positions));
          if (!table) return R::failure(table.error());
          for (const Vec3& p : *table) rest_on(placed, p, CommandKind::Table, 0, Vec3::Zero());
          for (uint32_t m : seen_here) rest_on(placed, marks[m], CommandKind::Measure, m, Vec3::Zero());
          stats.mark_touches += static_cast<int>(seen_here.size());
          measured = seen_here;
        } else {
          // Registered on the marks measured that it sees; then the others it sees are measured for later turns.
          size_t known = 0;
          for (uint32_t m : seen_here)
            if (is_measured(m)) {
              rest_on(placed, marks[m], CommandKind::MarkMeasured, m, Vec3::Zero());
              ++known;
            } else {
              to_measure.push_back(m);
            }
          if (known < 3)
            return R::failure("--measure-marks: pose " + std::to_string(step.pose) + " shows both cameras " + std::to_string(known) +
                              " mark(s) measured in the poses before it, a registration needs 3");
          stats.mark_touches += static_cast<int>(known);
        }
        first = false;
        travel_to(pen, 0.3);  // the pen lifted off the last mark
        command(t, CommandKind::Register);
        ++stats.registrations;
        for (uint32_t m : to_measure) {
          rest_on(placed, marks[m], CommandKind::Measure, m, Vec3::Zero());
          measured.push_back(m);
          ++stats.mark_touches;
        }
        if (!to_measure.empty()) travel_to(pen, 0.3);
        break;
      }
      case PlanStep::Kind::Stroke: {
        std::vector<Vec3> world;
        for (const Vec3& p : step.points) world.push_back(placed(p));
        Polyline path = make_polyline(std::move(world));
        travel_to(path.points.front(), kTravel_s);
        hold(d.hold_s);
        const double move = SpeedProfile{path.arc.back(), d.speed_m_s, kAccel}.duration();
        timeline.push_back({Phase::Move, t, t + move, static_cast<int>(strokes.size()), pen, path.points.back()});
        t += move;
        pen = path.points.back();
        hold(d.hold_s * 2 / 3);
        strokes.push_back(std::move(path));
        ++stats.strokes;
        break;
      }
      case PlanStep::Kind::Undo:
        travel_to(pen, kUndoWait_s);
        command(t, CommandKind::Undo);
        ++stats.undos;
        break;
      case PlanStep::Kind::Hole:
      case PlanStep::Kind::Sharp: {
        // The pen touches the face to open or the curve to mark sharp, unlit, and the pad's button is pressed.
        const bool hole = step.kind == PlanStep::Kind::Hole;
        travel_to(placed(step.points.front()), kTravel_s);
        hold(d.mark_hold_s);
        command(t - 0.2, hole ? CommandKind::Hole : CommandKind::Sharp, 0, step.points.front());
        ++(hole ? stats.holes : stats.sharp);
        break;
      }
    }
  }
  std::vector<int> used;
  for (const PlanStep& step : plan) used.push_back(step.pose);
  std::sort(used.begin(), used.end());
  stats.poses = static_cast<int>(std::unique(used.begin(), used.end()) - used.begin());
  stats.border_strokes = planned->border_strokes;
  stats.pieces = planned->pieces;
  stats.split_strokes = stats.strokes - stats.border_strokes;
  const double duration = t + 1.0;
  if (duration > 3600) return R::failure("the drawing would last more than an hour (" + std::to_string(duration) + " s)");
  timeline.push_back({Phase::Travel, t, std::numeric_limits<double>::infinity(), -1, pen, pen});

  auto pose_at = [&](double time) -> const Pose& {
    const auto it = std::upper_bound(pose_from.begin(), pose_from.end(), time,
                                     [](double v, const std::pair<double, int>& p) { return v < p.first; });
    return poses[static_cast<size_t>(std::prev(it)->second)];
  };
  Scene scene = [&](double time) { return pen_at(timeline, strokes, PenMotion{d.speed_m_s, kAccel}, time); };
  const Occluded occluded = [&](double time, const Vec3& light, const Vec3& centre) { return hidden(pose_at(time), light, centre); };
  std::vector<InputEvent> header = common_header("drawing", o);
  add_meta(header, "mesh", d.mesh_name + " height_m=" + format_double(d.height_m));
  add_meta(header, "drawing", "strokes=" + std::to_string(stats.strokes) + " undos=" + std::to_string(stats.undos) +
                                  " registrations=" + std::to_string(stats.registrations) + " curves=" +
                                  std::to_string(stats.curves_drawn) + "/" + std::to_string(stats.curves_total) +
                                  " speed_m_s=" + format_double(d.speed_m_s));
  SimulatedDrawing out;
  out.session = run_session(o, Scenario::Drawing, *rig, duration, scene, occluded, std::move(header), commands);
  out.session.stats.strokes = stats.strokes;
  out.marks = marks;
  out.drawing = stats;
  return out;
}

DrawingNetwork drawing_network(const Mesh& m) {
  DrawingNetwork net;
  std::vector<uint32_t> curve_of(m.edge_slots(), 0);
  for (uint32_t v = 0; v < m.vertex_slots(); ++v) net.vertices.push_back(m.vertices.position[v]);
  for (EdgeIndex e{0}; e < m.edge_slots(); ++e) {
    if (!m.edge_alive(e)) continue;
    const std::span<const Vec3> points = m.polyline(e);
    curve_of[e] = static_cast<uint32_t>(net.curves.size());
    net.curves.push_back({m.edges.vertex[e][0], m.edges.vertex[e][1], {points.begin(), points.end()}, m.is_border_edge(e),
                          (m.edges.flags[e] & kSharpEdge) != 0});
  }
  for (FaceIndex f{0}; f < m.face_slots(); ++f) {
    if (!m.face_alive(f)) continue;
    Chain& loop = net.faces.emplace_back();
    for (OrientedEdge oe : m.face_loop(f)) loop.push_back({curve_of[edge_of(oe)], !is_reversed(oe)});
  }
  return net;
}

}  // namespace fire::simulation
